/* A body's visual surface embedded in the rest tets (see visual.h). */
#include "visual.h"

#include "cohfrac/world.h"
#include "linalg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void cf_visual_free(cf_visual *v)
{
    if (!v)
        return;
    free(v->vertices), free(v->triangles), free(v->tet);
    memset(v, 0, sizeof *v);
}

/* A uniform grid over the rest tets' bounding boxes: cell -> tets. */
typedef struct grid {
    double lo[3], h;
    int n[3];
    int *start, *item; /* CSR: the tets of cell c are item[start[c] .. start[c + 1]) */
    double *bary;      /* [nt][12]: each tet's inverse edge matrix (9) and first
                          vertex (3), the map to its barycentric coordinates;
                          NaN first for a flat tet */
} grid;

static long cell_of(const grid *g, const double x[3], int c[3])
{
    for (int k = 0; k < 3; k++) {
        int i = (int)floor((x[k] - g->lo[k]) / g->h);
        c[k] = i < 0 ? 0 : i >= g->n[k] ? g->n[k] - 1 : i;
    }
    return ((long)c[2] * g->n[1] + c[1]) * g->n[0] + c[0];
}

/* The cells a tet's bounding box covers, a[] to b[] per axis. */
static void tet_cells(const grid *g, const double *X, const int *T, int a[3], int b[3])
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int j = 0; j < 4; j++)
        for (int k = 0; k < 3; k++)
            lo[k] = fmin(lo[k], X[3 * T[j] + k]), hi[k] = fmax(hi[k], X[3 * T[j] + k]);
    cell_of(g, lo, a), cell_of(g, hi, b);
}

/* Each tet's map to barycentric coordinates, computed once: a triangle's
 * search tests some twenty tets, most of them again for its neighbours. */
static int grid_bary(grid *g, const double *X, const int *tets, int nt)
{
    g->bary = malloc((size_t)(nt > 0 ? nt : 1) * 12 * sizeof(double));
    if (!g->bary)
        return -1;
    for (int t = 0; t < nt; t++) {
        const int *T = &tets[4 * t];
        double M[9], *B = &g->bary[12 * t];
        for (int k = 0; k < 3; k++) {
            M[3 * k + 0] = X[3 * T[1] + k] - X[3 * T[0] + k];
            M[3 * k + 1] = X[3 * T[2] + k] - X[3 * T[0] + k];
            M[3 * k + 2] = X[3 * T[3] + k] - X[3 * T[0] + k];
            B[9 + k] = X[3 * T[0] + k];
        }
        if (m3_inv(M, B) == 0)
            B[0] = NAN;
    }
    return 0;
}

static int grid_build(grid *g, const double *X, int nn, const int *tets, int nt)
{
    if (grid_bary(g, X, tets, nt))
        return -1;
    double hi[3], vol = 1;
    points_bbox(X, nn, g->lo, hi);
    for (int k = 0; k < 3; k++)
        vol *= fmax(hi[k] - g->lo[k], 1e-12);
    g->h = 1.5 * cbrt(vol / (nt > 0 ? nt : 1)); /* a few tets a cell */
    long cells = 1;
    for (int k = 0; k < 3; k++)
        cells *= g->n[k] = (int)fmin(512, floor((hi[k] - g->lo[k]) / g->h) + 1);
    g->start = calloc((size_t)cells + 1, sizeof *g->start);
    int *fill = calloc((size_t)cells + 1, sizeof *fill);
    if (!g->start || !fill) {
        free(fill);
        return -1;
    }
    for (int pass = 0; pass < 2; pass++) { /* count, then fill */
        for (int t = 0; t < nt; t++) {
            int a[3], b[3];
            tet_cells(g, X, &tets[4 * t], a, b);
            for (int z = a[2]; z <= b[2]; z++)
                for (int y = a[1]; y <= b[1]; y++)
                    for (int x = a[0]; x <= b[0]; x++) {
                        long c = ((long)z * g->n[1] + y) * g->n[0] + x;
                        if (pass == 0)
                            g->start[c + 1]++;
                        else
                            g->item[fill[c]++] = t;
                    }
        }
        if (pass == 0) {
            for (long c = 0; c < cells; c++)
                g->start[c + 1] += g->start[c], fill[c] = g->start[c];
            g->item = malloc(((size_t)g->start[cells] + 1) * sizeof *g->item);
            if (!g->item) {
                free(fill);
                return -1;
            }
        }
    }
    free(fill);
    return 0;
}

