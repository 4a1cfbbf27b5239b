/* cohfrac — Gmsh MSH reader: 4.1 ASCII, 4.1 binary and 2.2 ASCII.
 *
 * The whole file is read into memory and parsed section by section:
 * $MeshFormat (must come first), $PhysicalNames, $Entities (4.1: maps an
 * entity to its physical tags), $Nodes, $Elements; every other section
 * ($Periodic, $NodeData, ...) is skipped up to its $End line.
 *
 * Node tags may be any positive numbers in any order: node i of the mesh is
 * the i-th node of the file.  4-node tets (element type 4) become the tets;
 * every element of a physical group (any type) adds its nodes to the group.
 *
 * Error positions are "file:line" in ASCII files and "file: byte N" in
 * binary ones (where a line number means nothing).
 */
#include "file_text.h"
#include "cohfrac/mesh.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define REEXPORT                                                                               \
    "re-export it as MSH 4.1: `gmsh -3 -format msh41 FILE.geo -o FILE.msh`, or in the Gmsh "  \
    "GUI File > Export > Gmsh MSH, Version 4.1"

/* ---- parser state ------------------------------------------------------- */

typedef struct entity {
    int dim, tag;
    int n_phys, first; /* physical tags: phys[first .. first + n_phys) */
} entity;

typedef struct group_acc { /* a physical group while it is being filled */
    int dim, tag;
    int n, cap;
    int *nodes; /* with repeats until the end */
} group_acc;

typedef struct phys_name {
    int dim, tag;
    char name[64];
} phys_name;

typedef struct node_key {
    long long tag;
    int index;
} node_key;

typedef struct msh {
    const char *path;
    const char *buf;
    size_t len, pos, at; /* at: start of the item being read (for messages) */
    int line;            /* 1-based line of buf[pos] (ASCII files) */
    int v22, binary, sz; /* sz: bytes of a size_t field in binary files */
    cf_error *err;

    int have_nodes, have_elements;
    int n_nodes;
    double *x;
    node_key *keys;  /* sorted by tag, for node lookup */
    long long first; /* when tags are first, first+1, ... in file order, else -1 */

    int n_ent, cap_ent;
    entity *ent;
    int n_phys, cap_phys;
    int *phys;

    int n_tets, cap_tets;
    int *tets;
    long long n_other_3d; /* volume elements that are not 4-node tets */

    int n_groups, cap_groups;
    group_acc *groups;

    int n_names, cap_names;
    phys_name *names;
} msh;

