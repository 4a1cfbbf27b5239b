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

#include "cohfrac/types.h"

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

#endif
