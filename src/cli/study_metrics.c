/* cohfrac study: the metrics of a case against the reference
 * (src/cli/study.h gives their definitions): the fragment matching by
 * subtrees, the trajectory error, the mass distribution's distance, the
 * ledger's residual, and the Pareto front of wall time against error. */
#define _GNU_SOURCE /* qsort_r */
#include "study_metrics.h"

#include "linalg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Per frame of a trajectory: the mass and mass moment of the fragments
 * alive in it summed over every fragment's subtree (itself and its
 * descendants): S[j] = sum m x, M[j] = sum m. */
static void subtree_sums(const cf_trajectory *t, int k, double *S, double *M)
{
    memset(S, 0, 3 * (size_t)t->N * sizeof *S);
    memset(M, 0, (size_t)t->N * sizeof *M);
    const double *x = &t->pos[3 * (size_t)k * t->N];
    for (int j = 0; j < t->N; j++) {
        if (isnan(x[3 * j]))
            continue;
        for (int a = j; a >= 0; a = t->parent[a]) {
            for (int d = 0; d < 3; d++)
                S[3 * a + d] += t->mass[j] * x[3 * j + d];
            M[a] += t->mass[j];
        }
    }
}

static int by_mass_desc(const void *a, const void *b, void *mass)
{
    double ma = ((const double *)mass)[*(const int *)a];
    double mb = ((const double *)mass)[*(const int *)b];
    return ma < mb ? 1 : ma > mb ? -1 : *(const int *)a - *(const int *)b;
}

/* The children of fragment `p` (all roots for p = -1), heaviest first. */
static int children(const cf_trajectory *t, int p, int *out)
{
    int n = 0;
    for (int j = 0; j < t->N; j++)
        if (t->parent[j] == p)
            out[n++] = j;
    qsort_r(out, (size_t)n, sizeof *out, by_mass_desc, t->mass);
    return n;
}

/* partner[j] of each fragment of `v` in `r` (-1 unmatched): roots in order,
 * then the children of matched pairs, heaviest with heaviest. */
static int match_fragments(const cf_trajectory *v, const cf_trajectory *r, int *partner)
{
    int *cv = malloc(((size_t)v->N + 1) * sizeof *cv);
    int *cr = malloc(((size_t)r->N + 1) * sizeof *cr);
    int *queue = malloc(((size_t)v->N + 1) * sizeof *queue);
    if (!cv || !cr || !queue) {
        free(cv), free(cr), free(queue);
        return -1;
    }
    for (int j = 0; j < v->N; j++)
        partner[j] = -1;
    int head = 0, tail = 0;
    int nv = children(v, -1, cv), nr = children(r, -1, cr);
    /* Initial bodies keep their scene order (ids 0..n-1). */
    for (int i = 0; i < nv && i < nr; i++)
        partner[i] = i, queue[tail++] = i;
    while (head < tail) {
        int a = queue[head++];
        nv = children(v, a, cv);
        nr = children(r, partner[a], cr);
        for (int i = 0; i < nv && i < nr; i++)
            partner[cv[i]] = cr[i], queue[tail++] = cv[i];
    }
    free(cv), free(cr), free(queue);
    return 0;
}

/* The reference frame nearest in time to t (-1 when t is past its end by
 * more than half a frame). */
