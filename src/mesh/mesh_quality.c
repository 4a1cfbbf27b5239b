/* cohfrac — the quality of a Tet4 mesh that sets the explicit step, and the
 * peeling of boundary slivers.
 *
 * The explicit step is dt_cfl = min over tets of h / c_d with h twice the
 * inradius (docs/physics.md §3), so one flat tet sets the step of the whole
 * body.  With tetgen -Y the surface is kept exactly, and the flattest tets
 * are caps whose four nodes all lie on the surface: tetgen may not split the
 * surface to improve them.  Removing such a cap when two or three of its faces
 * are on the surface changes the surface only by the cap's volume (an edge
 * flip of the surface triangulation, or a vertex removed), and it stays a
 * closed 2-manifold (Cheng, Dey and Shewchuk, "Delaunay Mesh Generation",
 * 2012, ch. 10, on peeling slivers off the boundary). */
#define _XOPEN_SOURCE 700 /* M_PI */

#include "cohfrac/mesh.h"
#include "linalg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const int FACE[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

/* Outward (unnormalised) normal of face k of tet t, whose length is twice
 * the face's area, for a positive tet. */
static void face_normal(const cf_mesh *m, int t, int k, double n[3])
{
    const int *T = &m->tets[4 * t];
    double e1[3], e2[3];
    v3_sub(&m->x[3 * T[FACE[k][1]]], &m->x[3 * T[FACE[k][0]]], e1);
    v3_sub(&m->x[3 * T[FACE[k][2]]], &m->x[3 * T[FACE[k][0]]], e2);
    v3_cross(e1, e2, n);
}

/* Twice the inradius (m) and the smallest dihedral angle (degrees) of tet t. */
static void tet_shape(const cf_mesh *m, int t, double *h, double *dihedral)
{
    const int *T = &m->tets[4 * t];
    double n[4][3], len[4], area = 0;
    for (int k = 0; k < 4; k++) {
        face_normal(m, t, k, n[k]);
        len[k] = v3_norm(n[k]);
        area += 0.5 * len[k];
    }
    double vol = fabs(cf_tet_volume(&m->x[3 * T[0]], &m->x[3 * T[1]], &m->x[3 * T[2]],
                                    &m->x[3 * T[3]]));
    *h = area > 0 ? 6 * vol / area : 0;
    double lowest = 180;
    for (int i = 0; i < 4; i++)
        for (int j = i + 1; j < 4; j++) {
            double c = v3_dot(n[i], n[j]) / (len[i] * len[j]);
            double a = 180 - acos(fmax(-1.0, fmin(1.0, c))) * 180 / M_PI;
            lowest = fmin(lowest, len[i] > 0 && len[j] > 0 ? a : 0);
        }
    *dihedral = lowest;
}

static int by_double(const void *x, const void *y)
{
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

/* Median of h over the tets (sorted copy); NAN without tets or memory. */
static double median_h(const double *h, int n)
{
    double *c = n > 0 ? malloc((size_t)n * sizeof *c) : NULL, med = NAN;
    if (c) {
        memcpy(c, h, (size_t)n * sizeof *c);
        qsort(c, (size_t)n, sizeof *c, by_double);
        med = n % 2 ? c[n / 2] : 0.5 * (c[n / 2 - 1] + c[n / 2]);
    }
    free(c);
    return med;
}

cf_mesh_quality cf_mesh_quality_of(const cf_mesh *m)
{
    cf_mesh_quality q = {NAN, NAN, -1};
    double *h = m->n_tets > 0 ? malloc((size_t)m->n_tets * sizeof *h) : NULL;
    if (!h)
        return q;
    q.min_dihedral = 180;
    for (int t = 0; t < m->n_tets; t++) {
        double d;
        tet_shape(m, t, &h[t], &d);
        q.min_dihedral = fmin(q.min_dihedral, d);
        if (q.worst_tet < 0 || h[t] < h[q.worst_tet])
            q.worst_tet = t;
    }
    q.dt_ratio = h[q.worst_tet] / median_h(h, m->n_tets);
    free(h);
    return q;
}

/* ---- peeling ------------------------------------------------------------- */

typedef struct {
    int v[3]; /* sorted node indices */
    int tet, k;
} face_rec;

static int by_face(const void *x, const void *y)
{
    const face_rec *a = x, *b = y;
    for (int i = 0; i < 3; i++)
        if (a->v[i] != b->v[i])
            return (a->v[i] > b->v[i]) - (a->v[i] < b->v[i]);
    return (a->tet > b->tet) - (a->tet < b->tet);
}

static void sort3(int v[3])
{
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2 - i; j++)
            if (v[j] > v[j + 1]) {
                int s = v[j];
                v[j] = v[j + 1], v[j + 1] = s;
            }
}

