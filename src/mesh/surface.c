/* cohfrac — closed triangle surfaces: input through assimp, OFF output,
 * enclosed volume, closedness, self-intersection search, the valence-3
 * repair of docs/scenes.md, the general repair through CGAL and
 * decimation through meshoptimizer. */
#define _GNU_SOURCE /* dladdr */
#include "cohfrac/surface.h"

#include <dlfcn.h>

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <meshoptimizer.h>

#include "cf_cgal.h" /* the report's codes and sizes only: CGAL runs in cohfrac-repair */
#include "file_text.h"
#include "process.h"
#include "surface_raw.h"

/* ====================================================================== */
/* Input through assimp                                                   */
/* ====================================================================== */

typedef struct ibuf {
    int *a;
    size_t n, cap;
} ibuf;

static int ibuf_push(ibuf *b, int v)
{
    if (b->n == b->cap) {
        size_t nc = b->cap ? 2 * b->cap : 1024;
        int *na = realloc(b->a, nc * sizeof *na);
        if (!na)
            return -1;
        b->a = na, b->cap = nc;
    }
    b->a[b->n++] = v;
    return 0;
}

/* assimp reports some defects only to its log and goes on: an OFF face
 * index past the vertex list, for one, is logged and clamped.  The first
 * logged "out of range" refuses the file; its other errors (a missing
 * material library, an OBJ without an object name) do not concern the
 * geometry. */
static char ai_first_error[256];

static void ai_log(const char *msg, char *user)
{
    (void)user;
    const char *tag = "Error, ";
    if (ai_first_error[0] || strncmp(msg, tag, strlen(tag)) != 0 || !strstr(msg, "out of range"))
        return;
    const char *text = strchr(msg + strlen(tag), ':'); /* after "T0:" */
    text = text ? text + 1 + (text[1] == ' ') : msg;
    snprintf(ai_first_error, sizeof ai_first_error, "%s", text);
    ai_first_error[strcspn(ai_first_error, "\r\n")] = '\0';
}

static const struct aiScene *ai_import(const char *path)
{
    struct aiPropertyStore *props = aiCreatePropertyStore();
    /* Positions only: normals, texture coordinates and colours removed
     * first, so corners at one position are joined however the file
     * attributes them. */
    aiSetImportPropertyInteger(props, AI_CONFIG_PP_RVC_FLAGS,
                               aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                   aiComponent_COLORS | aiComponent_TEXCOORDS |
                                   aiComponent_BONEWEIGHTS | aiComponent_ANIMATIONS |
                                   aiComponent_TEXTURES | aiComponent_LIGHTS |
                                   aiComponent_CAMERAS | aiComponent_MATERIALS);
    struct aiLogStream log = {ai_log, NULL};
    ai_first_error[0] = '\0';
    aiAttachLogStream(&log);
    const struct aiScene *sc = aiImportFileExWithProperties(
        path,
        aiProcess_RemoveComponent | aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
            aiProcess_PreTransformVertices | aiProcess_ValidateDataStructure,
        NULL, props);
    aiDetachLogStream(&log);
    aiReleasePropertyStore(props);
    return sc;
}

/* Copy every triangle of every mesh (node transforms applied by assimp);
 * triangles with a repeated corner are dropped. */
static cf_status copy_scene(const char *path, const struct aiScene *sc, cf_surface *s,
                            cf_error *err)
{
    size_t nv = 0, nt = 0;
    for (unsigned i = 0; i < sc->mNumMeshes; i++) {
        nv += sc->mMeshes[i]->mNumVertices;
        for (unsigned f = 0; f < sc->mMeshes[i]->mNumFaces; f++)
            nt += sc->mMeshes[i]->mFaces[f].mNumIndices == 3;
    }
    if (nt == 0 || nv > INT_MAX / 3 || nt > INT_MAX / 3)
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s: %zu triangles in %u meshes: a surface needs triangles, and at "
                            "most %d of them",
                            path, nt, sc->mNumMeshes, INT_MAX / 3);
    s->v = malloc(nv * 3 * sizeof(double));
    s->tri = malloc(nt * 3 * sizeof(int));
    if (!s->v || !s->tri)
        return cf_error_set(err, CF_ERR_NOMEM, "%s: out of memory for %zu triangles", path, nt);
    for (unsigned i = 0, base = 0; i < sc->mNumMeshes; i++) {
        const struct aiMesh *m = sc->mMeshes[i];
        for (unsigned v = 0; v < m->mNumVertices; v++) {
            double *x = &s->v[3 * (size_t)s->n_verts++];
            x[0] = m->mVertices[v].x, x[1] = m->mVertices[v].y, x[2] = m->mVertices[v].z;
            if (!isfinite(x[0]) || !isfinite(x[1]) || !isfinite(x[2]))
                return cf_error_set(err, CF_ERR_MESH_PARSE,
                                    "%s: a vertex of mesh %u is not a finite number (%g %g %g)",
                                    path, i, x[0], x[1], x[2]);
        }
        for (unsigned f = 0; f < m->mNumFaces; f++) {
            const unsigned *c = m->mFaces[f].mIndices;
            if (m->mFaces[f].mNumIndices != 3 || c[0] == c[1] || c[1] == c[2] || c[2] == c[0])
                continue; /* points, lines and degenerate triangles */
            for (int k = 0; k < 3; k++)
                s->tri[3 * (size_t)s->n_tris + k] = (int)(base + c[k]);
            s->n_tris++;
        }
        base += m->mNumVertices;
    }
    if (s->n_tris == 0)
        return cf_error_set(err, CF_ERR_MESH_PARSE, "%s: the surface has no triangles", path);
    return CF_OK;
}

int cf_surface_format_known(const char *path)
{
    const char *dot = strrchr(path, '.');
    return dot && !strchr(dot, '/') && aiIsExtensionSupported(dot);
}

