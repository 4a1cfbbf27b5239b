/* cohfrac — TetGen .node/.ele reader and writer, Tet4 volume checks. */
#include "file_text.h"
#include "cohfrac/mesh.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- small text helpers ------------------------------------------------ */


/* Iterates over the meaningful lines of a TetGen file: comments (from '#')
 * and blank lines are skipped; `line` is the 1-based line number. */
typedef struct line_iter {
    char *p;
    int line;
} line_iter;

/* Next non-empty line, '#' comment cut off and NUL-terminated in place. */
static char *next_line(line_iter *it)
{
    while (*it->p) {
        char *s = it->p, *e = s;
        while (*e && *e != '\n')
            e++;
        it->p = *e ? e + 1 : e;
        *e = '\0';
        it->line++;
        char *hash = strchr(s, '#');
        if (hash)
            *hash = '\0';
        for (char *q = s; *q; q++)
            if (!isspace((unsigned char)*q))
                return s;
    }
    return NULL;
}

/* Read up to `max` numbers from a line.  Returns how many were read, or -1
 * when a token is not a number (the token is copied into `bad`). */
static int read_numbers(const char *s, double *out, int max, char bad[32])
{
    int n = 0;
    while (n < max) {
        while (isspace((unsigned char)*s) || *s == ',')
            s++;
        if (!*s)
            break;
        char *end;
        errno = 0;
        double v = strtod(s, &end);
        if (end == s || !(isspace((unsigned char)*end) || *end == ',' || *end == '\0') ||
            !isfinite(v)) {
            int k = 0;
            while (s[k] && !isspace((unsigned char)s[k]) && k < 31)
                bad[k] = s[k], k++;
            bad[k] = '\0';
            return -1;
        }
        out[n++] = v;
        s = end;
    }
    return n;
}

static int is_int(double v) { return v == floor(v) && fabs(v) < (double)INT_MAX; }

/* Header entry k as an int (absent: def); *ok cleared when it is not a
 * whole number in int range (no float-to-int overflow). */
static int header_int(const double *h, int nh, int k, int def, int *ok)
{
    if (k >= nh)
        return def;
    if (!is_int(h[k])) {
        *ok = 0;
        return def;
    }
    return (int)h[k];
}

/* Lines left in the text after the iterator: an upper bound on the entries
 * it can hold, checked against a header's count before allocating. */
static long lines_left(const line_iter *it)
{
    long n = 1;
    for (const char *q = it->p; *q; q++)
        n += *q == '\n';
    return n;
}

/* `base` without a trailing ".node" / ".ele". Caller frees. */
static char *strip_ext(const char *base)
{
    size_t n = strlen(base);
    char *b = malloc(n + 1);
    if (!b)
        return NULL;
    memcpy(b, base, n + 1);
    if (n > 5 && !strcmp(b + n - 5, ".node"))
        b[n - 5] = '\0';
    else if (n > 4 && !strcmp(b + n - 4, ".ele"))
        b[n - 4] = '\0';
    return b;
}

/* ---- .node / .ele parsing ------------------------------------------------ */

