/* cohfrac — closed triangle surfaces: OBJ/OFF/STL input, OFF output,
 * enclosed volume, closedness, self-intersection search, the valence-3
 * repair of docs/scenes.md and quadric-error decimation. */
#include "file_text.h"
#include "cohfrac/surface.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

/* ====================================================================== */
/* Growable arrays and file input                                         */
/* ====================================================================== */

typedef struct dbuf {
    double *a;
    size_t n, cap;
} dbuf;
typedef struct ibuf {
    int *a;
    size_t n, cap;
} ibuf;

static int dbuf_push(dbuf *b, double v)
{
    if (b->n == b->cap) {
        size_t nc = b->cap ? 2 * b->cap : 1024;
        double *na = realloc(b->a, nc * sizeof *na);
        if (!na)
            return -1;
        b->a = na, b->cap = nc;
    }
    b->a[b->n++] = v;
    return 0;
}

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


/* Cut the next line out of *p (NUL-terminating it in place). */
static char *take_line(char **p, int *line)
{
    if (!**p)
        return NULL;
    char *s = *p, *e = s;
    while (*e && *e != '\n')
        e++;
    *p = *e ? e + 1 : e;
    *e = '\0';
    (*line)++;
    return s;
}

static char *skip_ws(char *s)
{
    while (isspace((unsigned char)*s))
        s++;
    return s;
}

/* Parse a finite double at *s; advances *s.  0 on success. */
static int parse_double(char **s, double *v)
{
    char *p = skip_ws(*s), *end;
    *v = strtod(p, &end);
    if (end == p || !isfinite(*v) || (*end && !isspace((unsigned char)*end)))
        return -1;
    *s = end;
    return 0;
}

static int parse_long(char **s, long *v)
{
    char *p = skip_ws(*s), *end;
    errno = 0;
    *v = strtol(p, &end, 10);
    if (end == p || errno)
        return -1;
    *s = end;
    return 0;
}

/* First token of s (for messages), at most 31 chars. */
static const char *token_of(const char *s, char out[32])
{
    while (isspace((unsigned char)*s))
        s++;
    int k = 0;
    while (s[k] && !isspace((unsigned char)s[k]) && k < 31)
        out[k] = s[k], k++;
    out[k] = '\0';
    return out;
}

/* ====================================================================== */
/* Loaders                                                                */
/* ====================================================================== */

/* Append triangle (a,b,c) unless two corners coincide (such a triangle has
 * no area and no orientation; dropping it is what a mesher would do). */
static int add_tri(ibuf *t, int a, int b, int c)
{
    if (a == b || b == c || a == c)
        return 0;
    return (ibuf_push(t, a) || ibuf_push(t, b) || ibuf_push(t, c)) ? -1 : 0;
}

static cf_status load_obj(const char *path, char *text, dbuf *v, ibuf *t, cf_error *err)
{
    ibuf tline = {0}; /* line number of each triangle, for index errors */
    char *p = text, *s, tok[32];
    int line = 0;
    cf_status st = CF_OK;
    int poly[64];
    while (st == CF_OK && (s = take_line(&p, &line))) {
        char *c = strchr(s, '#');
        if (c)
            *c = '\0';
        s = skip_ws(s);
        if (s[0] == 'v' && isspace((unsigned char)s[1])) {
            s++;
            for (int k = 0; k < 3 && st == CF_OK; k++) {
                double x;
                if (parse_double(&s, &x))
                    st = cf_error_set(err, CF_ERR_MESH_PARSE,
                                      "%s:%d: vertex needs 3 numbers 'v x y z', found '%s'", path,
                                      line, token_of(s, tok));
                else if (dbuf_push(v, x))
                    st = cf_error_set(err, CF_ERR_NOMEM, "%s: out of memory", path);
            }
        } else if (s[0] == 'f' && isspace((unsigned char)s[1])) {
            s++;
            int n = 0;
            for (;;) {
                s = skip_ws(s);
                if (!*s)
                    break;
                long id;
                if (parse_long(&s, &id) || id == 0) {
                    st = cf_error_set(err, CF_ERR_MESH_PARSE,
                                      "%s:%d: face corner '%s' is not a vertex number", path, line,
                                      token_of(s, tok));
                    break;
                }
                /* skip "/vt/vn" */
                while (*s && !isspace((unsigned char)*s))
                    s++;
                long nv = (long)(v->n / 3);
                long idx = id > 0 ? id - 1 : nv + id; /* negative: relative to the end */
                if (idx < 0) {
                    st = cf_error_set(err, CF_ERR_MESH_INDEX,
                                      "%s:%d: face refers to vertex %ld, but only %ld vertices are "
                                      "defined before it",
                                      path, line, id, nv);
                    break;
                }
                if (idx > 0x7fffffffL || n == 64) {
                    st = cf_error_set(err, CF_ERR_MESH_PARSE,
                                      "%s:%d: face too large (vertex %ld, corner %d)", path, line,
                                      id, n);
                    break;
                }
                poly[n++] = (int)idx;
            }
            if (st != CF_OK)
                break;
            if (n < 3) {
                st = cf_error_set(err, CF_ERR_MESH_PARSE,
                                  "%s:%d: face has %d corners; a face needs at least 3", path,
                                  line, n);
                break;
            }
            for (int k = 1; k + 1 < n && st == CF_OK; k++) {
                size_t before = t->n;
                if (add_tri(t, poly[0], poly[k], poly[k + 1]))
                    st = cf_error_set(err, CF_ERR_NOMEM, "%s: out of memory", path);
                else if (t->n > before && ibuf_push(&tline, line))
                    st = cf_error_set(err, CF_ERR_NOMEM, "%s: out of memory", path);
            }
        }
        /* vt, vn, g, o, s, usemtl, mtllib, l, p ...: not geometry we need */
    }
    int nv = (int)(v->n / 3);
    for (size_t i = 0; st == CF_OK && i < t->n; i++)
        if (t->a[i] >= nv)
            st = cf_error_set(err, CF_ERR_MESH_INDEX,
                              "%s:%d: face refers to vertex %d, but the file has %d vertices",
                              path, tline.a[i / 3], t->a[i] + 1, nv);
    free(tline.a);
    return st;
}

