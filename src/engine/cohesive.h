/* Cohesive elements: the facets where extrinsic insertion opened a crack
 * (docs/physics.md §5, §6).  Each holds three node pairs across the crack;
 * their tractions come from a cohesive law (cohesive_law.h: PPR first),
 * integrated at the nodes.  Openings in m, tractions in Pa, energies in J. */
#ifndef COHFRAC_COHESIVE_H
#define COHFRAC_COHESIVE_H

#include "cohesive_law.h"
#include "solid.h"

/* Add the forces of the cohesive elements elems[0..n) to s->f.
 * Nodal (Newton-Cotes) integration: each node pair carries traction * A/3,
 * A the current mid-surface area, normal from side A to side B.
 * Compression (Delta_n < 0, faces still facing each other, failed or not) is
 * a penalty T_n = K_p Delta_n with K_p = fc->kp Pa/m, capped per node pair so
 * that the pair is stable at step dt: K_p A/3 <= 1/(4 dt^2 (1/m_a + 1/m_b)),
 * a sixteenth of the two-mass limit, as a node pair may sit in ~8 elements
 * (docs/physics.md §6); kp = 0 means the cap; kp < 0: no penalty, for runs whose
 * PBD crack-contact constraint (cf_cohesive_project_contact) keeps the faces
 * apart.  The penalty's stiffness follows the cap, which changes with the
 * facet's area: on a pair that already overlaps it releases energy that no
 * load put in (measured: nodes at 100+ m/s in a 4.4 m/s drop), so the two
 * are never combined.  The tangential traction rises from
 * zero with the same capped stiffness (time continuity), and so does the
 * normal traction when fc->normal_rises is set (solver.time_continuity "both"),
 * until each meets the law's envelope.
 * Faces pressed together (the penalty engaged, T_n < 0) also carry Coulomb
 * friction when s->mat.crack_friction = mu > 0 (s->coh_fric holds their
 * state): a tangential traction that sticks with half the capped
 * stiffness and slides at mu |T_n|, on top of the law's
 * (docs/physics.md §6, regularisation 3).
 * Each element's absorbed work (the trapezoid of its pairs' forces over the
 * change of their separations, what the leapfrog's kinetic energy gives up
 * to them) and
 * stored energy are updated (cf_cohesive).  The penalty pushes along the
 * normal only, so it is not a potential: pressed faces that slide across a
 * turning normal can give out more than they took, and the stored energy
 * then falls below zero (docs/physics.md §6, §14.20).
 * Returns the number of node pairs in complete failure.
 * (Each element with the law `law` at `params`, scaled to its facet's
 * strength: law->scale.)  The elements are evaluated in parallel (OpenMP,
 * from CF_COHESIVE_PARALLEL_MIN on) into `pairs` ([3 n], the caller's
 * scratch), and their forces then added in list and pair order: the same
 * sums for any thread count. */
#define CF_COHESIVE_PARALLEL_MIN 256

/* One node pair's force of this evaluation: f (N) pulls node a towards b
 * (a < 0: the pair carries none). */
typedef struct cf_pair_force {
    int a, b;
    double f[3];
} cf_pair_force;

/* How the faces of cohesive elements meet: the compression penalty's
 * stiffness kp (Pa/m; 0 the cap, < 0 none) and whether the normal
 * traction rises from zero (the Coulomb coefficient of pressed faces is
 * the solid's material.crack_friction). */
typedef struct cf_face_contact {
    double kp;
    int normal_rises;
} cf_face_contact;

int cf_cohesive_forces(cf_solid *s, const cf_cohesive_law *law, const void *params,
                       const int *elems, int n, double dt, const cf_face_contact *fc,
                       cf_pair_force *pairs);

/* Energy of cohesive elements elems[0..n) (all of them when elems is NULL),
 * J: stored (recoverable, on the secant; includes compression penalty) and
 * dissipated (absorbed work minus stored; G_I A for a facet of area A opened
 * to complete failure in pure mode I). */
void cf_cohesive_energy(const cf_solid *s, const int *elems, int n, double *stored,
                        double *dissipated);

/* Drop the recoverable energy of elems[0..n) (a fragment handed to rigid
 * mode, whose openings reset): returns the energy dropped, J. */
double cf_cohesive_release(cf_solid *s, const int *elems, int n);

/* Fail every node pair of cohesive element e at once (a side crushed,
 * docs/physics.md §2.2): what it stores is dissipated, and it carries no
 * more traction (only the compression penalty of a failed pair). */
void cf_cohesive_fail(cf_solid *s, int e);

/* Where cohesive element e is now: its mid-surface centre (m), unit normal
 * (A -> B) and area (m^2), its normal and tangential openings (m, means of
 * its three node pairs) and whether every pair has failed. */
void cf_cohesive_state(const cf_solid *s, int e, double centroid[3], double normal[3],
                       double *area, double *opening, double *sliding, int *failed);

/* Damage of cohesive element e, 0 (intact) to 1 (a free crack face): the
 * energy its node pairs have dissipated over what opening its facet in
 * pure mode I takes, G_I times its area now, at most 1; 1 once every pair
 * has failed.  Law-independent (every law books its dissipation). */
double cf_cohesive_damage(const cf_solid *s, int e);

/* Compression across a crack: a PBD non-penetration constraint on the
 * predicted positions s->p, Delta_n >= 0 for every open node pair, the
 * correction split by inverse masses, for pairs closer than half the facet's
 * size (sqrt(A)/2).  It lives in the relaxation loop with
 * the bars and the obstacles, so it is stable at any dt (a penalty force at
 * the PBD time steps used here is not). */
void cf_cohesive_project_contact(cf_solid *s, const int *elems, int n);

#endif
