#include "cohesive_ppr.h"

#include "linalg.h"

static double macaulay(double x) { return x > 0 ? x : 0; }

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

void cf_ppr_envelope(const cf_ppr *p, double dn, double dt, double *Tn, double *Tt)
{
    *Tn = *Tt = 0;
    if (dn >= p->delta_n || dt >= p->delta_t)
        return;
    double un = 1 - dn / p->delta_n, ut = 1 - dt / p->delta_t;
    if (dn >= 0 && dt <= p->dbar_t)
        *Tn = -(p->alpha * p->Gamma_n / p->delta_n) * pow(un, p->alpha - 1) *
              (p->Gamma_t * pow(ut, p->beta) + macaulay(p->phi_t - p->phi_n));
    if (dn <= p->dbar_n)
        *Tt = -(p->beta * p->Gamma_t / p->delta_t) * pow(ut, p->beta - 1) *
              (p->Gamma_n * pow(un, p->alpha) + macaulay(p->phi_n - p->phi_t));
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
    double en, et;
    double dnp = macaulay(dn);
    /* On the envelope when at the largest opening so far, else on the secant. */
    cf_ppr_envelope(p, *dn_max, dt, &en, &et);
    *Tn = (dnp >= *dn_max) ? en : (*dn_max > 0 ? en * dnp / *dn_max : en);
    cf_ppr_envelope(p, dnp, *dt_max, &en, &et);
    *Tt = (dt >= *dt_max) ? et : (*dt_max > 0 ? et * dt / *dt_max : et);
}

int cf_cohesive_forces(cf_solid *s, const cf_ppr *p, int first, int last, double dt)
{
    int n_failed = 0;
    for (int c = first; c < last; c++) {
        cf_cohesive *ce = &s->coh[c];
        int a[3], b[3];
        double mid[3][3];
        for (int i = 0; i < 3; i++) {
            a[i] = s->tet[4 * ce->tet[0] + ce->slot[0][i]];
            b[i] = s->tet[4 * ce->tet[1] + ce->slot[1][i]];
            for (int k = 0; k < 3; k++)
                mid[i][k] = 0.5 * (s->x[3 * a[i] + k] + s->x[3 * b[i] + k]);
        }
        double e1[3], e2[3], n[3];
        v3_sub(mid[1], mid[0], e1), v3_sub(mid[2], mid[0], e2), v3_cross(e1, e2, n);
        double nn = v3_norm(n);
        if (nn == 0)
            continue;
        double area = 0.5 * nn;
        for (int k = 0; k < 3; k++)
            n[k] /= nn;
        for (int i = 0; i < 3; i++) {
            if (a[i] == b[i]) /* the crack has not opened at this vertex yet */
                continue;
            double d[3], tv[3];
            v3_sub(&s->x[3 * b[i]], &s->x[3 * a[i]], d);
            double dn = v3_dot(d, n);
            for (int k = 0; k < 3; k++)
                tv[k] = d[k] - dn * n[k];
            double dtl = v3_norm(tv);
            double Tn, Tt;
            cf_ppr_traction(p, dn, dtl, &ce->dn_max[i], &ce->dt_max[i], &ce->failed[i], &Tn, &Tt);
            n_failed += ce->failed[i];
            double fvec[3] = {0, 0, 0};
            double w = area / 3.0;
            if (dn < 0) { /* penalty contact, stable with margin for a node in 3 pairs */
                double mmin = s->m[a[i]] < s->m[b[i]] ? s->m[a[i]] : s->m[b[i]];
                v3_axpy(0.1 * mmin / (dt * dt) * dn, n, fvec);
            } else {
                v3_axpy(w * Tn, n, fvec);
            }
            if (dtl > 0)
                v3_axpy(w * Tt / dtl, tv, fvec);
            v3_axpy(1.0, fvec, &s->f[3 * a[i]]);  /* pulls A towards B */
            v3_axpy(-1.0, fvec, &s->f[3 * b[i]]);
        }
    }
    return n_failed;
}