static cf_status parse_node(const char *path, char *text, cf_mesh *m, int *first, cf_error *err)
{
    line_iter it = {text, 0};
    char bad[32];
    double h[4];
    char *s = next_line(&it);
    if (!s)
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s: empty file; expected the header '<#points> 3 <#attributes> "
                            "<#markers>'",
                            path);
    int nh = read_numbers(s, h, 4, bad);
    if (nh < 1 || !is_int(h[0]) || h[0] < 0)
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s:%d: bad header; expected '<#points> 3 <#attributes> <#markers>'",
                            path, it.line);
    int ok = 1, n = (int)h[0], dim = header_int(h, nh, 1, 3, &ok);
    int nattr = header_int(h, nh, 2, 0, &ok), nmark = header_int(h, nh, 3, 0, &ok);
    if (!ok)
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s:%d: bad header: its counts must be whole numbers; expected "
                            "'<#points> 3 <#attributes> <#markers>'",
                            path, it.line);
    if (dim != 3)
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s:%d: dimension is %d; only 3-D meshes are supported", path,
                            it.line, dim);
    if (n == 0)
        return cf_error_set(err, CF_ERR_MESH_PARSE, "%s:%d: the mesh has no nodes", path, it.line);
    if (nattr < 0 || nmark < 0 || nmark > 1)
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s:%d: bad attribute/marker counts (%d, %d) in header", path,
                            it.line, nattr, nmark);
    if (n > lines_left(&it))
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s:%d: the header announces %d nodes but the file has only %ld more "
                            "lines (truncated file, or not a TetGen .node file?)",
                            path, it.line, n, lines_left(&it));
    m->x = malloc((size_t)n * 3 * sizeof(double));
    if (!m->x)
        return cf_error_set(err, CF_ERR_NOMEM, "%s: out of memory for %d nodes", path, n);
    m->n_nodes = n;
    for (int i = 0; i < n; i++) {
        s = next_line(&it);
        if (!s)
            return cf_error_set(err, CF_ERR_MESH_PARSE,
                                "%s:%d: file ends after %d of %d nodes (truncated file?)", path,
                                it.line, i, n);
        double v[4];
        int got = read_numbers(s, v, 4, bad);
        if (got < 0)
            return cf_error_set(err, CF_ERR_MESH_PARSE,
                                "%s:%d: '%s' is not a number; expected '<index> <x> <y> <z>'",
                                path, it.line, bad);
        if (got < 4)
            return cf_error_set(err, CF_ERR_MESH_PARSE,
                                "%s:%d: node line has %d numbers; expected '<index> <x> <y> <z>'",
                                path, it.line, got);
        if (!is_int(v[0]))
            return cf_error_set(err, CF_ERR_MESH_PARSE, "%s:%d: node index %g is not an integer",
                                path, it.line, v[0]);
        if (i == 0) {
            if (v[0] != 0 && v[0] != 1)
                return cf_error_set(err, CF_ERR_MESH_PARSE,
                                    "%s:%d: first node is numbered %g; TetGen numbering starts at "
                                    "0 or 1",
                                    path, it.line, v[0]);
            *first = (int)v[0];
        } else if ((int)v[0] != *first + i) {
            return cf_error_set(err, CF_ERR_MESH_PARSE,
                                "%s:%d: node numbered %d, expected %d (nodes must be numbered "
                                "consecutively)",
                                path, it.line, (int)v[0], *first + i);
        }
        memcpy(&m->x[3 * i], &v[1], 3 * sizeof(double));
    }
    return CF_OK;
}

static cf_status parse_ele(const char *path, char *text, cf_mesh *m, int first, cf_error *err)
{
    line_iter it = {text, 0};
    char bad[32];
    double h[3];
    char *s = next_line(&it);
    if (!s)
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s: empty file; expected the header '<#tets> 4 <#attributes>'", path);
    int nh = read_numbers(s, h, 3, bad);
    if (nh < 1 || !is_int(h[0]) || h[0] < 0)
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s:%d: bad header; expected '<#tets> 4 <#attributes>'", path, it.line);
    int ok = 1, n = (int)h[0], npt = header_int(h, nh, 1, 4, &ok);
    if (!ok)
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s:%d: bad header: its counts must be whole numbers; expected "
                            "'<#tets> 4 <#attributes>'",
                            path, it.line);
    if (npt != 4)
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s:%d: %d nodes per tet; only linear 4-node tets are supported "
                            "(re-run tetgen without -o2)",
                            path, it.line, npt);
    if (n == 0)
        return cf_error_set(err, CF_ERR_MESH_PARSE, "%s:%d: the mesh has no tets", path, it.line);
    if (n > lines_left(&it))
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s:%d: the header announces %d tets but the file has only %ld more "
                            "lines (truncated file, or not a TetGen .ele file?)",
                            path, it.line, n, lines_left(&it));
    m->tets = malloc((size_t)n * 4 * sizeof(int));
    if (!m->tets)
        return cf_error_set(err, CF_ERR_NOMEM, "%s: out of memory for %d tets", path, n);
    m->n_tets = n;
    for (int t = 0; t < n; t++) {
        s = next_line(&it);
        if (!s)
            return cf_error_set(err, CF_ERR_MESH_PARSE,
                                "%s:%d: file ends after %d of %d tets (truncated file?)", path,
                                it.line, t, n);
        double v[5];
        int got = read_numbers(s, v, 5, bad);
        if (got < 0)
            return cf_error_set(err, CF_ERR_MESH_PARSE,
                                "%s:%d: '%s' is not a number; expected '<index> <n0> <n1> <n2> "
                                "<n3>'",
                                path, it.line, bad);
        if (got < 5)
            return cf_error_set(err, CF_ERR_MESH_PARSE,
                                "%s:%d: tet line has %d numbers; expected '<index> <n0> <n1> <n2> "
                                "<n3>'",
                                path, it.line, got);
        for (int k = 0; k < 4; k++) {
            double id = v[1 + k];
            if (!is_int(id) || id < first || id - first >= m->n_nodes)
                return cf_error_set(err, CF_ERR_MESH_INDEX,
                                    "%s:%d: tet %d refers to node %g, but the nodes are numbered "
                                    "%d..%d: check that .node and .ele belong together",
                                    path, it.line, t, id, first, first + m->n_nodes - 1);
            m->tets[4 * t + k] = (int)id - first;
        }
    }
    return CF_OK;
}

