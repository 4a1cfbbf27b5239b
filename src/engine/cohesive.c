/* Cohesive elements (cohesive.h): forces, energy, state and the
 * crack-contact constraint, for any cohesive law (cohesive_law.h). */
#include "cohesive.h"

#include "linalg.h"
#include "parallel.h"

#include <string.h>

/* The current nodes of pair i of element ce, side A and side B. */
static void pair_nodes(const cf_solid *s, const cf_cohesive *ce, int i, int *a, int *b)
{
    *a = s->tet[4 * ce->tet[0] + ce->slot[0][i]];
    *b = s->tet[4 * ce->tet[1] + ce->slot[1][i]];
}

/* Unit normal (A -> B) and area of element ce's mid-surface at positions pos. */
static double mid_normal(const cf_solid *s, const cf_cohesive *ce, const double *pos, int stride,
                         int a[3], int b[3], double n[3])
{
    double mid[3][3];
    for (int i = 0; i < 3; i++) {
        pair_nodes(s, ce, i, &a[i], &b[i]);
        for (int k = 0; k < 3; k++)
            mid[i][k] = 0.5 * (pos[stride * a[i] + k] + pos[stride * b[i] + k]);
    }
    double e1[3], e2[3];
    v3_sub(mid[1], mid[0], e1), v3_sub(mid[2], mid[0], e2), v3_cross(e1, e2, n);
    double nn = v3_norm(n);
    for (int k = 0; k < 3 && nn > 0; k++)
        n[k] /= nn;
    return 0.5 * nn;
}

/* Coulomb friction of pair i of ce at separation d (x_B - x_A, m) across
 * the unit normal nrm, its faces pressed together with normal traction
 * Tn < 0 (Pa).  The friction traction T (Pa; NULL, no friction state:
 * none) sticks with stiffness kf (Pa/m) to the tangential change of d
 * since the last evaluation and slides where it would pass mu |Tn| (a
 * return map onto the Coulomb cone, as penalty contact does, Wriggers,
 * Computational Contact Mechanics, 2006).  It acts on top of the law's
 * tangential traction: faces of a brittle solid pressed together resist
 * sliding by friction, bonded or failed (Snozzi and Molinari, IJNME
 * 93:510, 2013).  Adds its force on A, the traction times a3 (A/3, m^2),
 * to fvec (N) and returns the stick spring's energy |T|^2 a3 / (2 kf) (J).
 * Faces apart, or mu = 0, carry none and forget it. */
static double friction(const cf_cohesive *ce, double T[3], int i, const double d[3],
                       const double nrm[3], double Tn, double kf, double mu, double a3,
                       double fvec[3])
{
    if (!T)
        return 0;
    if (mu <= 0 || Tn >= 0 || kf <= 0 || !ce->started[i]) {
        T[0] = T[1] = T[2] = 0;
        return 0;
    }
    double inc[3];
    v3_sub(d, ce->d_last[i], inc);
    v3_axpy(kf, inc, T);
    v3_axpy(-v3_dot(T, nrm), nrm, T); /* in the faces' current plane */
    double t = v3_norm(T), lim = mu * -Tn;
    if (t > lim)
        for (int k = 0; k < 3; k++)
            T[k] *= lim / t;
    v3_axpy(a3, T, fvec);
    return a3 * v3_dot(T, T) / (2.0 * kf);
}

/* Element ce's three node pairs: tractions, energies and state, and each
 * pair's force into out[0..2].  Writes only ce and out.  Returns its pairs
 * in complete failure. */