cf_status cf_surface_load(const char *path, cf_surface *s, cf_error *err)
{
    memset(s, 0, sizeof *s);
    struct stat sb;
    if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode))
        return cf_error_set(err, CF_ERR_FILE_OPEN,
                            "%s is a directory, not a surface file: give a .obj, .off or .stl "
                            "file",
                            path);
    if (!cf_surface_format_known(path))
        return cf_error_set(err, CF_ERR_FILE_OPEN,
                            "%s: unknown surface format; use .obj, .off or .stl, or another "
                            "format assimp reads (.ply, .gltf, .glb, .3ds, .fbx, .dae, ...)",
                            path);
    if (access(path, R_OK) != 0)
        return cf_error_set(err, CF_ERR_FILE_OPEN, "%s: cannot read it: %s", path,
                            strerror(errno));
    const struct aiScene *sc = ai_import(path);
    cf_status st = CF_OK;
    if (!sc || ai_first_error[0]) {
        const char *why = ai_first_error[0] ? ai_first_error : aiGetErrorString();
        int index = strstr(why, "out of range") != NULL;
        /* assimp reports a failed allocation as the exception's text, or
         * with no text at all when its C entry point caught the exception
         * of its first allocation, the importer that would hold the text */
        int nomem = why[0] == '\0' || strstr(why, "bad_alloc") != NULL ||
                    strstr(why, "out of memory") != NULL;
        st = cf_error_set(err, nomem ? CF_ERR_NOMEM : index ? CF_ERR_MESH_INDEX : CF_ERR_MESH_PARSE,
                          "%s: %s (read with assimp)", path, nomem ? "out of memory" : why);
    } else {
        st = copy_scene(path, sc, s, err);
    }
    aiReleaseImport(sc);
    if (st != CF_OK)
        cf_surface_free(s);
    return st;
}

cf_status cf_surface_write_off(const cf_surface *s, const char *path, cf_error *err)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return cf_error_set(err, cf_status_of_errno(errno, CF_ERR_OUTPUT),
                            "%s: cannot write (%s)", path, strerror(errno));
    fprintf(f, "OFF\n%d %d 0\n", s->n_verts, s->n_tris);
    for (int i = 0; i < s->n_verts; i++)
        fprintf(f, "%.17g %.17g %.17g\n", s->v[3 * i], s->v[3 * i + 1], s->v[3 * i + 2]);
    for (int i = 0; i < s->n_tris; i++)
        fprintf(f, "3 %d %d %d\n", s->tri[3 * i], s->tri[3 * i + 1], s->tri[3 * i + 2]);
    int bad = ferror(f);
    bad |= fclose(f) != 0;
    if (bad)
        return cf_error_set(err, CF_ERR_OUTPUT, "%s: write failed (disk full?)", path);
    return CF_OK;
}

void cf_surface_free(cf_surface *s)
{
    if (!s)
        return;
    free(s->v);
    free(s->tri);
    memset(s, 0, sizeof *s);
}

/* ====================================================================== */
/* Volume, closedness, compaction                                         */
/* ====================================================================== */

double cf_surface_volume(const cf_surface *s)
{
    double sum = 0.0, c = 0.0; /* Neumaier-compensated */
    for (int t = 0; t < s->n_tris; t++) {
        const double *a = &s->v[3 * s->tri[3 * t]], *b = &s->v[3 * s->tri[3 * t + 1]],
                     *d = &s->v[3 * s->tri[3 * t + 2]];
        double x = a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0]) +
                   a[2] * (b[0] * d[1] - b[1] * d[0]);
        double u = sum + x;
        c += fabs(sum) >= fabs(x) ? (sum - u) + x : (x - u) + sum;
        sum = u;
    }
    return (sum + c) / 6.0;
}

void cf_surface_flip(cf_surface *s)
{
    for (int t = 0; t < s->n_tris; t++) {
        int tmp = s->tri[3 * t + 1];
        s->tri[3 * t + 1] = s->tri[3 * t + 2];
        s->tri[3 * t + 2] = tmp;
    }
}

int cf_surface_remove_unused(cf_surface *s)
{
    int *map = malloc((size_t)(s->n_verts > 0 ? s->n_verts : 1) * sizeof *map);
    if (!map)
        return -1;
    for (int i = 0; i < s->n_verts; i++)
        map[i] = -1;
    for (int i = 0; i < 3 * s->n_tris; i++)
        map[s->tri[i]] = 0;
    int n = 0;
    for (int i = 0; i < s->n_verts; i++)
        if (map[i] == 0) {
            memmove(&s->v[3 * n], &s->v[3 * i], 3 * sizeof(double));
            map[i] = n++;
        }
    for (int i = 0; i < 3 * s->n_tris; i++)
        s->tri[i] = map[s->tri[i]];
    int removed = s->n_verts - n;
    s->n_verts = n;
    free(map);
    return removed;
}

static int edge_cmp(const void *pa, const void *pb)
{
    const int *a = pa, *b = pb; /* lo, hi, slot */
    return a[0] != b[0] ? (a[0] > b[0]) - (a[0] < b[0]) : (a[1] > b[1]) - (a[1] < b[1]);
}

int cf_surface_subdivide(cf_surface *s)
{
    size_t nt = (size_t)s->n_tris, ne = 3 * nt;
    if ((size_t)s->n_verts + ne > INT_MAX / 3 || 4 * nt > INT_MAX / 3)
        return -1;
    int *e = malloc(ne * 3 * sizeof *e), *mid = malloc(ne * sizeof *mid);
    int *tri = malloc(4 * nt * 3 * sizeof *tri);
    double *v = realloc(s->v, ((size_t)s->n_verts + ne) * 3 * sizeof *v);
    if (v)
        s->v = v;
    if (!e || !mid || !tri || !v) {
        free(e), free(mid), free(tri);
        return -1;
    }
    for (size_t k = 0; k < ne; k++) { /* edge k: corner k%3 to the next */
        int a = s->tri[k], b = s->tri[3 * (k / 3) + (k % 3 + 1) % 3];
        e[3 * k] = a < b ? a : b, e[3 * k + 1] = a < b ? b : a, e[3 * k + 2] = (int)k;
    }
    qsort(e, ne, 3 * sizeof *e, edge_cmp);
    int nv = s->n_verts;
    for (size_t k = 0; k < ne; k++) { /* one midpoint per distinct edge */
        if (k == 0 || edge_cmp(&e[3 * k], &e[3 * (k - 1)]) != 0) {
            for (int d = 0; d < 3; d++)
                s->v[3 * (size_t)nv + d] = 0.5 * (s->v[3 * e[3 * k] + d] + s->v[3 * e[3 * k + 1] + d]);
            nv++;
        }
        mid[e[3 * k + 2]] = nv - 1;
    }
    for (size_t t = 0; t < nt; t++) {
        const int *c = &s->tri[3 * t], *m = &mid[3 * t]; /* m[i]: edge c[i] c[i+1] */
        int q[4][3] = {{c[0], m[0], m[2]}, {m[0], c[1], m[1]}, {m[2], m[1], c[2]},
                       {m[0], m[1], m[2]}};
        memcpy(&tri[12 * t], q, sizeof q);
    }
    free(s->tri);
    s->tri = tri, s->n_tris = (int)(4 * nt), s->n_verts = nv;
    free(e), free(mid);
    return 0;
}

