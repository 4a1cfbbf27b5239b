/* The extrinsic PPR cohesive law (cohesive_ppr.h), and its entry in the
 * table of cohesive laws (cohesive_law.h). */
#include "cohesive_ppr.h"
#include "cohesive_law.h"

#include "linalg.h"

static double macaulay(double x) { return x > 0 ? x : 0; }

/* x^y.  At the default shape parameters (alpha = beta = 2)
 * half the powers are first powers: x itself, exactly what pow returns
 * for them, without its cost. */
static double power(double x, double y) { return y == 1 ? x : pow(x, y); }

void cf_ppr_init(cf_ppr *p, const cf_material *m)
{
    p->phi_n = m->G_I, p->phi_t = m->G_II;
    p->sigma_max = m->sigma_max, p->tau_max = m->tau_max;
    p->alpha = m->alpha, p->beta = m->beta;
    p->delta_n = p->alpha * p->phi_n / p->sigma_max;
    p->delta_t = p->beta * p->phi_t / p->tau_max;
    if (p->phi_n >= p->phi_t)
        p->Gamma_n = -p->phi_n, p->Gamma_t = 1;
    else
        p->Gamma_n = 1, p->Gamma_t = -p->phi_t;
    p->dbar_n = p->delta_n * (1 - pow(macaulay(p->phi_n - p->phi_t) / p->phi_n, 1 / p->alpha));
    p->dbar_t = p->delta_t * (1 - pow(macaulay(p->phi_t - p->phi_n) / p->phi_t, 1 / p->beta));
}

/* The envelope's normal and tangential tractions, each on its own: the
 * traction reads each at other openings (cf_ppr_traction), and the part
 * it did not use cost two pow calls of the four. */
static double envelope_n(const cf_ppr *p, double dn, double dt)
{
    if (dn >= p->delta_n || dt >= p->delta_t || !(dn >= 0 && dt <= p->dbar_t))
        return 0;
    double un = 1 - dn / p->delta_n, ut = 1 - dt / p->delta_t;
    return -(p->alpha * p->Gamma_n / p->delta_n) * power(un, p->alpha - 1) *
           (p->Gamma_t * power(ut, p->beta) + macaulay(p->phi_t - p->phi_n));
}

static double envelope_t(const cf_ppr *p, double dn, double dt)
{
    if (dn >= p->delta_n || dt >= p->delta_t || !(dn <= p->dbar_n))
        return 0;
    double un = 1 - dn / p->delta_n, ut = 1 - dt / p->delta_t;
    return -(p->beta * p->Gamma_t / p->delta_t) * power(ut, p->beta - 1) *
           (p->Gamma_n * power(un, p->alpha) + macaulay(p->phi_n - p->phi_t));
}

void cf_ppr_envelope(const cf_ppr *p, double dn, double dt, double *Tn, double *Tt)
{
    *Tn = envelope_n(p, dn, dt);
    *Tt = envelope_t(p, dn, dt);
}

void cf_ppr_traction(const cf_ppr *p, double dn, double dt, double *dn_max, double *dt_max,
                     unsigned char *failed, double *Tn, double *Tt)
{
    if (dn > *dn_max)
        *dn_max = dn;
    if (dt > *dt_max)
        *dt_max = dt;
    if (*dn_max >= p->delta_n || *dt_max >= p->delta_t)
        *failed = 1;
    *Tn = *Tt = 0;
    if (*failed)
        return;
    double dnp = macaulay(dn);
    /* On the envelope when at the largest opening so far, else on the secant. */
    double en = envelope_n(p, *dn_max, dt);
    *Tn = (dnp >= *dn_max) ? en : (*dn_max > 0 ? en * dnp / *dn_max : en);
    double et = envelope_t(p, dnp, *dt_max);
    *Tt = (dt >= *dt_max) ? et : (*dt_max > 0 ? et * dt / *dt_max : et);
}

const cf_ppr *cf_ppr_scaled(const cf_ppr *p, double w, cf_ppr *out)
{
    *out = *p;
    out->sigma_max *= w, out->tau_max *= w;
    out->delta_n /= w, out->delta_t /= w, out->dbar_n /= w, out->dbar_t /= w;
    return out;
}


/* The law's table entry: its parameters are a cf_ppr. */
_Static_assert(sizeof(cf_ppr) <= CF_LAW_PARAMS_MAX * sizeof(double), "cf_ppr fits the table");
static void law_init(void *p, const cf_material *m) { cf_ppr_init(p, m); }

static void law_scale(void *p, double w)
{
    cf_ppr base = *(cf_ppr *)p;
    cf_ppr_scaled(&base, w, p);
}

static void law_envelope(const void *p, double dn, double dt, double *Tn, double *Tt)
{
    cf_ppr_envelope(p, dn, dt, Tn, Tt);
}

static void law_traction(const void *p, double dn, double dt, double *dn_max, double *dt_max,
                         unsigned char *failed, double *Tn, double *Tt)
{
    cf_ppr_traction(p, dn, dt, dn_max, dt_max, failed, Tn, Tt);
}

const cf_cohesive_law cf_law_ppr = {"ppr", sizeof(cf_ppr), law_init, law_scale, law_envelope,
                                    law_traction};
