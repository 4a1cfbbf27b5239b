/* Tet4 elasticity (DESIGN §3.1): constant-gradient linear tetrahedra,
 * corotational (default) or small-strain ("linear", the source's) stress.
 *
 * Shape-function gradients: rows of Dm^-1 are grad N1..N3 (1/m),
 * grad N0 = -(grad N1 + grad N2 + grad N3).  F = Ds Dm^-1.
 * Corotational: F = R S, eps = sym(S) - I, sigma = lambda tr(eps) I + 2 mu eps,
 * f_i = -V R sigma grad N_i.  Small strain: eps = sym(F) - I, f_i = -V sigma grad N_i. */
#ifndef COHFRAC_TET4_H
#define COHFRAC_TET4_H

#include "solid.h"

/* Gradients of the 4 shape functions of tet t, [4][3], 1/m. */
void cf_tet4_gradients(const cf_solid *s, int t, double g[4][3]);

/* Fragments of fewer tets than this are done on one thread. */
#define CF_TET4_PARALLEL_MIN 4096

/* For each tet of the list: internal nodal forces into s->tf ([4][3] per
 * tet, N), strain energy V (1/2 sigma : eps) into s->tw (J) and, when
 * `want_stress`, the world-frame Cauchy stress into s->sigma (Pa).  Parallel
 * over tets (OpenMP) from CF_TET4_PARALLEL_MIN tets on; each tet writes only its own slots, so the result does
 * not depend on the thread count.  Returns the number of inverted tets
 * (det F <= 0). */
int cf_tet4_forces(cf_solid *s, const int *tets, int nt, cf_elasticity kind, int want_stress);

/* Add the per-tet forces to the nodes: f[node] += tf[slot], in list order. */
void cf_tet4_scatter(cf_solid *s, const int *tets, int nt);

/* Elastic strain energy of the listed tets (J), from the last force pass. */
double cf_tet4_strain_energy(const cf_solid *s, const int *tets, int nt);

#endif
