/* Extrinsic PPR cohesive law (docs/physics.md §6): Park, Paulino, Celes, Espinha
 * 2012, IJNME 92:1-35 — the extrinsic (lambda -> 0) limit of the
 * Park-Paulino-Roesler potential, JMPS 57:891-908 (2009).
 *
 * Openings in m, tractions in Pa, fracture energies in N/m.  The traction is
 * sigma_max at zero opening; pure mode-I work is sigma_max delta_n / alpha =
 * phi_n.  Unloading and reloading follow the secant to the origin; complete
 * failure when an opening passes its final width; compression is a penalty. */
#ifndef COHFRAC_COHESIVE_PPR_H
#define COHFRAC_COHESIVE_PPR_H

#include "solid.h"

typedef struct cf_ppr {
    double phi_n, phi_t, sigma_max, tau_max, alpha, beta;
    double delta_n, delta_t;     /* final openings, m */
    double Gamma_n, Gamma_t;     /* energy constants */
    double dbar_n, dbar_t;       /* conjugate final openings, m */
} cf_ppr;

void cf_ppr_init(cf_ppr *p, const cf_material *m);

/* The law of a facet of strength w sigma_max (material.strength): the
 * strengths times w, the fracture energies kept, so every final opening
 * divided by w.  Writes it into *out and returns out. */
const cf_ppr *cf_ppr_scaled(const cf_ppr *p, double w, cf_ppr *out);

/* Envelope (monotonic loading) tractions at normal opening dn >= 0 and
 * tangential opening dt >= 0. */
void cf_ppr_envelope(const cf_ppr *p, double dn, double dt, double *Tn, double *Tt);

/* Traction with history for one node pair (Pa): on the envelope at the
 * largest openings so far, else on the secant to the origin; zero after
 * complete failure.  A negative dn counts as zero opening (the caller adds
 * the compression penalty).  Updates *dn_max, *dt_max, *failed. */
void cf_ppr_traction(const cf_ppr *p, double dn, double dt, double *dn_max, double *dt_max,
                     unsigned char *failed, double *Tn, double *Tt);

/* Add the forces of the cohesive elements elems[0..n) to s->f.
 * Nodal (Newton-Cotes) integration: each node pair carries traction * A/3,
 * A the current mid-surface area, normal from side A to side B.
 * Compression (Delta_n < 0, faces still facing each other, failed or not) is
 * a penalty T_n = K_p Delta_n with K_p = kp Pa/m, capped per node pair so
 * that the pair is stable at step dt: K_p A/3 <= 1/(4 dt^2 (1/m_a + 1/m_b)),
 * a sixteenth of the two-mass limit, as a node pair may sit in ~8 elements
 * (docs/physics.md §6); kp = 0 means the cap; kp < 0: no penalty, for runs whose
 * PBD crack-contact constraint (cf_cohesive_project_contact) keeps the faces
 * apart.  The penalty's stiffness follows the cap, which changes with the
 * facet's area: on a pair that already overlaps it releases energy that no
 * load put in (measured: nodes at 100+ m/s in a 4.4 m/s drop), so the two
 * are never combined.  The tangential traction rises from
 * zero with the same capped stiffness (time continuity).
 * Each pair's absorbed work and stored energy are updated (cf_cohesive).
 * Returns the number of node pairs in complete failure. */
/* (Each element with the law of its facet's strength, cf_ppr_scaled.) */
int cf_cohesive_forces(cf_solid *s, const cf_ppr *p, const int *elems, int n, double dt,
                       double kp);

/* Energy of cohesive elements elems[0..n) (all of them when elems is NULL),
 * J: stored (recoverable, on the secant; includes compression penalty) and
 * dissipated (absorbed work minus stored; G_I A for a facet of area A opened
 * to complete failure in pure mode I). */
void cf_cohesive_energy(const cf_solid *s, const int *elems, int n, double *stored,
                        double *dissipated);

/* Drop the recoverable energy of elems[0..n) (a fragment handed to rigid
 * mode, whose openings reset): returns the energy dropped, J. */
double cf_cohesive_release(cf_solid *s, const int *elems, int n);

/* Where cohesive element e is now: its mid-surface centre (m), unit normal
 * (A -> B) and area (m^2), its normal and tangential openings (m, means of
 * its three node pairs) and whether every pair has failed. */
void cf_cohesive_state(const cf_solid *s, int e, double centroid[3], double normal[3],
                       double *area, double *opening, double *sliding, int *failed);

/* Compression across a crack: a PBD non-penetration constraint on the
 * predicted positions s->p, Delta_n >= 0 for every open node pair, the
 * correction split by inverse masses, for pairs closer than half the facet's
 * size (sqrt(A)/2).  It lives in the relaxation loop with
 * the bars and the obstacles, so it is stable at any dt (a penalty force at
 * the PBD time steps used here is not). */
void cf_cohesive_project_contact(cf_solid *s, const int *elems, int n);

#endif
