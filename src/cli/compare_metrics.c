/* cohfrac compare: the metrics (compare_metrics.h). */
#include "compare_metrics.h"

#include "linalg.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

double cf_cmp_dist(const double a[3], const double b[3])
{
    double d[3];
    v3_sub(a, b, d);
    return v3_norm(d);
}

/* Angle of q_a^-1 q_b, rad, in [0, pi]. */
double cf_cmp_quat_angle(const double a[4], const double b[4])
{
    /* conj(a) b: scalar part and the norm of the vector part */
    double w = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    double x = a[0] * b[1] - a[1] * b[0] - a[2] * b[3] + a[3] * b[2];
    double y = a[0] * b[2] + a[1] * b[3] - a[2] * b[0] - a[3] * b[1];
    double z = a[0] * b[3] - a[1] * b[2] + a[2] * b[1] - a[3] * b[0];
    return 2.0 * atan2(sqrt(x * x + y * y + z * z), fabs(w));
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* partner[i]: index in sb of the fragment of run b holding the most tets of
 * sa's fragment i (-1: none); shared[i]: how many.  keys: scratch [tets]. */
void cf_cmp_match_fragments(const cf_sim *a, const cf_sim *b, const snap *sa, const snap *sb,
                            uint64_t *keys, int *partner, int *shared)
{
    int nt = cf_world_tet_count(cf_sim_world(a)), nk = 0;
    for (int t = 0; t < nt; t++) {
        int fa = cf_world_tet_fragment(cf_sim_world(a), t), fb = cf_world_tet_fragment(cf_sim_world(b), t);
        if (fa >= 0 && fb >= 0)
            keys[nk++] = (uint64_t)fa << 32 | (uint64_t)(uint32_t)fb;
    }
    qsort(keys, (size_t)nk, sizeof *keys, cmp_u64);
    for (int i = 0; i < sa->n; i++)
        partner[i] = -1, shared[i] = 0;
    for (int k = 0; k < nk;) {
        int run = k;
        while (run < nk && keys[run] == keys[k])
            run++;
        int fa = (int)(keys[k] >> 32), fb = (int)(keys[k] & 0xffffffffu);
        int ia = fa < sa->index_cap ? sa->index[fa] : -1;
        int ib = fb < sb->index_cap ? sb->index[fb] : -1;
        if (ia >= 0 && ib >= 0 && run - k > shared[ia])
            partner[ia] = ib, shared[ia] = run - k;
        k = run;
    }
}

void cf_cmp_sum_totals(const snap *s, const double g[3], totals *o)
{
    memset(o, 0, sizeof *o);
    for (int i = 0; i < s->n; i++) {
        const cf_fragment_state *f = &s->f[i];
        o->M += f->mass;
        o->E += f->kinetic - f->mass * v3_dot(g, f->com);
        v3_axpy(1.0, f->momentum, o->P);
        v3_axpy(1.0, f->angular_momentum, o->L);
        v3_axpy(f->mass, f->com, o->com);
    }
    if (o->M > 0)
        for (int k = 0; k < 3; k++)
            o->com[k] /= o->M;
}

int cf_cmp_heaviest(const snap *s)
{
    int best = -1;
    for (int i = 0; i < s->n; i++)
        if (best < 0 || s->f[i].mass > s->f[best].mass)
            best = i;
    return best;
}

static void ballistic(const double x0[3], const double v0[3], const double g[3], double t,
                      double x[3])
{
    for (int k = 0; k < 3; k++)
        x[k] = x0[k] + v0[k] * t + 0.5 * g[k] * t * t;
}

/* Centre of mass of the reference at t; returns 0 (x NaN) past its validity. */
int cf_cmp_reference_at(const reference *r, double t, double x[3])
{
    if (r->kind == CF_CMP_REF_NONE || (r->kind == CF_CMP_REF_BOUNCE && t > r->t2 + 1e-12)) {
        x[0] = x[1] = x[2] = NAN;
        return 0;
    }
    if (r->kind == CF_CMP_REF_BOUNCE && t > r->t1)
        ballistic(r->x1, r->v1, r->g, t - r->t1, x);
    else
        ballistic(r->x0, r->v0, r->g, t, x);
    return 1;
}

/* Decide the reference from the scene and the state at t = 0 (Bullet run). */
void cf_cmp_reference_setup(const cf_world_def *sc, cf_sim *sim, const snap *first, reference *r)
{
    memset(r, 0, sizeof *r);
    r->kind = CF_CMP_REF_NONE;
    r->t2 = INFINITY;
    if (sc->n_bodies != 1 || sc->n_boundaries != 0 || first->n != 1)
        return;
    const cf_body_def *b = &sc->bodies[0];
    const cf_fragment_state *f = &first->f[0];
    memcpy(r->x0, f->com, sizeof r->x0);
    memcpy(r->g, sc->gravity, sizeof r->g);
    /* v0 from the scene's velocity field at the centre of mass (the spin
     * term vanishes there), not from either backend */
    for (int k = 0; k < 3; k++) {
        double c = b->has_expansion_center ? b->expansion_center[k] : f->com[k];
        r->v0[k] = b->velocity[k] + b->expansion_rate[k] * (f->com[k] - c);
    }
    double w0n = v3_norm(b->angular_velocity);
    if (sc->n_obstacles == 0) {
        r->kind = v3_norm(r->v0) == 0 ? CF_CMP_REF_FREE_FALL : CF_CMP_REF_PROJECTILE;
        /* symmetric top: which moment is the distinct one */
        const double *p = f->principal;
        int k_sym = -1;
        for (int k = 0; k < 3; k++) {
            int i = (k + 1) % 3, j = (k + 2) % 3;
            double pij = fmax(p[i], p[j]);
            if (pij > 0 && fabs(p[i] - p[j]) <= TOP_TOLERANCE * pij &&
                fabs(p[k] - 0.5 * (p[i] + p[j])) > TOP_TOLERANCE * pij)
                k_sym = k;
        }
        if (w0n == 0 || k_sym < 0)
            return;
        double I1 = 0.5 * (p[(k_sym + 1) % 3] + p[(k_sym + 2) % 3]);
        /* L = R0 A diag(p) A^T R0^T w0, A the rest principal axes */
        double R0[9], RA[9], tmp[3], L[3];
        quat_to_mat(f->quat, R0);
        m3_mul(R0, f->axes, RA);
        m3_tmulv(RA, b->angular_velocity, tmp);
        for (int k = 0; k < 3; k++)
            tmp[k] *= p[k];
        m3_mulv(RA, tmp, L);
        double Ln = v3_norm(L);
        for (int k = 0; k < 3; k++) {
            r->e_sym[k] = f->axes[3 * k + k_sym];
            r->Lhat[k] = L[k] / Ln;
        }
        double a0[3];
        m3_mulv(R0, r->e_sym, a0);
        double along = v3_dot(a0, r->Lhat);
        for (int k = 0; k < 3; k++)
            r->u1[k] = a0[k] - along * r->Lhat[k];
        double u1n = v3_norm(r->u1);
        if (!(u1n > 1e-6)) /* spinning about the symmetry axis: nothing precesses */
            return;
        for (int k = 0; k < 3; k++)
            r->u1[k] /= u1n;
        v3_cross(r->Lhat, r->u1, r->u2);
        r->top = 1;
        r->omega_p = Ln / I1;
        return;
    }
    if (sc->n_obstacles != 1 || sc->obstacles[0].type != CF_OBSTACLE_PLANE ||
        sc->solver.criterion != CF_CRITERION_NONE || w0n != 0)
        return;
    const cf_obstacle *o = &sc->obstacles[0];
    memcpy(r->n, o->normal, sizeof r->n);
    double mn[3] = {-r->n[0], -r->n[1], -r->n[2]}, d[3];
    double h = cf_world_fragment_support(cf_sim_world(sim), f->id, mn);
    v3_sub(r->x0, o->point, d);
    double s0 = v3_dot(d, r->n), vn0 = v3_dot(r->v0, r->n), gn = v3_dot(r->g, r->n);
    if (!(gn < 0) || !(s0 > h))
        return;
    r->kind = CF_CMP_REF_BOUNCE;
    r->e = sc->material.restitution * o->restitution;
    double disc = vn0 * vn0 - 2.0 * gn * (s0 - h);
    r->t1 = (vn0 + sqrt(disc)) / -gn;
    double vt1[3];
    ballistic(r->x0, r->v0, r->g, r->t1, r->x1);
    for (int k = 0; k < 3; k++)
        vt1[k] = r->v0[k] + r->g[k] * r->t1;
    double vn1 = v3_dot(vt1, r->n); /* < 0: approaching */
    for (int k = 0; k < 3; k++)
        r->v1[k] = vt1[k] - (1.0 + r->e) * vn1 * r->n[k];
    r->t2 = r->t1 + 2.0 * (-r->e * vn1) / -gn;
}

/* Wrapped angle (rad) of the top's symmetry axis about L. */
double cf_cmp_axis_angle(const reference *r, const cf_fragment_state *f)
{
    double R[9], a[3];
    quat_to_mat(f->quat, R);
    m3_mulv(R, r->e_sym, a);
    return atan2(v3_dot(a, r->u2), v3_dot(a, r->u1));
}

/* Least-squares slope of the unwrapped angle series a[0..n) over t; unwraps in place. */
double cf_cmp_unwrap_slope(const sample *s, int n, double *a)
{
    for (int i = 1; i < n; i++) {
        double d = a[i] - a[i - 1];
        a[i] -= TWO_PI * floor((d + 0.5 * TWO_PI) / TWO_PI);
    }
    double tm = 0, am = 0;
    for (int i = 0; i < n; i++)
        tm += s[i].t, am += a[i];
    tm /= n, am /= n;
    double num = 0, den = 0;
    for (int i = 0; i < n; i++)
        num += (s[i].t - tm) * (a[i] - am), den += (s[i].t - tm) * (s[i].t - tm);
    return den > 0 ? num / den : NAN;
}