/* Marks bnd[4 t + k] = 1 where face k of tet t is on the surface (no other
 * tet shares it).  Returns -1 without memory. */
static int boundary_faces(const cf_mesh *m, unsigned char *bnd)
{
    int nf = 4 * m->n_tets;
    face_rec *f = malloc((size_t)nf * sizeof *f);
    if (!f)
        return -1;
    for (int t = 0; t < m->n_tets; t++)
        for (int k = 0; k < 4; k++) {
            face_rec *r = &f[4 * t + k];
            for (int j = 0; j < 3; j++)
                r->v[j] = m->tets[4 * t + FACE[k][j]];
            sort3(r->v);
            r->tet = t, r->k = k;
        }
    qsort(f, (size_t)nf, sizeof *f, by_face);
    for (int i = 0; i < nf;) {
        int j = i + 1;
        while (j < nf && !memcmp(f[j].v, f[i].v, sizeof f[i].v))
            j++;
        for (int q = i; q < j; q++)
            bnd[4 * f[q].tet + f[q].k] = (j - i) == 1;
        i = j;
    }
    free(f);
    return 0;
}

/* Tets around each node, as compressed rows: the tets of node v are
 * tet[start[v] .. start[v+1]). */
typedef struct {
    int *start, *tet;
} node_star;

static int star_build(const cf_mesh *m, node_star *st)
{
    st->start = calloc((size_t)m->n_nodes + 1, sizeof *st->start);
    st->tet = malloc((size_t)(4 * m->n_tets + 1) * sizeof *st->tet);
    if (!st->start || !st->tet)
        return -1;
    for (int i = 0; i < 4 * m->n_tets; i++)
        st->start[m->tets[i] + 1]++;
    for (int v = 0; v < m->n_nodes; v++)
        st->start[v + 1] += st->start[v];
    for (int i = 0; i < 4 * m->n_tets; i++)
        st->tet[st->start[m->tets[i]]++] = i / 4;
    for (int v = m->n_nodes; v > 0; v--) /* the fill moved each start one row on */
        st->start[v] = st->start[v - 1];
    st->start[0] = 0;
    return 0;
}

static void star_free(node_star *st) { free(st->start), free(st->tet); }

/* Whether nodes a and b share a surface face of a tet other than skip. */
static int surface_edge(const cf_mesh *m, const unsigned char *bnd, const node_star *st, int a,
                        int b, int skip)
{
    for (int i = st->start[a]; i < st->start[a + 1]; i++) {
        int t = st->tet[i];
        for (int k = 0; k < 4 && t != skip; k++) {
            if (!bnd[4 * t + k])
                continue;
            int has = 0;
            for (int j = 0; j < 3; j++) {
                int v = m->tets[4 * t + FACE[k][j]];
                has += (v == a) + (v == b);
            }
            if (has == 2)
                return 1;
        }
    }
    return 0;
}

/* Whether removing tet t (its surface faces marked in bnd) leaves the
 * surface a closed 2-manifold: with two surface faces the two exposed faces
 * share an edge that must not already be a surface edge; with three, the
 * node they share must belong to t alone. */
static int peelable(const cf_mesh *m, const unsigned char *bnd, const node_star *st, int t)
{
    const int *T = &m->tets[4 * t];
    int nb = bnd[4 * t] + bnd[4 * t + 1] + bnd[4 * t + 2] + bnd[4 * t + 3];
    if (nb == 2) { /* exposed: the two interior faces, sharing the edge of */
        int e[2], n = 0; /* the two nodes opposite the surface faces */
        for (int k = 0; k < 4; k++)
            if (bnd[4 * t + k])
                e[n++] = T[k];
        return !surface_edge(m, bnd, st, e[0], e[1], t);
    }
    if (nb == 3) /* the interior face is opposite the shared node */
        for (int k = 0; k < 4; k++)
            if (!bnd[4 * t + k])
                return st->start[T[k] + 1] - st->start[T[k]] == 1;
    return 0;
}

