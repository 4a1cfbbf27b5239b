/* Convex decomposition by recursive bisection of the fragment with planes
 * (docs/physics.md §9).  Each piece is the part of the fragment inside a convex cell
 * (an intersection of half-spaces); tets that straddle a cutting plane are
 * clipped by it, so neighbouring hulls meet on the plane without gap or
 * overlap and the summed hull volume is that of their union.  Hulls and
 * their volumes come from Bullet's btConvexHullComputer through the bridge. */
#include "decompose.h"

#include "cf_bullet.h"
#include "linalg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct cluster {
    int *tets, nt;       /* tets inside or straddling the cell */
    double *planes;      /* [np][4]: n.x <= d inside */
    int np;
    double tet_volume;   /* m^3 of the fragment inside the cell */
    double hull_volume;  /* m^3 */
    double *pts;         /* hull vertices [n_pts][3] */
    double *cen;         /* [nt][3]: the centroid of each tet's part inside the
                            cell, the tet's own where none is (cluster_hull) */
    int n_pts;
    int frozen;          /* a cut left one side empty: split no further */
} cluster;

typedef struct keyed {
    double key;
    int tet;
} keyed;

static int by_key(const void *a, const void *b)
{
    const keyed *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return (x->tet > y->tet) - (x->tet < y->tet);
}

static double side(const double *pl, const double x[3]) { return v3_dot(pl, x) - pl[3]; }

/* The part of a tet inside a cell, as tets: [n][4][3] in `a` (capacity
 * `cap` tets; `b` the same size, scratch). */
typedef struct clip_buf {
    double *a, *b;
    int cap;
} clip_buf;

static int clip_reserve(clip_buf *cb, int n)
{
    if (n <= cb->cap)
        return 0;
    int cap = 2 * n;
    double *a = realloc(cb->a, (size_t)cap * 12 * sizeof(double));
    if (a)
        cb->a = a;
    double *b = a ? realloc(cb->b, (size_t)cap * 12 * sizeof(double)) : NULL;
    if (!b)
        return -1;
    cb->b = b, cb->cap = cap;
    return 0;
}

static void clip_free(clip_buf *cb) { free(cb->a), free(cb->b); }

/* Where the edge from p (inside, sp <= 0) to q (outside, sq > 0) crosses the plane. */
static void cross_point(const double *p, double sp, const double *q, double sq, double *out)
{
    double t = sp / (sp - sq);
    for (int c = 0; c < 3; c++)
        out[c] = p[c] + t * (q[c] - p[c]);
}

static void put_tet(double *dst, const double *p0, const double *p1, const double *p2,
                    const double *p3)
{
    memcpy(dst, p0, 3 * sizeof(double)), memcpy(dst + 3, p1, 3 * sizeof(double));
    memcpy(dst + 6, p2, 3 * sizeof(double)), memcpy(dst + 9, p3, 3 * sizeof(double));
}

/* Clip tet x ([4][3]) by the half-space side <= 0 of pl into at most
 * three tets written to out ([3][4][3]); returns how many.  One vertex in
 * gives a tet; two give a wedge and three a prism, three tets each.  Only
 * the tet's own edges are cut, so the parts' vertices are exactly those
 * of the clipped tet and their volumes add up to its volume. */