/* Next non-comment, non-blank line of an OFF file. */
static char *off_line(char **p, int *line)
{
    char *s;
    while ((s = take_line(p, line))) {
        char *c = strchr(s, '#');
        if (c)
            *c = '\0';
        s = skip_ws(s);
        if (*s)
            return s;
    }
    return NULL;
}

static cf_status load_off(const char *path, char *text, dbuf *v, ibuf *t, cf_error *err)
{
    char *p = text, tok[32];
    int line = 0;
    char *s = off_line(&p, &line);
    size_t hl;
    if (!s || (hl = strcspn(s, " \t\r")) < 3 || strncmp(s + hl - 3, "OFF", 3))
        return cf_error_set(err, CF_ERR_MESH_PARSE, "%s:%d: expected the header 'OFF'", path, line);
    s = skip_ws(s + hl);
    if (!*s && !(s = off_line(&p, &line)))
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s:%d: missing '<#vertices> <#faces> <#edges>'",
                            path, line);
    long nv, nf;
    if (parse_long(&s, &nv) || parse_long(&s, &nf) || nv < 0 || nf < 0 || nv > 0x7fffffffL)
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s:%d: expected '<#vertices> <#faces> <#edges>'", path, line);
    for (long i = 0; i < nv; i++) {
        if (!(s = off_line(&p, &line)))
            return cf_error_set(err, CF_ERR_MESH_PARSE,
                                "%s:%d: file ends after %ld of %ld vertices", path, line, i, nv);
        for (int k = 0; k < 3; k++) {
            double x;
            if (parse_double(&s, &x))
                return cf_error_set(err, CF_ERR_MESH_PARSE,
                                    "%s:%d: vertex needs 3 numbers, found '%s'", path, line,
                                    token_of(s, tok));
            if (dbuf_push(v, x))
                return cf_error_set(err, CF_ERR_NOMEM, "%s: out of memory", path);
        }
    }
    for (long i = 0; i < nf; i++) {
        if (!(s = off_line(&p, &line)))
            return cf_error_set(err, CF_ERR_MESH_PARSE, "%s:%d: file ends after %ld of %ld faces",
                                path, line, i, nf);
        long n;
        if (parse_long(&s, &n) || n < 3 || n > 64)
            return cf_error_set(err, CF_ERR_MESH_PARSE,
                                "%s:%d: face must start with its corner count (3..64), found '%s'",
                                path, line, token_of(s, tok));
        int poly[64];
        for (long k = 0; k < n; k++) {
            long id;
            if (parse_long(&s, &id))
                return cf_error_set(err, CF_ERR_MESH_PARSE,
                                    "%s:%d: face has fewer than the %ld corners it announces", path,
                                    line, n);
            if (id < 0 || id >= nv)
                return cf_error_set(err, CF_ERR_MESH_INDEX,
                                    "%s:%d: face refers to vertex %ld, but vertices are numbered "
                                    "0..%ld",
                                    path, line, id, nv - 1);
            poly[k] = (int)id;
        }
        for (long k = 1; k + 1 < n; k++)
            if (add_tri(t, poly[0], poly[k], poly[k + 1]))
                return cf_error_set(err, CF_ERR_NOMEM, "%s: out of memory", path);
    }
    return CF_OK;
}