/* A directed edge from -> to of triangle `tri`. */
typedef struct hedge {
    int from, to, tri;
} hedge;

static int hedge_cmp(const void *pa, const void *pb)
{
    const hedge *a = pa, *b = pb;
    if (a->from != b->from)
        return a->from < b->from ? -1 : 1;
    if (a->to != b->to)
        return a->to < b->to ? -1 : 1;
    return (a->tri > b->tri) - (a->tri < b->tri);
}

/* Index of directed edge (from,to) in the sorted array, or -1. */
static long hedge_find(const hedge *h, long n, int from, int to)
{
    long lo = 0, hi = n - 1;
    while (lo <= hi) {
        long mid = lo + (hi - lo) / 2;
        if (h[mid].from < from || (h[mid].from == from && h[mid].to < to))
            lo = mid + 1;
        else if (h[mid].from == from && h[mid].to == to)
            return mid;
        else
            hi = mid - 1;
    }
    return -1;
}

int cf_surface_check_closed(const cf_surface *s, char *why, size_t why_len)
{
    char dummy[8];
    if (!why)
        why = dummy, why_len = sizeof dummy;
    why[0] = '\0';
    long nh = 3L * s->n_tris;
    hedge *h = malloc((size_t)(nh > 0 ? nh : 1) * sizeof *h);
    int *deg = calloc((size_t)(s->n_verts > 0 ? s->n_verts : 1), sizeof *deg);
    if (!h || !deg) {
        free(h);
        free(deg);
        snprintf(why, why_len, "out of memory");
        return -1;
    }
    for (int t = 0; t < s->n_tris; t++)
        for (int k = 0; k < 3; k++) {
            h[3 * t + k] = (hedge){s->tri[3 * t + k], s->tri[3 * t + (k + 1) % 3], t};
            deg[s->tri[3 * t + k]]++;
        }
    qsort(h, (size_t)nh, sizeof *h, hedge_cmp);
    int ok = 1;
    for (long i = 0; i < nh && ok; i++) {
        if (i + 1 < nh && h[i + 1].from == h[i].from && h[i + 1].to == h[i].to) {
            snprintf(why, why_len,
                     "edge %d->%d has the same direction in triangles %d and %d (inconsistent "
                     "orientation or non-manifold edge)",
                     h[i].from, h[i].to, h[i].tri, h[i + 1].tri);
            ok = 0;
        } else if (hedge_find(h, nh, h[i].to, h[i].from) < 0) {
            snprintf(why, why_len,
                     "edge %d-%d is used by triangle %d only (a hole or a flipped neighbour)",
                     h[i].from, h[i].to, h[i].tri);
            ok = 0;
        }
    }
    /* Every edge has exactly one twin: now walk each vertex's fan.  A
     * manifold vertex has one fan through all of its triangles. */
    char *seen = ok ? calloc((size_t)(s->n_verts > 0 ? s->n_verts : 1), 1) : NULL;
    if (ok && !seen) {
        snprintf(why, why_len, "out of memory");
        ok = -1;
    }
    for (long i = 0; i < nh && ok == 1; i++) {
        int v = h[i].from;
        if (seen[v])
            continue;
        seen[v] = 1;
        int steps = 0;
        long e = i;
        do {
            /* In triangle (v, x, y) the edge y->v is followed by v->y in the
             * neighbour across it, which continues the fan around v. */
            int t = h[e].tri, y = -1;
            for (int k = 0; k < 3; k++)
                if (s->tri[3 * t + k] == v)
                    y = s->tri[3 * t + (k + 2) % 3];
            e = hedge_find(h, nh, v, y);
            steps++;
        } while (e != i && e >= 0 && steps <= deg[v]);
        if (steps != deg[v]) {
            snprintf(why, why_len,
                     "vertex %d is non-manifold: its %d triangles form more than one fan", v,
                     deg[v]);
            ok = 0;
        }
    }
    free(seen);
    free(h);
    free(deg);
    return ok;
}

/* ====================================================================== */
/* Triangle-triangle intersection                                         */
/* ====================================================================== */

/* det[b-a, c-a, d-a]: > 0 when d lies on the side of (b-a)x(c-a). */
static double orient3d(const double *a, const double *b, const double *c, const double *d)
{
    double u0 = b[0] - a[0], u1 = b[1] - a[1], u2 = b[2] - a[2];
    double v0 = c[0] - a[0], v1 = c[1] - a[1], v2 = c[2] - a[2];
    double w0 = d[0] - a[0], w1 = d[1] - a[1], w2 = d[2] - a[2];
    return u0 * (v1 * w2 - v2 * w1) - u1 * (v0 * w2 - v2 * w0) + u2 * (v0 * w1 - v1 * w0);
}

static double orient2d(const double *a, const double *b, const double *c)
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

static void cross3(const double *u, const double *v, double *w)
{
    w[0] = u[1] * v[2] - u[2] * v[1];
    w[1] = u[2] * v[0] - u[0] * v[2];
    w[2] = u[0] * v[1] - u[1] * v[0];
}

static double dot3(const double *u, const double *v)
{
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
}

static void sub3(const double *a, const double *b, double *c)
{
    c[0] = a[0] - b[0], c[1] = a[1] - b[1], c[2] = a[2] - b[2];
}

/* Project the triangle's points onto the coordinate plane that drops the
 * largest component of normal n (the best-conditioned 2-D view). */
static void project2(const double *n, const double *const *p3, int np, double (*p2)[2])
{
    int ax = 0;
    if (fabs(n[1]) > fabs(n[ax]))
        ax = 1;
    if (fabs(n[2]) > fabs(n[ax]))
        ax = 2;
    int i0 = (ax + 1) % 3, i1 = (ax + 2) % 3;
    for (int k = 0; k < np; k++)
        p2[k][0] = p3[k][i0], p2[k][1] = p3[k][i1];
}

static int sgn(double x) { return (x > 0) - (x < 0); }

