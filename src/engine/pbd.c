#include "pbd.h"

#include "insertion.h"
#include "lanes.h"
#include "linalg.h"
#include "parallel.h"

#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    int b;          /* the other end */
    double vol;     /* m^3, tributary volume */
} nbr;

/* The bars of node a: every other node b of the tets that hold a, merged
 * per node with their tets' sixths of volume added in ascending tet order.
 * Only b > a, except that with `lower` (a flag per node, or NULL) also the
 * b < a with lower[b] == 0.  Writes them ascending in b into out (room for
 * 3 x the star) and returns how many. */
static int node_bars(const cf_solid *s, int a, const unsigned char *lower, nbr *out)
{
    int o = s->origin[a], n = 0;
    for (int j = s->vt_start[o]; j < s->vt_start[o + 1]; j++) {
        int slot = s->vt_slot[j], t = slot / 4;
        if (s->tet[slot] != a)
            continue;
        for (int k = 0; k < 4; k++) {
            int b = s->tet[4 * t + k];
            if (b == a || (b < a && (!lower || lower[b])))
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

/* Bars of node a (node_bars) into the arrays at position at, each pair in
 * ascending order; returns 0, -1 out of memory. */
static int fill_node(const cf_solid *s, int a, const unsigned char *lower, int *ends, double *rest,
                     double *compliance, int at, int *count)
{
    nbr local[3 * 128];
    int need = 3 * star_size(s, a);
    nbr *e = need <= 3 * 128 ? local : malloc((size_t)need * sizeof *e);
    if (!e)
        return -1;
    int m = node_bars(s, a, lower, e);
    for (int i = 0; ends && i < m; i++) {
        double d[3];
        int b = e[i].b;
        ends[2 * (at + i)] = a < b ? a : b, ends[2 * (at + i) + 1] = a < b ? b : a;
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

/* The lowest colour free at both masks, marked used in both; CF_BARS_COLORS
 * when none is. */
static int take_colour(uint64_t *ma, uint64_t *mb)
{
    uint64_t lo = ~(ma[0] | mb[0]), hi = ~(ma[1] | mb[1]);
    int c = lo ? __builtin_ctzll(lo) : hi ? 64 + __builtin_ctzll(hi) : CF_BARS_COLORS;
    if (c < CF_BARS_COLORS) {
        ma[c / 64] |= 1ull << (c % 64);
        mb[c / 64] |= 1ull << (c % 64);
    }
    return c;
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
        int c = take_colour(mask[ends[2 * i]], mask[ends[2 * i + 1]]);
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
        CF_PARALLEL(big, "omp parallel for schedule(static) reduction(| : rc)",
            for (int i = 0; i < nn; i++)
                rc |= fill_node(s, nodes[i], NULL, NULL, NULL, NULL, 0, &start[i + 1]););
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
        CF_PARALLEL(big, "omp parallel for schedule(static) reduction(| : rc)",
            for (int i = 0; i < nn; i++) {
                int m;
                rc |= fill_node(s, nodes[i], NULL, ends, rest, compliance, start[i], &m);
            });
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
    b->n = n, b->cap = n, b->ends = e2, b->rest = r2, b->compliance = c2, b->lambda = lambda;
    b->n_colors = groups, b->color_start = color_start;
    return 0;
}

/* *p resized to cap elements of `size` bytes; on failure *p stays as it
 * was (still owned by the caller).  0 or -1. */
static int resize(void *p, size_t size, int cap)
{
    void *q = realloc(*(void **)p, (size_t)cap * size);
    if (!q)
        return -1;
    *(void **)p = q;
    return 0;
}

/* Room for `nodes` node flags and masks and `bars` new bars; 0 or -1. */
static int scratch_reserve(cf_bars_scratch *w, int nodes, int bars)
{
    if (nodes > w->node_cap) {
        int cap = nodes + nodes / 2 + 16;
        if (resize(&w->flag, 1, cap) || resize(&w->mask, sizeof *w->mask, cap) ||
            resize(&w->list, sizeof(int), cap))
            return -1;
        memset(w->flag + w->node_cap, 0, (size_t)(cap - w->node_cap));
        w->node_cap = cap;
    }
    if (bars > w->bar_cap) {
        int cap = bars + bars / 2 + 64;
        if (resize(&w->ends, 2 * sizeof(int), cap) || resize(&w->rest, sizeof(double), cap) ||
            resize(&w->compliance, sizeof(double), cap) || resize(&w->colour, 1, cap))
            return -1;
        w->bar_cap = cap;
    }
    return 0;
}

void cf_bars_scratch_free(cf_bars_scratch *w)
{
    free(w->flag), free(w->mask), free(w->list);
    free(w->ends), free(w->rest), free(w->compliance), free(w->colour);
    memset(w, 0, sizeof *w);
}

/* Room for n bars in b (amortised); 0 or -1. */
static int bars_reserve(cf_bars *b, int n)
{
    if (n <= b->cap)
        return 0;
    int cap = n + n / 8 + 64;
    if (resize(&b->ends, 2 * sizeof(int), cap) || resize(&b->rest, sizeof(double), cap) ||
        resize(&b->compliance, sizeof(double), cap) || resize(&b->lambda, sizeof(double), cap))
        return -1;
    b->cap = cap;
    return 0;
}

/* Flag values in cf_bars_scratch: a node whose star changed, and a node
 * that shares a new bar with one. */
enum { TOUCHED = 1, NEIGHBOUR = 2 };

int cf_bars_patch(cf_bars *b, const cf_solid *s, const int *touched, int n_touched,
                  cf_bars_scratch *w)
{
    if (n_touched == 0 || !b->color_start) /* no bars kept: none to patch */
        return 0;
    if (scratch_reserve(w, s->n_nodes, 0))
        return -1;
    /* The touched nodes, once each, ascending: the order the new bars are
     * made and coloured in depends only on which nodes changed. */
    int nd = 0, room = 0;
    for (int i = 0; i < n_touched; i++)
        if (!w->flag[touched[i]]) {
            w->flag[touched[i]] = TOUCHED, w->list[nd++] = touched[i];
            room += 3 * star_size(s, touched[i]); /* node_bars' bound */
        }
    cf_ints_sort(w->list, nd);
    /* Their bars: every bar at a touched node, a pair of touched nodes once. */
    if (scratch_reserve(w, s->n_nodes, room))
        return -1;
    int n_new = 0, m;
    for (int i = 0; i < nd; i++, n_new += m)
        if (fill_node(s, w->list[i], w->flag, w->ends, w->rest, w->compliance, n_new, &m))
            return -1;
    /* The colours the kept bars use at the new bars' untouched ends. */
    int nn = nd;
    for (int i = 0; i < 2 * n_new; i++) {
        int a = w->ends[i];
        if (w->flag[a] == 0)
            w->flag[a] = NEIGHBOUR, w->list[nn++] = a;
    }
    for (int i = 0; i < nn; i++)
        w->mask[w->list[i]][0] = w->mask[w->list[i]][1] = 0;
    /* Drop the bars at touched nodes, in place and in order. */
    int kept[CF_BARS_COLORS + 2], cnt[CF_BARS_COLORS + 1] = {0}, at = 0;
    for (int c = 0; c <= CF_BARS_COLORS; c++) {
        kept[c] = at;
        for (int i = b->color_start[c]; i < b->color_start[c + 1]; i++) {
            int e0 = b->ends[2 * i], e1 = b->ends[2 * i + 1];
            if (w->flag[e0] == TOUCHED || w->flag[e1] == TOUCHED)
                continue;
            if (c < CF_BARS_COLORS && w->flag[e0] == NEIGHBOUR)
                w->mask[e0][c / 64] |= 1ull << (c % 64);
            if (c < CF_BARS_COLORS && w->flag[e1] == NEIGHBOUR)
                w->mask[e1][c / 64] |= 1ull << (c % 64);
            b->ends[2 * at] = e0, b->ends[2 * at + 1] = e1;
            b->rest[at] = b->rest[i], b->compliance[at] = b->compliance[i];
            at++;
        }
    }
    kept[CF_BARS_COLORS + 1] = at;
    /* The new bars coloured greedily around them. */
    for (int j = 0; j < n_new; j++) {
        int c = take_colour(w->mask[w->ends[2 * j]], w->mask[w->ends[2 * j + 1]]);
        w->colour[j] = (unsigned char)c;
        cnt[c]++;
    }
    for (int i = 0; i < nn; i++)
        w->flag[w->list[i]] = 0;
    /* Regroup: each colour's kept bars, then its new ones.  Groups move
     * right (from the last), so nothing is overwritten before it moves. */
    int start[CF_BARS_COLORS + 2];
    start[0] = 0;
    for (int c = 0; c <= CF_BARS_COLORS; c++)
        start[c + 1] = start[c] + (kept[c + 1] - kept[c]) + cnt[c];
    int n = start[CF_BARS_COLORS + 1];
    if (bars_reserve(b, n))
        return -1;
    for (int c = CF_BARS_COLORS; c >= 0; c--) {
        size_t len = (size_t)(kept[c + 1] - kept[c]);
        memmove(&b->ends[2 * start[c]], &b->ends[2 * kept[c]], 2 * len * sizeof(int));
        memmove(&b->rest[start[c]], &b->rest[kept[c]], len * sizeof(double));
        memmove(&b->compliance[start[c]], &b->compliance[kept[c]], len * sizeof(double));
        cnt[c] = start[c] + (int)len; /* now: the next free slot of colour c */
    }
    for (int j = 0; j < n_new; j++) {
        int k = cnt[w->colour[j]]++;
        b->ends[2 * k] = w->ends[2 * j], b->ends[2 * k + 1] = w->ends[2 * j + 1];
        b->rest[k] = w->rest[j], b->compliance[k] = w->compliance[j];
    }
    memset(b->lambda, 0, (size_t)n * sizeof(double));
    memcpy(b->color_start, start, sizeof start);
    b->n = n, b->n_colors = 0;
    for (int c = 0; c <= CF_BARS_COLORS; c++)
        if (start[c + 1] > start[c])
            b->n_colors = c + 1;
    return 0;
}

int cf_bars_split(const cf_bars *src, const int *piece_of_node, int k, cf_bars *const *dst)
{
    int rc = 0;
    for (int p = 0; p < k; p++)
        cf_bars_free(dst[p]);
    if (!src->color_start) /* no bars kept: the pieces keep none */
        return 0;
    for (int p = 0; p < k; p++) {
        cf_bars *d = dst[p];
        d->color_start = calloc(CF_BARS_COLORS + 2, sizeof(int));
        rc |= !d->color_start;
    }
    if (rc)
        return -1;
    /* Counts per piece and colour, then each piece's bars in source order:
     * a subset of a colouring is a colouring. */
    for (int c = 0; c <= CF_BARS_COLORS; c++)
        for (int i = src->color_start[c]; i < src->color_start[c + 1]; i++)
            dst[piece_of_node[src->ends[2 * i]]]->color_start[c + 1]++;
    for (int p = 0; p < k; p++) {
        cf_bars *d = dst[p];
        for (int c = 0; c <= CF_BARS_COLORS; c++) {
            if (d->color_start[c + 1] > 0)
                d->n_colors = c + 1;
            d->color_start[c + 1] += d->color_start[c];
        }
        if (bars_reserve(d, d->color_start[CF_BARS_COLORS + 1]))
            return -1;
        d->n = 0;
    }
    for (int i = 0; i < src->n; i++) {
        cf_bars *d = dst[piece_of_node[src->ends[2 * i]]];
        int j = d->n++;
        d->ends[2 * j] = src->ends[2 * i], d->ends[2 * j + 1] = src->ends[2 * i + 1];
        d->rest[j] = src->rest[i], d->compliance[j] = src->compliance[i];
        d->lambda[j] = 0;
    }
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

/* Bar i now: its ends' rows of s->p (prediction, inverse mass), d = p1 - p2
 * and |d|. */
typedef struct {
    double *p1, *p2, d[3], len;
} bar_now;

static inline bar_now bar_at(const cf_bars *b, cf_solid *s, int i)
{
    bar_now r = {&s->p[4 * b->ends[2 * i]], &s->p[4 * b->ends[2 * i + 1]], {0, 0, 0}, 0};
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
    double w1 = r.p1[3], w2 = r.p2[3], c = k * (r.len - b->rest[i]) / ((w1 + w2) * r.len);
    v3_axpy(-w1 * c, r.d, r.p1);
    v3_axpy(w2 * c, r.d, r.p2);
}

/* One bar of the XPBD sweep. */
static inline void project_bar_xpbd(cf_bars *b, cf_solid *s, double dt, double scale, int i)
{
    bar_now r = bar_at(b, s, i);
    if (r.len == 0)
        return;
    double w1 = r.p1[3], w2 = r.p2[3], at = scale * b->compliance[i] / (dt * dt);
    double dl = (-(r.len - b->rest[i]) - at * b->lambda[i]) / (w1 + w2 + at);
    b->lambda[i] += dl;
    v3_axpy(w1 * dl / r.len, r.d, r.p1);
    v3_axpy(-w2 * dl / r.len, r.d, r.p2);
}

/* Bars i..i+LANES-1, of one colour: project_bar on each lane, all lanes
 * loaded before any is stored (they share no node, so that is the order
 * one at a time gives too).  Each lane does project_bar's operations in
 * its order: the same bits. */
static inline __attribute__((always_inline)) void project_lanes(const cf_bars *b, cf_solid *s,
                                                                double k, int i)
{
    int r1[LANES], r2[LANES];
    for (int l = 0; l < LANES; l++)
        r1[l] = b->ends[2 * (i + l)], r2[l] = b->ends[2 * (i + l) + 1];
    vd p1[4], p2[4], rest; /* x y z w of each end */
    lanes_load(s->p, 4, r1, p1);
    lanes_load(s->p, 4, r2, p2);
    __builtin_memcpy(&rest, &b->rest[i], sizeof rest);
    vd dx = p1[0] - p2[0], dy = p1[1] - p2[1], dz = p1[2] - p2[2];
    vd len = v_sqrt(dx * dx + dy * dy + dz * dz);
    vd c = splat(k) * (len - rest) / ((p1[3] + p2[3]) * len), a1 = -p1[3] * c, a2 = p2[3] * c;
    vm moves = (vm)(len != splat(0)); /* project_bar leaves a bar of zero length alone */
    p1[0] = pick(moves, p1[0] + a1 * dx, p1[0]), p1[1] = pick(moves, p1[1] + a1 * dy, p1[1]);
    p1[2] = pick(moves, p1[2] + a1 * dz, p1[2]);
    p2[0] = pick(moves, p2[0] + a2 * dx, p2[0]), p2[1] = pick(moves, p2[1] + a2 * dy, p2[1]);
    p2[2] = pick(moves, p2[2] + a2 * dz, p2[2]);
    lanes_store(p1, 4, s->p, r1, LANES);
    lanes_store(p2, 4, s->p, r2, LANES);
}

/* A colour's bars reach their ends' rows all over the prediction (1.6 MB
 * on the 203k-tet bunny: more than a core's L2), in an order the hardware
 * cannot guess: each block asks for the rows of the bars this many ahead
 * (the PBD stage x1.07 on one thread; 32 ahead was no better). */
enum { PREFETCH = 16 };

/* Bar i's two ends see each other's speed (a comparison, not fmax: the
 * library call cost more than the rest of the sweep; speeds are never NaN). */
static inline void neighbour_speed(const cf_bars *b, const double *speed, double *cap, int i)
{
    int a = b->ends[2 * i], c = b->ends[2 * i + 1];
    cap[a] = speed[c] > cap[a] ? speed[c] : cap[a];
    cap[c] = speed[a] > cap[c] ? speed[a] : cap[c];
}

/* One bar: project_bar, and with cap its neighbour_speed (a run's last
 * bars and the serial group). */
static inline void project_one(const cf_bars *b, cf_solid *s, double k, const double *speed,
                               double *cap, int i)
{
    project_bar(b, s, k, i);
    if (cap)
        neighbour_speed(b, speed, cap, i);
}

/* Bars i0..i1-1 of one colour: four at a time, the rest one by one (one
 * call per thread and colour, so the clone is chosen once per run); with
 * cap, each bar's neighbour_speed too. */
CF_LANE_CLONES static void project_run(const cf_bars *b, cf_solid *s, double k, const double *speed,
                                       double *cap, int i0, int i1)
{
    int i = i0;
    for (; i + LANES <= i1; i += LANES) {
        for (int j = 2 * (i + PREFETCH); j < 2 * (i + PREFETCH + LANES) && j < 2 * i1; j++)
            __builtin_prefetch(&s->p[4 * b->ends[j]], 1);
        project_lanes(b, s, k, i);
        for (int l = 0; cap && l < LANES; l++)
            neighbour_speed(b, speed, cap, i + l);
    }
    for (; i < i1; i++)
        project_one(b, s, k, speed, cap, i);
}

/* Colour by colour; the bars of one colour share no node, so they run in
 * parallel and in any order with the same result.  Each thread takes one
 * run i0..i1-1 of the colour's bars (cut at multiples of W) and does RUN;
 * then all wait.  The last group holds bars no colour could take: one
 * thread, one bar i at a time in order (ONE).  SWEEP_EACH: ONE for every
 * bar, colours included. */
#define SWEEP_BODY(b, W, RUN, ONE)                                                             \
    {                                                                                          \
        long nth_ = omp_get_num_threads(), me_ = omp_get_thread_num();                         \
        for (int c = 0; c < (b)->n_colors && c < CF_BARS_COLORS; c++) {                        \
            int c0 = (b)->color_start[c], c1 = (b)->color_start[c + 1];                        \
            long nb_ = (c1 - c0 + (W)-1) / (W);                                                \
            int i0 = c0 + (W) * (int)(nb_ * me_ / nth_);                                       \
            int i1 = c0 + (W) * (int)(nb_ * (me_ + 1) / nth_);                                 \
            i0 = i0 < c1 ? i0 : c1, i1 = i1 < c1 ? i1 : c1;                                   \
            RUN;                                                                               \
            _Pragma("omp barrier")                                                             \
        }                                                                                      \
        _Pragma("omp single")                                                                  \
        for (int i = (b)->color_start[CF_BARS_COLORS]; i < (b)->n; i++)                        \
            ONE;                                                                               \
    }
/* On the threads only when they can share the work (parallel.h). */
#define SWEEP(b, W, RUN, ONE)                                                                  \
    do {                                                                                       \
        if ((b)->n >= CF_BARS_PARALLEL_MIN && omp_get_max_threads() > 1) {                     \
            _Pragma("omp parallel") SWEEP_BODY(b, W, RUN, ONE)                                 \
        } else {                                                                               \
            SWEEP_BODY(b, W, RUN, ONE)                                                         \
        }                                                                                      \
    } while (0)
#define SWEEP_EACH(b, ONE) SWEEP(b, 1, for (int i = i0; i < i1; i++) ONE, ONE)

void cf_bars_project(const cf_bars *b, cf_solid *s, double k, const double *speed, double *cap)
{
    if (b->n > 0)
        SWEEP(b, LANES, project_run(b, s, k, speed, cap, i0, i1),
              project_one(b, s, k, speed, cap, i));
}

void cf_bars_neighbour_speed(const cf_bars *b, const double *speed, double *cap)
{
    if (b->n > 0)
        SWEEP_EACH(b, neighbour_speed(b, speed, cap, i));
}

void cf_bars_project_xpbd(cf_bars *b, cf_solid *s, double dt, double scale)
{
    if (b->n > 0)
        SWEEP_EACH(b, project_bar_xpbd(b, s, dt, scale, i));
}

void cf_bars_reset_lambda(cf_bars *b)
{
    if (b->n > 0)
        memset(b->lambda, 0, (size_t)b->n * sizeof(double));
}