static int element_forces(const cf_solid *s, cf_cohesive *ce, const cf_cohesive_law *law,
                          const void *params, double dt, const cf_face_contact *fc,
                          double (*fric)[3], cf_pair_force out[3])
{
    int n_failed = 0, a[3], b[3];
    double nrm[3];
    for (int i = 0; i < 3; i++)
        out[i].a = -1;
    double area = mid_normal(s, ce, s->x, 3, a, b, nrm);
    if (area == 0)
        return 0;
    /* The law of the facet's strength (material.strength), where a pair
     * still holds: most elements of a fragment that broke are free crack
     * faces, which only the compression penalty below still reads. */
    double scaled[CF_LAW_PARAMS_MAX];
    const void *p = params;
    if (ce->strength != 1.0 && !cf_cohesive_all_failed(ce)) {
        memcpy(scaled, params, law->params_size);
        law->scale(scaled, ce->strength);
        p = scaled;
    }
    double elastic = 0;
    for (int i = 0; i < 3; i++) {
        if (a[i] == b[i]) /* the crack has not opened at this vertex yet */
            continue;
        double d[3], tv[3];
        v3_sub(&s->x[3 * b[i]], &s->x[3 * a[i]], d);
        double dn = v3_dot(d, nrm);
        for (int k = 0; k < 3; k++)
            tv[k] = d[k] - dn * nrm[k];
        double dtl = v3_norm(tv);
        double Tn = 0, Tt = 0;
        double *L = ce->last[i]; /* dn, Tn at the last evaluation */
        if (!ce->failed[i]) /* a failed pair's law gives none (cohesive_law.h) */
            law->traction(p, dn, dtl, &ce->dn_max[i], &ce->dt_max[i], &ce->failed[i], &Tn, &Tt);
        n_failed += ce->failed[i];
        /* Stability cap of a node pair at step dt: a node pair is shared
         * by up to ~8 elements, so a sixteenth of the two-mass limit
         * 4/(dt^2 (wa + wb)) keeps their sum stable.  Only a pair in
         * compression, with a tangential traction, or with a normal one
         * that rises from zero reads it. */
        double cap = 0;
        if (dn <= 0 || Tt != 0 || (fc->normal_rises && Tn > 0)) {
            double wa = 1.0 / s->m[a[i]], wb = 1.0 / s->m[b[i]];
            cap = 3.0 / (4.0 * area * dt * dt * (wa + wb));
        }
        if (dn <= 0) { /* compression: penalty, while the faces still face each other */
            /* The penalty engages only on a pair that reaches the overlap
             * facing (it was open, or just started) and holds while it
             * stays engaged.  A pair that slid past its partner and comes
             * back into view already overlapped would be kicked apart
             * with energy 1/2 K_p dn^2 that no load put in. */
            int engaged = !ce->started[i] || L[0] > 0 || L[1] < 0;
            int facing = fc->kp >= 0 && engaged && v3_dot(d, d) <= 0.25 * area;
            Tn = facing ? fmin(fc->kp > 0 ? fc->kp : cap, cap) * dn : 0;
        }
        /* The tangential traction rises from zero with the capped
         * stiffness: at zero tangential opening its direction is
         * undefined, and a jump to tau_max there would act in a
         * direction set by round-off (time continuity, Papoulia et al.
         * 2003). */
        if (Tt != 0)
            Tt = fmin(Tt, cap * dtl);
        /* With time_continuity "both" the normal traction does so too: an
         * element inserted where the traction is below its strength would
         * otherwise pull its faces shut with the whole strength at the
         * first opening (docs/physics.md §6, regularisation 2). */
        if (fc->normal_rises && dn > 0 && Tn > 0)
            Tn = fmin(Tn, cap * dn);
        double fvec[3] = {0, 0, 0}; /* pulls A towards B */
        v3_axpy(area / 3.0 * Tn, nrm, fvec);
        if (dtl > 0)
            v3_axpy(area / 3.0 * Tt / dtl, tv, fvec);
        /* Half the cap: the law's tangential traction may stiffen the pair
         * by the cap already. */
        elastic += friction(ce, fric ? fric[i] : NULL, i, d, nrm, Tn, 0.5 * cap,
                            s->mat.crack_friction, area / 3.0, fvec);
        /* The work absorbed is the trapezoid of the force over the change of
         * separation, 1/2 (F_n-1 + F_n) . (d_n - d_n-1): exactly what the
         * leapfrog's kinetic energy product gives up to the pair's two
         * forces, +F on A and -F on B (docs/physics.md §10).  Tractions times
         * the scalar openings missed the turn of the normal and the change
         * of area of facets that crush.  From the pair's first evaluation. */
        double *fo = ce->f_last[i], *d_o = ce->d_last[i];
        for (int k = 0; k < 3; k++) {
            if (ce->started[i])
                ce->work += 0.5 * (fo[k] + fvec[k]) * (d[k] - d_o[k]);
            fo[k] = fvec[k], d_o[k] = d[k];
        }
        elastic += area / 3.0 * 0.5 * (Tn * dn + Tt * dtl);
        L[0] = dn, L[1] = Tn;
        ce->started[i] = 1;
        out[i] = (cf_pair_force){a[i], b[i], {fvec[0], fvec[1], fvec[2]}};
    }
    ce->dissipated = fmax(ce->dissipated, ce->work - elastic);
    ce->stored = ce->work - ce->dissipated;
    return n_failed;
}

