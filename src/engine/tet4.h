/* Tet4 elasticity (docs/physics.md §2): constant-gradient linear tetrahedra,
 * corotational (default) or small-strain ("linear", the source's) stress.
 *
 * Shape-function gradients: rows of Dm^-1 are grad N1..N3 (1/m),
 * grad N0 = -(grad N1 + grad N2 + grad N3).  F = Ds Dm^-1.
 * Corotational: F = R S, eps = sym(S) - I, sigma = lambda tr(eps) I + 2 mu eps,
 * f_i = -V R sigma grad N_i.  Small strain: eps = sym(F) - I, f_i = -V sigma grad N_i. */
#ifndef COHFRAC_TET4_H
#define COHFRAC_TET4_H

#include "solid.h"

/* Gradients of the 4 shape functions of tet t, [4][3], 1/m: the formula
 * the force kernel applies four tets at a time (tet_block), one tet here
 * (the tests' reference). */
static inline void cf_tet4_gradients(const cf_solid *s, int t, double g[4][3])
{
    const double *Di = &s->Dm_inv[9 * t];
    for (int i = 0; i < 3; i++) {
        g[i + 1][0] = Di[3 * i], g[i + 1][1] = Di[3 * i + 1], g[i + 1][2] = Di[3 * i + 2];
    }
    for (int c = 0; c < 3; c++)
        g[0][c] = -(g[1][c] + g[2][c] + g[3][c]);
}

/* Fragments of fewer tets than this are done on one thread. */
#define CF_TET4_PARALLEL_MIN 4096

/* The insertion criterion's bound (insertion.h): a tet is "hot" when the
 * upper bound of its largest principal stress reaches s1 (Pa), or the bound
 * of its largest shear stress (half the spread of the principal values)
 * reaches tau (Pa; INFINITY: not checked).  A facet can qualify for
 * insertion only near a hot tet, so with no hot tet the check costs nothing. */
typedef struct cf_stress_check {
    double s1, tau;
    const float *s1_tet; /* [nt] Pa or NULL: a tet's own s1 where it is above s1
                            (s->tet_floor, insertion.h) */
} cf_stress_check;

/* For each tet of the list: internal nodal forces into s->tf ([4][3] per
 * tet, N) and strain energy V (1/2 sigma : eps) into s->tw (J).  With
 * crushing (s->ep, docs/physics.md §2.1) the stress is returned to the
 * yield surface, the plastic strain s->ep updated and its work added to
 * s->wp (J).  With
 * `check` (a check is due; needs the fracture state of
 * cf_solid_init_facets), also the world-frame Cauchy stress into s->sigma
 * (Pa) and s->hot (0/1) per tet, and the number of hot tets into *n_hot.
 * With the bulk viscosity (s->bv_eta, docs/physics.md §2.3) the forces
 * also carry its pressure at the velocities s->v (the step's half-step
 * velocities), and its work over the step of length dt (s) that ended at
 * these positions is added to s->bv_work (J); the stress of the check is
 * the material's without it.
 * Parallel over tets (OpenMP) from CF_TET4_PARALLEL_MIN tets on; each tet
 * writes only its own slots, so the result does not depend on the thread
 * count.  Returns the number of inverted tets (det F <= 0). */
int cf_tet4_forces(cf_solid *s, const int *tets, int nt, cf_elasticity kind,
                   const cf_stress_check *check, double dt, int *n_hot);

/* An upper bound of the largest eigenvalue of the symmetric 3x3 matrix A
 * (Pa for a stress): the Tet4 kernel's hot-flag bound (the tighter of
 * Gershgorin's and the deviator's), widened so that rounding cannot bring
 * it below the eigenvalue. */
double cf_tet4_max_principal_bound(const double A[9]);

/* World-frame Cauchy stress of tet t at the current positions (Pa), from
 * the rotation warm start and the plastic strain (neither updated). */
void cf_tet4_stress(const cf_solid *s, int t, cf_elasticity kind, double sigma[9]);

/* The energy (J) a force pass at the current positions would give the nt
 * listed tets: strain energy, and the plastic work of their return to the
 * yield surface when crushing.  Reads only (no warm start or plastic
 * strain is updated); in tet order, one thread.  What a hand-off that
 * moves nodes of an unstressed fragment puts in. */
double cf_tet4_energy_now(const cf_solid *s, const int *tets, int nt, cf_elasticity kind);

/* A fragment going back to rigid mode: its tets' plastic strain is dropped
 * with their elastic strain (a rigid fragment keeps the rest shape, so on
 * re-entry its nodes start from it unstressed).  The plastic work already
 * dissipated (s->wp) stays.  The bulk viscosity's last rate is zeroed (the
 * fragment rests in rigid mode, so its next spell starts with no viscous
 * force), its work stays.  No-op without either. */
void cf_tet4_to_rigid(cf_solid *s, const int *tets, int nt);

/* Nodal forces of a fragment: f = m g at each of its nodes (nn of them),
 * then the tf slots of its tets (nt, ascending) added at their nodes in
 * list order, so each node's sum is in ascending tet order: the same bits
 * for any thread count (parallel over node ranges).  g: gravity, m/s^2. */
void cf_tet4_scatter(cf_solid *s, const int *tets, int nt, const int *nodes, int nn,
                     const double g[3]);

/* Elastic strain energy of the listed tets (J), from the last force pass. */
double cf_tet4_strain_energy(const cf_solid *s, const int *tets, int nt);

#endif
