/* A run's fragments as glTF 2.0 (see cohfrac/export.h): read the output
 * file's geometry and poses, write through the tinygltf bridge. */
#include "cohfrac/export.h"

#include "cf_gltf.h"
#include "h5_quiet.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Everything the export reads, whole. */
typedef struct run_data {
    hsize_t T, N, nn, M;             /* frames, fragment columns, rest nodes, triangles */
    int nf;                          /* fragment records */
    double *time, *pos, *quat, *X, *com_rest, *mass, *birth;
    int *id, *tri, *first, *count, *crack, *parent, *n_tets, *debris, *mode;
    /* The visual surface (/visual, optional) and, per fragment, the visual
     * triangles that ride on its tets: vis_item[vis_start[i] ..). */
    double *vis_v;
    int *vis_tri, *vis_tet, n_vis, *vis_start, *vis_item;
} run_data;

static void run_free(run_data *r)
{
    free(r->time), free(r->pos), free(r->quat), free(r->X), free(r->com_rest);
    free(r->id), free(r->tri), free(r->first), free(r->count);
    free(r->mass), free(r->birth), free(r->crack), free(r->parent), free(r->n_tets);
    free(r->debris), free(r->mode);
    free(r->vis_v), free(r->vis_tri), free(r->vis_tet), free(r->vis_start), free(r->vis_item);
}

/* vis_start/vis_item: the visual triangles of each fragment, those whose
 * tet is the fragment's in tf (rows [rows][nt] of tet -> fragment, each
 * written at tf_time when the map changed) at the first frame it is
 * alive; a fragment keeps its tets for its life.  -1 out of memory. */
static int own_visual(run_data *r, const int *tf, const double *tf_time, hsize_t rows,
                      hsize_t nt)
{
    hsize_t T = r->T;
    int nf = r->nf;
    long *born = malloc(((size_t)nf + 1) * sizeof *born);
    r->vis_start = calloc((size_t)nf + 2, sizeof *r->vis_start);
    if (!born || !r->vis_start) {
        free(born);
        return -1;
    }
    for (int i = 0; i < nf; i++) {
        born[i] = -1;
        for (hsize_t t = 0; t < T && born[i] < 0; t++)
            if ((hsize_t)i < r->N && r->id[t * r->N + i] >= 0)
                born[i] = (long)t;
    }
    /* The fragment a triangle rides with, at the frame that fragment is born. */
    for (int pass = 0; pass < 2; pass++) { /* count, then fill */
        for (hsize_t t = 0; t < T; t++) {
            int any = 0;
            for (int i = 0; i < nf && !any; i++)
                any = born[i] == (long)t;
            if (!any)
                continue;
            /* the map in force at frame t: the last row written by then (a
             * row is written when the map changes) */
            hsize_t row = 0;
            while (row + 1 < rows && tf_time[row + 1] <= r->time[t] * (1 + 1e-12) + 1e-15)
                row++;
            for (int j = 0; j < r->n_vis; j++) {
                int tet = r->vis_tet[j];
                int f = tet >= 0 && (hsize_t)tet < nt ? tf[row * nt + (hsize_t)tet] : -1;
                if (f < 0 || f >= nf || born[f] != (long)t)
                    continue;
                if (pass == 0)
                    r->vis_start[f + 2]++;
                else
                    r->vis_item[r->vis_start[f + 1]++] = j;
            }
        }
        if (pass == 0) {
            for (int i = 0; i < nf; i++)
                r->vis_start[i + 2] += r->vis_start[i + 1];
            r->vis_item = malloc(((size_t)r->vis_start[nf + 1] + 1) * sizeof *r->vis_item);
            if (!r->vis_item) {
                free(born);
                return -1;
            }
        }
    }
    free(born);
    return 0;
}

/* Rows [0, T) of a [..][cols][k] array (elements of `size` bytes) kept as
 * [T][n][k], in place (n <= cols). */
static void keep_columns(void *a, hsize_t T, hsize_t cols, hsize_t n, size_t k, size_t size)
{
    for (hsize_t t = 0; a && n < cols && t < T; t++)
        memmove((char *)a + t * n * k * size, (char *)a + t * cols * k * size, n * k * size);
}