static int clip_tet(const double *x, const double *pl, double *out)
{
    double sd[4];
    int in[4], out_[4], ni = 0, no = 0;
    for (int j = 0; j < 4; j++) {
        sd[j] = side(pl, &x[3 * j]);
        if (sd[j] <= 0)
            in[ni++] = j;
        else
            out_[no++] = j;
    }
    if (no == 0) {
        memcpy(out, x, 12 * sizeof(double));
        return 1;
    }
    if (ni == 0)
        return 0;
#define X(j) (&x[3 * (j)])
    double e[4][3]; /* crossing points */
    if (ni == 1) {
        int a = in[0];
        for (int k = 0; k < 3; k++)
            cross_point(X(a), sd[a], X(out_[k]), sd[out_[k]], e[k]);
        put_tet(out, X(a), e[0], e[1], e[2]);
        return 1;
    }
    if (ni == 3) { /* prism a b c | ad bd cd */
        int d = out_[0];
        for (int k = 0; k < 3; k++)
            cross_point(X(in[k]), sd[in[k]], X(d), sd[d], e[k]);
        put_tet(out, X(in[0]), X(in[1]), X(in[2]), e[0]);
        put_tet(out + 12, X(in[1]), X(in[2]), e[0], e[1]);
        put_tet(out + 24, X(in[2]), e[0], e[1], e[2]);
        return 3;
    }
    /* wedge: triangles a ac ad and b bc bd */
    int a = in[0], b = in[1], c = out_[0], d = out_[1];
    cross_point(X(a), sd[a], X(c), sd[c], e[0]);
    cross_point(X(a), sd[a], X(d), sd[d], e[1]);
    cross_point(X(b), sd[b], X(c), sd[c], e[2]);
    cross_point(X(b), sd[b], X(d), sd[d], e[3]);
    put_tet(out, X(a), e[0], e[1], X(b));
    put_tet(out + 12, e[0], e[1], X(b), e[2]);
    put_tet(out + 24, e[1], X(b), e[2], e[3]);
    return 3;
#undef X
}

static double tet_volume_of(const double *x)
{
    double u[3], v[3], w[3], uv[3];
    v3_sub(&x[3], x, u), v3_sub(&x[6], x, v), v3_sub(&x[9], x, w);
    v3_cross(u, v, uv);
    return fabs(v3_dot(uv, w)) / 6;
}

/* A tet clipped by several planes would split into many tets (up to
 * three per plane): past one cut (PIECES_MAX tets) the part is carried on
 * as the vertices of its hull instead.  The one-cut case, the common one,
 * then needs no hull for its volume; carrying two or three cuts as tets
 * was no faster (on the 979-tet plaster drop 5.5-6.2 s of decomposition
 * either way, against 12.1 s clipping point sets from the first cut). */
#define PIECES_MAX 3

/* Points of a part clipped as a point set: at most 16 after each hull
 * reduction, so one more clip makes at most 16 + 8 x 8 = 80. */
#define CLIP_MAX 96

/* Clip the convex point set q[k] (k <= 16; CLIP_MAX capacity) by the
 * half-space pl: keep the points inside, add where each segment between an
 * inside and an outside point crosses the plane (the vertices of the cut
 * are among these).  Returns the new count, reduced to the hull's vertices
 * when it grows above 16, or -1 when Bullet runs out of memory for that
 * hull (the points are finite). */
static int clip_points(double *q, int k, const double *pl, double *tmp)
{
    double sd[CLIP_MAX];
    int m = 0;
    for (int i = 0; i < k; i++)
        sd[i] = side(pl, &q[3 * i]);
    for (int i = 0; i < k; i++)
        if (sd[i] <= 0)
            memcpy(&tmp[3 * m++], &q[3 * i], 3 * sizeof(double));
    for (int i = 0; i < k; i++)
        for (int j = 0; j < k && m < CLIP_MAX; j++)
            if (sd[i] < 0 && sd[j] > 0)
                cross_point(&q[3 * i], sd[i], &q[3 * j], sd[j], &tmp[3 * m++]);
    if (m > 16) {
        double v;
        return cfb_convex_hull(tmp, m, q, &v);
    }
    memcpy(q, tmp, (size_t)m * 3 * sizeof(double));
    return m;
}

/* The rest of tet_in_cell for a part of many pieces: its k points (in
 * cb->a) clipped as a point set by the cell's planes from p on; the
 * volume from their hull, the centroid the mean of its vertices. */