/* Drops nodes no tet uses, renumbering the rest in order. */
static int drop_unused_nodes(cf_mesh *m)
{
    int *map = malloc((size_t)m->n_nodes * sizeof *map), n = 0;
    if (!map)
        return -1;
    for (int v = 0; v < m->n_nodes; v++)
        map[v] = -1;
    for (int i = 0; i < 4 * m->n_tets; i++)
        map[m->tets[i]] = 0;
    for (int v = 0; v < m->n_nodes; v++)
        if (map[v] == 0) {
            memmove(&m->x[3 * n], &m->x[3 * v], 3 * sizeof *m->x);
            map[v] = n++;
        }
    for (int i = 0; i < 4 * m->n_tets; i++)
        m->tets[i] = map[m->tets[i]];
    m->n_nodes = n;
    free(map);
    return 0;
}

typedef struct {
    double h;
    int tet;
} ranked;

static int by_h(const void *x, const void *y)
{
    const ranked *a = x, *b = y;
    if (a->h != b->h)
        return (a->h > b->h) - (a->h < b->h);
    return (a->tet > b->tet) - (a->tet < b->tet);
}

/* One pass: removes the peelable caps thinner than `limit`, flattest first,
 * none sharing a node with a cap removed before it in this pass (whose
 * removal changed the surface there).  Returns the count, -1 without memory. */
static int peel_pass(cf_mesh *m, double limit, double *volume)
{
    unsigned char *bnd = malloc((size_t)m->n_tets * 4), *gone = calloc((size_t)m->n_tets, 1),
                  *used = calloc((size_t)m->n_nodes, 1);
    ranked *r = malloc((size_t)m->n_tets * sizeof *r);
    node_star st = {0};
    int n = 0, peeled = -1;
    if (!bnd || !gone || !used || !r || boundary_faces(m, bnd) != 0 || star_build(m, &st) != 0)
        goto out;
    for (int t = 0; t < m->n_tets; t++) {
        double h, d;
        tet_shape(m, t, &h, &d);
        if (h < limit)
            r[n].h = h, r[n++].tet = t;
    }
    qsort(r, (size_t)n, sizeof *r, by_h);
    peeled = 0;
    for (int i = 0; i < n; i++) {
        const int *T = &m->tets[4 * r[i].tet];
        if (used[T[0]] || used[T[1]] || used[T[2]] || used[T[3]] ||
            !peelable(m, bnd, &st, r[i].tet))
            continue;
        used[T[0]] = used[T[1]] = used[T[2]] = used[T[3]] = 1;
        gone[r[i].tet] = 1, peeled++;
        *volume += fabs(cf_tet_volume(&m->x[3 * T[0]], &m->x[3 * T[1]], &m->x[3 * T[2]],
                                      &m->x[3 * T[3]]));
    }
    int kept = 0;
    for (int t = 0; t < m->n_tets; t++)
        if (!gone[t])
            memmove(&m->tets[4 * kept++], &m->tets[4 * t], 4 * sizeof *m->tets);
    m->n_tets = kept;
out:
    star_free(&st);
    free(bnd), free(gone), free(used), free(r);
    return peeled;
}

cf_status cf_mesh_peel_slivers(cf_mesh *m, double fraction, int *peeled, double *volume,
                               cf_error *err)
{
    *peeled = 0, *volume = 0;
    if (m->n_groups > 0)
        return cf_error_set(err, CF_ERR_USAGE,
                            "cannot peel slivers off a mesh with node groups (they would "
                            "lose their numbering)");
    if (m->n_tets < 2)
        return CF_OK;
    double *h = malloc((size_t)m->n_tets * sizeof *h), d;
    if (!h)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory peeling slivers");
    for (int t = 0; t < m->n_tets; t++)
        tet_shape(m, t, &h[t], &d);
    /* The limit is fixed from the mesh as made: peeling must not chase a
     * median that it moves itself. */
    double limit = fraction * median_h(h, m->n_tets);
    free(h);
    for (int n = 1; n > 0;) {
        if ((n = peel_pass(m, limit, volume)) < 0)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory peeling slivers");
        *peeled += n;
    }
    if (*peeled > 0 && drop_unused_nodes(m) != 0)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory peeling slivers");
    return CF_OK;
}