static cf_status run_read(const char *path, run_data *r, cf_error *err)
{
    memset(r, 0, sizeof *r);
    if (H5Fis_hdf5(path) <= 0)
        return cf_error_set(err, CF_ERR_FILE_OPEN, "%s: not found or not an HDF5 file", path);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return cf_error_set(err, CF_ERR_FILE_OPEN, "%s: cannot open it", path);
    /* Every dataset the export reads, whole; the ones after com_rest are
     * optional (older files lack them; the nodes then go without). */
    enum { TIME, ID, POS, QUAT, X, TRI, FIRST, COUNT, COM, CRACK, MASS, BIRTH, PARENT, NTETS,
           DEBRIS, MODE, VIS_V, VIS_TRI, VIS_TET, N_READS };
    static const struct {
        const char *path;
        int is_double;
        size_t field; /* offset of the pointer in run_data */
    } reads[N_READS] = {
        {"/particles/fragments/position/time", 1, offsetof(run_data, time)},
        {"/particles/fragments/id/value", 0, offsetof(run_data, id)},
        {"/particles/fragments/position/value", 1, offsetof(run_data, pos)},
        {"/particles/fragments/orientation/value", 1, offsetof(run_data, quat)},
        {"/mesh/rest/nodes", 1, offsetof(run_data, X)},
        {"/surfaces/triangles", 0, offsetof(run_data, tri)},
        {"/fragments/surface_first", 0, offsetof(run_data, first)},
        {"/fragments/surface_count", 0, offsetof(run_data, count)},
        {"/fragments/com_rest", 1, offsetof(run_data, com_rest)},
        {"/surfaces/crack", 0, offsetof(run_data, crack)},
        {"/fragments/mass", 1, offsetof(run_data, mass)},
        {"/fragments/birth_time", 1, offsetof(run_data, birth)},
        {"/fragments/parent", 0, offsetof(run_data, parent)},
        {"/fragments/n_tets", 0, offsetof(run_data, n_tets)},
        {"/fragments/debris", 0, offsetof(run_data, debris)},
        {"/particles/fragments/mode/value", 0, offsetof(run_data, mode)},
        {"/visual/vertices", 1, offsetof(run_data, vis_v)},
        {"/visual/triangles", 0, offsetof(run_data, vis_tri)},
        {"/visual/tet", 0, offsetof(run_data, vis_tet)},
    };
    int rk;
    hsize_t dims[N_READS][3] = {{0}}, dmap[3], dmt[3];
    for (int k = 0; k < N_READS; k++) {
        void *data = cf_h5_read_all(f, reads[k].path,
                                    reads[k].is_double ? H5T_NATIVE_DOUBLE : H5T_NATIVE_INT,
                                    reads[k].is_double ? 8 : 4, &rk, dims[k]);
        memcpy((char *)r + reads[k].field, &data, sizeof data); /* the pointer field */
    }
    int *tf = NULL; /* /mesh/tet_fragment rows, read only with a visual surface */
    double *tf_time = NULL;
    if (r->vis_v && r->vis_tri && r->vis_tet) {
        r->n_vis = (int)dims[VIS_TRI][0];
        tf = cf_h5_read_all(f, "/mesh/tet_fragment/value", H5T_NATIVE_INT, 4, &rk, dmap);
        tf_time = cf_h5_read_all(f, "/mesh/tet_fragment/time", H5T_NATIVE_DOUBLE, 8, &rk, dmt);
    }
    /* Whole frames only: the count the file keeps, never more rows than
     * the shortest per-frame dataset holds, and the columns all of them
     * have (a run killed during a flush may leave one dataset a row
     * longer, or a frame's new columns wider, than another). */
    const int per_frame[] = {ID, POS, QUAT, MODE};
    const size_t width[] = {1, 3, 4, 1};
    enum { N_PER_FRAME = sizeof per_frame / sizeof per_frame[0] };
    void *data[N_PER_FRAME];
    hsize_t rows = dims[TIME][0], cols = dims[ID][1];
    for (int k = 0; k < N_PER_FRAME; k++) {
        const hsize_t *d = dims[per_frame[k]];
        memcpy(&data[k], (char *)r + reads[per_frame[k]].field, sizeof data[k]);
        rows = data[k] && d[0] < rows ? d[0] : rows;
        cols = data[k] && d[1] < cols ? d[1] : cols;
    }
    r->T = cf_h5_whole_frames(f, rows);
    for (int k = 0; k < N_PER_FRAME; k++)
        keep_columns(data[k], r->T, dims[per_frame[k]][1], cols, width[k],
                     reads[per_frame[k]].is_double ? 8 : 4);
    H5Fclose(f);
    if (!r->X || !r->first || !r->count || !r->com_rest || !r->tri)
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s holds no fragment geometry (/mesh/rest, /surfaces): written by "
                            "an older cohfrac; run the scene again",
                            path);
    if (!r->time || !r->id || !r->pos || !r->quat)
        return cf_error_set(err, CF_ERR_MESH_PARSE, "%s holds no frames (/particles/fragments)",
                            path);
    r->N = cols, r->nn = dims[X][0], r->M = dims[TRI][0], r->nf = (int)dims[FIRST][0];
    cf_status st = CF_OK;
    if (tf && tf_time &&
        own_visual(r, tf, tf_time, dmap[0] < dmt[0] ? dmap[0] : dmt[0], dmap[1]) != 0)
        st = cf_error_set(err, CF_ERR_NOMEM, "out of memory for the visual surface");
    free(tf), free(tf_time);
    return st;
}

