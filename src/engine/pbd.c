#include "pbd.h"

#include "linalg.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    int b;          /* the other end */
    double vol;     /* m^3, tributary volume */
} nbr;

/* The bars (a, b > a) of node a: every other node of the tets that hold a,
 * merged per node with their tets' sixths of volume added in ascending tet
 * order.  Writes them ascending in b into out (room for 3 x the star) and
 * returns how many. */
static int node_bars(const cf_solid *s, int a, nbr *out)
{
    int o = s->origin[a], n = 0;
    for (int j = s->vt_start[o]; j < s->vt_start[o + 1]; j++) {
        int slot = s->vt_slot[j], t = slot / 4;
        if (s->tet[slot] != a)
            continue;
        for (int k = 0; k < 4; k++) {
            int b = s->tet[4 * t + k];
            if (b <= a)
                continue;
            /* insertion, stable: equal ends keep ascending tet order */
            int i = n++;
            for (; i > 0 && out[i - 1].b > b; i--)
                out[i] = out[i - 1];
            out[i] = (nbr){b, s->vol[t] / 6.0}; /* tributary volume: a sixth per edge */
        }
    }
    int m = 0;
    for (int i = 0; i < n; i++) {
        if (m > 0 && out[m - 1].b == out[i].b)
            out[m - 1].vol += out[i].vol;
        else
            out[m++] = out[i];
    }
    return m;
}

static int star_size(const cf_solid *s, int a)
{
    return s->vt_start[s->origin[a] + 1] - s->vt_start[s->origin[a]];
}

/* Bars of node a into the arrays at position at; returns 0, -1 out of memory. */
static int fill_node(const cf_solid *s, int a, int *ends, double *rest, double *compliance,
                     int at, int *count)
{
    nbr local[3 * 128];
    int need = 3 * star_size(s, a);
    nbr *e = need <= 3 * 128 ? local : malloc((size_t)need * sizeof *e);
    if (!e)
        return -1;
    int m = node_bars(s, a, e);
    for (int i = 0; ends && i < m; i++) {
        double d[3];
        int b = e[i].b;
        ends[2 * (at + i)] = a, ends[2 * (at + i) + 1] = b;
        v3_sub(&s->X[3 * a], &s->X[3 * b], d);
        rest[at + i] = v3_norm(d);
        /* A bar of section V/L and length L: stiffness E V / L^2. */
        compliance[at + i] = rest[at + i] * rest[at + i] / (s->mat.E * e[i].vol);
    }
    *count = m;
    if (e != local)
        free(e);
    return 0;
}

/* Greedy colouring in bar order: the lowest colour that no bar at either
 * end has yet (128 per node in two masks; beyond that, the last, serial
 * group CF_BARS_COLORS).  Returns the number of groups used. */
static int colour(const int *ends, int n, int nodes, unsigned char *colour_of)
{
    uint64_t (*mask)[2] = calloc((size_t)nodes, sizeof *mask);
    if (!mask)
        return -1;
    int used = 0;
    for (int i = 0; i < n; i++) {
        uint64_t *ma = mask[ends[2 * i]], *mb = mask[ends[2 * i + 1]];
        uint64_t lo = ~(ma[0] | mb[0]), hi = ~(ma[1] | mb[1]);
        int c = lo ? __builtin_ctzll(lo) : hi ? 64 + __builtin_ctzll(hi) : CF_BARS_COLORS;
        if (c < CF_BARS_COLORS) {
            ma[c / 64] |= 1ull << (c % 64);
            mb[c / 64] |= 1ull << (c % 64);
        }
        colour_of[i] = (unsigned char)c;
        used = c + 1 > used ? c + 1 : used;
    }
    free(mask);
    return used;
}

int cf_bars_build(cf_bars *b, const cf_solid *s, const int *tets, int nt)
{
    /* The nodes of the tets, in tet order; then each node's bars. */
    unsigned char *seen = calloc((size_t)s->n_nodes, 1);
    int *nodes = malloc((size_t)(4 * nt + 1) * sizeof(int)), nn = 0;
    int *start = malloc((size_t)(4 * nt + 2) * sizeof(int));
    int rc = -(!seen || !nodes || !start);
    for (int i = 0; rc == 0 && i < nt; i++)
        for (int j = 0; j < 4; j++) {
            int a = s->tet[4 * tets[i] + j];
            if (!seen[a])
                seen[a] = 1, nodes[nn++] = a;
        }
    free(seen);
    int big = nn >= CF_NODES_PARALLEL_MIN;
    /* Each loop runs only when everything before it worked: inside it rc
     * is each thread's copy for the reduction, which starts at 0, so a
     * test of rc there cannot see an earlier failure. */
    if (rc == 0) {
#pragma omp parallel for schedule(static) reduction(| : rc) if (big)
        for (int i = 0; i < nn; i++)
            rc |= fill_node(s, nodes[i], NULL, NULL, NULL, 0, &start[i + 1]);
    }
    int n = 0;
    if (rc == 0) {
        start[0] = 0;
        for (int i = 0; i < nn; i++)
            start[i + 1] += start[i];
        n = start[nn];
    }
    size_t cap = (size_t)(n ? n : 1);
    int *ends = malloc(cap * 2 * sizeof(int)), *e2 = malloc(cap * 2 * sizeof(int));
    double *rest = malloc(cap * sizeof(double)), *r2 = malloc(cap * sizeof(double));
    double *compliance = malloc(cap * sizeof(double)), *c2 = malloc(cap * sizeof(double));
    double *lambda = calloc(cap, sizeof(double));
    unsigned char *col = malloc(cap);
    int *color_start = calloc(CF_BARS_COLORS + 2, sizeof(int));
    if (rc || !ends || !e2 || !rest || !r2 || !compliance || !c2 || !lambda || !col || !color_start)
        rc = -1;
    if (rc == 0) {
#pragma omp parallel for schedule(static) reduction(| : rc) if (big)
        for (int i = 0; i < nn; i++) {
            int m;
            rc |= fill_node(s, nodes[i], ends, rest, compliance, start[i], &m);
        }
    }
    int groups = rc ? -1 : colour(ends, n, s->n_nodes, col);
    if (groups < 0)
        rc = -1;
    if (rc == 0) { /* counting sort by colour, stable */
        for (int i = 0; i < n; i++)
            color_start[col[i] + 1]++;
        for (int c = 0; c <= CF_BARS_COLORS; c++)
            color_start[c + 1] += color_start[c];
        int at[CF_BARS_COLORS + 1]; /* the next slot of each colour */
        memcpy(at, color_start, sizeof at);
        for (int i = 0; i < n; i++) {
            int k = at[col[i]]++;
            e2[2 * k] = ends[2 * i], e2[2 * k + 1] = ends[2 * i + 1];
            r2[k] = rest[i], c2[k] = compliance[i];
        }
    }
    free(nodes), free(start), free(col), free(ends), free(rest), free(compliance);
    if (rc) {
        free(e2), free(r2), free(c2), free(lambda), free(color_start);
        return -1;
    }
    cf_bars_free(b);
    b->n = n, b->ends = e2, b->rest = r2, b->compliance = c2, b->lambda = lambda;
    b->n_colors = groups, b->color_start = color_start;
    return 0;
}