/* ---- STL: triangle soup, welded by exact coordinates ---- */

typedef struct weld {
    int *slot; /* vertex index or -1 */
    size_t mask;
    dbuf *v;
} weld;

static uint64_t hash3(const double x[3])
{
    uint64_t h = 1469598103934665603ULL;
    for (int k = 0; k < 3; k++) {
        double d = x[k] + 0.0; /* -0.0 and 0.0 are the same point */
        uint64_t u;
        memcpy(&u, &d, sizeof u);
        h ^= u;
        h *= 1099511628211ULL;
        h ^= h >> 29;
    }
    return h;
}

static int weld_init(weld *w, size_t expect, dbuf *v)
{
    size_t cap = 1024;
    while (cap < 2 * expect)
        cap *= 2;
    w->slot = malloc(cap * sizeof *w->slot);
    if (!w->slot)
        return -1;
    memset(w->slot, 0xff, cap * sizeof *w->slot);
    w->mask = cap - 1;
    w->v = v;
    return 0;
}

/* Double the table when half full (keeps probe chains short and
 * guarantees a free slot). */
static int weld_grow(weld *w)
{
    size_t cap = 2 * (w->mask + 1);
    int *slot = malloc(cap * sizeof *slot);
    if (!slot)
        return -1;
    memset(slot, 0xff, cap * sizeof *slot);
    int n = (int)(w->v->n / 3);
    for (int k = 0; k < n; k++) {
        size_t i = (size_t)hash3(&w->v->a[3 * (size_t)k]) & (cap - 1);
        while (slot[i] >= 0)
            i = (i + 1) & (cap - 1);
        slot[i] = k;
    }
    free(w->slot);
    w->slot = slot;
    w->mask = cap - 1;
    return 0;
}

/* Index of point x, adding it if new; -1 on memory error. */
static int weld_get(weld *w, const double x[3])
{
    if (2 * (w->v->n / 3 + 1) > w->mask + 1 && weld_grow(w))
        return -1;
    size_t i = (size_t)hash3(x) & w->mask;
    for (;;) {
        int k = w->slot[i];
        if (k < 0)
            break;
        const double *y = &w->v->a[3 * (size_t)k];
        if (y[0] == x[0] && y[1] == x[1] && y[2] == x[2])
            return k;
        i = (i + 1) & w->mask;
    }
    int k = (int)(w->v->n / 3);
    if (dbuf_push(w->v, x[0]) || dbuf_push(w->v, x[1]) || dbuf_push(w->v, x[2]))
        return -1;
    w->slot[i] = k;
    return k;
}