/* The smallest barycentric coordinate of p in tet t: >= 0 inside. */
static double inside(const grid *g, int t, const double p[3])
{
    const double *B = &g->bary[12 * t];
    if (isnan(B[0]))
        return -INFINITY;
    double r[3] = {p[0] - B[9], p[1] - B[10], p[2] - B[11]}, l[3];
    for (int j = 0; j < 3; j++)
        l[j] = B[3 * j] * r[0] + B[3 * j + 1] * r[1] + B[3 * j + 2] * r[2];
    return fmin(fmin(l[0], l[1]), fmin(l[2], 1 - l[0] - l[1] - l[2]));
}

/* The tet holding p, else the one whose coordinates miss by the least,
 * searched in rings of cells around p until one is found a ring ago. */
static int locate(const grid *g, const double p[3])
{
    int c[3], best = -1;
    double best_in = -INFINITY;
    cell_of(g, p, c);
    int rmax = g->n[0] + g->n[1] + g->n[2];
    for (int r = 0; r <= rmax; r++) {
        for (int z = c[2] - r; z <= c[2] + r; z++)
            for (int y = c[1] - r; y <= c[1] + r; y++)
                for (int x = c[0] - r; x <= c[0] + r; x++) {
                    if (x < 0 || y < 0 || z < 0 || x >= g->n[0] || y >= g->n[1] ||
                        z >= g->n[2])
                        continue;
                    if (abs(x - c[0]) != r && abs(y - c[1]) != r && abs(z - c[2]) != r)
                        continue; /* the ring's shell only */
                    long cell = ((long)z * g->n[1] + y) * g->n[0] + x;
                    for (int i = g->start[cell]; i < g->start[cell + 1]; i++) {
                        int t = g->item[i];
                        double in = inside(g, t, p);
                        if (in > best_in || (in == best_in && t < best))
                            best_in = in, best = t;
                    }
                }
        if (best_in >= 0 || (best >= 0 && r >= 1))
            break;
    }
    return best;
}

cf_status cf_visual_embed(const cf_world_def *def, const cf_body_source *src,
                          const cf_world_meshes *meshes,
                          const double *X, int nn, const int *tets, int nt, int threads,
                          cf_visual *out, cf_error *err)
{
    memset(out, 0, sizeof *out);
    cf_status st = CF_OK;
    grid g = {0};
    for (int b = 0; src && b < def->n_bodies && st == CF_OK; b++) {
        const cf_body_def *bd = &def->bodies[b];
        if (!src[b].visual[0])
            continue;
        if (!g.start && grid_build(&g, X, nn, tets, nt) != 0) {
            st = cf_error_set(err, CF_ERR_NOMEM, "out of memory embedding the visual surface");
            break;
        }
        cf_surface s = {0};
        if ((st = cf_surface_load(src[b].visual, &s, err)) != CF_OK) {
            char why[sizeof err->msg];
            memcpy(why, err->msg, sizeof why);
            cf_error_set(err, st, "bodies[%d].visual: %s", b + 1, why);
            break;
        }
        int v0 = out->n_vertices, t0 = out->n_triangles;
        double *V = realloc(out->vertices, 3 * sizeof(double) * ((size_t)v0 + s.n_verts + 1));
        if (V)
            out->vertices = V;
        int *T = realloc(out->triangles, 3 * sizeof(int) * ((size_t)t0 + s.n_tris + 1));
        if (T)
            out->triangles = T;
        int *E = realloc(out->tet, sizeof(int) * ((size_t)t0 + s.n_tris + 1));
        if (E)
            out->tet = E;
        if (!V || !T || !E) {
            cf_surface_free(&s);
            st = cf_error_set(err, CF_ERR_NOMEM, "out of memory for the visual surface");
            break;
        }
        cf_body_place(bd, &meshes->bodies[b], s.v, s.n_verts, &V[3 * v0]); /* as the mesh */
        /* Each triangle on its own: on the threads, the same tets.  The
         * 70,000 triangles of `make run`'s bunny took a tenth of its run.
         * On the run's threads, not OpenMP's default of every core. */
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads > 0 ? threads : 1)
        for (int i = 0; i < s.n_tris; i++) {
            double c[3] = {0, 0, 0};
            for (int j = 0; j < 3; j++) {
                int v = s.tri[3 * i + j];
                T[3 * (t0 + i) + j] = v0 + v;
                for (int k = 0; k < 3; k++)
                    c[k] += V[3 * (v0 + v) + k] / 3;
            }
            E[t0 + i] = locate(&g, c);
        }
        out->n_vertices += s.n_verts, out->n_triangles += s.n_tris;
        cf_surface_free(&s);
    }
    free(g.start), free(g.item), free(g.bary);
    if (st != CF_OK)
        cf_visual_free(out);
    return st;
}