/* An element's loads come through three indirections (the element, the
 * node rows of its two tets, its six nodes), and on a fragment that broke
 * the duplicated nodes lie far apart: each is a cache miss the core waits
 * on.  The loop fetches them ahead, each stage once the one before it has
 * arrived: element e + 3 LEAD, the tets' rows of e + 2 LEAD, the nodes of
 * e + LEAD. */
enum { LEAD = 4 };

static void prefetch_element(const cf_solid *s, const int *elems, int e, int n)
{
    if (e + 3 * LEAD < n) {
        const char *c = (const char *)&s->coh[elems[e + 3 * LEAD]];
        for (size_t k = 0; k < sizeof(cf_cohesive); k += 64)
            __builtin_prefetch(c + k);
    }
    if (e + 2 * LEAD < n) {
        const cf_cohesive *ce = &s->coh[elems[e + 2 * LEAD]];
        __builtin_prefetch(&s->tet[4 * ce->tet[0]]);
        __builtin_prefetch(&s->tet[4 * ce->tet[1]]);
    }
    if (e + LEAD < n) {
        const cf_cohesive *ce = &s->coh[elems[e + LEAD]];
        for (int i = 0; i < 3; i++) {
            int a, b;
            pair_nodes(s, ce, i, &a, &b);
            __builtin_prefetch(&s->x[3 * a]);
            __builtin_prefetch(&s->x[3 * b]);
        }
    }
}

int cf_cohesive_forces(cf_solid *s, const cf_cohesive_law *law, const void *params,
                       const int *elems, int n, double dt, const cf_face_contact *fc,
                       cf_pair_force *pairs)
{
    int n_failed = 0;
    CF_PARALLEL(n >= CF_COHESIVE_PARALLEL_MIN,
                "omp parallel for schedule(static) reduction(+ : n_failed)",
        for (int e = 0; e < n; e++) {
            prefetch_element(s, elems, e, n);
            n_failed += element_forces(s, &s->coh[elems[e]], law, params, dt, fc,
                                        s->coh_fric ? s->coh_fric[elems[e]] : NULL,
                                        &pairs[3 * e]);
        });
    /* Elements share nodes: the sums in list and pair order, on one thread. */
    for (int j = 0; j < 3 * n; j++)
        if (pairs[j].a >= 0) {
            v3_axpy(1.0, pairs[j].f, &s->f[3 * pairs[j].a]); /* pulls A towards B */
            v3_axpy(-1.0, pairs[j].f, &s->f[3 * pairs[j].b]);
        }
    return n_failed;
}

void cf_cohesive_energy(const cf_solid *s, const int *elems, int n, double *stored,
                        double *dissipated)
{
    double st = 0, w = 0;
    int count = elems ? n : s->n_coh;
    for (int e = 0; e < count; e++) {
        const cf_cohesive *ce = &s->coh[elems ? elems[e] : e];
        st += ce->stored, w += ce->dissipated;
    }
    *stored = st;
    *dissipated = w;
}

