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

/* Points of a clipped tet before they are reduced to their hull. */
#define CLIP_MAX 96

typedef struct cluster {
    int *tets, nt;       /* tets inside or straddling the cell */
    double *planes;      /* [np][4]: n.x <= d inside */
    int np;
    double tet_volume;   /* m^3 of the fragment inside the cell */
    double hull_volume;  /* m^3 */
    double *pts;         /* hull vertices [n_pts][3] */
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

/* Clip the convex point set q[k] by the half-space pl: keep the points
 * inside, add where each segment between an inside and an outside point
 * crosses the plane (the vertices of the cut are among these).  Returns the
 * new count, reduced to the hull's vertices when it grows large, or -1 when
 * Bullet runs out of memory for that hull (the points are finite). */
static int clip(double *q, int k, const double *pl, double *tmp)
{
    double s[CLIP_MAX];
    int m = 0;
    for (int i = 0; i < k; i++)
        s[i] = side(pl, &q[3 * i]);
    for (int i = 0; i < k; i++)
        if (s[i] <= 0)
            memcpy(&tmp[3 * m++], &q[3 * i], 3 * sizeof(double));
    for (int i = 0; i < k; i++)
        for (int j = 0; j < k && m < CLIP_MAX; j++)
            if (s[i] < 0 && s[j] > 0) {
                double t = s[i] / (s[i] - s[j]);
                for (int c = 0; c < 3; c++)
                    tmp[3 * m + c] = q[3 * i + c] + t * (q[3 * j + c] - q[3 * i + c]);
                m++;
            }
    if (m > 16) {
        double v;
        return cfb_convex_hull(tmp, m, q, &v);
    }
    memcpy(q, tmp, (size_t)m * 3 * sizeof(double));
    return m;
}

/* The points and volume of tet t inside the cell: its 4 nodes when it lies
 * inside every plane; otherwise its clipped vertices.  Returns the count
 * written to q (CLIP_MAX capacity), 0 when nothing is inside, -1 when
 * Bullet runs out of memory (a part dropped or a volume unset would
 * silently make a wrong hull). */
static int tet_in_cell(const cf_solid *s, int t, const cluster *c, double *q, double *tmp,
                       double *volume, int *whole)
{
    for (int j = 0; j < 4; j++)
        memcpy(&q[3 * j], &s->X[3 * s->tet[4 * t + j]], 3 * sizeof(double));
    int k = 4;
    *whole = 1;
    for (int p = 0; p < c->np && k > 0; p++) {
        const double *pl = &c->planes[4 * p];
        int out = 0;
        for (int j = 0; j < k; j++)
            out |= side(pl, &q[3 * j]) > 0;
        if (out) {
            *whole = 0;
            k = clip(q, k, pl, tmp);
            if (k < 0)
                return -1;
        }
    }
    if (*whole) {
        *volume = s->vol[t];
    } else if (k >= 4) {
        if (cfb_convex_hull(q, k, NULL, volume) < 0)
            return -1;
    } else {
        *volume = 0;
    }
    return k;
}

/* Gather the cell's points and make its hull.  `stamp` marks nodes already
 * taken for this cluster (value `mark`).  Returns 0 or -1. */
static int cluster_hull(const cf_solid *s, cluster *c, int *stamp, int mark, double **buf,
                        int *cap)
{
    double q[3 * CLIP_MAX], tmp[3 * CLIP_MAX];
    int n = 0;
    c->tet_volume = 0;
    for (int i = 0; i < c->nt; i++) {
        int t = c->tets[i], whole;
        double v;
        int k = tet_in_cell(s, t, c, q, tmp, &v, &whole);
        if (k < 0)
            return -1;
        c->tet_volume += v;
        if (n + k > *cap) {
            int nc = 2 * (n + k);
            double *b = realloc(*buf, (size_t)nc * 3 * sizeof(double));
            if (!b)
                return -1;
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
 * tets' parts inside the cell, normal to their principal axis of spread: c
 * keeps the side n.x <= d, d gets the other. */
static int split(const cf_solid *s, cluster *c, cluster *d)
{
    int n = c->nt;
    keyed *k = malloc((size_t)n * sizeof *k);
    double *cen = malloc((size_t)n * 3 * sizeof(double));
    int *lo = malloc((size_t)n * sizeof(int)), *hi = malloc((size_t)n * sizeof(int));
    double *pc = malloc((size_t)(c->np + 1) * 4 * sizeof(double));
    double *pd = malloc((size_t)(c->np + 1) * 4 * sizeof(double));
    if (!k || !cen || !lo || !hi || !pc || !pd) {
        free(k), free(cen), free(lo), free(hi), free(pc), free(pd);
        return -1;
    }
    double mean[3] = {0, 0, 0}, C[9] = {0}, q[3 * CLIP_MAX], tmp[3 * CLIP_MAX];
    for (int i = 0; i < n; i++) {
        double v;
        int whole, m = tet_in_cell(s, c->tets[i], c, q, tmp, &v, &whole);
        if (m < 0) {
            free(k), free(cen), free(lo), free(hi), free(pc), free(pd);
            return -1;
        }
        cen[3 * i] = cen[3 * i + 1] = cen[3 * i + 2] = 0;
        for (int j = 0; j < m; j++)
            v3_axpy(1.0 / m, &q[3 * j], &cen[3 * i]);
        v3_axpy(1.0 / n, &cen[3 * i], mean);
    }
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
    free(c->tets), free(c->planes);
    c->tets = lo, c->nt = nl, c->planes = pc, c->np++;
    free(k), free(cen);
    return 0;
}

static double excess(const cluster *c) { return c->hull_volume - c->tet_volume; }

int cf_decompose(const cf_solid *s, const int *tets, int nt, double max_error, int max_hulls,
                 int min_tets, cf_hulls *out)
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
        free(cl[i].pts), free(cl[i].tets), free(cl[i].planes);
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