static uint32_t le32(const unsigned char *b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

static cf_status load_stl(const char *path, unsigned char *buf, size_t len, dbuf *v, ibuf *t,
                          cf_error *err)
{
    weld w;
    if (len >= 84 && 84 + 50 * (uint64_t)le32(buf + 80) == len) {
        uint32_t n = le32(buf + 80);
        if (n > 0x7fffffffU / 3 || weld_init(&w, 3 * (size_t)n, v))
            return cf_error_set(err, CF_ERR_NOMEM, "%s: out of memory", path);
        for (uint32_t i = 0; i < n; i++) {
            const unsigned char *r = buf + 84 + 50 * (size_t)i + 12; /* skip the normal */
            int id[3];
            for (int c = 0; c < 3; c++) {
                double x[3];
                for (int k = 0; k < 3; k++) {
                    uint32_t u = le32(r + 12 * c + 4 * k);
                    float f;
                    memcpy(&f, &u, sizeof f);
                    x[k] = f;
                }
                if (!isfinite(x[0]) || !isfinite(x[1]) || !isfinite(x[2])) {
                    free(w.slot);
                    return cf_error_set(err, CF_ERR_MESH_PARSE,
                                        "%s: triangle %u has a non-finite coordinate", path, i);
                }
                if ((id[c] = weld_get(&w, x)) < 0) {
                    free(w.slot);
                    return cf_error_set(err, CF_ERR_NOMEM, "%s: out of memory", path);
                }
            }
            if (add_tri(t, id[0], id[1], id[2])) {
                free(w.slot);
                return cf_error_set(err, CF_ERR_NOMEM, "%s: out of memory", path);
            }
        }
        free(w.slot);
        return CF_OK;
    }
    char *s = skip_ws((char *)buf), tok[32];
    if (strncmp(s, "solid", 5))
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s: neither ASCII STL (starts with 'solid') nor binary STL (84 + 50 "
                            "bytes per triangle; this file has %zu bytes)",
                            path, len);
    /* a facet takes at least ~80 bytes: size the table from that */
    if (weld_init(&w, len / 80 + 16, v))
        return cf_error_set(err, CF_ERR_NOMEM, "%s: out of memory", path);
    cf_status st = CF_OK;
    char *p = (char *)buf;
    int line = 0, corner = 0, id[3] = {0, 0, 0};
    while (st == CF_OK && (s = take_line(&p, &line))) {
        s = skip_ws(s);
        if (!strncmp(s, "vertex", 6) && isspace((unsigned char)s[6])) {
            double x[3];
            s += 6;
            for (int k = 0; k < 3 && st == CF_OK; k++)
                if (parse_double(&s, &x[k]))
                    st = cf_error_set(err, CF_ERR_MESH_PARSE,
                                      "%s:%d: 'vertex' needs 3 numbers, found '%s'", path, line,
                                      token_of(s, tok));
            if (st != CF_OK)
                break;
            if (corner == 3) {
                st = cf_error_set(err, CF_ERR_MESH_PARSE,
                                  "%s:%d: more than 3 vertices in one facet loop", path, line);
                break;
            }
            if ((id[corner++] = weld_get(&w, x)) < 0)
                st = cf_error_set(err, CF_ERR_NOMEM, "%s: out of memory", path);
        } else if (!strncmp(s, "endloop", 7)) {
            if (corner != 3)
                st = cf_error_set(err, CF_ERR_MESH_PARSE,
                                  "%s:%d: facet loop has %d vertices; STL facets are triangles",
                                  path, line, corner);
            else if (add_tri(t, id[0], id[1], id[2]))
                st = cf_error_set(err, CF_ERR_NOMEM, "%s: out of memory", path);
            corner = 0;
        }
        /* solid, facet normal, outer loop, endfacet, endsolid: structure only */
    }
    if (st == CF_OK && corner != 0)
        st = cf_error_set(err, CF_ERR_MESH_PARSE, "%s:%d: file ends inside a facet (truncated?)",
                          path, line);
    free(w.slot);
    return st;
}

static int ext_is(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    if (n < e)
        return 0;
    for (size_t i = 0; i < e; i++)
        if (tolower((unsigned char)path[n - e + i]) != ext[i])
            return 0;
    return 1;
}

/* Any other format assimp reads (PLY, glTF, 3DS, FBX, COLLADA, ...):
 * every mesh of the file, node transforms applied, triangulated, identical
 * vertices joined; coordinates as the file has them. */
static cf_status load_with_assimp(const char *path, cf_surface *s, cf_error *err)
{
    const struct aiScene *sc =
        aiImportFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                               aiProcess_PreTransformVertices);
    if (!sc)
        return cf_error_set(err, CF_ERR_MESH_PARSE, "%s: %s (read with assimp)", path,
                            aiGetErrorString());
    size_t nv = 0, nt = 0;
    for (unsigned i = 0; i < sc->mNumMeshes; i++) {
        nv += sc->mMeshes[i]->mNumVertices;
        for (unsigned f = 0; f < sc->mMeshes[i]->mNumFaces; f++)
            nt += sc->mMeshes[i]->mFaces[f].mNumIndices == 3;
    }
    cf_status st = CF_OK;
    if (nt == 0 || nv > INT_MAX / 3 || nt > INT_MAX / 3)
        st = cf_error_set(err, CF_ERR_MESH_PARSE,
                          "%s: %zu triangles in %u meshes (read with assimp): a surface needs "
                          "triangles, and at most %d of them",
                          path, nt, sc->mNumMeshes, INT_MAX / 3);
    if (st == CF_OK) {
        s->v = malloc(nv * 3 * sizeof(double));
        s->tri = malloc(nt * 3 * sizeof(int));
        if (!s->v || !s->tri)
            st = cf_error_set(err, CF_ERR_NOMEM, "%s: out of memory for %zu triangles", path, nt);
    }
    for (unsigned i = 0, base = 0; st == CF_OK && i < sc->mNumMeshes; i++) {
        const struct aiMesh *m = sc->mMeshes[i];
        for (unsigned v = 0; v < m->mNumVertices; v++) {
            s->v[3 * (size_t)s->n_verts + 0] = m->mVertices[v].x;
            s->v[3 * (size_t)s->n_verts + 1] = m->mVertices[v].y;
            s->v[3 * (size_t)s->n_verts + 2] = m->mVertices[v].z;
            s->n_verts++;
        }
        for (unsigned f = 0; f < m->mNumFaces; f++) {
            const struct aiFace *face = &m->mFaces[f];
            if (face->mNumIndices != 3)
                continue; /* points and lines */
            for (int k = 0; k < 3; k++)
                s->tri[3 * (size_t)s->n_tris + k] = (int)(base + face->mIndices[k]);
            s->n_tris++;
        }
        base += m->mNumVertices;
    }
    aiReleaseImport(sc);
    if (st != CF_OK)
        cf_surface_free(s);
    return st;
}