/* cohfrac (x, y, z), +z up -> glTF (x, z, -y), +y up. */
static void to_gltf(const double v[3], float out[3])
{
    out[0] = (float)v[0], out[1] = (float)v[2], out[2] = (float)-v[1];
}

/* The numbers each node carries in its extras, SI units (docs/output.md). */
static const char *const EXTRA_KEYS[] = {"fragment", "mass",  "parent", "birth_time",
                                         "n_tets",   "debris", "mode"};
enum { N_EXTRAS = sizeof EXTRA_KEYS / sizeof EXTRA_KEYS[0] };

/* Corner c of rest-mesh or visual vertex v (`vis`), in fragment i's body
 * frame, glTF axes, into pos[3 * at]. */
static void corner(const run_data *r, int i, int vis, int v, float *pos)
{
    const double *x = vis ? &r->vis_v[3 * v] : &r->X[3 * v];
    double rel[3];
    for (int c = 0; c < 3; c++)
        rel[c] = x[c] - r->com_rest[3 * i + c];
    to_gltf(rel, pos);
}

/* Fragment i's triangles into n: its outer surface, then its crack faces
 * (n_inner).  The outer surface is the visual surface's triangles that
 * ride on its tets where the file has one (vis_start/vis_item), its rest
 * surface's outer faces otherwise.  Each corner is a vertex of its own
 * (flat shading).  0 done, 1 nothing to draw, -1 out of memory. */
static int node_geometry(const run_data *r, int i, cfg_node *n)
{
    int a = r->first[i], m = r->count[i];
    if (m <= 0 || a < 0 || (hsize_t)(a + m) > r->M)
        return 1;
    int n_vis = r->vis_start ? r->vis_start[i + 1] - r->vis_start[i] : 0;
    size_t cap = (size_t)m + (size_t)n_vis;
    float *pos = malloc(3 * 3 * cap * sizeof(float) + 1);
    unsigned *idx = malloc(3 * cap * sizeof(unsigned) + 1);
    if (!pos || !idx) {
        free(pos), free(idx);
        return -1;
    }
    int k = 0, inner = 0;
    for (int j = 0; j < n_vis; j++) /* the visual surface on its tets */
        for (int c3 = 0; c3 < 3; c3++, k++)
            corner(r, i, 1, r->vis_tri[3 * r->vis_item[r->vis_start[i] + j] + c3], &pos[3 * k]);
    for (int pass = 0; pass < 2; pass++) /* its rest surface: outer faces, then cracks */
        for (int j = a; j < a + m; j++) {
            int is_crack = r->crack && r->crack[j] != 0;
            if (is_crack != pass || (!is_crack && r->vis_start))
                continue;
            inner += is_crack;
            for (int c3 = 0; c3 < 3; c3++, k++)
                corner(r, i, 0, r->tri[3 * j + c3], &pos[3 * k]);
        }
    for (int v = 0; v < k; v++)
        idx[v] = (unsigned)v;
    n->n_vertices = k, n->positions = pos;
    n->n_triangles = k / 3, n->indices = idx, n->n_inner = inner;
    return k > 0 ? 0 : 1;
}

/* One fragment's node: its surface in its body frame (node_geometry), its
 * extras, its keys at `slow_motion` times the run's time. */
