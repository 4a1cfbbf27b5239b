#include "insertion.h"

#include "chunks.h"
#include "grow.h"
#include "linalg.h"
#include "parallel.h"
#include "tet4.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>

int cf_int_list_reserve(cf_int_list *l, int n)
{
    return cf_grow_to((void **)&l->v, &l->cap, n, sizeof(int), 64);
}

int cf_int_list_push(cf_int_list *l, int value)
{
    if (cf_int_list_reserve(l, l->n + 1))
        return -1;
    l->v[l->n++] = value;
    return 0;
}

static int by_int(const void *x, const void *y)
{
    int a = *(const int *)x, b = *(const int *)y;
    return (a > b) - (a < b);
}

void cf_ints_sort(int *v, int n) { qsort(v, (size_t)n, sizeof(int), by_int); }

/* Current unit normal of face k of tet t (outward from t). */
static void face_normal(const cf_solid *s, int t, int k, double n[3])
{
    const int *T = &s->tet[4 * t];
    const double *a = &s->x[3 * T[CF_TET_FACE[k][0]]], *b = &s->x[3 * T[CF_TET_FACE[k][1]]],
                 *c = &s->x[3 * T[CF_TET_FACE[k][2]]];
    double e1[3], e2[3];
    v3_sub(b, a, e1), v3_sub(c, a, e2), v3_cross(e1, e2, n);
    double l = v3_norm(n);
    for (int i = 0; i < 3; i++)
        n[i] = l > 0 ? n[i] / l : 0;
}

/* Largest eigenvalue of a symmetric 3x3 matrix (trigonometric closed form). */
static double max_principal(const double A[9])
{
    double p1 = A[1] * A[1] + A[2] * A[2] + A[5] * A[5];
    if (p1 == 0)
        return fmax(A[0], fmax(A[4], A[8]));
    double q = (A[0] + A[4] + A[8]) / 3;
    double p2 = (A[0] - q) * (A[0] - q) + (A[4] - q) * (A[4] - q) + (A[8] - q) * (A[8] - q) + 2 * p1;
    double p = sqrt(p2 / 6), B[9];
    for (int k = 0; k < 9; k++)
        B[k] = (A[k] - ((k % 4) == 0 ? q : 0)) / p;
    double r = fmax(-1.0, fmin(1.0, m3_det(B) / 2));
    return q + 2 * p * cos(acos(r) / 3);
}

/* Volume-averaged maximum principal stress at node n: over the tets of
 * fragment `frag` that hold a copy of n's original vertex, in ascending tet
 * order.  The whole star, not the copy's own part of it: where node
 * duplication has split a vertex beside a crack, a copy's part is a few
 * tets on one side, and its average would read the stress of one tet
 * instead of the material's around the vertex (docs/physics.md §5.1).
 * Where a bound shows it to lie below `lowest` (Pa) the bound is returned
 * instead (still below it), without the eigenvalue's trigonometry.  The
 * mean stress itself goes to s->nodal_stress[n], stamped with this check. */
static double nodal_principal(cf_solid *s, int n, int frag, double lowest)
{
    int o = s->origin[n];
    double a[10] = {0};
    for (int j = s->vt_start[o]; j < s->vt_start[o + 1]; j++) {
        int slot = s->vt_slot[j], t = slot / 4;
        if (s->tet_frag[t] != frag)
            continue;
        for (int k = 0; k < 9; k++)
            a[k] += s->vol[t] * s->sigma[9 * t + k];
        a[9] += s->vol[t];
    }
    double sig[9], *out = &s->nodal_stress[6 * n];
    for (int k = 0; k < 9; k++)
        sig[k] = a[k] / a[9];
    out[0] = sig[0], out[1] = sig[4], out[2] = sig[8], out[3] = sig[1], out[4] = sig[2],
    out[5] = sig[5];
    s->nodal_check[n] = s->check_stamp;
    double bound = cf_tet4_max_principal_bound(sig);
    return bound < lowest ? bound : max_principal(sig);
}

/* The source rule's threshold for a facet of strength factor w, Pa: 0.9 of
 * its strength (the source's §6.6.2). */
static double source_threshold(double sigma_max, double w) { return 0.9 * sigma_max * w; }

/* Normal and shear traction (Pa) on face k of tet ta from the mean stress of
 * the facet's two tets, across its current normal. */
static void facet_traction(const cf_solid *s, int ta, int k, double *sn, double *tau)
{
    int tb = s->facet[4 * s->tet_facet[4 * ta + k] + 2];
    double sig[9], n[3], t[3];
    for (int j = 0; j < 9; j++)
        sig[j] = 0.5 * (s->sigma[9 * ta + j] + s->sigma[9 * tb + j]);
    face_normal(s, ta, k, n);
    m3_mulv(sig, n, t);
    *sn = v3_dot(n, t);
    double tau2 = v3_dot(t, t) - *sn * *sn;
    *tau = tau2 > 0 ? sqrt(tau2) : 0;
}

/* Whether facet (ta, face k) passes the source's rule: every one of its
 * three nodes is held by a hot tet and its nodal value (computed for those
 * nodes by nodal_values) reaches the threshold. */
static int source_rule(const cf_solid *s, int ta, int k, double threshold)
{
    for (int j = 0; j < 3; j++) {
        int n = s->tet[4 * ta + CF_TET_FACE[k][j]];
        if (!s->node_mark[n] || s->nodal[n] < threshold)
            return 0;
    }
    return 1;
}

/* Clears the marks of nodes[0..n). */
static void clear_marks(cf_solid *s, const int *nodes, int n)
{
    for (int i = 0; i < n; i++)
        s->node_mark[nodes[i]] = 0;
}

/* Marks the nodes of hot tets, listing each once in `marked`; out of
 * memory: -1, with no mark left set.  The hot tets lie between positions
 * first and last of the list: the scan for them starts and ends there.
 * On one thread (par unset) the list is in the scan's order; on the
 * threads the marks are set first and the list is read from them in node
 * order.  Each loop that reads the list treats every node on its own, so
 * its order never shows (the state hashes of the plaster drops are the
 * same); the serial list was a fortieth of the 202,231-tet drop's break
 * on the main thread. */
static int mark_hot_nodes(cf_solid *s, const int *tets, int first, int last, int par,
                          cf_int_list *marked)
{
    if (!par) {
        for (int i = first; i <= last; i++)
            if (s->hot[tets[i]])
                for (int j = 0; j < 4; j++) {
                    int n = s->tet[4 * tets[i] + j];
                    if (s->node_mark[n])
                        continue;
                    if (cf_int_list_push(marked, n)) {
                        clear_marks(s, marked->v, marked->n);
                        return -1;
                    }
                    s->node_mark[n] = 1;
                }
        return 0;
    }
    int lo = INT_MAX, hi = -1;
    CF_PARALLEL(last >= first,
                "omp parallel for schedule(static) reduction(min : lo) reduction(max : hi)",
        for (int i = first; i <= last; i++)
            if (s->hot[tets[i]])
                for (int j = 0; j < 4; j++) {
                    int n = s->tet[4 * tets[i] + j];
                    __atomic_store_n(&s->node_mark[n], 1, __ATOMIC_RELAXED);
                    lo = n < lo ? n : lo, hi = n > hi ? n : hi;
                });
    if (hi < lo)
        return 0;
    if (cf_int_list_reserve(marked, marked->n + (hi - lo + 1))) {
        memset(s->node_mark + lo, 0, (size_t)(hi - lo + 1)); /* only this check's marks */
        return -1;
    }
    marked->n += cf_flagged_chunks(NULL, lo, hi - lo + 1, s->node_mark, 1, marked->v + marked->n);
    return 0;
}