cf_status cf_mesh_load_tetgen_unchecked(const char *base, cf_mesh *m, cf_error *err)
{
    memset(m, 0, sizeof *m);
    char *b = strip_ext(base);
    if (!b)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    size_t bl = strlen(b);
    char *path = malloc(bl + 6);
    if (!path) {
        free(b);
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    }
    cf_status st = CF_OK;
    int first = 0;
    for (int pass = 0; pass < 2 && st == CF_OK; pass++) {
        snprintf(path, bl + 6, "%s%s", b, pass == 0 ? ".node" : ".ele");
        char *text = cf_file_read(path, NULL);
        if (!text) {
            st = cf_error_set(err, cf_status_of_errno(errno, CF_ERR_FILE_OPEN),
                              "%s: cannot read (%s); give the mesh as the base name of a "
                              "TetGen .node/.ele pair",
                              path, strerror(errno));
            break;
        }
        st = pass == 0 ? parse_node(path, text, m, &first, err)
                       : parse_ele(path, text, m, first, err);
        free(text);
    }
    free(path);
    free(b);
    if (st != CF_OK)
        cf_mesh_free(m);
    return st;
}

cf_status cf_mesh_load_tetgen(const char *base, cf_mesh *m, cf_error *err)
{
    cf_status st = cf_mesh_load_tetgen_unchecked(base, m, err);
    if (st != CF_OK)
        return st;
    st = cf_mesh_check(m, base, err);
    if (st != CF_OK)
        cf_mesh_free(m);
    return st;
}

/* ---- geometry ----------------------------------------------------------- */

/* det[b-a, c-a, d-a] */
static double det4(const double a[3], const double b[3], const double c[3], const double d[3])
{
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
}

double cf_tet_volume(const double a[3], const double b[3], const double c[3], const double d[3])
{
    return det4(a, b, c, d) / 6.0;
}

double cf_mesh_volume(const cf_mesh *m)
{
    /* Sum the determinants (Neumaier-compensated) and divide by 6 once, so
     * that meshes with exactly representable determinants sum exactly. */
    double s = 0.0, c = 0.0;
    for (int t = 0; t < m->n_tets; t++) {
        const int *T = &m->tets[4 * t];
        double d = det4(&m->x[3 * T[0]], &m->x[3 * T[1]], &m->x[3 * T[2]], &m->x[3 * T[3]]);
        double u = s + d;
        c += fabs(s) >= fabs(d) ? (s - u) + d : (d - u) + s;
        s = u;
    }
    return (s + c) / 6.0;
}