static int points_in_cell(const cluster *c, int p, clip_buf *cb, int k, double *volume,
                          double centroid[3])
{
    double q[3 * CLIP_MAX], tmp[3 * CLIP_MAX], vol = 0;
    if ((k = cfb_convex_hull(cb->a, k, q, NULL)) < 0)
        return -1;
    for (; p < c->np && k > 0; p++)
        if ((k = clip_points(q, k, &c->planes[4 * p], tmp)) < 0)
            return -1;
    if (k >= 4 && (k = cfb_convex_hull(q, k, tmp, &vol)) < 0)
        return -1;
    if (k >= 4)
        memcpy(q, tmp, (size_t)k * 3 * sizeof(double));
    if (volume)
        *volume = k >= 4 ? vol : 0;
    if (centroid) {
        centroid[0] = centroid[1] = centroid[2] = 0;
        for (int j = 0; j < k; j++)
            v3_axpy(1.0 / k, &q[3 * j], centroid);
    }
    if (clip_reserve(cb, (k + 3) / 4))
        return -1;
    memcpy(cb->a, q, (size_t)k * 3 * sizeof(double));
    return k;
}

/* The part of tet t inside the cell: its 4 nodes when it lies inside every
 * plane; otherwise the tets it is clipped into, in cb->a.  Writes the
 * part's volume and centroid (either may be NULL) and returns the number of
 * points (4 per tet; 0 when nothing is inside), or -1 out of memory. */
static int tet_in_cell(const cf_solid *s, int t, const cluster *c, clip_buf *cb, double *volume,
                       double centroid[3], int *whole)
{
    if (clip_reserve(cb, 1))
        return -1;
    for (int j = 0; j < 4; j++)
        memcpy(&cb->a[3 * j], &s->X[3 * s->tet[4 * t + j]], 3 * sizeof(double));
    int n = 1;
    *whole = 1;
    int p = 0;
    for (; p < c->np && n > 0; p++) {
        const double *pl = &c->planes[4 * p];
        int out = 0;
        for (int j = 0; j < 4 * n; j++)
            out |= side(pl, &cb->a[3 * j]) > 0;
        if (!out)
            continue;
        *whole = 0;
        if (3 * n > PIECES_MAX)
            break;
        if (clip_reserve(cb, 3 * n))
            return -1;
        int m = 0;
        for (int i = 0; i < n; i++)
            m += clip_tet(&cb->a[12 * i], pl, &cb->b[12 * m]);
        double *sw = cb->a;
        cb->a = cb->b, cb->b = sw, n = m;
    }
    if (p < c->np && n > 0)
        return points_in_cell(c, p, cb, 4 * n, volume, centroid);
    double vol = 0, cen[3] = {0, 0, 0};
    if (*whole) {
        vol = s->vol[t];
        for (int j = 0; j < 4; j++)
            v3_axpy(0.25, &cb->a[3 * j], cen);
    } else {
        for (int i = 0; i < n; i++) {
            double v = tet_volume_of(&cb->a[12 * i]);
            vol += v;
            for (int j = 0; j < 4; j++)
                v3_axpy(0.25 * v, &cb->a[12 * i + 3 * j], cen);
        }
        if (vol > 0)
            for (int k = 0; k < 3; k++)
                cen[k] /= vol;
    }
    if (volume)
        *volume = vol;
    if (centroid)
        memcpy(centroid, cen, sizeof cen);
    return 4 * n;
}

/* Gather the cell's points and make its hull, and keep the centroids of
 * its tets' parts for the cut that may split it (split).  `stamp` marks
 * nodes already taken for this cluster (value `mark`).  Returns 0 or -1. */