/* Loops that walk each marked node's star (some 16-24 tets, each read
 * whole) go on the threads from this many nodes: a walk costs what some
 * hundred plain node updates do, so they repay the fork and join sooner
 * than CF_NODES_PARALLEL_MIN's loops. */
enum { STAR_PARALLEL_MIN = 256 };

/* The threshold of the source's rule of the weakest interior facet on
 * original vertex o, Pa (INFINITY where none). */
static double strength_floor(const cf_solid *s, int o)
{
    return source_threshold(s->mat.sigma_max, s->vert_wmin ? s->vert_wmin[o] : s->strength_min);
}

/* The lowest threshold of the source's rule among the facets on node n's
 * original vertex, Pa: its weakest facet's (strength_floor); with a front
 * threshold from the toughness, no more than the lowest of the fronts it
 * now has ahead (s->vert_front_active: a front needs a cracked edge, so a
 * vertex that none faces passes only at its strength).  A nodal value below
 * it passes no facet there (source_threshold grows with the strength,
 * rounding included). */
static double vertex_floor(const cf_solid *s, int n)
{
    int o = s->origin[n];
    double floor = strength_floor(s, o);
    return s->vert_front_active ? fmin(floor, s->vert_front_active[o]) : floor;
}

/* The source's nodal values at the marked nodes (each node writes its
 * own), exact from `lowest` (Pa, the weakest facet's threshold) up; then
 * the nodes whose value lies below their vertex's floor (vertex_floor),
 * which no facet's rule can take, unmarked and dropped from the list, in
 * order.  Only the tets the rest own can then qualify: the same facets,
 * from fewer stars.  With a strength field the floor of a vertex is its
 * own weakest facet's, where the solid's weakest would keep most stressed
 * nodes.  The values stay exact from `lowest` up all the same where a
 * front's rank reads all three of its nodes' (facet_ratio), the two on its
 * cracked edge below any floor; with `floor_exact` no rank reads a value
 * below its vertex's floor (a front ranks by its normal stress, a nucleus
 * has all three nodes at their thresholds, or no rank is read), and the
 * values are exact from each vertex's floor up: the eigenvalue's
 * trigonometry is spared where a bound shows a node below it. */
static void nodal_values(cf_solid *s, cf_int_list *marked, int frag, double lowest,
                         int floor_exact)
{
    /* The copies of one original vertex in the fragment share its star,
     * so they share its value: the first copy to claim the vertex in this
     * check walks the star, the others take what it found.  Beside a crack
     * a vertex has two or more copies, and the marked nodes lie there. */
    unsigned stamp = s->check_stamp;
    CF_PARALLEL(marked->n >= STAR_PARALLEL_MIN, "omp parallel for schedule(static)",
        for (int i = 0; i < marked->n; i++) {
            int n = marked->v[i], o = s->origin[n];
            if (__atomic_exchange_n(&s->vert_check[o], stamp, __ATOMIC_RELAXED) != stamp) {
                double from = floor_exact ? vertex_floor(s, n) : lowest;
                s->vert_node[o] = n;
                s->nodal[n] = nodal_principal(s, n, frag, from);
            }
        });
    CF_PARALLEL(marked->n >= STAR_PARALLEL_MIN, "omp parallel for schedule(static)",
        for (int i = 0; i < marked->n; i++) {
            int n = marked->v[i], m = s->vert_node[s->origin[n]];
            if (m != n) {
                s->nodal[n] = s->nodal[m], s->nodal_check[n] = stamp;
                memcpy(&s->nodal_stress[6 * n], &s->nodal_stress[6 * m], 6 * sizeof(double));
            }
        });
    int kept = 0;
    for (int i = 0; i < marked->n; i++) {
        int n = marked->v[i];
        if (s->nodal[n] < vertex_floor(s, n)) /* a NaN stays, as source_rule lets it pass */
            s->node_mark[n] = 0;
        else
            marked->v[kept++] = n;
    }
    marked->n = kept;
}

/* The original vertices of face k of tet t. */
static void face_vertices(const cf_solid *s, int t, int k, int o[3])
{
    for (int j = 0; j < 3; j++)
        o[j] = s->tet0[4 * t + CF_TET_FACE[k][j]];
}

/* Slot of original vertex o in tet t, or -1. */
static int slot_of(const cf_solid *s, int t, int o)
{
    for (int j = 0; j < 4; j++)
        if (s->tet0[4 * t + j] == o)
            return j;
    return -1;
}

/* The edge of corners i and j of a tet, as s->edge_cracks numbers it. */
static const unsigned char CF_TET_EDGE[4][4] = {{0, 0, 1, 2}, {0, 0, 3, 4}, {1, 3, 0, 5},
                                               {2, 4, 5, 0}};

/* How many cracked facets hold the edge of corners i and j of tet t. */
static int edge_count(const cf_solid *s, int t, int i, int j)
{
    return s->edge_cracks[6 * t + CF_TET_EDGE[i][j]];
}

/* Whether a cracked facet other than f holds the edge of corners i and j
 * of tet t, which facet f holds. */
static int edge_cracked(const cf_solid *s, int f, int t, int i, int j)
{
    return edge_count(s, t, i, j) > s->cracked[f];
}

/* The widest crack on the edge of original vertices a and b: among the
 * cracked facets other than `skip` there, the one with the lowest
 * penny-crack threshold (cf_front_penny), which goes to *th (INFINITY
 * where none).  Returns that facet, or -1.  With s->nucleus. */
static int widest_on_edge(const cf_solid *s, int a, int b, int skip, double *th)
{
    int widest = -1;
    *th = INFINITY;
    for (int j = s->vt_start[a]; j < s->vt_start[a + 1]; j++) {
        int slot = s->vt_slot[j], t = slot / 4, sb = slot_of(s, t, b);
        for (int q = 0; sb >= 0 && q < 4; q++) { /* face q holds every corner but q */
            int g = s->tet_facet[4 * t + q];
            if (q == slot % 4 || q == sb || g == skip || !s->cracked[g])
                continue;
            double p = cf_front_penny(s, s->nucleus[g], a, b);
            if (p < *th)
                *th = p, widest = g;
        }
    }
    return widest;
}

/* The threshold of the vertex at corner j of face k of tet ta as the vertex
 * ahead of a front, Pa: the facet's `threshold`, or with
 * solver.front_threshold "toughness" at most the field of a crack tip at
 * the toughness, K_IC / sqrt(2 pi r), r the vertex's rest distance from
 * the line of the face's other two vertices, the front's edge (linear
 * elastic fracture mechanics: the stress a distance r ahead of a tip of
 * stress intensity K is K / sqrt(2 pi r); docs/physics.md §5.1), or with
 * "crack" at most the far stress that makes the widest crack on that edge
 * critical as a penny crack (widest_on_edge). */
static double front_threshold(const cf_solid *s, int ta, int k, int j, double threshold)
{
    if (s->front_K <= 0)
        return threshold;
    if (!s->nucleus)
        return fmin(threshold, cf_front_toughness(s, ta, k, j));
    const int *K = CF_TET_FACE[k];
    double th;
    widest_on_edge(s, s->tet0[4 * ta + K[(j + 1) % 3]], s->tet0[4 * ta + K[(j + 2) % 3]],
                   s->tet_facet[4 * ta + k], &th);
    return fmin(threshold, th);
}