int cf_surface_format_known(const char *path)
{
    if (ext_is(path, ".obj") || ext_is(path, ".off") || ext_is(path, ".stl"))
        return 1;
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
    int kind = ext_is(path, ".obj") ? 0 : ext_is(path, ".off") ? 1 : ext_is(path, ".stl") ? 2 : -1;
    if (kind < 0) {
        const char *dot = strrchr(path, '.');
        if (dot && !strchr(dot, '/') && aiIsExtensionSupported(dot)) {
            if (access(path, R_OK) != 0)
                return cf_error_set(err, CF_ERR_FILE_OPEN, "%s: cannot read it: %s", path,
                                    strerror(errno));
            return load_with_assimp(path, s, err);
        }
        return cf_error_set(err, CF_ERR_FILE_OPEN,
                            "%s: unknown surface format; use .obj, .off or .stl, or a format "
                            "assimp reads (.ply, .gltf, .glb, .3ds, .fbx, .dae, ...)",
                            path);
    }
    size_t len;
    unsigned char *buf = (unsigned char *)cf_file_read(path, &len);
    if (!buf)
        return cf_error_set(err, errno == ENOMEM ? CF_ERR_NOMEM : CF_ERR_FILE_OPEN,
                            "%s: cannot read (%s)", path, strerror(errno));
    dbuf v = {0};
    ibuf t = {0};
    cf_status st = kind == 0   ? load_obj(path, (char *)buf, &v, &t, err)
                   : kind == 1 ? load_off(path, (char *)buf, &v, &t, err)
                               : load_stl(path, buf, len, &v, &t, err);
    free(buf);
    if (st == CF_OK && t.n == 0)
        st = cf_error_set(err, CF_ERR_MESH_PARSE, "%s: the surface has no triangles", path);
    if (st != CF_OK) {
        free(v.a);
        free(t.a);
        return st;
    }
    s->n_verts = (int)(v.n / 3);
    s->n_tris = (int)(t.n / 3);
    s->v = v.a;
    s->tri = t.a;
    return CF_OK;
}

cf_status cf_surface_write_off(const cf_surface *s, const char *path, cf_error *err)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return cf_error_set(err, CF_ERR_OUTPUT, "%s: cannot write (%s)", path, strerror(errno));
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
/* Quadric-error decimation (Garland & Heckbert 1997)                     */
/* ====================================================================== */

/* Symmetric 4x4 quadric, upper triangle: a2 ab ac ad b2 bc bd c2 cd d2. */
typedef struct quad {
    double q[10];
} quad;

static double quad_eval(const quad *Q, const double *p)
{
    const double *q = Q->q;
    double x = p[0], y = p[1], z = p[2];
    return q[0] * x * x + 2 * q[1] * x * y + 2 * q[2] * x * z + 2 * q[3] * x + q[4] * y * y +
           2 * q[5] * y * z + 2 * q[6] * y + q[7] * z * z + 2 * q[8] * z + q[9];
}

/* Minimiser of the quadric if well conditioned (0), else -1. */
static int quad_optimum(const quad *Q, double *p)
{
    const double *q = Q->q;
    double A[3][3] = {{q[0], q[1], q[2]}, {q[1], q[4], q[5]}, {q[2], q[5], q[7]}};
    double b[3] = {-q[3], -q[6], -q[8]};
    double c00 = A[1][1] * A[2][2] - A[1][2] * A[2][1], c01 = A[1][2] * A[2][0] - A[1][0] * A[2][2],
           c02 = A[1][0] * A[2][1] - A[1][1] * A[2][0];
    double det = A[0][0] * c00 + A[0][1] * c01 + A[0][2] * c02;
    double tr = A[0][0] + A[1][1] + A[2][2];
    /* relative test: a flat or ridge-only neighbourhood is singular */
    if (!(fabs(det) > 1e-9 * tr * tr * tr))
        return -1;
    double inv[3][3] = {
        {c00, A[0][2] * A[2][1] - A[0][1] * A[2][2], A[0][1] * A[1][2] - A[0][2] * A[1][1]},
        {c01, A[0][0] * A[2][2] - A[0][2] * A[2][0], A[0][2] * A[1][0] - A[0][0] * A[1][2]},
        {c02, A[0][1] * A[2][0] - A[0][0] * A[2][1], A[0][0] * A[1][1] - A[0][1] * A[1][0]}};
    for (int i = 0; i < 3; i++)
        p[i] = (inv[i][0] * b[0] + inv[i][1] * b[1] + inv[i][2] * b[2]) / det;
    return 0;
}