/* Closed 2-D segments ab and cd share a point. */
static int seg_seg_2d(const double *a, const double *b, const double *c, const double *d)
{
    int o1 = sgn(orient2d(a, b, c)), o2 = sgn(orient2d(a, b, d));
    int o3 = sgn(orient2d(c, d, a)), o4 = sgn(orient2d(c, d, b));
    if (o1 * o2 < 0 && o3 * o4 < 0)
        return 1;
    /* collinear touching: a point of one on the other */
#define ON_SEG(p, q, r)                                                                            \
    (fmin(p[0], q[0]) <= r[0] && r[0] <= fmax(p[0], q[0]) && fmin(p[1], q[1]) <= r[1] &&         \
     r[1] <= fmax(p[1], q[1]))
    if (o1 == 0 && ON_SEG(a, b, c))
        return 1;
    if (o2 == 0 && ON_SEG(a, b, d))
        return 1;
    if (o3 == 0 && ON_SEG(c, d, a))
        return 1;
    if (o4 == 0 && ON_SEG(c, d, b))
        return 1;
#undef ON_SEG
    return 0;
}

/* Point p inside or on the 2-D triangle abc (either orientation). */
static int point_in_tri_2d(const double *p, const double *a, const double *b, const double *c)
{
    int s1 = sgn(orient2d(a, b, p)), s2 = sgn(orient2d(b, c, p)), s3 = sgn(orient2d(c, a, p));
    return !((s1 < 0 || s2 < 0 || s3 < 0) && (s1 > 0 || s2 > 0 || s3 > 0));
}

/* Coplanar triangles P and Q (no shared vertex) overlap. */
static int coplanar_overlap(const double *const *P, const double *const *Q)
{
    double n[3], u[3], v[3];
    sub3(P[1], P[0], u);
    sub3(P[2], P[0], v);
    cross3(u, v, n);
    double p[3][2], q[3][2];
    project2(n, P, 3, p);
    project2(n, Q, 3, q);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (seg_seg_2d(p[i], p[(i + 1) % 3], q[j], q[(j + 1) % 3]))
                return 1;
    return point_in_tri_2d(p[0], q[0], q[1], q[2]) || point_in_tri_2d(q[0], p[0], p[1], p[2]);
}

/* Extent of triangle T ∩ (other plane) along direction D; d[] are the
 * signed plane tests of T's corners. */
static void plane_cut(const double *const *T, const double *d, const double *D, double *lo,
                      double *hi)
{
    *lo = INFINITY, *hi = -INFINITY;
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3;
        double x;
        if (d[i] == 0) {
            x = dot3(T[i], D);
        } else if ((d[i] > 0 && d[j] < 0) || (d[i] < 0 && d[j] > 0)) {
            double t = d[i] / (d[i] - d[j]), X[3];
            for (int k = 0; k < 3; k++)
                X[k] = T[i][k] + t * (T[j][k] - T[i][k]);
            x = dot3(X, D);
        } else {
            continue;
        }
        *lo = fmin(*lo, x);
        *hi = fmax(*hi, x);
    }
}

/* Triangles P and Q with no common vertex intersect (touching counts). */
static int tri_tri_disjoint(const double *const *P, const double *const *Q)
{
    double dq[3], dp[3];
    for (int i = 0; i < 3; i++)
        dq[i] = orient3d(P[0], P[1], P[2], Q[i]);
    if ((dq[0] > 0 && dq[1] > 0 && dq[2] > 0) || (dq[0] < 0 && dq[1] < 0 && dq[2] < 0))
        return 0;
    for (int i = 0; i < 3; i++)
        dp[i] = orient3d(Q[0], Q[1], Q[2], P[i]);
    if ((dp[0] > 0 && dp[1] > 0 && dp[2] > 0) || (dp[0] < 0 && dp[1] < 0 && dp[2] < 0))
        return 0;
    if ((dq[0] == 0 && dq[1] == 0 && dq[2] == 0) || (dp[0] == 0 && dp[1] == 0 && dp[2] == 0))
        return coplanar_overlap(P, Q);
    /* Both triangles cross the other's plane: their cuts lie on the line of
     * the two planes; they intersect iff the cuts overlap along it. */
    double u[3], v[3], nP[3], nQ[3], D[3];
    sub3(P[1], P[0], u);
    sub3(P[2], P[0], v);
    cross3(u, v, nP);
    sub3(Q[1], Q[0], u);
    sub3(Q[2], Q[0], v);
    cross3(u, v, nQ);
    cross3(nP, nQ, D);
    double lo1, hi1, lo2, hi2;
    plane_cut(P, dp, D, &lo1, &hi1);
    plane_cut(Q, dq, D, &lo2, &hi2);
    return lo1 <= hi2 && lo2 <= hi1;
}

/* Triangles (p,a,b) and (p,c,d) share only p: do they meet elsewhere?
 * Near p each is a planar wedge; convexity means they meet away from p iff
 * the wedges share a ray. */
static int tri_tri_vertex(const double *p, const double *a, const double *b, const double *c,
                          const double *d)
{
    double sc = orient3d(p, a, b, c), sd = orient3d(p, a, b, d);
    if ((sc > 0 && sd > 0) || (sc < 0 && sd < 0))
        return 0;
    double sa = orient3d(p, c, d, a), sb = orient3d(p, c, d, b);
    if ((sa > 0 && sb > 0) || (sa < 0 && sb < 0))
        return 0;
    if ((sc == 0 && sd == 0) || (sa == 0 && sb == 0)) {
        double u[3], v[3], n[3];
        sub3(a, p, u);
        sub3(b, p, v);
        cross3(u, v, n);
        const double *pts[5] = {p, a, b, c, d};
        double q[5][2];
        project2(n, pts, 5, q);
        double w[4][2];
        for (int k = 0; k < 4; k++)
            w[k][0] = q[k + 1][0] - q[0][0], w[k][1] = q[k + 1][1] - q[0][1];
        /* make both wedges counter-clockwise: (w0,w1) and (w2,w3) */
        for (int k = 0; k < 4; k += 2)
            if (w[k][0] * w[k + 1][1] - w[k][1] * w[k + 1][0] < 0) {
                double t0 = w[k][0], t1 = w[k][1];
                w[k][0] = w[k + 1][0], w[k][1] = w[k + 1][1];
                w[k + 1][0] = t0, w[k + 1][1] = t1;
            }
#define CR(x, y) ((x)[0] * (y)[1] - (x)[1] * (y)[0])
#define IN_WEDGE(r, lo, hi) (CR(lo, r) >= 0 && CR(r, hi) >= 0)
        /* two convex wedges share a ray iff one holds a side of the other */
        return IN_WEDGE(w[2], w[0], w[1]) || IN_WEDGE(w[3], w[0], w[1]) ||
               IN_WEDGE(w[0], w[2], w[3]) || IN_WEDGE(w[1], w[2], w[3]);
#undef IN_WEDGE
#undef CR
    }
    /* Each wedge cuts the other's plane in a ray from p along the common
     * line; the points where edges ab and cd cross the planes fix them. */
    double X1[3], X2[3], r1[3], r2[3];
    for (int k = 0; k < 3; k++) {
        X1[k] = sa == sb ? a[k] : a[k] + (b[k] - a[k]) * (sa / (sa - sb));
        X2[k] = sc == sd ? c[k] : c[k] + (d[k] - c[k]) * (sc / (sc - sd));
    }
    sub3(X1, p, r1);
    sub3(X2, p, r2);
    return dot3(r1, r2) > 0;
}