/* The vertices of face k of tet ta, an uncracked facet, that may lie ahead
 * of a front, as bits 1 << j (j the corner in CF_TET_FACE[k]): marked, and
 * the edge off them cracked (any cracked facet on it is another, as this
 * one is not).  Only the tet's own bytes, no facet's. */
static unsigned ahead_of_fronts(const cf_solid *s, int ta, int k)
{
    const int *K = CF_TET_FACE[k];
    unsigned ahead = 0;
    for (int j = 0; j < 3; j++)
        if (s->node_mark[s->tet[4 * ta + K[j]]] &&
            edge_count(s, ta, K[(j + 1) % 3], K[(j + 2) % 3]))
            ahead |= 1u << j;
    return ahead;
}

/* The source's rule at a crack front (docs/physics.md §5.1): face k of tet
 * ta shares an edge with a cracked facet, and its vertex off that edge,
 * the one ahead of the front, reaches the threshold; `ahead` holds the
 * vertices that may (ahead_of_fronts).  The two vertices on the edge sit
 * on the crack, whose faces carry no traction, so their averages read half
 * a star of unloaded tets: the stress ahead of the front is the third
 * vertex's. */
static int front_rule(const cf_solid *s, int ta, int k, unsigned ahead, double threshold)
{
    for (int j = 0; j < 3; j++) {
        if (!(ahead >> j & 1))
            continue;
        /* The vertex's lowest front floor first, then the threshold's
         * square root. */
        int n = s->tet[4 * ta + CF_TET_FACE[k][j]];
        double v = s->nodal[n]; /* a NaN passes, as in source_rule */
        if (v < threshold && ((s->vert_front_active && v < s->vert_front_active[s->origin[n]]) ||
                              v < front_threshold(s, ta, k, j, threshold)))
            continue;
        return 1;
    }
    return 0;
}

/* The faces of tet ta that qualify, as bits 1 << k.  The traction rule
 * needs ta or its neighbour hot, so a tet with fewer than three marked
 * nodes (the nodes of hot tets) is done without reading a facet.  The
 * source's rule is asked only of tets that hold a marked node (a node whose
 * value may pass, qualify_near_marks), and at a front one marked vertex
 * may be enough (front_rule). */
static unsigned char qualifying_faces(const cf_solid *s, int ta, cf_criterion rule)
{
    const int *T = &s->tet[4 * ta];
    const unsigned char *mark = s->node_mark;
    if (rule != CF_CRITERION_SOURCE && mark[T[0]] + mark[T[1]] + mark[T[2]] + mark[T[3]] < 3)
        return 0;
    double smax = s->mat.sigma_max, tmax = s->mat.tau_max;
    unsigned char bits = 0, open = s->tet_open[ta];
    for (int k = 0; k < 4; k++) {
        if (!(open >> k & 1)) /* not an uncracked candidate facet that ta owns */
            continue;
        if (rule == CF_CRITERION_SOURCE) {
            /* Both rules need marked nodes: the facet's strength is read
             * only where they are. */
            const int *K = CF_TET_FACE[k];
            unsigned ahead = ahead_of_fronts(s, ta, k);
            if (!ahead && !(mark[T[K[0]]] && mark[T[K[1]]] && mark[T[K[2]]]))
                continue;
            int f = s->tet_facet[4 * ta + k];
            double th = source_threshold(smax, s->strength ? s->strength[f] : 1.0);
            bits |= (unsigned char)((source_rule(s, ta, k, th) ||
                                     front_rule(s, ta, k, ahead, th)) << k);
            continue;
        }
        int f = s->tet_facet[4 * ta + k];
        double w = s->strength ? s->strength[f] : 1.0; /* this facet's strength */
        if (!s->hot[ta] && !s->hot[s->facet[4 * f + 2]]) /* the mean stress is below both bounds */
            continue;
        double sn, tau;
        facet_traction(s, ta, k, &sn, &tau);
        bits |= (unsigned char)((sn >= smax * w || tau >= tmax * w) << k);
    }
    return bits;
}

cf_stress_check cf_insertion_bound(const cf_solid *s, cf_criterion rule)
{
    cf_stress_check c = {INFINITY, INFINITY, NULL};
    double w = s->strength ? s->strength_min : 1.0; /* the weakest facet */
    if (rule == CF_CRITERION_SOURCE) /* and no front's below the weakest vertex's */
        c.s1 = fmin(source_threshold(s->mat.sigma_max, w),
                    s->vert_front_active ? s->front_floor_min : INFINITY),
        c.s1_tet = s->tet_floor; /* away from the cracks, no front's */
    else if (rule == CF_CRITERION_TRACTION)
        c.s1 = s->mat.sigma_max * w, c.tau = s->mat.tau_max * w;
    return c;
}

/* Whether the node at corner j of tet t owns t: no corner before j holds a
 * marked node.  Every tet with a marked node has exactly one owner. */
static int owns(const cf_solid *s, int t, int j)
{
    for (int k = 0; k < j; k++)
        if (s->node_mark[s->tet[4 * t + k]])
            return 0;
    return 1;
}

/* s->qualify (qualifying_faces) of the tets the marked nodes own, each
 * visited from its owner's star: the only tets that may qualify, since a
 * qualifying face needs three marked nodes, so the rest of the fragment's
 * tets are never read.  In parallel over the nodes (a tet has one owner,
 * so one thread writes its byte).  Returns how many tets qualify. */
static int qualify_near_marks(cf_solid *s, const cf_int_list *marked, cf_criterion rule)
{
    int count = 0;
    CF_PARALLEL(marked->n >= STAR_PARALLEL_MIN,
                "omp parallel for schedule(static) reduction(+ : count)",
        for (int i = 0; i < marked->n; i++) {
            int n = marked->v[i], o = s->origin[n];
            for (int j = s->vt_start[o]; j < s->vt_start[o + 1]; j++) {
                int slot = s->vt_slot[j], t = slot / 4;
                if (s->tet[slot] == n && owns(s, t, slot % 4))
                    count += (s->qualify[t] = qualifying_faces(s, t, rule)) != 0;
            }
        });
    return count;
}

/* Appends to `out` the tets of tets[0..nt) whose s->qualify is set, in
 * list order (ascending), `count` of them: a scan of the fragment's bytes
 * (on the threads with par), where the stars of the marked nodes, walked
 * again and sorted, cost a serial tenth of the 202,231-tet drop's check
 * (docs/performance.md).  0, or -1 out of memory. */
static int list_qualified(const cf_solid *s, const int *tets, int nt, int count, int par,
                          cf_int_list *out)
{
    if (cf_int_list_reserve(out, out->n + count))
        return -1;
    out->n += cf_flagged_chunks(tets, 0, nt, s->qualify, par, out->v + out->n);
    return 0;
}

/* Clears s->qualify of every tet holding node n. */
static void star_unqualify(cf_solid *s, int n)
{
    int o = s->origin[n];
    for (int j = s->vt_start[o]; j < s->vt_start[o + 1]; j++)
        s->qualify[s->vt_slot[j] / 4] = 0;
}