static double dist3(const double *a, const double *b)
{
    double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

cf_status cf_mesh_check(const cf_mesh *m, const char *what, cf_error *err)
{
    if (!what)
        what = "mesh";
    for (int t = 0; t < m->n_tets; t++) {
        const int *T = &m->tets[4 * t];
        for (int k = 0; k < 4; k++)
            if (T[k] < 0 || T[k] >= m->n_nodes)
                return cf_error_set(err, CF_ERR_MESH_INDEX,
                                    "%s: tet %d refers to node %d, but there are %d nodes", what,
                                    t, T[k], m->n_nodes);
        const double *p[4];
        for (int k = 0; k < 4; k++)
            p[k] = &m->x[3 * T[k]];
        double v = cf_tet_volume(p[0], p[1], p[2], p[3]);
        double le = 0.0;
        for (int i = 0; i < 4; i++)
            for (int j = i + 1; j < 4; j++)
                le += dist3(p[i], p[j]);
        le /= 6.0;
        /* Scale-free threshold: the tet's own mean edge sets the size. */
        if (!(v > 1e-12 * le * le * le)) {
            return cf_error_set(err, CF_ERR_MESH_INVERTED,
                                "%s: tet %d (0-based; nodes %d %d %d %d) has volume %.3g "
                                "(the file's length unit cubed; %s): re-run tetgen or fix the "
                                "node order",
                                what, t, T[0], T[1], T[2], T[3], v,
                                v < 0 ? "inverted" : "degenerate");
        }
    }
    return CF_OK;
}

int cf_mesh_orient_positive(cf_mesh *m)
{
    int flipped = 0;
    for (int t = 0; t < m->n_tets; t++) {
        int *T = &m->tets[4 * t];
        if (det4(&m->x[3 * T[0]], &m->x[3 * T[1]], &m->x[3 * T[2]], &m->x[3 * T[3]]) < 0) {
            int tmp = T[2];
            T[2] = T[3], T[3] = tmp;
            flipped++;
        }
    }
    return flipped;
}

/* Write to `path`.tmp and rename, so a reader never sees a half file. */
static cf_status write_atomic(const char *path, const cf_mesh *m, int ele, cf_error *err)
{
    size_t n = strlen(path);
    char *tmp = malloc(n + 5);
    if (!tmp)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    snprintf(tmp, n + 5, "%s.tmp", path);
    FILE *f = fopen(tmp, "w");
    if (!f) {
        cf_status st = cf_error_set(err, cf_status_of_errno(errno, CF_ERR_OUTPUT),
                                    "%s: cannot write (%s)", tmp, strerror(errno));
        free(tmp);
        return st;
    }
    if (!ele) {
        fprintf(f, "# cohfrac Tet4 mesh nodes, 0-based, metres\n%d 3 0 0\n", m->n_nodes);
        for (int i = 0; i < m->n_nodes; i++)
            fprintf(f, "%d %.17g %.17g %.17g\n", i, m->x[3 * i], m->x[3 * i + 1],
                    m->x[3 * i + 2]);
    } else {
        fprintf(f, "# cohfrac Tet4 mesh, 0-based, det[x1-x0,x2-x0,x3-x0] > 0\n%d 4 0\n",
                m->n_tets);
        for (int t = 0; t < m->n_tets; t++)
            fprintf(f, "%d %d %d %d %d\n", t, m->tets[4 * t], m->tets[4 * t + 1],
                    m->tets[4 * t + 2], m->tets[4 * t + 3]);
    }
    int bad = ferror(f);
    bad |= fclose(f) != 0;
    if (bad || rename(tmp, path) != 0) {
        remove(tmp);
        free(tmp);
        return cf_error_set(err, CF_ERR_OUTPUT, "%s: write failed (disk full?)", path);
    }
    free(tmp);
    return CF_OK;
}

cf_status cf_mesh_write_tetgen(const cf_mesh *m, const char *base, cf_error *err)
{
    char *b = strip_ext(base);
    if (!b)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    size_t bl = strlen(b);
    char *path = malloc(bl + 6);
    cf_status st = path ? CF_OK : cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    for (int pass = 0; pass < 2 && st == CF_OK; pass++) {
        snprintf(path, bl + 6, "%s%s", b, pass == 0 ? ".node" : ".ele");
        st = write_atomic(path, m, pass, err);
    }
    free(path);
    free(b);
    return st;
}