static int nearest_frame(const cf_trajectory *r, double t)
{
    int best = -1;
    double bd = INFINITY;
    for (int k = 0; k < r->T; k++)
        if (fabs(r->time[k] - t) < bd)
            bd = fabs(r->time[k] - t), best = k;
    double half = r->T > 1 ? 0.5 * (r->time[1] - r->time[0]) : 0;
    return best >= 0 && bd <= half * (1 + 1e-9) + 1e-12 ? best : -1;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The masses of the fragments alive in the last frame, ascending, and
 * their sum; NULL when out of memory or without frames. */
static double *final_masses(const cf_trajectory *t, int *n, double *total)
{
    double *m = malloc(((size_t)t->N + 1) * sizeof *m);
    *n = 0, *total = 0;
    if (!m || t->T == 0) {
        free(m);
        return NULL;
    }
    const double *x = &t->pos[3 * (size_t)(t->T - 1) * t->N];
    for (int j = 0; j < t->N; j++)
        if (!isnan(x[3 * j]))
            m[(*n)++] = t->mass[j], *total += t->mass[j];
    qsort(m, (size_t)*n, sizeof *m, cmp_double);
    return m;
}

/* Kolmogorov-Smirnov distance of the last frames' fragment mass
 * distributions, each weighted by mass: sup over m of |F_a(m) - F_b(m)|,
 * F(m) the fraction of the mass in fragments of mass <= m. */
static double mass_ks(const cf_trajectory *a, const cf_trajectory *b)
{
    int n[2], i[2] = {0, 0};
    double tot[2], F[2] = {0, 0}, d = 0;
    double *m[2] = {final_masses(a, &n[0], &tot[0]), final_masses(b, &n[1], &tot[1])};
    if (!m[0] || !m[1] || tot[0] <= 0 || tot[1] <= 0) {
        free(m[0]), free(m[1]);
        return NAN;
    }
    while (i[0] < n[0] || i[1] < n[1]) {
        double next = INFINITY;
        for (int s = 0; s < 2; s++)
            if (i[s] < n[s])
                next = fmin(next, m[s][i[s]]);
        for (int s = 0; s < 2; s++)
            while (i[s] < n[s] && m[s][i[s]] <= next)
                F[s] += m[s][i[s]++] / tot[s];
        d = fmax(d, fabs(F[0] - F[1]));
    }
    free(m[0]), free(m[1]);
    return d;
}

/* Mass-weighted RMS distance over the frames between the fragments of `v`
 * and their partners in `r` (study.h); NaN when no frame pairs up. */
static double trajectory_error(const cf_trajectory *v, const cf_trajectory *r)
{
    int *partner = malloc(((size_t)v->N + 1) * sizeof *partner);
    double *S = malloc((3 * (size_t)r->N + 1) * sizeof *S);
    double *M = malloc(((size_t)r->N + 1) * sizeof *M);
    double sum = 0;
    int frames = 0;
    if (partner && S && M && match_fragments(v, r, partner) == 0) {
        for (int k = 0; k < v->T; k++) {
            int kr = nearest_frame(r, v->time[k]);
            if (kr < 0)
                continue;
            subtree_sums(r, kr, S, M);
            const double *x = &v->pos[3 * (size_t)k * v->N];
            double e2 = 0, mass = 0;
            for (int f = 0; f < v->N; f++) {
                if (isnan(x[3 * f]))
                    continue;
                int a = f;
                while (a >= 0 && partner[a] < 0)
                    a = v->parent[a];
                int p = a >= 0 ? partner[a] : -1;
                while (p >= 0 && M[p] <= 0) /* not born yet in the reference */
                    p = r->parent[p];
                if (p < 0)
                    continue;
                double y[3] = {0, 0, 0}, dx[3];
                v3_axpy(1 / M[p], &S[3 * p], y); /* the partners' centre of mass */
                v3_sub(&x[3 * f], y, dx);
                e2 += v->mass[f] * v3_dot(dx, dx);
                mass += v->mass[f];
            }
            if (mass > 0)
                sum += e2 / mass, frames++;
        }
    }
    free(partner), free(S), free(M);
    return frames ? sqrt(sum / frames) : NAN;
}

/* D of study.h: RMS over the frames of the distance the initial bodies'
 * centres of mass travel, mass-weighted over the bodies. */
double cf_study_travel(const cf_trajectory *r)
{
    double *S = malloc((3 * (size_t)r->N + 1) * sizeof *S);
    double *M = malloc(((size_t)r->N + 1) * sizeof *M);
    double *X0 = malloc((3 * (size_t)r->N + 1) * sizeof *X0);
    double sum = 0;
    int frames = 0;
    for (int k = 0; S && M && X0 && k < r->T; k++) {
        subtree_sums(r, k, S, M);
        double e2 = 0, mass = 0;
        for (int j = 0; j < r->N; j++) {
            if (r->parent[j] >= 0 || M[j] <= 0)
                continue;
            double d2 = 0;
            for (int d = 0; d < 3; d++) {
                double X = S[3 * j + d] / M[j];
                if (k == 0)
                    X0[3 * j + d] = X;
                d2 += (X - X0[3 * j + d]) * (X - X0[3 * j + d]);
            }
            e2 += M[j] * d2, mass += M[j];
        }
        if (mass > 0)
            sum += e2 / mass, frames++;
    }
    free(S), free(M), free(X0);
    return frames ? sqrt(sum / frames) : NAN;
}

/* |a - b| / max(|b|, floor), for the final momenta. */
static double rel_diff3(const double *a, const double *b, double floor)
{
    double d[3];
    v3_sub(a, b, d);
    return v3_norm(d) / fmax(v3_norm(b), floor);
}

/* Fill the case's metrics from its output and the reference's. */
void cf_study_case_measure(cf_study_case *c, const cf_trajectory *v, const cf_trajectory *r,
                           double D)
{
    c->t_end = v->T ? v->time[v->T - 1] : 0;
    c->n_fragments = 0;
    for (int j = 0; v->T && j < v->N; j++)
        c->n_fragments += !isnan(v->pos[3 * ((size_t)(v->T - 1) * v->N + j)]);
    c->traj_rms = trajectory_error(v, r);
    c->traj_rel = D > 0 ? c->traj_rms / D : NAN;
    c->mass_ks = mass_ks(v, r);
    c->crack_area = v->last[CF_OBS_CRACK_AREA];
    c->dissipated = v->last[CF_OBS_DISSIPATED];
    /* L about the origin is near 0 for motion along a line through it: scale
     * it by the reference's |P| times the distance travelled. */
    const double *P = &r->last[CF_OBS_PX];
    c->p_err = rel_diff3(&v->last[CF_OBS_PX], P, 1e-300);
    c->l_err = rel_diff3(&v->last[CF_OBS_LX], &r->last[CF_OBS_LX], fmax(v3_norm(P) * D, 1e-300));
    double in = v->first[CF_OBS_KINETIC] + v->first[CF_OBS_STRAIN] +
                fabs(v->last[CF_OBS_WORK_GRAVITY]) + fabs(v->last[CF_OBS_WORK_BOUNDARY]) +
                fabs(v->last[CF_OBS_WORK_OBSTACLES]);
    c->residual_rel = in > 0 ? fabs(v->last[CF_OBS_RESIDUAL]) / in : NAN;
}

cf_status cf_study_measure(const char *case_h5, const char *reference_h5, cf_study_case *c,
                           double *travel_out, cf_error *err)
{
    cf_trajectory v, r;
    cf_status st = cf_trajectory_read(reference_h5, &r, err);
    if (st != CF_OK)
        return st;
    st = cf_trajectory_read(case_h5, &v, err);
    if (st == CF_OK) {
        double D = cf_study_travel(&r);
        cf_study_case_measure(c, &v, &r, D);
        if (travel_out)
            *travel_out = D;
        cf_trajectory_free(&v);
    }
    cf_trajectory_free(&r);
    return st;
}

/* Pareto front over (wall, traj_rel) of the finished variants, and the
 * cheapest one within the tolerance. */
int cf_study_pareto(cf_study_case *c, int n, double tol)
{
    int best = -1;
    for (int i = 1; i < n; i++) {
        c[i].pareto = 0;
        if (c[i].exit_code != 0 || !isfinite(c[i].traj_rel))
            continue;
        int dominated = 0;
        for (int j = 1; j < n && !dominated; j++)
            dominated = j != i && c[j].exit_code == 0 && isfinite(c[j].traj_rel) &&
                        c[j].wall <= c[i].wall && c[j].traj_rel <= c[i].traj_rel &&
                        (c[j].wall < c[i].wall || c[j].traj_rel < c[i].traj_rel);
        c[i].pareto = !dominated;
        if (c[i].traj_rel <= tol && (best < 0 || c[i].wall < c[best].wall))
            best = i;
    }
    return best;
}