int cf_insertion_candidates(cf_solid *s, const int *tets, int nt, cf_criterion rule, int n_hot,
                            const cf_growth *g, cf_int_list *out)
{
    out->n = 0;
    if (n_hot == 0 || rule == CF_CRITERION_NONE)
        return 0;
    /* The nodes of hot tets, marked; `out` lists them until the faces are
     * tested.  The source's rule needs their nodal values. */
    int first = nt, last = -1, par = nt >= CF_TET4_PARALLEL_MIN;
    CF_PARALLEL(par,
                "omp parallel for schedule(static) reduction(min : first) reduction(max : last)",
        for (int i = 0; i < nt; i++)
            if (s->hot[tets[i]])
                first = i < first ? i : first, last = i;);
    if (mark_hot_nodes(s, tets, first, last, par, out))
        return -1;
    if (++s->check_stamp == 0) { /* wrapped: no node was valued in check 0 */
        memset(s->nodal_check, 0, (size_t)s->cap_nodes * sizeof(unsigned));
        memset(s->vert_check, 0, (size_t)s->n_verts0 * sizeof(unsigned));
        s->check_stamp = 1;
    }
    if (rule == CF_CRITERION_SOURCE) /* no facet threshold lies below the bound's s1 */
        nodal_values(s, out, s->tet_frag[tets[0]], cf_insertion_bound(s, rule).s1,
                     g && (g->rule == CF_GROWTH_ALL || g->along_stress));
    /* The faces of the tets that may have a qualifying one, then those
     * tets listed after the nodes. */
    int m = out->n, rc = 0, nq = qualify_near_marks(s, out, rule);
    if (nq > 0)
        rc = list_qualified(s, tets, nt, nq, par, out); /* the tets, after the nodes */
    for (int i = 0; rc && i < m; i++) /* out of memory: no qualify byte left set */
        star_unqualify(s, out->v[i]);
    clear_marks(s, out->v, m);
    if (rc)
        return -1;
    /* The tets in ascending order, as `tets` lists them; then each one's
     * facets, written from the last back to the first (a tet has at least
     * one, so no tet is overwritten before it is read). */
    int nf = 0, *q = out->v;
    memmove(q, q + m, (size_t)nq * sizeof(int));
    out->n = nq;
    for (int i = 0; i < nq; i++)
        nf += __builtin_popcount(s->qualify[q[i]]);
    if (cf_int_list_reserve(out, nf)) {
        for (int i = 0; i < nq; i++)
            s->qualify[out->v[i]] = 0;
        return -1;
    }
    q = out->v;
    for (int i = nq - 1, at = nf; i >= 0; i--) {
        int t = q[i];
        for (int k = 3; k >= 0; k--)
            if (s->qualify[t] >> k & 1)
                q[--at] = s->tet_facet[4 * t + k];
        s->qualify[t] = 0;
    }
    out->n = nf;
    return nf;
}