static int cluster_hull(const cf_solid *s, cluster *c, int *stamp, int mark, double **buf,
                        int *cap)
{
    clip_buf cb = {0};
    int n = 0;
    c->tet_volume = 0;
    free(c->cen);
    c->cen = malloc((size_t)(c->nt > 0 ? c->nt : 1) * 3 * sizeof(double));
    if (!c->cen)
        return -1;
    for (int i = 0; i < c->nt; i++) {
        int t = c->tets[i], whole;
        double v, *cen = &c->cen[3 * i];
        int k = tet_in_cell(s, t, c, &cb, &v, cen, &whole);
        if (k < 0) {
            clip_free(&cb);
            return -1;
        }
        if (k == 0) /* no part inside the cell: the tet's own centroid */
            for (int j = 0; j < 4; j++)
                for (int a = 0; a < 3; a++)
                    cen[a] += 0.25 * s->X[3 * s->tet[4 * t + j] + a];
        const double *q = cb.a;
        c->tet_volume += v;
        if (n + k > *cap) {
            int nc = 2 * (n + k);
            double *b = realloc(*buf, (size_t)nc * 3 * sizeof(double));
            if (!b) {
                clip_free(&cb);
                return -1;
            }
            *buf = b, *cap = nc;
        }
        if (!whole) {
            memcpy(&(*buf)[3 * n], q, (size_t)k * 3 * sizeof(double));
            n += k;
            continue;
        }
        for (int j = 0; j < 4; j++) {
            int a = s->tet[4 * t + j];
            if (stamp[a] != mark) {
                stamp[a] = mark;
                memcpy(&(*buf)[3 * n++], &s->X[3 * a], 3 * sizeof(double));
            }
        }
    }
    clip_free(&cb);
    free(c->pts);
    c->pts = malloc((size_t)(n > 0 ? n : 1) * 3 * sizeof(double));
    if (!c->pts)
        return -1;
    int nv = n >= 4 ? cfb_convex_hull(*buf, n, c->pts, &c->hull_volume) : 0;
    if (nv < 0)
        return -1; /* the points are valid: Bullet ran out of memory */
    if (nv < 4 || !(c->hull_volume > 0)) { /* flat or empty: no hull */
        nv = 0;
        c->hull_volume = 0;
    }
    c->n_pts = nv;
    return 0;
}

/* Cut cluster c by the plane through the median of the centroids of its
 * tets' parts inside the cell (c->cen, from cluster_hull), normal to their
 * principal axis of spread: c keeps the side n.x <= d, d gets the other;
 * cluster_hull then makes both hulls and their centroids. */
static int split(const cf_solid *s, cluster *c, cluster *d)
{
    int n = c->nt;
    keyed *k = malloc((size_t)n * sizeof *k);
    const double *cen = c->cen;
    int *lo = malloc((size_t)n * sizeof(int)), *hi = malloc((size_t)n * sizeof(int));
    double *pc = malloc((size_t)(c->np + 1) * 4 * sizeof(double));
    double *pd = malloc((size_t)(c->np + 1) * 4 * sizeof(double));
    if (!k || !lo || !hi || !pc || !pd) {
        free(k), free(lo), free(hi), free(pc), free(pd);
        return -1;
    }
    double mean[3] = {0, 0, 0}, C[9] = {0};
    for (int i = 0; i < n; i++)
        v3_axpy(1.0 / n, &cen[3 * i], mean);
    for (int i = 0; i < n; i++) {
        double r[3];
        v3_sub(&cen[3 * i], mean, r);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                C[3 * a + b] += r[a] * r[b];
    }
    double w[3], V[9];
    sym3_eigen(C, w, V);
    int best = 0;
    for (int a = 1; a < 3; a++)
        if (w[a] > w[best])
            best = a;
    double pl[4] = {V[best], V[3 + best], V[6 + best], 0};
    for (int i = 0; i < n; i++) {
        k[i].key = v3_dot(&cen[3 * i], pl);
        k[i].tet = c->tets[i];
    }
    qsort(k, (size_t)n, sizeof *k, by_key);
    pl[3] = 0.5 * (k[(n - 1) / 2].key + k[n / 2].key);
    int nl = 0, nh = 0;
    for (int i = 0; i < n; i++) {
        int t = c->tets[i], below = 0, above = 0;
        for (int j = 0; j < 4; j++) {
            double sd = side(pl, &s->X[3 * s->tet[4 * t + j]]);
            below |= sd < 0, above |= sd > 0;
        }
        if (below || !above)
            lo[nl++] = t;
        if (above)
            hi[nh++] = t;
    }
    if (c->np > 0) { /* the first cell has no planes (and a NULL list) */
        memcpy(pc, c->planes, (size_t)c->np * 4 * sizeof(double));
        memcpy(pd, c->planes, (size_t)c->np * 4 * sizeof(double));
    }
    memcpy(&pc[4 * c->np], pl, sizeof pl);
    for (int a = 0; a < 4; a++)
        pd[4 * c->np + a] = -pl[a];
    memset(d, 0, sizeof *d);
    d->tets = hi, d->nt = nh, d->planes = pd, d->np = c->np + 1;
    free(c->tets), free(c->planes), free(c->cen);
    c->tets = lo, c->nt = nl, c->planes = pc, c->np++, c->cen = NULL;
    free(k);
    return 0;
}