static int make_node(const run_data *r, int i, double slow_motion, cfg_node *n, char *name,
                     size_t name_len)
{
    memset(n, 0, sizeof *n);
    snprintf(name, name_len, "fragment_%d", i);
    n->name = name;
    int geo = node_geometry(r, i, n);
    if (geo != 0) {
        free((void *)n->positions), free((void *)n->indices);
        n->positions = NULL, n->indices = NULL;
        return geo < 0 ? -1 : 0;
    }
    float *times = malloc(r->T * sizeof(float)), *tr = malloc(r->T * 3 * sizeof(float));
    float *rot = malloc(r->T * 4 * sizeof(float)), *scale = malloc(r->T * sizeof(float));
    double *extras = malloc(N_EXTRAS * sizeof *extras);
    if (!times || !tr || !rot || !scale || !extras) {
        free(times), free(tr), free(rot), free(scale), free(extras);
        free((void *)n->positions), free((void *)n->indices);
        return -1;
    }
    /* Keys at every frame; before the first and after the last alive frame
     * the nearest alive pose is held, hidden by scale 0. */
    long first = -1, last = -1;
    for (hsize_t t = 0; t < r->T; t++)
        if ((hsize_t)i < r->N && r->id[t * r->N + i] >= 0)
            last = (long)t, first = first < 0 ? (long)t : first;
    for (hsize_t t = 0; t < r->T; t++) {
        long s = first < 0 ? 0 : (long)t < first ? first : (long)t > last ? last : (long)t;
        const double *p = &r->pos[((hsize_t)s * r->N + i) * 3];
        const double *q = &r->quat[((hsize_t)s * r->N + i) * 4]; /* w, x, y, z */
        int alive = first >= 0 && (long)t >= first && (long)t <= last;
        times[t] = (float)(slow_motion * r->time[t]);
        to_gltf(p, &tr[3 * t]);
        double qv[3] = {q[1], q[2], q[3]};
        float qg[3];
        to_gltf(qv, qg);
        rot[4 * t] = qg[0], rot[4 * t + 1] = qg[1], rot[4 * t + 2] = qg[2];
        rot[4 * t + 3] = (float)q[0];
        if (!isfinite(rot[4 * t] + rot[4 * t + 3]) || first < 0)
            rot[4 * t] = rot[4 * t + 1] = rot[4 * t + 2] = 0, rot[4 * t + 3] = 1;
        if (!isfinite(tr[3 * t] + tr[3 * t + 1] + tr[3 * t + 2]))
            tr[3 * t] = tr[3 * t + 1] = tr[3 * t + 2] = 0;
        scale[t] = alive ? 1.0f : 0.0f;
    }
    /* A colour per fragment, spread around the hue circle. */
    double h = fmod(0.618033988749895 * i, 1.0);
    for (int c = 0; c < 3; c++)
        n->color[c] = (float)(0.45 + 0.4 * cos(6.283185307179586 * (h + c / 3.0)));
    n->color[3] = 1.0f;
    /* mode: at the last frame it is alive (0 rigid, 1 fracture; -1 never seen) */
    int mode = -1;
    if (r->mode && last >= 0)
        mode = r->mode[(hsize_t)last * r->N + i];
    const double values[N_EXTRAS] = {i,
                                     r->mass ? r->mass[i] : NAN,
                                     r->parent ? r->parent[i] : -1,
                                     r->birth ? r->birth[i] : NAN,
                                     r->n_tets ? r->n_tets[i] : -1,
                                     r->debris ? r->debris[i] : 0,
                                     mode};
    memcpy(extras, values, sizeof values);
    n->extra_keys = EXTRA_KEYS, n->extra_values = extras, n->n_extras = N_EXTRAS;
    n->n_keys = (int)r->T, n->times = times, n->translation = tr, n->rotation = rot;
    n->scale = scale;
    return 1;
}

static void node_free(cfg_node *n)
{
    free((void *)n->positions), free((void *)n->indices), free((void *)n->times);
    free((void *)n->translation), free((void *)n->rotation), free((void *)n->scale);
    free((void *)n->extra_values);
}

cf_status cf_export_gltf(const char *h5_path, const char *glb_path, double slow_motion,
                         cf_error *err)
{
    if (!(slow_motion > 0) || !isfinite(slow_motion))
        return cf_error_set(err, CF_ERR_USAGE,
                            "the slow-motion factor must be a number > 0 (1: real time), got %g",
                            slow_motion);
    quiet_state q;
    quiet_begin(&q);
    run_data r;
    cf_status st = run_read(h5_path, &r, err);
    quiet_end(&q);
    cfg_node *nodes = st == CF_OK ? calloc((size_t)r.nf + 1, sizeof *nodes) : NULL;
    char (*names)[32] = st == CF_OK ? calloc((size_t)r.nf + 1, sizeof *names) : NULL;
    if (st == CF_OK && (!nodes || !names))
        st = cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    int n = 0;
    for (int i = 0; st == CF_OK && i < r.nf; i++) {
        int k = make_node(&r, i, slow_motion, &nodes[n], names[i], sizeof names[i]);
        if (k < 0)
            st = cf_error_set(err, CF_ERR_NOMEM, "out of memory for fragment %d", i);
        n += k > 0;
    }
    char why[256] = "";
    if (st == CF_OK && cfg_write_glb(glb_path, nodes, n, "fragments", why, sizeof why) != 0)
        st = cf_error_set(err, CF_ERR_OUTPUT, "%s", why);
    for (int i = 0; nodes && i < n; i++)
        node_free(&nodes[i]);
    free(nodes), free(names);
    run_free(&r);
    return st;
}