static int uf_find(int *parent, int i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

/* Join the tets of a vertex's star (star[i]: the slot 4 t + j of the
 * vertex in tet t, ns of them) through their uncracked facets that contain
 * the vertex: parent[] of a union-find, each root the lowest of its part. */
static void join_star(const cf_solid *s, const int *star, int ns, int *parent)
{
    for (int i = 0; i < ns; i++)
        parent[i] = i;
    for (int i = 0; i < ns; i++) {
        int t = star[i] / 4, j = star[i] % 4;
        for (int k = 0; k < 4; k++) {
            if (k == j) /* the face opposite the vertex does not contain it */
                continue;
            int f = s->tet_facet[4 * t + k];
            const int *F = &s->facet[4 * f];
            if (F[2] < 0 || s->cracked[f])
                continue;
            int other = F[0] == t ? F[2] : F[0];
            for (int q = 0; q < ns; q++)
                if (star[q] / 4 == other) {
                    int ra = uf_find(parent, i), rb = uf_find(parent, q);
                    if (ra != rb)
                        parent[ra > rb ? ra : rb] = ra < rb ? ra : rb;
                }
        }
    }
}

/* Split the star of node copy `n` of original vertex `o` into its
 * components (tets joined through uncracked facets containing o); every
 * component but the one with the lowest tet gets a new copy of the node. */
static int split_star(cf_solid *s, int o, int n, cf_int_list *nodes, cf_int_list *touched)
{
    int lo = s->vt_start[o], hi = s->vt_start[o + 1];
    int local[3 * 256]; /* stars of up to 256 tets without the heap */
    int *buf = hi - lo <= 256 ? local : malloc(3 * (size_t)(hi - lo) * sizeof(int));
    if (!buf)
        return -1;
    /* star[i]: the slot 4 t + j of o in each tet t that holds copy n */
    int *star = buf, *parent = buf + (hi - lo), *copy_of_root = buf + 2 * (hi - lo);
    int ns = 0, rc = 0;
    for (int i = lo; i < hi; i++)
        if (s->tet[s->vt_slot[i]] == n)
            star[ns++] = s->vt_slot[i];
    join_star(s, star, ns, parent);
    int keep = uf_find(parent, 0);
    for (int i = 0; i < ns; i++)
        copy_of_root[i] = -1;
    for (int i = 0; i < ns; i++) {
        int r = uf_find(parent, i);
        if (r == keep)
            continue;
        if (copy_of_root[r] < 0) {
            int c = cf_solid_copy_node(s, n);
            if (c < 0 || cf_int_list_push(nodes, c) || cf_int_list_push(touched, c) ||
                cf_int_list_push(touched, n)) {
                rc = -1;
                break;
            }
            copy_of_root[r] = c;
        }
        s->tet[star[i]] = copy_of_root[r];
    }
    /* Re-lump only the copies of o: the other nodes of these tets keep theirs. */
    for (int i = 0; i < ns; i++)
        s->m[s->tet[star[i]]] = 0;
    for (int i = 0; i < ns; i++)
        s->m[s->tet[star[i]]] += cf_tet_mass(s, star[i] / 4) / 4.0;
    if (buf != local)
        free(buf);
    return rc;
}

/* s->tet_floor of tet t: the lowest strength floor at its vertices,
 * rounded down to a float (a hot tet's bound then reaches every vertex
 * floor it must), or 0 with a vertex near a crack. */
static float tet_floor(const cf_solid *s, int t)
{
    double floor = INFINITY;
    for (int j = 0; j < 4; j++) {
        int o = s->tet0[4 * t + j];
        if (s->vert_front_near[o])
            return 0;
        floor = fmin(floor, strength_floor(s, o));
    }
    float f = (float)floor;
    return (double)f > floor ? nextafterf(f, 0.0f) : f;
}

/* The vertices sharing a tet with original vertex o become near a crack,
 * and every tet of theirs loses its own floor. */
static void near_crack(cf_solid *s, int o)
{
    for (int j = s->vt_start[o]; j < s->vt_start[o + 1]; j++) {
        const int *T = &s->tet0[4 * (s->vt_slot[j] / 4)];
        for (int k = 0; k < 4; k++) {
            int u = T[k];
            if (s->vert_front_near[u])
                continue;
            s->vert_front_near[u] = 1;
            for (int i = s->vt_start[u]; i < s->vt_start[u + 1]; i++)
                s->tet_floor[s->vt_slot[i] / 4] = 0;
        }
    }
}

/* Facet f's crack flag moved by d (+1, -1 or 0) on the edge of original
 * vertices a and b: d added to the edge's crack count in every tet around
 * it (s->edge_cracks); with `fronts`, each other interior facet on the
 * edge has a front there, whose threshold at its vertex off the edge
 * (front_threshold, rounded down to a float) bounds that vertex's
 * s->vert_front_active. */
static void crack_edge(cf_solid *s, int f, int a, int b, int d, int fronts)
{
    for (int j = s->vt_start[a]; j < s->vt_start[a + 1]; j++) {
        int slot = s->vt_slot[j], t = slot / 4, sb = slot_of(s, t, b);
        if (sb < 0)
            continue;
        s->edge_cracks[6 * t + CF_TET_EDGE[slot % 4][sb]] += (unsigned char)d;
        for (int q = 0; fronts && q < 4; q++) { /* face q holds every corner but q */
            int g = s->tet_facet[4 * t + q];
            const int *G = &s->facet[4 * g];
            if (q == slot % 4 || q == sb || g == f || G[2] < 0)
                continue;
            /* the vertex off the edge as the facet's own tet names it */
            int c = s->tet0[4 * t + (6 - q - slot % 4 - sb)], jc = 0;
            while (s->tet0[4 * G[0] + CF_TET_FACE[G[1]][jc]] != c)
                jc++;
            double field = s->nucleus ? cf_front_penny(s, s->nucleus[f], a, b)
                                      : cf_front_toughness(s, G[0], G[1], jc);
            float th = nextafterf((float)field, 0.0f);
            s->vert_front_active[c] = fminf(s->vert_front_active[c], th);
        }
    }
}

void cf_mark_cracked(cf_solid *s, int f, unsigned char cracked)
{
    const int *F = &s->facet[4 * f];
    int o[3];
    face_vertices(s, F[0], F[1], o);
    int d = (int)cracked - (int)s->cracked[f];
    s->cracked[f] = cracked;
    cf_solid_update_open(s, f);
    /* a facet marked again (taken, then opened) changes nothing on its edges */
    for (int i = 0; d && i < 3; i++)
        crack_edge(s, f, o[(i + 1) % 3], o[(i + 2) % 3], d, d > 0 && s->vert_front_active);
    for (int i = 0; i < 3; i++) {
        if (s->vert_front_near && s->vert_cracks[o[i]] == 0)
            near_crack(s, o[i]);
        s->vert_cracks[o[i]]++;
    }
}

void cf_insertion_init_front_floors(cf_solid *s)
{
    if (!s->vert_front_near)
        return;
    for (int o = 0; o < s->n_verts0; o++) {
        s->vert_front_active[o] = INFINITY;
        if (s->vert_cracks[o])
            near_crack(s, o);
    }
    for (int f = 0; f < s->n_facets; f++)
        if (s->cracked[f])
            for (int i = 0; i < 3; i++) { /* its counts are there already */
                const int *F = &s->facet[4 * f], *K = CF_TET_FACE[F[1]];
                crack_edge(s, f, s->tet0[4 * F[0] + K[(i + 1) % 3]],
                           s->tet0[4 * F[0] + K[(i + 2) % 3]], 0, 1);
            }
    for (int t = 0; t < s->n_tets; t++)
        s->tet_floor[t] = tet_floor(s, t);
}

/* Mark facet f cracked and duplicate the nodes whose star it disconnects;
 * the facet's three slots in each of its tets go to `slot` (may be NULL). */
static int separate_facet(cf_solid *s, int f, cf_int_list *nodes, cf_int_list *touched,
                          int slot[2][3])
{
    const int *F = &s->facet[4 * f];
    int ta = F[0], fa = F[1], tb = F[2];
    cf_mark_cracked(s, f, 1);
    for (int i = 0; i < 3; i++) {
        int sa = CF_TET_FACE[fa][i];
        int o = s->tet0[4 * ta + sa], sb = slot_of(s, tb, o);
        if (slot)
            slot[0][i] = sa, slot[1][i] = sb;
        int na = s->tet[4 * ta + sa];
        int nb = s->tet[4 * tb + sb];
        if (split_star(s, o, na, nodes, touched))
            return -1;
        if (nb != na && split_star(s, o, nb, nodes, touched))
            return -1;
    }
    return 0;
}

int cf_crack_facet(cf_solid *s, int f, cf_int_list *nodes, cf_int_list *touched)
{
    cf_cohesive ce;
    memset(&ce, 0, sizeof ce);
    ce.tet[0] = s->facet[4 * f], ce.tet[1] = s->facet[4 * f + 2];
    ce.strength = s->strength ? s->strength[f] : 1.0;
    if (separate_facet(s, f, nodes, touched, ce.slot))
        return -1;
    if (s->n_coh == s->cap_coh) {
        int cap = s->cap_coh ? 2 * s->cap_coh : 256;
        cf_cohesive *c = realloc(s->coh, (size_t)cap * sizeof *c);
        if (!c)
            return -1;
        s->coh = c;
        if (s->mat.crack_friction > 0) { /* only a scene with crack friction pays for it */
            void *fr = realloc(s->coh_fric, (size_t)cap * sizeof *s->coh_fric);
            if (!fr)
                return -1;
            s->coh_fric = fr;
        }
        s->cap_coh = cap;
    }
    if (s->coh_fric)
        memset(s->coh_fric[s->n_coh], 0, sizeof *s->coh_fric);
    s->coh[s->n_coh++] = ce;
    return 0;
}

/* How far qualifying facet f exceeds its strength: the smallest of its
 * three nodal values over the facet's threshold (source), or the larger of
 * sigma_n / sigma_max_f and tau / tau_max_f (traction), from the nodal
 * values and stresses of the check that found it.  A front facet qualifies
 * on the vertex ahead alone (front_rule), and a node on its cracked edge
 * that no hot tet holds was not valued in this check: the array holds
 * what the last check that valued it found, another state of the body.
 * No tet of such a node is hot, so it reads as 0, below every threshold,
 * as the edge's unloaded wake does.  A NaN reads as infinitely far (the
 * divergence guard stops the run). */
static double facet_ratio(const cf_solid *s, int f, cf_criterion rule)
{
    const int *F = &s->facet[4 * f];
    double w = s->strength ? s->strength[f] : 1.0, r;
    if (rule == CF_CRITERION_SOURCE) {
        double threshold = source_threshold(s->mat.sigma_max, w);
        r = INFINITY;
        for (int j = 0; j < 3; j++) {
            int a = s->tet[4 * F[0] + CF_TET_FACE[F[1]][j]];
            double q = s->nodal_check[a] == s->check_stamp ? s->nodal[a] / threshold : 0;
            r = q < r ? q : r;
        }
    } else {
        double sn, tau;
        facet_traction(s, F[0], F[1], &sn, &tau);
        r = fmax(sn / (s->mat.sigma_max * w), tau / (s->mat.tau_max * w));
    }
    return r == r ? r : INFINITY;
}

/* A front facet's rank under the maximum tangential stress criterion
 * (Erdogan and Sih, J Basic Eng 85:519, 1963; docs/physics.md §5.1): the
 * normal stress across facet f's current normal, from the mean stress of
 * each of its nodes valued in this check (nodal_principal), the largest of
 * them, over the facet's threshold.  The node ahead of the front gives it:
 * the two on the cracked edge read the unloaded wake, as the front rule
 * says.  With a front threshold from the toughness, also each vertex ahead
 * of a cracked edge over its own (front_threshold), and the larger ratio.
 * A NaN reads as infinitely far (the divergence guard stops the run);
 * -INFINITY when no node was valued. */
static double front_stress_ratio(const cf_solid *s, int f)
{
    const int *F = &s->facet[4 * f];
    double n[3], sn = -INFINITY, w = s->strength ? s->strength[f] : 1.0;
    double th = source_threshold(s->mat.sigma_max, w), ratio = -INFINITY;
    face_normal(s, F[0], F[1], n);
    for (int j = 0; j < 3; j++) {
        int a = s->tet[4 * F[0] + CF_TET_FACE[F[1]][j]];
        if (s->nodal_check[a] != s->check_stamp)
            continue;
        const double *q = &s->nodal_stress[6 * a];
        double t = q[0] * n[0] * n[0] + q[1] * n[1] * n[1] + q[2] * n[2] * n[2] +
                   2 * (q[3] * n[0] * n[1] + q[4] * n[0] * n[2] + q[5] * n[1] * n[2]);
        if (t != t)
            return INFINITY;
        sn = fmax(sn, t);
        /* With the toughness each vertex ahead of a cracked edge has a
         * threshold of its own: the largest ratio among those. */
        const int *K = CF_TET_FACE[F[1]];
        if (s->front_K > 0 && edge_cracked(s, f, F[0], K[(j + 1) % 3], K[(j + 2) % 3]))
            ratio = fmax(ratio, t / front_threshold(s, F[0], F[1], j, th));
    }
    return s->front_K > 0 ? fmax(ratio, sn / th) : sn / th;
}

/* Rest centroid of a triangle of original vertices, m. */
static void centroid(const cf_solid *s, const int o[3], double c[3])
{
    for (int k = 0; k < 3; k++)
        c[k] = (s->X[3 * o[0] + k] + s->X[3 * o[1] + k] + s->X[3 * o[2] + k]) / 3.0;
}

/* Rest distance from point c to the centroid of a triangle of original
 * vertices, m. */
static double centroid_distance(const cf_solid *s, const double c[3], const int o[3])
{
    double co[3], d[3];
    centroid(s, o, co);
    v3_sub(c, co, d);
    return v3_norm(d);
}

/* Unit vector in the rest plane of the edge e0-e1 and vertex p, normal to
 * the edge, pointing to p. */
static void away_from_edge(const cf_solid *s, int e0, int e1, int p, double u[3])
{
    double e[3], d[3];
    v3_sub(&s->X[3 * e1], &s->X[3 * e0], e);
    v3_sub(&s->X[3 * p], &s->X[3 * e0], d);
    memcpy(u, d, sizeof d);
    v3_axpy(-v3_dot(d, e) / v3_dot(e, e), e, u);
    double n = v3_norm(u);
    for (int k = 0; k < 3; k++)
        u[k] /= n;
}

/* Whether facet f (original vertices o) continues cracked facet g (og)
 * across their shared edge, the one opposite o[off], turning from g's
 * plane by at most max_kink (rad, rest shape; 0: any turn): a facet
 * straight ahead of g turns by 0, one folded back onto it by pi. */
static int within_kink(const cf_solid *s, const int o[3], int off, const int og[3],
                       double max_kink)
{
    if (max_kink <= 0)
        return 1;
    int e0 = o[(off + 1) % 3], e1 = o[(off + 2) % 3], pg = og[0];
    for (int p = 0; p < 3; p++)
        if (og[p] != e0 && og[p] != e1)
            pg = og[p];
    double uf[3], ug[3];
    away_from_edge(s, e0, e1, o[off], uf);
    away_from_edge(s, e0, e1, pg, ug);
    return -v3_dot(uf, ug) >= cos(max_kink);
}

/* How facet f (original vertices o, rest centroid c) meets the cracks at
 * time t: CF_FRONT when one of its edges is the edge of exactly one cracked
 * facet (the crack surface ends there: a front), inserted at least d / speed
 * earlier (d between their rest centroids: a front moves no faster than
 * `speed`), from whose plane f turns by at most max_kink (rad; 0 any);
 * CF_TOUCH when it meets a cracked facet otherwise (at a vertex,
 * across an edge the crack reached too recently, this check's insertions
 * included, across an edge inside a crack surface, which two cracked
 * facets already share: a branch, or across an edge where the crack would
 * kink further); CF_CLEAR when it meets none. */
enum { CF_CLEAR, CF_TOUCH, CF_FRONT };
static int crack_contact(cf_solid *s, int f, const int o[3], const double c[3], double t,
                         double speed, double max_kink)
{
    /* The answer holds while no facet on f's vertices cracks: a front stays
     * a front, and a facet that only touches stays so until a crack on one
     * of its edges is old enough.  Most candidates of a cracked body are
     * found again at every check, and the walk below was 39 % of the
     * default drop's wall. */
    uint64_t key = 1 + (uint64_t)s->vert_cracks[o[0]] + s->vert_cracks[o[1]] +
                   s->vert_cracks[o[2]];
    if (key == 1) /* no facet on its vertices was ever cracked */
        return CF_CLEAR;
    if (s->contact_key[f] == key && t < s->contact_until[f])
        return s->contact_kind[f];
    /* Per edge of f (named by o's vertex off it): the first cracked facet
     * met on it, and whether there are none, one, or more (a branch). */
    int touch = CF_CLEAR, first[3], n_edge[3] = {0, 0, 0}, ready[3] = {0, 0, 0};
    double at[3];
    for (int a = 0; a < 3; a++)
        for (int j = s->vt_start[o[a]]; j < s->vt_start[o[a] + 1]; j++) {
            int slot = s->vt_slot[j], tt = slot / 4;
            for (int k = 0; k < 4; k++) {
                int g = s->tet_facet[4 * tt + k];
                if (k == slot % 4 || g == f || !s->cracked[g])
                    continue;
                touch = CF_TOUCH;
                int og[3], shared = 0, off = 0; /* off: o's vertex not on g */
                face_vertices(s, tt, k, og);
                for (int p = 0; p < 3; p++) {
                    int in = og[0] == o[p] || og[1] == o[p] || og[2] == o[p];
                    shared += in;
                    if (!in)
                        off = p;
                }
                if (shared != 2)
                    continue;
                if (n_edge[off] == 0) { /* g is met again through every tet at the edge */
                    double wait = centroid_distance(s, c, og) / speed;
                    first[off] = g, n_edge[off] = 1;
                    ready[off] = t - s->crack_time[g] >= wait;
                    /* when it may be ready, a little early (the test's rounding) */
                    at[off] = s->crack_time[g] + wait;
                    at[off] -= 1e-12 * (fabs(at[off]) + wait) + 1e-300;
                    /* a front that would kink too far never is one */
                    if (!within_kink(s, o, off, og, max_kink))
                        ready[off] = 0, at[off] = INFINITY;
                } else if (first[off] != g) {
                    n_edge[off] = 2;
                }
            }
        }
    int kind = touch;
    double until = INFINITY;
    for (int e = 0; e < 3; e++)
        if (n_edge[e] == 1)
            kind = ready[e] ? CF_FRONT : kind, until = ready[e] ? until : fmin(until, at[e]);
    s->contact_key[f] = key, s->contact_kind[f] = (unsigned char)kind;
    s->contact_until[f] = kind == CF_FRONT ? INFINITY : until;
    return kind;
}

/* Whether cracking facet f would close crack faces (and the boundary)
 * around a small piece on either side: one of at most `most` tets, or of
 * less volume than `least_volume` (m^3).  A search through the uncracked
 * interior facets from each of its tets, which stops once the piece it has
 * found is large on both counts. */
static int closes_small_piece(cf_solid *s, int f, int most, double least_volume)
{
    for (int side = 0; side < 2 && (most > 0 || least_volume > 0); side++) {
        unsigned stamp = ++s->piece_stamp;
        if (stamp == 0) { /* wrapped: clear the marks once in 2^32 searches */
            memset(s->piece_mark, 0, (size_t)s->n_tets * sizeof(unsigned));
            stamp = s->piece_stamp = 1;
        }
        int n = 0, t0 = s->facet[4 * f + 2 * side];
        double vol = s->vol[t0];
        s->piece[n++] = t0, s->piece_mark[t0] = stamp;
        for (int i = 0; i < n && (n <= most || vol < least_volume); i++)
            for (int k = 0; k < 4; k++) {
                int g = s->tet_facet[4 * s->piece[i] + k];
                const int *G = &s->facet[4 * g];
                if (g == f || G[2] < 0 || s->cracked[g])
                    continue;
                int other = G[0] == s->piece[i] ? G[2] : G[0];
                if (s->piece_mark[other] != stamp)
                    s->piece[n++] = other, s->piece_mark[other] = stamp, vol += s->vol[other];
            }
        if (n <= most || vol < least_volume)
            return 1;
    }
    return 0;
}

/* Crack facet f (rest centroid c) at time t, of the crack that facet
 * `nucleus` began: on the crack grid, marked, and appended to cand at
 * *kept.  Returns 0, or -1 out of memory. */
static int take_facet(cf_solid *s, int f, int nucleus, const double c[3], double t,
                      cf_int_list *cand, int *kept)
{
    if (cf_int_list_reserve(cand, *kept + 1) || cf_crack_grid_add(&s->cracks, c))
        return -1;
    if (s->nucleus) /* before its edges' fronts are valued (crack_edge) */
        s->nucleus[f] = nucleus;
    cf_mark_cracked(s, f, 1), s->crack_time[f] = t;
    cand->v[(*kept)++] = f;
    return 0;
}

/* The nucleus of the crack front facet f (original vertices o) extends:
 * among the cracked facets on its edges, the one whose front is the widest
 * (the lowest cf_front_penny); f itself without s->nucleus or such a
 * facet. */
static int crack_of(const cf_solid *s, int f, const int o[3])
{
    int best = f;
    double low = INFINITY, th;
    for (int e = 0; s->nucleus && e < 3; e++) {
        int g = widest_on_edge(s, o[(e + 1) % 3], o[(e + 2) % 3], f, &th);
        if (g >= 0 && th < low)
            low = th, best = s->nucleus[g];
    }
    return best;
}

/* Which side of the plane through original vertex o with normal n (rest
 * shape) tet t lies on: its rest centroid's distance from the plane, m. */
static double tet_side(const cf_solid *s, int t, int o, const double n[3])
{
    double d = 0;
    for (int k = 0; k < 3; k++) {
        double c = 0;
        for (int a = 0; a < 4; a++)
            c += 0.25 * s->X[3 * s->tet0[4 * t + a] + k];
        d += (c - s->X[3 * o + k]) * n[k];
    }
    return d;
}

/* Whether original vertex o's star is whole: its tets all joined through
 * uncracked facets that contain o (no copy of o would part).  -1 out of
 * memory. */
static int star_whole(const cf_solid *s, int o)
{
    int lo = s->vt_start[o], ns = s->vt_start[o + 1] - lo, local[2 * 256];
    int *buf = ns <= 256 ? local : malloc(2 * (size_t)ns * sizeof(int));
    if (!buf)
        return -1;
    memcpy(buf, &s->vt_slot[lo], (size_t)ns * sizeof(int));
    join_star(s, buf, ns, buf + ns);
    int whole = 1;
    for (int i = 1; i < ns; i++)
        whole &= uf_find(buf + ns, i) == 0;
    if (buf != local)
        free(buf);
    return whole;
}

/* solver.front_split "plane" (docs/physics.md §5.1 rule 3): front facet f
 * (original vertices o, of tet ta), just taken, splits each of its
 * vertices that lies on its crack (on an edge another cracked facet holds)
 * and whose star the cracks do not part yet: the uncracked interior facets
 * of that star between its tets on the two sides of f's rest plane
 * through the vertex (tet_side) are taken at time t, each unless it would
 * close a small piece or its rest centroid lies farther than split_reach
 * from the vertex.  Returns 0, or -1 out of memory. */
static int split_front(cf_solid *s, int f, int ta, const int o[3], const cf_growth *g,
                       cf_int_list *cand, int *kept)
{
    const int *K = CF_TET_FACE[s->facet[4 * f + 1]];
    double e1[3], e2[3], n[3];
    v3_sub(&s->X[3 * o[1]], &s->X[3 * o[0]], e1), v3_sub(&s->X[3 * o[2]], &s->X[3 * o[0]], e2);
    v3_cross(e1, e2, n);
    unsigned behind = 0;
    for (int e = 0; e < 3; e++) /* f itself holds each of its edges */
        if (edge_count(s, ta, K[(e + 1) % 3], K[(e + 2) % 3]) > 1)
            behind |= 1u << (e + 1) % 3 | 1u << (e + 2) % 3;
    for (int a = 0; a < 3; a++) {
        int whole = behind >> a & 1 ? star_whole(s, o[a]) : 0;
        if (whole < 0)
            return -1;
        for (int i = s->vt_start[o[a]]; whole && i < s->vt_start[o[a] + 1]; i++) {
            int t = s->vt_slot[i] / 4;
            if (tet_side(s, t, o[a], n) <= 0) /* each facet from its tet on the + side */
                continue;
            for (int k = 0; k < 4; k++) {
                int h = s->tet_facet[4 * t + k], oh[3];
                const int *H = &s->facet[4 * h];
                if (k == s->vt_slot[i] % 4 || H[2] < 0 || s->cracked[h] ||
                    tet_side(s, H[0] == t ? H[2] : H[0], o[a], n) > 0)
                    continue;
                double c[3], d[3];
                face_vertices(s, H[0], H[1], oh);
                centroid(s, oh, c);
                v3_sub(c, &s->X[3 * o[a]], d);
                if ((g->split_reach > 0 && v3_norm(d) > g->split_reach) ||
                    closes_small_piece(s, h, g->min_piece_tets, g->min_piece_volume))
                    continue;
                if (take_facet(s, h, s->nucleus ? s->nucleus[f] : h, c, g->t, cand, kept))
                    return -1;
            }
        }
    }
    return 0;
}

/* solver.front_snap "stress" (docs/physics.md §5.1 rule 3): front facet f
 * (original vertices o, of tet ta), just taken, moves its vertex ahead,
 * the one off the front's edge, when that vertex lies on no other crack,
 * inside the body, onto the plane through the edge normal to the largest
 * principal stress there (its nodal mean stress of this check, its normal
 * pulled back to the rest shape by the star's mean gradient), as far as
 * cf_solid_move_vertex allows: the whole way, else half or a quarter of it.
 * The fronts the crack then has ahead of that vertex's edges read their
 * floors from the new shape (crack_edge). */
static void snap_front(cf_solid *s, int f, int ta, const int o[3])
{
    const int *K = CF_TET_FACE[s->facet[4 * f + 1]];
    int a = 0;
    while (a < 3 && edge_count(s, ta, K[(a + 1) % 3], K[(a + 2) % 3]) < 2)
        a++; /* the edge another cracked facet holds */
    if (a == 3 || s->vert_cracks[o[a]] != 1) /* f the only crack on it */
        return;
    int c = o[a], e0 = o[(a + 1) % 3], e1 = o[(a + 2) % 3], n = s->tet[s->vt_slot[s->vt_start[c]]];
    for (int i = s->vt_start[c]; i < s->vt_start[c + 1]; i++)
        for (int k = 0; k < 4; k++)
            if (k != s->vt_slot[i] % 4 && s->facet[4 * s->tet_facet[4 * (s->vt_slot[i] / 4) + k] + 2] < 0)
                return; /* on the surface: the body's shape stays */
    double F[9];
    if (s->nodal_check[n] != s->check_stamp || !cf_solid_star_gradient(s, c, F))
        return;
    const double *q = &s->nodal_stress[6 * n];
    double A[9] = {q[0], q[3], q[4], q[3], q[1], q[5], q[4], q[5], q[2]}, w[3], V[9];
    sym3_eigen(A, w, V);
    int top = w[0] >= w[1] ? (w[0] >= w[2] ? 0 : 2) : (w[1] >= w[2] ? 1 : 2);
    double p[3] = {V[top], V[3 + top], V[6 + top]}, u[3], e[3], d[3], to[3];
    m3_tmulv(F, p, u); /* the rest normal: F^T p */
    v3_sub(&s->X[3 * e1], &s->X[3 * e0], e);
    v3_axpy(-v3_dot(u, e) / v3_dot(e, e), e, u); /* the plane holds the edge */
    double nu = v3_norm(u);
    if (!(nu > 1e-9 * v3_norm(e) * v3_norm(p)))
        return;
    v3_sub(&s->X[3 * c], &s->X[3 * e0], d);
    double off = v3_dot(d, u) / (nu * nu);
    for (double frac = 1; frac > 0.2; frac *= 0.5) {
        for (int k = 0; k < 3; k++)
            to[k] = s->X[3 * c + k] - frac * off * u[k];
        if (cf_solid_move_vertex(s, c, to, F, 0.5)) {
            for (int i = 0; s->vert_front_active && i < 3; i++)
                crack_edge(s, f, o[(i + 1) % 3], o[(i + 2) % 3], 0, 1);
            return;
        }
    }
}

typedef struct {
    double ratio;
    int facet;
} ranked;

/* Larger ratio first; the lower facet first among equals. */
static int by_ratio(const void *x, const void *y)
{
    const ranked *a = x, *b = y;
    if (a->ratio != b->ratio)
        return a->ratio > b->ratio ? -1 : 1;
    return (a->facet > b->facet) - (a->facet < b->facet);
}

int cf_insertion_select(cf_solid *s, cf_int_list *cand, cf_criterion rule, const cf_growth *g)
{
    int nc = cand->n;
    if (g->rule == CF_GROWTH_ALL || nc == 0) {
        for (int i = 0; i < nc; i++)
            s->crack_time[cand->v[i]] = g->t;
        return nc;
    }
    /* A facet that touches a crack and is not a front of it (CF_TOUCH)
     * stays so through the check, as the facets it takes are not yet old
     * enough to be fronts: those, nine in ten of the candidates in a
     * cracked body, are dropped first, in parallel, before the ranking,
     * with the fronts that along_stress refuses. */
    ranked *r = malloc((size_t)nc * sizeof *r);
    if (!r)
        return -1;
    CF_PARALLEL(nc >= STAR_PARALLEL_MIN, "omp parallel for schedule(dynamic, 64)",
        for (int i = 0; i < nc; i++) {
            int f = cand->v[i], o[3];
            double c[3];
            face_vertices(s, s->facet[4 * f], s->facet[4 * f + 1], o);
            centroid(s, o, c);
            int kind = crack_contact(s, f, o, c, g->t, g->front_speed, g->max_kink);
            double q = 0;
            if (kind == CF_FRONT && g->along_stress && rule == CF_CRITERION_SOURCE)
                q = front_stress_ratio(s, f), kind = q >= 1 ? kind : CF_TOUCH;
            else if (kind != CF_TOUCH)
                q = facet_ratio(s, f, rule);
            r[i].facet = kind == CF_TOUCH ? -1 : f;
            r[i].ratio = kind == CF_TOUCH ? 0 : q;
        });
    int nr = 0;
    for (int i = 0; i < nc; i++)
        if (r[i].facet >= 0)
            r[nr++] = r[i];
    nc = nr;
    qsort(r, (size_t)nc, sizeof *r, by_ratio);
    int kept = 0;
    for (int i = 0; i < nc; i++) {
        int f = r[i].facet, ta = s->facet[4 * f], tb = s->facet[4 * f + 2];
        /* one new facet per tet and check; a front's split may have taken f */
        if (s->qualify[ta] || s->qualify[tb] || s->cracked[f])
            continue;
        /* A front extends its crack; a facet clear of every crack nucleates
         * one (the largest ratio around it, as the ratios come in falling
         * order and any facet taken before touches it); a facet that only
         * touches a crack does neither. */
        int o[3];
        double c[3], q = r[i].ratio;
        face_vertices(s, ta, s->facet[4 * f + 1], o);
        centroid(s, o, c);
        int contact = crack_contact(s, f, o, c, g->t, g->front_speed, g->max_kink);
        /* A crack shields a radius that shrinks as 1/ratio^2 (Irwin: the
         * flaw that is critical at a stress sigma grows as
         * l_ch (sigma_max / sigma)^2), so an overloaded solid still
         * nucleates wherever the stress exceeds the strength. */
        double shield = s->nucleation_radius / (q * q);
        if (contact == CF_TOUCH ||
            (contact == CF_CLEAR && cf_crack_grid_near(&s->cracks, c, shield)) ||
            closes_small_piece(s, f, g->min_piece_tets, g->min_piece_volume))
            continue;
        if (take_facet(s, f, contact == CF_FRONT ? crack_of(s, f, o) : f, c, g->t, cand, &kept) ||
            (g->split_plane && contact == CF_FRONT && split_front(s, f, ta, o, g, cand, &kept))) {
            for (int j = 0; j < kept; j++) { /* nothing marked */
                const int *F = &s->facet[4 * cand->v[j]];
                cf_mark_cracked(s, cand->v[j], 0), s->qualify[F[0]] = s->qualify[F[2]] = 0;
            }
            free(r);
            return -1;
        }
        if (g->snap && contact == CF_FRONT)
            snap_front(s, f, ta, o);
        s->qualify[ta] = s->qualify[tb] = 1;
    }
    free(r);
    for (int i = 0; i < kept; i++) {
        const int *F = &s->facet[4 * cand->v[i]];
        s->qualify[F[0]] = s->qualify[F[2]] = 0;
    }
    cand->n = kept;
    cf_ints_sort(cand->v, kept);
    return kept;
}

int cf_crush_tets(cf_solid *s, const int *tets, int nt, double t, cf_int_list *nodes,
                  cf_int_list *touched, cf_int_list *crushed_tets, double *released)
{
    double eps = s->mat.crushing_strain, sc = s->mat.compressive_strength;
    *released = 0;
    if (!s->crushed)
        return 0;
    int crushed = 0;
    for (int i = 0; i < nt; i++) {
        int tt = tets[i];
        /* Plastic work over sigma_c V: the equivalent plastic strain of
         * perfect plasticity, summed over every spell. */
        if (s->crushed[tt] || s->wp[tt] < eps * sc * s->vol[tt])
            continue;
        for (int k = 0; k < 4; k++) {
            int f = s->tet_facet[4 * tt + k];
            if (s->facet[4 * f + 2] < 0 || s->cracked[f])
                continue;
            s->crack_time[f] = t;
            if (separate_facet(s, f, nodes, touched, NULL))
                return -1;
        }
        /* Powder stores nothing: the strain energy goes with the crushing
         * work, and the tet pushes no more on its nodes from this step on. */
        s->crushed[tt] = 1;
        s->wp[tt] += s->tw[tt];
        *released += s->tw[tt];
        s->tw[tt] = 0;
        memset(&s->tf[12 * tt], 0, 12 * sizeof(double));
        if (cf_int_list_push(crushed_tets, tt))
            return -1;
        crushed++;
    }
    return crushed;
}