/* Triangles (a,b,c) and (a,b,d) share edge ab: they overlap only when
 * coplanar with c and d on the same side of ab (a fold-over). */
static int tri_tri_edge(const double *a, const double *b, const double *c, const double *d)
{
    if (orient3d(a, b, c, d) != 0)
        return 0;
    double u[3], v[3], n[3];
    sub3(b, a, u);
    sub3(c, a, v);
    cross3(u, v, n);
    const double *pts[4] = {a, b, c, d};
    double q[4][2];
    project2(n, pts, 4, q);
    return sgn(orient2d(q[0], q[1], q[2])) * sgn(orient2d(q[0], q[1], q[3])) > 0;
}

/* Do surface triangles ti and tj intersect other than along their shared
 * vertices/edge? */
static int tris_intersect(const cf_surface *s, int ti, int tj)
{
    const int *A = &s->tri[3 * ti], *B = &s->tri[3 * tj];
    if (A[0] == A[1] || A[1] == A[2] || A[2] == A[0] || B[0] == B[1] || B[1] == B[2] ||
        B[2] == B[0])
        return 1; /* a triangle with a repeated corner is a defect wherever it lies */
    int ia[3], ib[3], ns = 0; /* positions of shared vertices */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (A[i] == B[j])
                ia[ns] = i, ib[ns] = j, ns++;
#define VX(k) (&s->v[3 * (size_t)(k)])
    if (ns == 3)
        return 1; /* the same triangle twice */
    if (ns == 0) {
        const double *P[3] = {VX(A[0]), VX(A[1]), VX(A[2])};
        const double *Q[3] = {VX(B[0]), VX(B[1]), VX(B[2])};
        return tri_tri_disjoint(P, Q);
    }
    if (ns == 1) {
        int i = ia[0], j = ib[0];
        return tri_tri_vertex(VX(A[i]), VX(A[(i + 1) % 3]), VX(A[(i + 2) % 3]), VX(B[(j + 1) % 3]),
                              VX(B[(j + 2) % 3]));
    }
    int c = 3 - ia[0] - ia[1], d = 3 - ib[0] - ib[1];
    return tri_tri_edge(VX(A[ia[0]]), VX(A[ia[1]]), VX(A[c]), VX(B[d]));
#undef VX
}

/* ---- broad phase: uniform grid ---- */

static int pair_cmp(const void *pa, const void *pb)
{
    const int *a = pa, *b = pb;
    if (a[0] != b[0])
        return a[0] < b[0] ? -1 : 1;
    return (a[1] > b[1]) - (a[1] < b[1]);
}

static int cmp_double(const void *pa, const void *pb)
{
    double a = *(const double *)pa, b = *(const double *)pb;
    return (a > b) - (a < b);
}

/* All intersecting pairs (i < j, sorted); *out malloc'd.  Returns the count
 * or -1 when out of memory. */
static long find_pairs(const cf_surface *s, int **out)
{
    *out = NULL;
    int nt = s->n_tris;
    if (nt < 2)
        return 0;
    double *box = malloc((size_t)nt * 6 * sizeof *box), *ext = malloc((size_t)nt * sizeof *ext);
    if (!box || !ext) {
        free(box);
        free(ext);
        return -1;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int t = 0; t < nt; t++) {
        double *b = &box[6 * t];
        for (int k = 0; k < 3; k++)
            b[k] = INFINITY, b[3 + k] = -INFINITY;
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++) {
                double x = s->v[3 * s->tri[3 * t + c] + k];
                b[k] = fmin(b[k], x), b[3 + k] = fmax(b[3 + k], x);
            }
        ext[t] = fmax(b[3] - b[0], fmax(b[4] - b[1], b[5] - b[2]));
        for (int k = 0; k < 3; k++)
            lo[k] = fmin(lo[k], b[k]), hi[k] = fmax(hi[k], b[3 + k]);
    }
    /* Cell size: twice the median triangle extent (robust to a few huge
     * triangles), but no more than ~8 cells per triangle in total. */
    qsort(ext, (size_t)nt, sizeof *ext, cmp_double);
    double h = 2.0 * ext[nt / 2];
    double span = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    if (!(h > 0))
        h = span > 0 ? span : 1.0;
    /* Counted in doubles: a far-away vertex (1e10 m) must not overflow an
     * int before the cell size has grown to fit (the loop ends with every
     * count at most 8 nt + 64). */
    int dim[3];
    double dd[3];
    for (;;) {
        double cells = 1.0;
        for (int k = 0; k < 3; k++) {
            dd[k] = floor((hi[k] - lo[k]) / h) + 1;
            cells *= dd[k];
        }
        if (cells <= 8.0 * nt + 64)
            break;
        h *= 1.25;
    }
    for (int k = 0; k < 3; k++)
        dim[k] = (int)dd[k];
    free(ext);
    size_t ncell = (size_t)dim[0] * dim[1] * dim[2];
    size_t *start = calloc(ncell + 1, sizeof *start);
    if (!start) {
        free(box);
        return -1;
    }