typedef struct dec_entry {
    double cost;
    int a, b;          /* a < b */
    unsigned sa, sb;   /* vertex stamps when pushed (stale when changed) */
} dec_entry;

typedef struct dec_heap {
    dec_entry *e;
    size_t n, cap;
} dec_heap;

/* Strict total order, so the collapse sequence is reproducible. */
static int dec_less(const dec_entry *x, const dec_entry *y)
{
    if (x->cost != y->cost)
        return x->cost < y->cost;
    if (x->a != y->a)
        return x->a < y->a;
    return x->b < y->b;
}

static int heap_push(dec_heap *h, dec_entry e)
{
    if (h->n == h->cap) {
        size_t nc = h->cap ? 2 * h->cap : 4096;
        dec_entry *ne = realloc(h->e, nc * sizeof *ne);
        if (!ne)
            return -1;
        h->e = ne, h->cap = nc;
    }
    size_t i = h->n++;
    while (i > 0) {
        size_t p = (i - 1) / 2;
        if (!dec_less(&e, &h->e[p]))
            break;
        h->e[i] = h->e[p];
        i = p;
    }
    h->e[i] = e;
    return 0;
}

static dec_entry heap_pop(dec_heap *h)
{
    dec_entry top = h->e[0], last = h->e[--h->n];
    size_t i = 0;
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= h->n)
            break;
        if (c + 1 < h->n && dec_less(&h->e[c + 1], &h->e[c]))
            c++;
        if (!dec_less(&h->e[c], &last))
            break;
        h->e[i] = h->e[c];
        i = c;
    }
    if (h->n > 0)
        h->e[i] = last;
    return top;
}

typedef struct decim {
    cf_surface *s;
    quad *Q;
    unsigned *stamp;
    char *vdead, *tdead;
    int **vt; /* per-vertex live triangle lists */
    int *vtn, *vtcap;
    int *mark, mark_id;
    dec_heap heap;
} decim;

/* Target point of collapsing edge (a,b) and its cost. */
static double collapse_point(const decim *d, int a, int b, double *p)
{
    quad Q;
    for (int k = 0; k < 10; k++)
        Q.q[k] = d->Q[a].q[k] + d->Q[b].q[k];
    const double *xa = &d->s->v[3 * a], *xb = &d->s->v[3 * b];
    double len2 = 0, mid[3];
    for (int k = 0; k < 3; k++) {
        mid[k] = 0.5 * (xa[k] + xb[k]);
        len2 += (xb[k] - xa[k]) * (xb[k] - xa[k]);
    }
    if (quad_optimum(&Q, p) == 0) {
        double dd = 0;
        for (int k = 0; k < 3; k++)
            dd += (p[k] - mid[k]) * (p[k] - mid[k]);
        if (dd <= len2) /* stay near the edge: far optima fold the surface */
            return fmax(quad_eval(&Q, p), 0.0);
    }
    const double *cand[3] = {xa, xb, mid};
    double best = INFINITY;
    for (int c = 0; c < 3; c++) {
        double e = quad_eval(&Q, cand[c]);
        if (e < best) {
            best = e;
            memcpy(p, cand[c], 3 * sizeof(double));
        }
    }
    return fmax(best, 0.0);
}

static int push_edge(decim *d, int a, int b)
{
    if (a > b) {
        int t = a;
        a = b, b = t;
    }
    double p[3];
    dec_entry e = {collapse_point(d, a, b, p), a, b, d->stamp[a], d->stamp[b]};
    return heap_push(&d->heap, e);
}

/* Triangle quality 4*sqrt(3)*area / sum of squared edges: 1 equilateral. */
static double tri_quality(const double *a, const double *b, const double *c, double *n)
{
    double u[3], v[3], w[3];
    sub3(b, a, u);
    sub3(c, a, v);
    sub3(c, b, w);
    cross3(u, v, n);
    double area2 = sqrt(dot3(n, n)), l = dot3(u, u) + dot3(v, v) + dot3(w, w);
    return l > 0 ? 2.0 * sqrt(3.0) * area2 / l : 0.0;
}