static cf_status fail(msh *f, cf_status code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Set `err` to "<file>:<line>: <what>" (or "<file>: byte <N>: <what>"). */
static cf_status fail(msh *f, cf_status code, const char *fmt, ...)
{
    char what[800];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    if (f->binary)
        return cf_error_set(f->err, code, "%s: byte %zu: %s", f->path, f->at, what);
    return cf_error_set(f->err, code, "%s:%d: %s", f->path, f->line, what);
}

static cf_status no_memory(msh *f)
{
    return cf_error_set(f->err, CF_ERR_NOMEM, "%s: out of memory while reading the mesh", f->path);
}

/* Make room for `need` elements of `size` bytes in *p (capacity *cap). */
static int grow(void **p, int *cap, int need, size_t size)
{
    if (need <= *cap)
        return 1;
    int c = *cap ? *cap : 16;
    while (c < need)
        c = c > INT_MAX / 2 ? INT_MAX : 2 * c;
    void *q = realloc(*p, (size_t)c * size);
    if (!q)
        return 0;
    *p = q, *cap = c;
    return 1;
}

/* ---- reading numbers, ASCII and binary ------------------------------------ */

static void skip_ws(msh *f)
{
    while (f->pos < f->len && isspace((unsigned char)f->buf[f->pos])) {
        if (f->buf[f->pos] == '\n')
            f->line++;
        f->pos++;
    }
}

/* Next whitespace-delimited token, cut to n-1 characters.  Returns its full
 * length (0 at the end of the file; >= n when it was cut). */
static size_t token(msh *f, char *tok, size_t n)
{
    skip_ws(f);
    f->at = f->pos;
    size_t k = 0;
    while (f->pos < f->len && !isspace((unsigned char)f->buf[f->pos])) {
        if (k + 1 < n)
            tok[k] = f->buf[f->pos];
        k++, f->pos++;
    }
    tok[k < n ? k : n - 1] = '\0';
    return k;
}

/* Rest of the current line (a section header) up to and including '\n':
 * binary data starts right after it. */
static void end_line(msh *f)
{
    while (f->pos < f->len && f->buf[f->pos] != '\n')
        f->pos++;
    if (f->pos < f->len)
        f->pos++, f->line++;
}

static cf_status ended(msh *f, const char *what)
{
    return fail(f, CF_ERR_MESH_PARSE, "file ends where %s was expected (truncated file?)", what);
}

/* An ASCII integer in [lo, hi]. */
static cf_status ascii_ll(msh *f, long long lo, long long hi, long long *v, const char *what)
{
    *v = 0;
    char tok[48];
    size_t n = token(f, tok, sizeof tok);
    if (n == 0)
        return ended(f, what);
    char *end;
    errno = 0;
    long long x = strtoll(tok, &end, 10);
    if (n >= sizeof tok || end == tok || *end || errno)
        return fail(f, CF_ERR_MESH_PARSE, "expected %s (an integer), found '%s'", what, tok);
    if (x < lo || x > hi)
        return fail(f, CF_ERR_MESH_PARSE, "%s is %lld; expected %lld..%lld", what, x, lo, hi);
    *v = x;
    return CF_OK;
}

static cf_status bytes(msh *f, void *dst, size_t n, const char *what)
{
    f->at = f->pos;
    if (f->len - f->pos < n)
        return ended(f, what);
    memcpy(dst, f->buf + f->pos, n);
    f->pos += n;
    return CF_OK;
}

/* A size_t field (binary: f->sz bytes), as a count or tag in [0, LLONG_MAX]. */
static cf_status get_size(msh *f, long long *v, const char *what)
{
    *v = 0;
    if (!f->binary)
        return ascii_ll(f, 0, LLONG_MAX, v, what);
    cf_status st;
    if (f->sz == 4) {
        uint32_t u = 0;
        if ((st = bytes(f, &u, 4, what)) != CF_OK)
            return st;
        *v = (long long)u;
        return CF_OK;
    }
    uint64_t u = 0;
    if ((st = bytes(f, &u, 8, what)) != CF_OK)
        return st;
    if (u > (uint64_t)LLONG_MAX)
        return fail(f, CF_ERR_MESH_PARSE, "%s is %llu, too large", what, (unsigned long long)u);
    *v = (long long)u;
    return CF_OK;
}

static cf_status get_int(msh *f, int *v, const char *what)
{
    if (!f->binary) {
        long long x;
        cf_status st = ascii_ll(f, INT_MIN, INT_MAX, &x, what);
        *v = (int)x;
        return st;
    }
    int32_t i = 0;
    cf_status st = bytes(f, &i, 4, what);
    *v = i;
    return st;
}

static cf_status get_double(msh *f, double *v, const char *what)
{
    if (f->binary) {
        cf_status st = bytes(f, v, 8, what);
        if (st == CF_OK && !isfinite(*v))
            return fail(f, CF_ERR_MESH_PARSE, "%s is not a finite number", what);
        return st;
    }
    char tok[64];
    size_t n = token(f, tok, sizeof tok);
    if (n == 0)
        return ended(f, what);
    char *end;
    *v = strtod(tok, &end);
    if (n >= sizeof tok || end == tok || *end || !isfinite(*v))
        return fail(f, CF_ERR_MESH_PARSE, "expected %s (a number), found '%s'", what, tok);
    return CF_OK;
}

/* A count of items that each take at least `min_bytes` bytes in the file:
 * a count the rest of the file cannot hold is a truncated or corrupt file
 * (checked before anything is allocated for it). */
static cf_status get_count(msh *f, int *n, size_t min_bytes, const char *what)
{
    *n = 0;
    long long v;
    cf_status st = get_size(f, &v, what);
    if (st != CF_OK)
        return st;
    if (v > INT_MAX || (unsigned long long)v > (f->len - f->pos) / min_bytes)
        return fail(f, CF_ERR_MESH_PARSE,
                    "%s is %lld, more than the rest of the file can hold (truncated or "
                    "corrupt file?)",
                    what, v);
    *n = (int)v;
    return CF_OK;
}

/* Bytes that one ASCII number or one binary field takes at least. */
static size_t min_field(const msh *f, size_t binary_bytes) { return f->binary ? binary_bytes : 2; }

/* ---- element types ---------------------------------------------------------- */

/* Nodes per element and dimension of a Gmsh element type; 0 when unknown. */
static int type_nodes(int type, int *dim)
{
    static const signed char nodes[32] = {0,  2,  3,  4,  4,  8,  6,  5,  3,  6,  9,
                                          10, 27, 18, 14, 1,  8,  20, 15, 13, 9,  10,
                                          12, 15, 15, 21, 4,  5,  6,  20, 35, 56};
    static const signed char dims[32] = {0, 1, 2, 2, 3, 3, 3, 3, 1, 2, 2, 3, 3, 3, 3, 0,
                                         2, 3, 3, 3, 2, 2, 2, 2, 2, 2, 1, 1, 1, 3, 3, 3};
    if (type == 92 || type == 93) { /* 64- and 125-node hexahedra */
        *dim = 3;
        return type == 92 ? 64 : 125;
    }
    if (type < 1 || type > 31)
        return 0;
    *dim = dims[type];
    return nodes[type];
}

/* ---- lookups -------------------------------------------------------------- */

static int cmp_key(const void *a, const void *b)
{
    long long x = ((const node_key *)a)->tag, y = ((const node_key *)b)->tag;
    return (x > y) - (x < y);
}

/* Node index of a tag, or -1. */
static int node_index(const msh *f, long long tag)
{
    if (f->first >= 0)
        return tag >= f->first && tag - f->first < f->n_nodes ? (int)(tag - f->first) : -1;
    node_key k = {tag, 0};
    const node_key *hit = bsearch(&k, f->keys, (size_t)f->n_nodes, sizeof k, cmp_key);
    return hit ? hit->index : -1;
}

/* Sort the tags (`tags[i]` is the tag of node i) for lookup; duplicates are errors. */
static cf_status index_nodes(msh *f, const long long *tags)
{
    f->first = f->n_nodes > 0 ? tags[0] : 0;
    for (int i = 1; i < f->n_nodes && f->first >= 0; i++)
        if (tags[i] != tags[0] + i)
            f->first = -1;
    if (f->first >= 0)
        return CF_OK;
    f->keys = malloc((size_t)f->n_nodes * sizeof *f->keys);
    if (!f->keys)
        return no_memory(f);
    for (int i = 0; i < f->n_nodes; i++)
        f->keys[i].tag = tags[i], f->keys[i].index = i;
    qsort(f->keys, (size_t)f->n_nodes, sizeof *f->keys, cmp_key);
    for (int i = 1; i < f->n_nodes; i++)
        if (f->keys[i].tag == f->keys[i - 1].tag)
            return cf_error_set(f->err, CF_ERR_MESH_PARSE,
                                "%s: node tag %lld appears twice in $Nodes (corrupt file?)",
                                f->path, f->keys[i].tag);
    return CF_OK;
}

static const entity *find_entity(const msh *f, int dim, int tag)
{
    for (int i = 0; i < f->n_ent; i++)
        if (f->ent[i].dim == dim && f->ent[i].tag == tag)
            return &f->ent[i];
    return NULL;
}

static group_acc *find_group(msh *f, int dim, int tag, int create)
{
    for (int i = 0; i < f->n_groups; i++)
        if (f->groups[i].dim == dim && f->groups[i].tag == tag)
            return &f->groups[i];
    if (!create || !grow((void **)&f->groups, &f->cap_groups, f->n_groups + 1, sizeof *f->groups))
        return NULL;
    group_acc *g = &f->groups[f->n_groups++];
    memset(g, 0, sizeof *g);
    g->dim = dim, g->tag = tag;
    return g;
}

/* ---- one element ---------------------------------------------------------- */

/* Map the element's node tags to indices, keep it if it is a tet, add its
 * nodes to its physical groups (`phys[n_phys]`, all of dimension `dim`). */
static cf_status add_element(msh *f, long long etag, int type, const long long *ntag, int nn,
                             int dim, const int *phys, int n_phys)
{
    int idx[125];
    for (int k = 0; k < nn; k++) {
        idx[k] = node_index(f, ntag[k]);
        if (idx[k] < 0)
            return fail(f, CF_ERR_MESH_INDEX,
                        "element %lld refers to node %lld, which is not in $Nodes: the file is "
                        "inconsistent; re-export it from Gmsh",
                        etag, ntag[k]);
    }
    int tdim = 0;
    type_nodes(type, &tdim);
    if (tdim == 3 && type != 4)
        f->n_other_3d++;
    if (type == 4) {
        if (f->n_tets == INT_MAX / 4 ||
            !grow((void **)&f->tets, &f->cap_tets, f->n_tets + 1, 4 * sizeof(int)))
            return no_memory(f);
        memcpy(&f->tets[4 * f->n_tets++], idx, 4 * sizeof(int));
    }
    for (int p = 0; p < n_phys; p++) {
        group_acc *g = find_group(f, dim, phys[p], 1);
        if (!g || g->n > INT_MAX - nn || !grow((void **)&g->nodes, &g->cap, g->n + nn, sizeof(int)))
            return no_memory(f);
        memcpy(&g->nodes[g->n], idx, (size_t)nn * sizeof(int));
        g->n += nn;
    }
    return CF_OK;
}

/* ---- sections --------------------------------------------------------------- */

static cf_status parse_format(msh *f)
{
    char tok[32];
    if (!token(f, tok, sizeof tok))
        return ended(f, "the version number");
    if (!strcmp(tok, "4") || !strcmp(tok, "4.0"))
        return fail(f, CF_ERR_MESH_FORMAT, "MSH version 4.0 is not supported; " REEXPORT);
    int v41 = !strcmp(tok, "4.1");
    f->v22 = !strcmp(tok, "2.2");
    if (!v41 && !f->v22)
        return fail(f, CF_ERR_MESH_FORMAT,
                    "MSH version '%s' is not supported (only 4.1 and 2.2 ASCII); " REEXPORT, tok);
    long long type, size;
    cf_status st = ascii_ll(f, 0, 1, &type, "the file type (0 ASCII, 1 binary)");
    if (st == CF_OK)
        st = ascii_ll(f, 0, 64, &size, "the data size");
    if (st != CF_OK)
        return st;
    if (type == 1 && f->v22)
        return fail(f, CF_ERR_MESH_FORMAT, "binary MSH 2.2 is not supported; " REEXPORT);
    if (type == 1) {
        if (size != 4 && size != 8)
            return fail(f, CF_ERR_MESH_FORMAT,
                        "binary file with data size %lld (sizeof(size_t) must be 4 or 8); " REEXPORT,
                        size);
        end_line(f);
        int32_t one = 0;
        if ((st = bytes(f, &one, 4, "the binary endianness marker")) != CF_OK)
            return st;
        f->binary = 1, f->sz = (int)size;
        if (one != 1)
            return fail(f, CF_ERR_MESH_FORMAT,
                        "binary file written on a machine of the other byte order; re-export it "
                        "as ASCII (`-format msh41` without `-bin`) or on this machine");
    }
    return CF_OK;
}

/* $PhysicalNames: ASCII even in binary files. */
static cf_status parse_names(msh *f)
{
    long long n; /* each name takes at least 6 bytes: 0 1 "" */
    cf_status st = ascii_ll(f, 0, (long long)((f->len - f->pos) / 6), &n,
                            "the number of physical names");
    for (long long i = 0; i < n && st == CF_OK; i++) {
        long long dim, tag;
        if ((st = ascii_ll(f, 0, 3, &dim, "a physical group dimension")) != CF_OK ||
            (st = ascii_ll(f, INT_MIN, INT_MAX, &tag, "a physical group tag")) != CF_OK)
            break;
        while (f->pos < f->len && (f->buf[f->pos] == ' ' || f->buf[f->pos] == '\t'))
            f->pos++;
        f->at = f->pos;
        if (f->pos >= f->len || f->buf[f->pos] != '"') {
            st = fail(f, CF_ERR_MESH_PARSE, "expected a quoted physical name after '%lld %lld'",
                      dim, tag);
            break;
        }
        size_t s = ++f->pos;
        while (f->pos < f->len && f->buf[f->pos] != '"' && f->buf[f->pos] != '\n')
            f->pos++;
        if (f->pos >= f->len || f->buf[f->pos] != '"') {
            st = fail(f, CF_ERR_MESH_PARSE, "physical name without its closing quote");
            break;
        }
        if (!grow((void **)&f->names, &f->cap_names, f->n_names + 1, sizeof *f->names)) {
            st = no_memory(f);
            break;
        }
        phys_name *pn = &f->names[f->n_names++];
        size_t l = f->pos - s < sizeof pn->name - 1 ? f->pos - s : sizeof pn->name - 1;
        memcpy(pn->name, f->buf + s, l);
        pn->name[l] = '\0';
        pn->dim = (int)dim, pn->tag = (int)tag;
        f->pos++;
    }
    return st;
}

static cf_status parse_entities(msh *f)
{
    static const char *what[4] = {"the number of points", "the number of curves",
                                  "the number of surfaces", "the number of volumes"};
    int count[4];
    cf_status st = CF_OK;
    for (int d = 0; d < 4 && st == CF_OK; d++)
        st = get_count(f, &count[d], min_field(f, 4 + 24 + (size_t)f->sz), what[d]);
    for (int d = 0; d < 4 && st == CF_OK; d++) {
        for (int i = 0; i < count[d] && st == CF_OK; i++) {
            int tag, np;
            double box[6];
            if ((st = get_int(f, &tag, "an entity tag")) != CF_OK)
                break;
            /* points: x y z; curves, surfaces, volumes: a bounding box */
            for (int k = 0; k < (d == 0 ? 3 : 6) && st == CF_OK; k++)
                st = get_double(f, &box[k], d == 0 ? "a point coordinate" : "a bounding box value");
            if (st != CF_OK ||
                (st = get_count(f, &np, min_field(f, 4), "the number of physical tags")) != CF_OK)
                break;
            if (!grow((void **)&f->ent, &f->cap_ent, f->n_ent + 1, sizeof *f->ent) ||
                !grow((void **)&f->phys, &f->cap_phys, f->n_phys + np, sizeof *f->phys))
                return no_memory(f);
            entity *e = &f->ent[f->n_ent++];
            e->dim = d, e->tag = tag, e->n_phys = np, e->first = f->n_phys;
            for (int k = 0; k < np && st == CF_OK; k++)
                st = get_int(f, &f->phys[f->n_phys++], "a physical tag");
            if (d > 0 && st == CF_OK) { /* bounding entities: not needed */
                int nb, b;
                st = get_count(f, &nb, min_field(f, 4), "the number of bounding entities");
                for (int k = 0; k < nb && st == CF_OK; k++)
                    st = get_int(f, &b, "a bounding entity tag");
            }
        }
    }
    return st;
}

static cf_status parse_nodes(msh *f)
{
    int n_blocks = 0, n;
    long long tmp;
    cf_status st;
    if (f->v22) {
        st = get_count(f, &n, 8, "the number of nodes");
    } else {
        st = get_count(f, &n_blocks, min_field(f, 12 + (size_t)f->sz), "the number of node blocks");
        if (st == CF_OK)
            st = get_count(f, &n, min_field(f, (size_t)f->sz + 24), "the number of nodes");
        if (st == CF_OK && (st = get_size(f, &tmp, "the minimum node tag")) == CF_OK)
            st = get_size(f, &tmp, "the maximum node tag");
    }
    if (st != CF_OK)
        return st;
    f->x = malloc(((size_t)n * 3 + 1) * sizeof(double));
    long long *tags = malloc(((size_t)n + 1) * sizeof *tags);
    if (!f->x || !tags) {
        free(tags);
        return no_memory(f);
    }
    int done = 0;
    if (f->v22) {
        for (; done < n && st == CF_OK; done++) {
            st = get_size(f, &tags[done], "a node tag");
            for (int k = 0; k < 3 && st == CF_OK; k++)
                st = get_double(f, &f->x[3 * done + k], "a node coordinate");
        }
    }
    for (int b = 0; b < n_blocks && st == CF_OK; b++) {
        int dim, etag, param, nb;
        if ((st = get_int(f, &dim, "an entity dimension")) != CF_OK ||
            (st = get_int(f, &etag, "an entity tag")) != CF_OK ||
            (st = get_int(f, &param, "the parametric flag")) != CF_OK ||
            (st = get_count(f, &nb, min_field(f, (size_t)f->sz + 24), "the block's node count")) !=
                CF_OK)
            break;
        if (nb > n - done) {
            st = fail(f, CF_ERR_MESH_PARSE, "node blocks hold more than the %d nodes announced", n);
            break;
        }
        int extra = param ? (dim < 0 ? 0 : dim > 3 ? 3 : dim) : 0; /* u, v, w */
        for (int i = 0; i < nb && st == CF_OK; i++)
            st = get_size(f, &tags[done + i], "a node tag");
        for (int i = 0; i < nb && st == CF_OK; i++) {
            for (int k = 0; k < 3 && st == CF_OK; k++)
                st = get_double(f, &f->x[3 * (done + i) + k], "a node coordinate");
            double uvw;
            for (int k = 0; k < extra && st == CF_OK; k++)
                st = get_double(f, &uvw, "a parametric coordinate");
        }
        done += nb;
    }
    if (st == CF_OK && done != n)
        st = fail(f, CF_ERR_MESH_PARSE, "the node blocks hold %d nodes, the header announced %d",
                  done, n);
    f->n_nodes = n;
    if (st == CF_OK)
        st = index_nodes(f, tags);
    free(tags);
    return st;
}

static cf_status parse_elements(msh *f)
{
    if (!f->have_nodes)
        return fail(f, CF_ERR_MESH_PARSE, "$Elements comes before $Nodes; expected $Nodes first");
    int n_blocks = 0, n;
    long long tmp, tags[125];
    cf_status st = get_count(f, &n_blocks, min_field(f, 12 + (size_t)f->sz), "the number of element blocks");
    if (st == CF_OK)
        st = get_count(f, &n, min_field(f, 2 * (size_t)f->sz), "the number of elements");
    if (st == CF_OK && (st = get_size(f, &tmp, "the minimum element tag")) == CF_OK)
        st = get_size(f, &tmp, "the maximum element tag");
    for (int b = 0; b < n_blocks && st == CF_OK; b++) {
        int dim, etag, type, nb, tdim;
        if ((st = get_int(f, &dim, "an entity dimension")) != CF_OK ||
            (st = get_int(f, &etag, "an entity tag")) != CF_OK ||
            (st = get_int(f, &type, "an element type")) != CF_OK)
            break;
        int nn = type_nodes(type, &tdim);
        if (nn == 0)
            return fail(f, CF_ERR_MESH_FORMAT,
                        "element type %d is not supported; export linear elements (`gmsh -3 "
                        "-order 1 -format msh41 FILE.geo`)",
                        type);
        if ((st = get_count(f, &nb, min_field(f, (size_t)(nn + 1) * (size_t)f->sz),
                            "the block's element count")) != CF_OK)
            break;
        const entity *e = find_entity(f, dim, etag);
        for (int i = 0; i < nb && st == CF_OK; i++) {
            long long el;
            st = get_size(f, &el, "an element tag");
            for (int k = 0; k < nn && st == CF_OK; k++)
                st = get_size(f, &tags[k], "an element node tag");
            if (st == CF_OK)
                st = add_element(f, el, type, tags, nn, dim, e ? &f->phys[e->first] : NULL,
                                 e ? e->n_phys : 0);
        }
    }
    return st;
}

static cf_status parse_elements_22(msh *f)
{
    if (!f->have_nodes)
        return fail(f, CF_ERR_MESH_PARSE, "$Elements comes before $Nodes; expected $Nodes first");
    int n;
    long long tags[125];
    cf_status st = get_count(f, &n, 8, "the number of elements");
    for (int i = 0; i < n && st == CF_OK; i++) {
        long long el, type, nt, v;
        int phys = 0, dim = 0;
        if ((st = get_size(f, &el, "an element tag")) != CF_OK ||
            (st = ascii_ll(f, 1, INT_MAX, &type, "an element type")) != CF_OK ||
            (st = ascii_ll(f, 0, 1000, &nt, "the number of element tags")) != CF_OK)
            break;
        for (int k = 0; k < nt && st == CF_OK; k++) {
            st = ascii_ll(f, LLONG_MIN, LLONG_MAX, &v, "an element tag");
            if (k == 0 && st == CF_OK)
                phys = v > 0 && v <= INT_MAX ? (int)v : 0; /* 0: no physical group */
        }
        int nn = st == CF_OK ? type_nodes((int)type, &dim) : 0;
        if (st == CF_OK && nn == 0)
            return fail(f, CF_ERR_MESH_FORMAT,
                        "element type %lld is not supported; export linear elements (`gmsh -3 "
                        "-order 1 -format msh41 FILE.geo`)",
                        type);
        for (int k = 0; k < nn && st == CF_OK; k++)
            st = get_size(f, &tags[k], "an element node tag");
        if (st == CF_OK)
            st = add_element(f, el, (int)type, tags, nn, dim, &phys, phys ? 1 : 0);
    }
    return st;
}

/* Find the line "$End<name>" and stop in front of it. */
static cf_status skip_section(msh *f, const char *name)
{
    char end[96];
    snprintf(end, sizeof end, "$End%s", name);
    size_t el = strlen(end);
    for (size_t p = f->pos; p + el <= f->len; p++) {
        if (f->buf[p] == '\n')
            f->line++;
        if ((p == 0 || f->buf[p - 1] == '\n') && !memcmp(f->buf + p, end, el)) {
            f->pos = p;
            return CF_OK;
        }
    }
    f->pos = f->len;
    return fail(f, CF_ERR_MESH_PARSE, "section $%s has no %s line (truncated file?)", name, end);
}

static cf_status expect_end(msh *f, const char *name)
{
    char tok[96], want[96];
    snprintf(want, sizeof want, "$End%s", name);
    size_t n = token(f, tok, sizeof tok);
    if (n == 0)
        return ended(f, want);
    if (n >= sizeof tok || strcmp(tok, want))
        return fail(f, CF_ERR_MESH_PARSE, "expected %s, found '%.40s' (wrong count or corrupt file?)",
                    want, tok);
    return CF_OK;
}

static cf_status parse(msh *f)
{
    char tok[80];
    size_t n = token(f, tok, sizeof tok);
    if (n == 0)
        return fail(f, CF_ERR_MESH_PARSE, "empty file; expected a Gmsh mesh starting with $MeshFormat");
    if (!strcmp(tok, "$NOD") || !strcmp(tok, "$NOE"))
        return fail(f, CF_ERR_MESH_FORMAT, "MSH version 1 is not supported; " REEXPORT);
    if (strcmp(tok, "$MeshFormat"))
        return fail(f, CF_ERR_MESH_PARSE,
                    "expected $MeshFormat at the start: not a Gmsh .msh file");
    cf_status st = parse_format(f);
    if (st == CF_OK)
        st = expect_end(f, "MeshFormat");
    while (st == CF_OK && (n = token(f, tok, sizeof tok)) > 0) {
        if (tok[0] != '$' || n >= sizeof tok)
            return fail(f, CF_ERR_MESH_PARSE, "expected a section like $Nodes, found '%.40s'", tok);
        const char *sect = tok + 1;
        end_line(f);
        if (!strcmp(sect, "PhysicalNames")) {
            st = parse_names(f);
        } else if (!strcmp(sect, "Entities") && !f->v22) {
            st = parse_entities(f);
        } else if (!strcmp(sect, "Nodes") || !strcmp(sect, "Elements")) {
            int *have = sect[0] == 'N' ? &f->have_nodes : &f->have_elements;
            if (*have)
                return fail(f, CF_ERR_MESH_PARSE, "a second $%s section; expected one", sect);
            *have = 1;
            if (sect[0] == 'N')
                st = parse_nodes(f);
            else
                st = f->v22 ? parse_elements_22(f) : parse_elements(f);
        } else {
            st = skip_section(f, sect);
        }
        if (st == CF_OK)
            st = expect_end(f, sect);
    }
    if (st != CF_OK)
        return st;
    if (!f->have_nodes || !f->have_elements)
        return cf_error_set(f->err, CF_ERR_MESH_PARSE,
                            "%s: no $%s section (truncated file?); expected $Nodes and $Elements",
                            f->path, f->have_nodes ? "Elements" : "Nodes");
    if (f->n_tets == 0 && f->n_other_3d > 0)
        return cf_error_set(f->err, CF_ERR_MESH_FORMAT,
                            "%s: the mesh has %lld volume elements but no 4-node tetrahedra "
                            "(second order or hexahedra?): mesh with linear tets, `gmsh -3 "
                            "-order 1 -format msh41 FILE.geo -o FILE.msh`",
                            f->path, f->n_other_3d);
    if (f->n_tets == 0)
        return cf_error_set(f->err, CF_ERR_MESH_FORMAT,
                            "%s: the mesh has no tetrahedra (a surface mesh?): mesh the volume "
                            "with `gmsh -3 -format msh41 FILE.geo -o FILE.msh` (Physical Volume "
                            "groups, if any, must include every volume)",
                            f->path);
    return CF_OK;
}

/* ---- result -------------------------------------------------------------- */

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

static int cmp_group(const void *a, const void *b)
{
    const group_acc *x = a, *y = b;
    if (x->dim != y->dim)
        return x->dim - y->dim;
    return (x->tag > y->tag) - (x->tag < y->tag);
}

/* The groups of the file, named, sorted by (dim, tag), nodes sorted and unique. */
static cf_status make_groups(msh *f, cf_mesh *m)
{
    for (int i = 0; i < f->n_names; i++) /* named groups without elements too */
        if (!find_group(f, f->names[i].dim, f->names[i].tag, 1))
            return no_memory(f);
    if (f->n_groups == 0)
        return CF_OK;
    qsort(f->groups, (size_t)f->n_groups, sizeof *f->groups, cmp_group);
    m->groups = calloc((size_t)f->n_groups, sizeof *m->groups);
    if (!m->groups)
        return no_memory(f);
    m->n_groups = f->n_groups;
    for (int i = 0; i < f->n_groups; i++) {
        group_acc *g = &f->groups[i];
        cf_mesh_group *o = &m->groups[i];
        o->dim = g->dim;
        snprintf(o->name, sizeof o->name, "%d:%d", g->dim, g->tag);
        for (int k = 0; k < f->n_names; k++)
            if (f->names[k].dim == g->dim && f->names[k].tag == g->tag)
                snprintf(o->name, sizeof o->name, "%s", f->names[k].name);
        if (g->n > 0)
            qsort(g->nodes, (size_t)g->n, sizeof(int), cmp_int);
        int u = 0;
        for (int k = 0; k < g->n; k++)
            if (u == 0 || g->nodes[k] != g->nodes[u - 1])
                g->nodes[u++] = g->nodes[k];
        o->n_nodes = u;
        o->nodes = g->nodes; /* handed over (may be NULL when empty) */
        g->nodes = NULL;
    }
    return CF_OK;
}

static void msh_free(msh *f)
{
    free(f->x);
    free(f->keys);
    free(f->ent);
    free(f->phys);
    free(f->tets);
    for (int i = 0; i < f->n_groups; i++)
        free(f->groups[i].nodes);
    free(f->groups);
    free(f->names);
}


cf_status cf_mesh_load_gmsh(const char *path, cf_mesh *m, cf_error *err)
{
    memset(m, 0, sizeof *m);
    size_t len = 0;
    char *buf = cf_file_read(path, &len);
    if (!buf)
        return cf_error_set(err, cf_status_of_errno(errno, CF_ERR_FILE_OPEN),
                            "%s: cannot read (%s); give the path of a Gmsh .msh file", path,
                            strerror(errno));
    msh f = {.path = path, .buf = buf, .len = len, .line = 1, .err = err, .first = -1};
    cf_status st = parse(&f);
    if (st == CF_OK) {
        m->n_nodes = f.n_nodes, m->x = f.x, f.x = NULL;
        m->n_tets = f.n_tets, m->tets = f.tets, f.tets = NULL;
        st = make_groups(&f, m);
    }
    msh_free(&f);
    free(buf);
    if (st == CF_OK) {
        cf_mesh_orient_positive(m);
        st = cf_mesh_check(m, path, err);
    }
    if (st != CF_OK)
        cf_mesh_free(m);
    return st;
}

cf_status cf_mesh_load(const char *path, cf_mesh *m, cf_error *err)
{
    size_t n = strlen(path);
    if (n >= 4 && path[n - 4] == '.' && tolower((unsigned char)path[n - 3]) == 'm' &&
        tolower((unsigned char)path[n - 2]) == 's' && tolower((unsigned char)path[n - 1]) == 'h')
        return cf_mesh_load_gmsh(path, m, err);
    return cf_mesh_load_tetgen(path, m, err);
}