#define CELL_RANGE(t, r)                                                                           \
    for (int k = 0; k < 3; k++) {                                                                  \
        r[k] = (int)floor((box[6 * (t) + k] - lo[k]) / h);                                         \
        r[3 + k] = (int)floor((box[6 * (t) + 3 + k] - lo[k]) / h);                                 \
        if (r[3 + k] >= dim[k])                                                                    \
            r[3 + k] = dim[k] - 1;                                                                 \
    }
    int r[6];
    for (int t = 0; t < nt; t++) {
        CELL_RANGE(t, r);
        for (int z = r[2]; z <= r[5]; z++)
            for (int y = r[1]; y <= r[4]; y++)
                for (int x = r[0]; x <= r[3]; x++)
                    start[((size_t)z * dim[1] + y) * dim[0] + x + 1]++;
    }
    for (size_t c = 0; c < ncell; c++)
        start[c + 1] += start[c];
    int *items = malloc((start[ncell] > 0 ? start[ncell] : 1) * sizeof *items);
    size_t *fill = malloc(ncell * sizeof *fill);
    if (!items || !fill) {
        free(items);
        free(fill);
        free(start);
        free(box);
        return -1;
    }
    memcpy(fill, start, ncell * sizeof *fill);
    for (int t = 0; t < nt; t++) {
        CELL_RANGE(t, r);
        for (int z = r[2]; z <= r[5]; z++)
            for (int y = r[1]; y <= r[4]; y++)
                for (int x = r[0]; x <= r[3]; x++)
                    items[fill[((size_t)z * dim[1] + y) * dim[0] + x]++] = t;
    }
#undef CELL_RANGE
    free(fill);
    ibuf pairs = {0};
    int oom = 0;
    for (size_t c = 0; c < ncell && !oom; c++) {
        int cx = (int)(c % dim[0]), cy = (int)(c / dim[0] % dim[1]);
        int cz = (int)(c / dim[0] / dim[1]);
        for (size_t i = start[c]; i < start[c + 1] && !oom; i++)
            for (size_t j = i + 1; j < start[c + 1]; j++) {
                int a = items[i], b = items[j];
                const double *ba = &box[6 * a], *bb = &box[6 * b];
                double m[3];
                int sep = 0;
                for (int k = 0; k < 3; k++) {
                    if (ba[k] > bb[3 + k] || bb[k] > ba[3 + k])
                        sep = 1;
                    m[k] = fmax(ba[k], bb[k]);
                }
                if (sep)
                    continue;
                /* Test a pair once: in the cell holding the low corner of
                 * the overlap of their boxes. */
                int mx = (int)floor((m[0] - lo[0]) / h), my = (int)floor((m[1] - lo[1]) / h),
                    mz = (int)floor((m[2] - lo[2]) / h);
                if (mx >= dim[0])
                    mx = dim[0] - 1;
                if (my >= dim[1])
                    my = dim[1] - 1;
                if (mz >= dim[2])
                    mz = dim[2] - 1;
                if (mx != cx || my != cy || mz != cz)
                    continue;
                if (tris_intersect(s, a, b)) {
                    int lo_t = a < b ? a : b, hi_t = a < b ? b : a;
                    if (ibuf_push(&pairs, lo_t) || ibuf_push(&pairs, hi_t)) {
                        oom = 1;
                        break;
                    }
                }
            }
    }
    free(items);
    free(start);
    free(box);
    if (oom) {
        free(pairs.a);
        return -1;
    }
    long np = (long)(pairs.n / 2);
    if (np > 1)
        qsort(pairs.a, (size_t)np, 2 * sizeof(int), pair_cmp);
    *out = pairs.a;
    return np;
}

int cf_surface_self_intersections(const cf_surface *s, int *pairs, int max_pairs)
{
    int *all;
    long n = find_pairs(s, &all);
    if (n < 0)
        return -1;
    for (long k = 0; k < n && k < max_pairs; k++)
        pairs[2 * k] = all[2 * k], pairs[2 * k + 1] = all[2 * k + 1];
    free(all);
    return n > 0x7fffffffL ? 0x7fffffff : (int)n;
}

/* ====================================================================== */
/* Vertex -> triangle adjacency (compressed rows)                          */
/* ====================================================================== */

typedef struct vt_adj {
    int *start; /* [n_verts+1] */
    int *tris;
} vt_adj;

static int vt_build(const cf_surface *s, vt_adj *a)
{
    a->start = calloc((size_t)s->n_verts + 1, sizeof *a->start);
    a->tris = malloc((size_t)(3 * s->n_tris > 0 ? 3 * s->n_tris : 1) * sizeof *a->tris);
    int *fill = malloc((size_t)(s->n_verts > 0 ? s->n_verts : 1) * sizeof *fill);
    if (!a->start || !a->tris || !fill) {
        free(a->start);
        free(a->tris);
        free(fill);
        return -1;
    }
    for (int i = 0; i < 3 * s->n_tris; i++)
        a->start[s->tri[i] + 1]++;
    for (int v = 0; v < s->n_verts; v++)
        a->start[v + 1] += a->start[v];
    memcpy(fill, a->start, (size_t)s->n_verts * sizeof *fill);
    for (int i = 0; i < 3 * s->n_tris; i++)
        a->tris[fill[s->tri[i]]++] = i / 3;
    free(fill);
    return 0;
}

static void vt_free(vt_adj *a)
{
    free(a->start);
    free(a->tris);
}

/* ====================================================================== */
/* Valence-3 repair                                                       */
/* ====================================================================== */

/* Drop triangles marked dead (alive[t] == 0), keeping order. */
static void compact_tris(cf_surface *s, const char *alive)
{
    int n = 0;
    for (int t = 0; t < s->n_tris; t++)
        if (alive[t]) {
            if (n != t)
                memcpy(&s->tri[3 * n], &s->tri[3 * t], 3 * sizeof(int));
            n++;
        }
    s->n_tris = n;
}

/* Remove valence-3 vertex v if its fan is a proper disc and the capping
 * triangle is new; the cap reuses one of v's triangle slots.  Returns 1 when
 * removed. */
