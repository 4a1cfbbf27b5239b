/* Pieces: connected parts of a set of tets, their mass properties and the
 * rigid state of a set of nodes (docs/physics.md §1, §9). */
#ifndef COHFRAC_PIECES_H
#define COHFRAC_PIECES_H

#include "solid.h"

/* Connected components of `tets` through shared nodes.  comp[i] receives the
 * component of tets[i]; components are numbered 0.. in order of their first
 * tet in the list.  Returns the number of components, or -1 out of memory. */
int cf_label_components(const cf_solid *s, const int *tets, int nt, int *comp);

/* The same, with the tets of each cohesive element coh[0..ncoh) that has a
 * node pair not yet failed counted as joined: the pieces a fracture-mode
 * fragment is in while its cracks still hold.  `tets` ascending, holding
 * both tets of every listed element. */
int cf_label_pieces(const cf_solid *s, const int *tets, int nt, const int *coh, int ncoh,
                    int *comp);

/* Mass properties of `tets` from the tet second moment (docs/physics.md §9):
 * per tet, int x x^T dm = (m/20)(sum_i x_i x_i^T + s s^T), s = sum_i x_i,
 * positions relative to the COM; I = tr(C) Id - C.
 * `pos` is s->X (rest) or s->x (current).  mass kg, com m, inertia kg m^2. */
typedef struct cf_mass_props {
    double mass;
    double com[3];
    double inertia[9];
} cf_mass_props;

void cf_tet_mass_props(const cf_solid *s, const int *tets, int nt, const double *pos,
                       cf_mass_props *mp);

/* Rigid state of a set of nodes from their lumped masses: total mass M (kg),
 * centre of mass (m), COM velocity (m/s), angular momentum about the COM
 * (kg m^2/s), kinetic energy (J), and the rotation R that best maps rest
 * onto current positions (shape matching: polar decomposition of
 * sum m (x - x_cm)(X - X_cm)^T), warm-started and updated through q. */
typedef struct cf_node_state {
    double M, com[3], v[3], L[3], ke;
    double R[9];
} cf_node_state;

void cf_nodes_state(const cf_solid *s, const int *nodes, int nn, double q[4], cf_node_state *st);

/* The same without the rotation (R left as zero): cheap momenta only. */
void cf_nodes_momenta(const cf_solid *s, const int *nodes, int nn, cf_node_state *st);

/* Adds m x of nodes[i0..i1-1], in that order, into mx[3] (kg m): the one
 * formula of a fragment's mass moment, whose change is the ledger's
 * gravity work, so that the step and the ledger's reset give the same bits
 * for the same positions. */
void cf_nodes_mass_moment_add(const cf_solid *s, const int *nodes, int i0, int i1, double mx[3]);

/* Global damping (docs/physics.md §8, source Table 6.1, Müller et al. 2007):
 * v_i += k (v_cm + w x r_i - v_i), w = I^-1 L.  k = 1 keeps only the rigid
 * motion; linear and angular momentum are preserved. */
void cf_global_damping(cf_solid *s, const int *nodes, int nn, double k);

/* Inertia tensor of the lumped point masses of `nodes` at positions `pos`
 * (s->X or s->x) about com, kg m^2. */
void cf_nodes_inertia(const cf_solid *s, const int *nodes, int nn, const double *pos,
                      const double com[3], double I[9]);

/* Angular velocity w = I^-1 L for the lumped point masses of `nodes` about
 * com (rad/s); zero when the inertia is singular. */
void cf_nodes_angular_velocity(const cf_solid *s, const int *nodes, int nn, const double com[3],
                               const double L[3], double w[3]);

#endif