/* Would moving a and b to p keep every surviving triangle unflipped and
 * not much worse shaped? */
static int collapse_ok(decim *d, int a, int b, const double *p)
{
    const cf_surface *s = d->s;
    for (int side = 0; side < 2; side++) {
        int v = side ? b : a, o = side ? a : b;
        for (int k = 0; k < d->vtn[v]; k++) {
            const int *T = &s->tri[3 * d->vt[v][k]];
            if (T[0] == o || T[1] == o || T[2] == o)
                continue; /* removed by the collapse */
            const double *P0[3], *P1[3];
            for (int c = 0; c < 3; c++) {
                P0[c] = &s->v[3 * T[c]];
                P1[c] = T[c] == v ? p : P0[c];
            }
            double n0[3], n1[3];
            double q0 = tri_quality(P0[0], P0[1], P0[2], n0);
            double q1 = tri_quality(P1[0], P1[1], P1[2], n1);
            double l0 = sqrt(dot3(n0, n0)), l1 = sqrt(dot3(n1, n1));
            if (!(l1 > 0) || dot3(n0, n1) < 0.5 * l0 * l1)
                return 0; /* flips or turns by more than 60 degrees */
            if (q1 < 0.1 && q1 < q0)
                return 0; /* needle: tetgen would pay for it inside */
        }
    }
    return 1;
}

static int vt_add(decim *d, int v, int t)
{
    if (d->vtn[v] == d->vtcap[v]) {
        int nc = d->vtcap[v] ? 2 * d->vtcap[v] : 8;
        int *na = realloc(d->vt[v], (size_t)nc * sizeof *na);
        if (!na)
            return -1;
        d->vt[v] = na, d->vtcap[v] = nc;
    }
    d->vt[v][d->vtn[v]++] = t;
    return 0;
}

/* Try to collapse b into a at p.  1 done, 0 refused, -1 out of memory. */
static int try_collapse(decim *d, int a, int b)
{
    cf_surface *s = d->s;
    double p[3];
    collapse_point(d, a, b, p);
    /* The two triangles on edge ab give the opposite corners c and e. */
    int opp[2], no = 0;
    for (int k = 0; k < d->vtn[a]; k++) {
        const int *T = &s->tri[3 * d->vt[a][k]];
        if (T[0] == b || T[1] == b || T[2] == b) {
            if (no == 2)
                return 0; /* non-manifold edge */
            opp[no++] = T[0] != a && T[0] != b ? T[0] : T[1] != a && T[1] != b ? T[1] : T[2];
        }
    }
    if (no != 2 || opp[0] == opp[1])
        return 0; /* boundary edge */
    /* Link condition: a and b share exactly the neighbours c and e.  Mark
     * a's neighbours with id M, then count b's neighbours that carry M
     * (re-marking them M+1 so each is counted once). */
    int M = d->mark_id += 2;
    for (int k = 0; k < d->vtn[a]; k++)
        for (int c = 0; c < 3; c++)
            d->mark[s->tri[3 * d->vt[a][k] + c]] = M - 1;
    int common = 0;
    for (int k = 0; k < d->vtn[b]; k++)
        for (int c = 0; c < 3; c++) {
            int w = s->tri[3 * d->vt[b][k] + c];
            if (w != a && w != b && d->mark[w] == M - 1) {
                d->mark[w] = M;
                common++;
            }
        }
    if (common != 2)
        return 0;
    /* Keep every vertex at valence >= 4 (valence = live triangles here): a
     * valence-3 vertex makes tetgen use the tet of it and its neighbours,
     * a sliver where the surface is nearly flat. */
    if (d->vtn[opp[0]] <= 4 || d->vtn[opp[1]] <= 4 || d->vtn[a] + d->vtn[b] - 4 < 4)
        return 0;
    if (!collapse_ok(d, a, b, p))
        return 0;
    /* Apply. */
    memcpy(&s->v[3 * a], p, sizeof p);
    for (int k = 0; k < 10; k++)
        d->Q[a].q[k] += d->Q[b].q[k];
    for (int k = 0; k < d->vtn[b]; k++) {
        int t = d->vt[b][k];
        int *T = &s->tri[3 * t];
        if (T[0] == a || T[1] == a || T[2] == a) {
            d->tdead[t] = 1;
            continue;
        }
        for (int c = 0; c < 3; c++)
            if (T[c] == b)
                T[c] = a;
        if (vt_add(d, a, t))
            return -1;
    }
    int n = 0;
    for (int k = 0; k < d->vtn[a]; k++)
        if (!d->tdead[d->vt[a][k]])
            d->vt[a][n++] = d->vt[a][k];
    d->vtn[a] = n;
    for (int w = 0; w < 2; w++) {
        int o = opp[w], m = 0;
        for (int k = 0; k < d->vtn[o]; k++)
            if (!d->tdead[d->vt[o][k]])
                d->vt[o][m++] = d->vt[o][k];
        d->vtn[o] = m;
    }
    free(d->vt[b]);
    d->vt[b] = NULL, d->vtn[b] = d->vtcap[b] = 0;
    d->vdead[b] = 1;
    d->stamp[a]++, d->stamp[b]++;
    /* New costs for the edges around a (each neighbour once). */
    d->mark_id++;
    for (int k = 0; k < d->vtn[a]; k++)
        for (int c = 0; c < 3; c++) {
            int w = s->tri[3 * d->vt[a][k] + c];
            if (w != a && d->mark[w] != d->mark_id) {
                d->mark[w] = d->mark_id;
                if (push_edge(d, a, w))
                    return -1;
            }
        }
    return 1;
}