static int remove_valence3(cf_surface *s, const vt_adj *adj, char *alive, int v)
{
    int ft[3], n = 0;
    for (int k = adj->start[v]; k < adj->start[v + 1]; k++)
        if (alive[adj->tris[k]]) {
            if (n == 3)
                return 0;
            ft[n++] = adj->tris[k];
        }
    if (n != 3)
        return 0;
    /* Rotate each triangle to (v, x_i, y_i): the fan's rim runs x_i -> y_i. */
    int x[3], y[3];
    for (int i = 0; i < 3; i++) {
        const int *T = &s->tri[3 * ft[i]];
        int k = T[0] == v ? 0 : T[1] == v ? 1 : 2;
        x[i] = T[(k + 1) % 3], y[i] = T[(k + 2) % 3];
    }
    /* The rim must be one 3-cycle n0 -> n1 -> n2 -> n0. */
    int n0 = x[0], n1 = y[0], n2 = -1;
    for (int i = 1; i < 3; i++)
        if (x[i] == n1)
            n2 = y[i];
    if (n2 < 0 || n2 == n0 || n2 == n1 || n0 == n1)
        return 0;
    int closes = 0;
    for (int i = 1; i < 3; i++)
        if (x[i] == n2 && y[i] == n0)
            closes = 1;
    if (!closes)
        return 0;
    /* Each neighbour keeps valence >= 3, and the cap must not already exist
     * (that would make the surface a doubled sheet there). */
    int nb[3] = {n0, n1, n2};
    for (int i = 0; i < 3; i++) {
        int val = 0;
        for (int k = adj->start[nb[i]]; k < adj->start[nb[i] + 1]; k++) {
            int t = adj->tris[k];
            if (!alive[t])
                continue;
            val++;
            const int *T = &s->tri[3 * t];
            int has = 0;
            for (int c = 0; c < 3; c++)
                has += T[c] == n0 || T[c] == n1 || T[c] == n2;
            if (has == 3)
                return 0;
        }
        if (val < 4)
            return 0;
    }
    alive[ft[1]] = alive[ft[2]] = 0;
    int *T = &s->tri[3 * ft[0]];
    T[0] = n0, T[1] = n1, T[2] = n2;
    return 1;
}

int cf_surface_repair_valence3(cf_surface *s)
{
    int removed = 0;
    for (int round = 0; round < 16; round++) {
        int *pairs;
        long np = find_pairs(s, &pairs);
        if (np <= 0)
            return np < 0 ? -1 : removed;
        vt_adj adj;
        char *alive = malloc((size_t)s->n_tris), *cand = calloc((size_t)s->n_verts, 1);
        if (!alive || !cand || vt_build(s, &adj)) {
            free(alive);
            free(cand);
            free(pairs);
            return -1;
        }
        memset(alive, 1, (size_t)s->n_tris);
        for (long k = 0; k < 2 * np; k++)
            for (int c = 0; c < 3; c++)
                cand[s->tri[3 * pairs[k] + c]] = 1;
        free(pairs);
        /* Ascending vertex order; a vertex next to one just removed waits
         * for the next round, when the adjacency is rebuilt. */
        int now = 0;
        for (int v = 0; v < s->n_verts; v++) {
            if (cand[v] != 1)
                continue;
            if (remove_valence3(s, &adj, alive, v)) {
                now++;
                for (int k = adj.start[v]; k < adj.start[v + 1]; k++)
                    for (int c = 0; c < 3; c++)
                        cand[s->tri[3 * adj.tris[k] + c]] = 2;
            }
        }
        vt_free(&adj);
        compact_tris(s, alive);
        free(alive);
        free(cand);
        if (cf_surface_remove_unused(s) < 0)
            return -1;
        removed += now;
        if (now == 0)
            break;
    }
    return removed;
}

/* ====================================================================== */
/* General repair (CGAL, through cohfrac-repair)                          */
/* ====================================================================== */

/* The program: $COHFRAC_REPAIR; else the one installed beside the code
 * that runs this (bin/../libexec/cohfrac, or from lib/ or lib/<triplet>/
 * of the library), found through dladdr so that a relocated install works;
 * else the build tree's; else the configured install path. */
static const char *repair_program(void)
{
    const char *env = getenv("COHFRAC_REPAIR");
    if (env && *env)
        return env;
    /* The file that holds this code: the library (dladdr), or the program
     * (/proc/self/exe: dladdr does not name the main program's file). */
    static char found[PATH_MAX], self[PATH_MAX];
    static const char here = 0;
    Dl_info info;
    const char *file = NULL;
    if (dladdr(&here, &info) && info.dli_fname && info.dli_fname[0] == '/')
        file = info.dli_fname;
    else {
        ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
        if (n > 0) {
            self[n] = '\0';
            file = self;
        }
    }
    if (file) {
        static const char *const up[] = {"/../libexec/cohfrac/cohfrac-repair",
                                         "/../../libexec/cohfrac/cohfrac-repair"};
        size_t dir = (size_t)(strrchr(file, '/') - file);
        for (size_t k = 0; k < sizeof up / sizeof up[0]; k++)
            if (snprintf(found, sizeof found, "%.*s%s", (int)dir, file, up[k]) <
                    (int)sizeof found &&
                access(found, X_OK) == 0)
                return found;
    }
    if (access(COHFRAC_REPAIR_BUILT, X_OK) == 0)
        return COHFRAC_REPAIR_BUILT;
    return COHFRAC_REPAIR_INSTALLED;
}

/* Runs cohfrac-repair with `args` (NULL-terminated, at most 4) on `s`,
 * replacing it by the result; the program's report line into report. */