double cf_cohesive_release(cf_solid *s, const int *elems, int n)
{
    double dropped = 0;
    for (int e = 0; e < n; e++) {
        cf_cohesive *ce = &s->coh[elems[e]];
        dropped += ce->stored;
        ce->work -= ce->stored;
        ce->stored = 0;
        memset(ce->started, 0, sizeof ce->started); /* the nodes move back to the rest shape */
    }
    return dropped;
}

void cf_cohesive_fail(cf_solid *s, int e)
{
    cf_cohesive *ce = &s->coh[e];
    memset(ce->failed, 1, sizeof ce->failed);
    ce->dissipated += ce->stored;
    ce->stored = 0;
}

void cf_cohesive_project_contact(cf_solid *s, const int *elems, int n)
{
    for (int e = 0; e < n; e++) {
        int a[3], b[3];
        double nrm[3];
        double area = mid_normal(s, &s->coh[elems[e]], s->p, 4, a, b, nrm);
        if (area == 0)
            continue;
        for (int i = 0; i < 3; i++) {
            if (a[i] == b[i])
                continue;
            double d[3];
            v3_sub(&s->p[4 * b[i]], &s->p[4 * a[i]], d);
            double dn = v3_dot(d, nrm);
            /* Only faces still facing each other: once the sides have moved
             * apart by more than the facet's size the mid-surface means nothing. */
            if (dn >= 0 || v3_dot(d, d) > 0.25 * area)
                continue;
            double wa = 1.0 / s->m[a[i]], wb = 1.0 / s->m[b[i]], c = dn / (wa + wb);
            v3_axpy(wa * c, nrm, &s->p[4 * a[i]]);
            v3_axpy(-wb * c, nrm, &s->p[4 * b[i]]);
        }
    }
}

double cf_cohesive_damage(const cf_solid *s, int e)
{
    const cf_cohesive *ce = &s->coh[e];
    if (cf_cohesive_all_failed(ce))
        return 1.0;
    int a[3], b[3];
    double n[3], area = mid_normal(s, ce, s->x, 3, a, b, n);
    double d = ce->dissipated;
    double full = s->mat.G_I * area;
    return full > 0 ? fmin(1.0, d / full) : 0.0;
}

void cf_cohesive_state(const cf_solid *s, int e, double centroid[3], double normal[3],
                       double *area, double *opening, double *sliding, int *failed)
{
    const cf_cohesive *ce = &s->coh[e];
    int a[3], b[3];
    *area = mid_normal(s, ce, s->x, 3, a, b, normal);
    *opening = *sliding = 0;
    *failed = cf_cohesive_all_failed(ce);
    centroid[0] = centroid[1] = centroid[2] = 0;
    for (int i = 0; i < 3; i++) {
        double d[3], mid[3];
        v3_sub(&s->x[3 * b[i]], &s->x[3 * a[i]], d);
        double dn = v3_dot(d, normal);
        for (int k = 0; k < 3; k++) {
            mid[k] = 0.5 * (s->x[3 * a[i] + k] + s->x[3 * b[i] + k]);
            centroid[k] += mid[k] / 3.0;
            d[k] -= dn * normal[k];
        }
        *opening += dn / 3.0;
        *sliding += v3_norm(d) / 3.0;
    }
}

const char *const cf_cohesive_law_names[] = {
#define CF_LAW_NAME_(law) #law,
    CF_COHESIVE_LAWS(CF_LAW_NAME_)
#undef CF_LAW_NAME_
    NULL};

const cf_cohesive_law *cf_cohesive_law_of(int i)
{
    static const cf_cohesive_law *const laws[] = {
#define CF_LAW_ENTRY_(law) &cf_law_##law,
        CF_COHESIVE_LAWS(CF_LAW_ENTRY_)
#undef CF_LAW_ENTRY_
    };
    return i >= 0 && i < (int)(sizeof laws / sizeof laws[0]) ? laws[i] : NULL;
}