static double excess(const cluster *c) { return c->hull_volume - c->tet_volume; }

int cf_decompose(const cf_solid *s, const int *tets, int nt, double max_error, int max_hulls,
                 int min_tets, cf_hulls *out, cf_decompose_tick tick, void *user)
{
    memset(out, 0, sizeof *out);
    if (max_hulls < 1)
        max_hulls = 1;
    if (min_tets < 1)
        min_tets = 1;
    int *stamp = malloc((size_t)s->n_nodes * sizeof(int));
    cluster *cl = calloc((size_t)max_hulls, sizeof *cl);
    double *buf = NULL;
    int cap = 0, n = 0, marks = 0;
    int ok = stamp && cl && (cl[0].tets = malloc((size_t)(nt > 0 ? nt : 1) * sizeof(int)));
    double tet_volume = 0;
    if (ok) {
        for (int a = 0; a < s->n_nodes; a++)
            stamp[a] = -1;
        memcpy(cl[0].tets, tets, (size_t)nt * sizeof(int));
        cl[0].nt = nt;
        ok = cluster_hull(s, &cl[0], stamp, marks++, &buf, &cap) == 0;
        n = 1;
        tet_volume = cl[0].tet_volume;
    }
    while (ok && n < max_hulls) {
        double hull_volume = 0;
        int worst = -1;
        for (int i = 0; i < n; i++) {
            hull_volume += cl[i].hull_volume;
            if (cl[i].nt >= 2 * min_tets && !cl[i].frozen &&
                (worst < 0 || excess(&cl[i]) > excess(&cl[worst])))
                worst = i;
        }
        if (worst < 0 || hull_volume <= (1 + max_error) * tet_volume)
            break;
        ok = split(s, &cl[worst], &cl[n]) == 0 &&
             cluster_hull(s, &cl[worst], stamp, marks++, &buf, &cap) == 0 &&
             cluster_hull(s, &cl[n], stamp, marks++, &buf, &cap) == 0;
        if (ok && (cl[worst].n_pts == 0 || cl[n].n_pts == 0))
            cl[worst].frozen = cl[n].frozen = 1;
        n++;
        if (tick)
            tick(user);
    }
    /* Cells with no volume of the fragment (a cut through empty space) add
     * no hull. */
    int total = 0, kept = 0;
    for (int i = 0; ok && i < n; i++)
        total += cl[i].n_pts, kept += cl[i].n_pts > 0;
    if (ok) {
        out->pts = malloc((size_t)(total > 0 ? total : 1) * 3 * sizeof(double));
        out->start = malloc((size_t)(kept + 1) * sizeof(int));
        ok = out->pts && out->start;
    }
    if (ok) {
        out->start[0] = 0;
        for (int i = 0; i < n; i++) {
            if (cl[i].n_pts == 0)
                continue;
            int h = out->n_hulls++;
            memcpy(&out->pts[3 * out->start[h]], cl[i].pts, (size_t)cl[i].n_pts * 3 * sizeof(double));
            out->start[h + 1] = out->start[h] + cl[i].n_pts;
            out->hull_volume += cl[i].hull_volume;
        }
        out->tet_volume = tet_volume;
    }
    for (int i = 0; cl && i < max_hulls; i++)
        free(cl[i].pts), free(cl[i].tets), free(cl[i].planes), free(cl[i].cen);
    free(cl), free(stamp), free(buf);
    if (!ok) {
        cf_hulls_free(out);
        return -1;
    }
    return 0;
}

double cf_hulls_error(const cf_hulls *h)
{
    return h->tet_volume > 0 ? h->hull_volume / h->tet_volume - 1 : 0;
}

void cf_hulls_free(cf_hulls *h)
{
    free(h->pts), free(h->start);
    memset(h, 0, sizeof *h);
}