static cf_status run_repair(cf_surface *s, const char *const *args, char *report, size_t len,
                            cf_error *err)
{
    const char *tmpdir = getenv("TMPDIR");
    char dir[512];
    snprintf(dir, sizeof dir, "%s/cohfrac-repair-XXXXXX",
             tmpdir && *tmpdir && strlen(tmpdir) < 400 ? tmpdir : "/tmp");
    if (!mkdtemp(dir))
        return cf_error_set(err, CF_ERR_OUTPUT, "cannot create a temporary directory %s (%s)",
                            dir, strerror(errno));
    char in[600], out[600], log[600];
    snprintf(in, sizeof in, "%s/in.surf", dir);
    snprintf(out, sizeof out, "%s/out.surf", dir);
    snprintf(log, sizeof log, "%s/log", dir);
    const char *prog = repair_program();
    char *argv[8] = {(char *)prog};
    int a = 1;
    for (; args[a - 1]; a++)
        argv[a] = (char *)args[a - 1];
    argv[a++] = in, argv[a++] = out, argv[a] = NULL;
    cf_status st = cf_surface_write_raw(s, in, err);
    pid_t pid;
    int rc = st == CF_OK ? cf_spawn(argv, log, &pid) : 0, status = 0;
    if (st == CF_OK && rc != 0)
        st = cf_error_set(err, CF_ERR_EXTERNAL, "cannot run '%s' (%s): build or install "
                          "cohfrac-repair, or point COHFRAC_REPAIR at it", prog, strerror(rc));
    if (st == CF_OK && cf_wait(pid, &status, NULL) < 0)
        st = cf_error_set(err, CF_ERR_EXTERNAL, "waiting for '%s': %s", prog, strerror(errno));
    char tail[700] = "";
    if (st == CF_OK && (!WIFEXITED(status) || WEXITSTATUS(status) != 0)) {
        cf_file_log_tail(log, tail, sizeof tail);
        char *e = strstr(tail, "error: ");
        st = cf_error_set(err, strstr(tail, "out of memory") ? CF_ERR_NOMEM : CF_ERR_MESH_PARSE,
                          "%s", WIFSIGNALED(status) ? "cohfrac-repair crashed"
                                : WEXITSTATUS(status) == 127 ? "cohfrac-repair not found"
                                : e ? e + 7 : tail);
    }
    cf_surface r = {0};
    if (st == CF_OK && (st = cf_surface_read_raw(out, &r, err)) == CF_OK) {
        cf_surface_free(s);
        *s = r;
        cf_file_log_tail(log, tail, sizeof tail);
        char *line = strstr(tail, "report ");
        snprintf(report, len, "%s", line ? line + 7 : "");
    }
    unlink(in), unlink(out), unlink(log), rmdir(dir);
    return st;
}

/* The value of key K in a "K=V K=V" report, 0 when absent. */
static double report_value(const char *report, const char *key)
{
    size_t n = strlen(key);
    for (const char *p = strstr(report, key); p; p = strstr(p + 1, key))
        if ((p == report || p[-1] == ' ') && p[n] == '=')
            return strtod(p + n + 1, NULL);
    return 0;
}

cf_status cf_surface_repair(cf_surface *s, char *report, size_t len, cf_error *err)
{
    static const char *const args[] = {"repair", NULL};
    char kv[700];
    cf_status st = run_repair(s, args, kv, sizeof kv, err);
    if (st != CF_OK)
        return st;
#define R(k) ((int)report_value(kv, k))
    static const char *const how[] = {
        [CFC_NONE_FOUND] = "",
        [CFC_FIXED_BY_UNION] = " (the overlapping parts joined into their union)",
        [CFC_FIXED_BY_AUTOREFINE] = " (cut along the intersections, the enclosed patches removed)",
        [CFC_WRAPPED] = "",
        [CFC_NOT_FIXED] = "",
    };
    int fixed = R("intersections_fixed");
    if (fixed < 0 || fixed > CFC_NOT_FIXED)
        fixed = CFC_NOT_FIXED;
    if (fixed == CFC_WRAPPED)
        snprintf(report, len,
                 "%d point(s) merged, %d degenerate or repeated triangle(s) removed; no exact "
                 "repair held (non-manifold edges, holes or intersections), so the surface was "
                 "wrapped (CGAL alpha wrapping, alpha %.4g, offset %.4g file units: the solid is "
                 "that much larger all round); %d -> %d triangles",
                 R("points_merged"), R("faces_removed"), report_value(kv, "wrap_alpha"),
                 report_value(kv, "wrap_offset"), R("faces_in"), R("faces_out"));
    else
        snprintf(report, len,
                 "%d point(s) merged, %d degenerate or repeated triangle(s) removed, %d "
                 "triangle(s) reoriented, %d hole(s) filled, %d intersecting triangle pair(s)%s; "
                 "%d -> %d triangles",
                 R("points_merged"), R("faces_removed"), R("faces_reoriented"),
                 R("holes_filled"), R("intersecting_pairs"), how[fixed], R("faces_in"),
                 R("faces_out"));
#undef R
    return CF_OK;
}

cf_status cf_surface_wrap(cf_surface *s, double alpha, double offset, cf_error *err)
{
    char a[32], o[32], ignored[8];
    snprintf(a, sizeof a, "%.17g", alpha);
    snprintf(o, sizeof o, "%.17g", offset);
    const char *const args[] = {"wrap", a, o, NULL};
    return run_repair(s, args, ignored, sizeof ignored, err);
}

cf_status cf_surface_remesh(cf_surface *s, double edge, cf_error *err)
{
    char e[32], ignored[8];
    snprintf(e, sizeof e, "%.17g", edge);
    const char *const args[] = {"remesh", e, NULL};
    return run_repair(s, args, ignored, sizeof ignored, err);
}

/* ====================================================================== */
/* Decimation (meshoptimizer)                                             */
/* ====================================================================== */

int cf_surface_decimate(cf_surface *s, int target_tris)
{
    size_t nv = (size_t)s->n_verts, nt = (size_t)s->n_tris;
    if (target_tris >= s->n_tris)
        return s->n_tris;
    /* meshoptimizer takes float positions: about the centroid, so float's
     * 7 digits resolve the shape; the kept vertices keep their doubles. */
    float *xyz = malloc(nv * 3 * sizeof *xyz);
    unsigned *in = malloc(nt * 3 * sizeof *in), *out = malloc(nt * 3 * sizeof *out);
    int result = -1;
    if (!xyz || !in || !out)
        goto done;
    double c[3] = {0, 0, 0};
    for (size_t i = 0; i < nv; i++)
        for (int k = 0; k < 3; k++)
            c[k] += s->v[3 * i + k] / (double)nv;
    for (size_t i = 0; i < nv; i++)
        for (int k = 0; k < 3; k++)
            xyz[3 * i + k] = (float)(s->v[3 * i + k] - c[k]);
    for (size_t i = 0; i < 3 * nt; i++)
        in[i] = (unsigned)s->tri[i];
    /* Error bound 1 (the whole extent): the triangle count decides. */
    size_t n = meshopt_simplify(out, in, 3 * nt, xyz, nv, 3 * sizeof(float),
                                3 * (size_t)target_tris, 1.0f, 0, NULL);
    for (size_t i = 0; i < n; i++)
        s->tri[i] = (int)out[i];
    s->n_tris = (int)(n / 3);
    if (cf_surface_remove_unused(s) >= 0 && cf_surface_repair_valence3(s) >= 0)
        result = s->n_tris;
done:
    free(xyz);
    free(in);
    free(out);
    return result;
}