int cf_surface_decimate(cf_surface *s, int target_tris)
{
    int nv = s->n_verts, nt = s->n_tris;
    if (target_tris >= nt)
        return nt;
    decim d = {0};
    d.s = s;
    d.Q = calloc((size_t)nv, sizeof *d.Q);
    d.stamp = calloc((size_t)nv, sizeof *d.stamp);
    d.vdead = calloc((size_t)nv, 1);
    d.tdead = calloc((size_t)nt, 1);
    d.vt = calloc((size_t)nv, sizeof *d.vt);
    d.vtn = calloc((size_t)nv, sizeof *d.vtn);
    d.vtcap = calloc((size_t)nv, sizeof *d.vtcap);
    d.mark = calloc((size_t)nv, sizeof *d.mark);
    int result = -1;
    if (!d.Q || !d.stamp || !d.vdead || !d.tdead || !d.vt || !d.vtn || !d.vtcap || !d.mark)
        goto done;
    /* Area-weighted plane quadrics of the original triangles. */
    for (int t = 0; t < nt; t++) {
        const int *T = &s->tri[3 * t];
        const double *a = &s->v[3 * T[0]], *b = &s->v[3 * T[1]], *c = &s->v[3 * T[2]];
        double u[3], v[3], n[3];
        sub3(b, a, u);
        sub3(c, a, v);
        cross3(u, v, n);
        double l = sqrt(dot3(n, n));
        if (l > 0) {
            double w = 0.5 * l; /* area */
            for (int k = 0; k < 3; k++)
                n[k] /= l;
            double pl[4] = {n[0], n[1], n[2], -dot3(n, a)};
            quad K;
            int m = 0;
            for (int i = 0; i < 4; i++)
                for (int j = i; j < 4; j++)
                    K.q[m++] = w * pl[i] * pl[j];
            for (int c2 = 0; c2 < 3; c2++)
                for (int k = 0; k < 10; k++)
                    d.Q[T[c2]].q[k] += K.q[k];
        }
        for (int c2 = 0; c2 < 3; c2++)
            if (vt_add(&d, T[c2], t))
                goto done;
    }
    for (int t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            int a = s->tri[3 * t + k], b = s->tri[3 * t + (k + 1) % 3];
            if (a < b && push_edge(&d, a, b)) /* each edge once (its a<b side) */
                goto done;
        }
    int live = nt;
    while (live > target_tris && d.heap.n > 0) {
        dec_entry e = heap_pop(&d.heap);
        if (d.vdead[e.a] || d.vdead[e.b] || e.sa != d.stamp[e.a] || e.sb != d.stamp[e.b])
            continue; /* stale */
        int r = try_collapse(&d, e.a, e.b);
        if (r < 0)
            goto done;
        if (r > 0)
            live -= 2;
    }
    for (int t = 0; t < nt; t++)
        d.tdead[t] = !d.tdead[t]; /* now "alive" flags */
    compact_tris(s, d.tdead);
    if (cf_surface_remove_unused(s) >= 0)
        result = s->n_tris;
done:
    for (int v = 0; v < nv && d.vt; v++)
        free(d.vt[v]);
    free(d.Q);
    free(d.stamp);
    free(d.vdead);
    free(d.tdead);
    free(d.vt);
    free(d.vtn);
    free(d.vtcap);
    free(d.mark);
    free(d.heap.e);
    return result;
}