void cf_bars_free(cf_bars *b)
{
    free(b->ends);
    free(b->rest);
    free(b->compliance);
    free(b->lambda);
    free(b->color_start);
    memset(b, 0, sizeof *b);
}

double cf_pbd_effective_stiffness(double k, int iterations, int iteration_independent)
{
    if (!iteration_independent || iterations < 1)
        return k;
    return 1.0 - pow(1.0 - k, 1.0 / iterations);
}

/* Bar i now: its ends' predictions and inverse masses, d = p1 - p2 and |d|. */
typedef struct {
    double *p1, *p2, w1, w2, d[3], len;
} bar_now;

static inline bar_now bar_at(const cf_bars *b, cf_solid *s, int i)
{
    int i1 = b->ends[2 * i], i2 = b->ends[2 * i + 1];
    bar_now r = {&s->p[3 * i1], &s->p[3 * i2], 1.0 / s->m[i1], 1.0 / s->m[i2], {0, 0, 0}, 0};
    v3_sub(r.p1, r.p2, r.d);
    r.len = v3_norm(r.d);
    return r;
}

/* One bar of the PBD sweep. */
static inline void project_bar(const cf_bars *b, cf_solid *s, double k, int i)
{
    bar_now r = bar_at(b, s, i);
    if (r.len == 0)
        return;
    double c = k * (r.len - b->rest[i]) / ((r.w1 + r.w2) * r.len);
    v3_axpy(-r.w1 * c, r.d, r.p1);
    v3_axpy(r.w2 * c, r.d, r.p2);
}

/* One bar of the XPBD sweep. */
static inline void project_bar_xpbd(cf_bars *b, cf_solid *s, double dt, double scale, int i)
{
    bar_now r = bar_at(b, s, i);
    if (r.len == 0)
        return;
    double at = scale * b->compliance[i] / (dt * dt);
    double dl = (-(r.len - b->rest[i]) - at * b->lambda[i]) / (r.w1 + r.w2 + at);
    b->lambda[i] += dl;
    v3_axpy(r.w1 * dl / r.len, r.d, r.p1);
    v3_axpy(-r.w2 * dl / r.len, r.d, r.p2);
}

/* Colour by colour; the bars of one colour share no node, so they run in
 * parallel and in any order with the same result.  The last group holds
 * bars no colour could take: one thread. */
#define SWEEP(b, CALL)                                                                         \
    _Pragma("omp parallel if ((b)->n >= CF_BARS_PARALLEL_MIN)")                                \
    {                                                                                          \
        for (int c = 0; c < (b)->n_colors && c < CF_BARS_COLORS; c++) {                        \
            _Pragma("omp for schedule(static)")                                                \
            for (int i = (b)->color_start[c]; i < (b)->color_start[c + 1]; i++)                \
                CALL;                                                                          \
        }                                                                                      \
        _Pragma("omp single")                                                                  \
        for (int i = (b)->color_start[CF_BARS_COLORS]; i < (b)->n; i++)                        \
            CALL;                                                                              \
    }

void cf_bars_project(const cf_bars *b, cf_solid *s, double k)
{
    if (b->n > 0)
        SWEEP(b, project_bar(b, s, k, i))
}

/* Bar i's two ends see each other's speed. */
static inline void neighbour_speed(const cf_bars *b, const double *v, double *cap, int i)
{
    int a = b->ends[2 * i], c = b->ends[2 * i + 1];
    cap[a] = fmax(cap[a], v3_norm(&v[3 * c]));
    cap[c] = fmax(cap[c], v3_norm(&v[3 * a]));
}

void cf_bars_neighbour_speed(const cf_bars *b, const double *v, double *cap)
{
    if (b->n > 0)
        SWEEP(b, neighbour_speed(b, v, cap, i))
}

void cf_bars_project_xpbd(cf_bars *b, cf_solid *s, double dt, double scale)
{
    if (b->n > 0)
        SWEEP(b, project_bar_xpbd(b, s, dt, scale, i))
}

void cf_bars_reset_lambda(cf_bars *b)
{
    if (b->n > 0)
        memset(b->lambda, 0, (size_t)b->n * sizeof(double));
}
