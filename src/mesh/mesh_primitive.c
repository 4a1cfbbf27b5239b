/* cohfrac — meshed primitives: a structured box in-engine, the others
 * (sphere, hollow sphere, plate, notched beam) by the `gmsh` program.
 *
 * Box: (cells[0]+1)(cells[1]+1)(cells[2]+1) grid nodes, node (i,j,k) at
 * index (k*(ny+1) + j)*(nx+1) + i.  Each cell is cut into
 *   6 tets (Kuhn/Freudenthal): the paths from the cell's lowest corner to
 *     its highest along the three axes in the 6 possible orders; every cell
 *     cuts its faces along the diagonal through its lowest corner, so
 *     neighbours agree;
 *   5 tets: a central tet and four corner tets.  The central tet joins the
 *     cell corners with i+j+k even (global grid indices), so every face
 *     diagonal joins two even corners in both neighbours: the mesh is
 *     conforming with alternating (checkerboard) cells.
 *
 * Gmsh primitives: a .geo script (OpenCASCADE kernel) is meshed with
 * `gmsh -3 -format msh41`; the mesh is cached as
 * <cache_dir>/<type>_<16 hex digits>.msh, the digits being the 64-bit FNV-1a
 * hash of the script (which prints every parameter), so any change of a
 * parameter or of the script gives a new file.  The .geo is kept beside it.
 */
#include "file_text.h"
#include "hash.h"
#include "process.h"
#include "cohfrac/mesh.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

static const char axis[3] = {'x', 'y', 'z'};

/* ---- structured box ------------------------------------------------------ */

cf_status cf_mesh_box(const double size[3], const int cells[3], int tets_per_cell, cf_mesh *m,
                      cf_error *err)
{
    memset(m, 0, sizeof *m);
    for (int k = 0; k < 3; k++) {
        if (!(size[k] > 0) || !isfinite(size[k]))
            return cf_error_set(err, CF_ERR_SCENE_VALUE,
                                "box: size along %c is %g m; it must be a positive length",
                                axis[k], size[k]);
        if (cells[k] < 1 || cells[k] > 100000)
            return cf_error_set(err, CF_ERR_SCENE_VALUE,
                                "box: cells along %c is %d; it must be 1..100000", axis[k],
                                cells[k]);
    }
    if (tets_per_cell != 5 && tets_per_cell != 6)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "box: tets_per_cell is %d; it must be 5 (alternating) or 6 (Kuhn)",
                            tets_per_cell);
    const int nx = cells[0], ny = cells[1], nz = cells[2];
    double n_cells = (double)nx * ny * nz, n_nodes = (double)(nx + 1) * (ny + 1) * (nz + 1);
    if (n_cells * tets_per_cell > INT_MAX / 4 || n_nodes > INT_MAX / 3)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "box: %d x %d x %d cells give too many tets; use fewer cells", nx, ny,
                            nz);
    m->n_nodes = (int)n_nodes;
    m->n_tets = (int)n_cells * tets_per_cell;
    m->x = malloc((size_t)m->n_nodes * 3 * sizeof(double));
    m->tets = malloc((size_t)m->n_tets * 4 * sizeof(int));
    if (!m->x || !m->tets) {
        cf_mesh_free(m);
        return cf_error_set(err, CF_ERR_NOMEM, "box: out of memory for %.0f tets",
                            n_cells * tets_per_cell);
    }
#define NODE(i, j, k) (((k) * (ny + 1) + (j)) * (nx + 1) + (i))
    for (int k = 0; k <= nz; k++)
        for (int j = 0; j <= ny; j++)
            for (int i = 0; i <= nx; i++) {
                double *x = &m->x[3 * NODE(i, j, k)];
                /* (i/n - 1/2) * size: the ends are exactly -size/2 and +size/2 */
                x[0] = size[0] * ((double)i / nx - 0.5);
                x[1] = size[1] * ((double)j / ny - 0.5);
                x[2] = size[2] * ((double)k / nz - 0.5);
            }
    /* Cell corners by bits: corner c is (i + (c&1), j + (c>>1&1), k + (c>>2&1)). */
    static const int kuhn[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                                   {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
    static const int five_even[5][4] = {{0, 3, 5, 6}, {1, 0, 3, 5}, {2, 0, 3, 6},
                                        {4, 0, 5, 6}, {7, 3, 5, 6}};
    static const int five_odd[5][4] = {{1, 2, 4, 7}, {0, 1, 2, 4}, {3, 1, 2, 7},
                                       {5, 1, 4, 7}, {6, 2, 4, 7}};
    int t = 0;
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                const int(*pattern)[4] = tets_per_cell == 6   ? kuhn
                                         : (i + j + k) % 2 == 0 ? five_even
                                                                : five_odd;
                for (int p = 0; p < tets_per_cell; p++, t++)
                    for (int v = 0; v < 4; v++) {
                        int c = pattern[p][v];
                        m->tets[4 * t + v] = NODE(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1));
                    }
            }
#undef NODE
    cf_mesh_orient_positive(m); /* the patterns above list some tets inverted */
    return CF_OK;
}

/* ---- gmsh primitives ------------------------------------------------------ */

static const char *type_name(cf_primitive_type t)
{
    switch (t) {
    case CF_PRIM_SPHERE: return "sphere";
    case CF_PRIM_HOLLOW_SPHERE: return "hollow_sphere";
    case CF_PRIM_PLATE: return "plate";
    case CF_PRIM_NOTCHED_BEAM: return "notched_beam";
    default: return NULL;
    }
}

static int positive(double v) { return v > 0 && isfinite(v); }

static cf_status check_params(const cf_primitive *p, const char *type, cf_error *err)
{
    if (!positive(p->mesh_size))
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "%s: mesh_size is %g m; it must be a positive length", type,
                            p->mesh_size);
    if (p->type == CF_PRIM_SPHERE || p->type == CF_PRIM_HOLLOW_SPHERE) {
        if (!positive(p->radius))
            return cf_error_set(err, CF_ERR_SCENE_VALUE,
                                "%s: radius is %g m; it must be a positive length", type,
                                p->radius);
        if (p->type == CF_PRIM_HOLLOW_SPHERE && (!positive(p->thickness) || p->thickness >= p->radius))
            return cf_error_set(err, CF_ERR_SCENE_VALUE,
                                "%s: thickness is %g m; it must be positive and less than the "
                                "radius (%g m)",
                                type, p->thickness, p->radius);
        return CF_OK;
    }
    for (int k = 0; k < 3; k++)
        if (!positive(p->size[k]))
            return cf_error_set(err, CF_ERR_SCENE_VALUE,
                                "%s: size along %c is %g m; it must be a positive length", type,
                                axis[k], p->size[k]);
    if (p->type == CF_PRIM_NOTCHED_BEAM) {
        const double *n = p->notch;
        if (!positive(n[0]) || n[0] >= p->size[2])
            return cf_error_set(err, CF_ERR_SCENE_VALUE,
                                "%s: notch depth is %g m; it must be positive and less "
                                "than the height size z (%g m)",
                                type, n[0], p->size[2]);
        if (!positive(n[1]))
            return cf_error_set(err, CF_ERR_SCENE_VALUE,
                                "%s: notch width is %g m; it must be a positive length",
                                type, n[1]);
        if (!isfinite(n[2]) || fabs(n[2]) + 0.5 * n[1] >= 0.5 * p->size[0])
            return cf_error_set(err, CF_ERR_SCENE_VALUE,
                                "%s: notch offset %g m with width %g m puts the notch "
                                "outside the length %g m; need |offset| + width/2 < length/2",
                                type, n[2], n[1], p->size[0]);
    }
    return CF_OK;
}

/* The .geo script of a primitive; NULL when out of memory. */
static char *geo_script(const cf_primitive *p)
{
    char body[1024];
    const double *s = p->size, *n = p->notch;
    switch (p->type) {
    case CF_PRIM_SPHERE:
        snprintf(body, sizeof body, "Sphere(1) = {0, 0, 0, %.17g};\n", p->radius);
        break;
    case CF_PRIM_HOLLOW_SPHERE:
        snprintf(body, sizeof body,
                 "Sphere(1) = {0, 0, 0, %.17g};\n"
                 "Sphere(2) = {0, 0, 0, %.17g};\n"
                 "BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };\n",
                 p->radius, p->radius - p->thickness);
        break;
    case CF_PRIM_PLATE:
        snprintf(body, sizeof body, "Box(1) = {%.17g, %.17g, %.17g, %.17g, %.17g, %.17g};\n",
                 -0.5 * s[0], -0.5 * s[1], -0.5 * s[2], s[0], s[1], s[2]);
        break;
    default: { /* notched beam: the cutter sticks out of the bottom and the sides by e */
        double e = 0.1 * (s[1] + s[2]);
        snprintf(body, sizeof body,
                 "Box(1) = {%.17g, %.17g, %.17g, %.17g, %.17g, %.17g};\n"
                 "Box(2) = {%.17g, %.17g, %.17g, %.17g, %.17g, %.17g}; // the notch\n"
                 "BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };\n",
                 -0.5 * s[0], -0.5 * s[1], -0.5 * s[2], s[0], s[1], s[2], n[2] - 0.5 * n[1],
                 -0.5 * s[1] - e, -0.5 * s[2] - e, n[1], s[1] + 2 * e, n[0] + e);
        break;
    }
    }
    const char *fmt = "// cohfrac %s primitive (generated; meshed with `gmsh -3 -format msh41`)\n"
                      "SetFactory(\"OpenCASCADE\");\n"
                      "%s"
                      "Mesh.CharacteristicLengthFromPoints = 0; // size from the maximum only\n"
                      "Mesh.CharacteristicLengthMax = %.17g;\n";
    int len = snprintf(NULL, 0, fmt, type_name(p->type), body, p->mesh_size);
    char *g = len > 0 ? malloc((size_t)len + 1) : NULL;
    if (g)
        snprintf(g, (size_t)len + 1, fmt, type_name(p->type), body, p->mesh_size);
    return g;
}

static cf_status write_text(const char *path, const char *text, cf_error *err)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return cf_error_set(err, cf_status_of_errno(errno, CF_ERR_OUTPUT),
                            "%s: cannot write (%s)", path, strerror(errno));
    fputs(text, f);
    int bad = ferror(f);
    bad |= fclose(f) != 0;
    if (bad)
        return cf_error_set(err, CF_ERR_OUTPUT, "%s: write failed (disk full?)", path);
    return CF_OK;
}


/* Run `<gmsh> -3 -format msh41 -o <msh> <geo>`, output into `logp`. */
static cf_status run_gmsh(const char *geo, const char *msh, const char *logp, cf_error *err)
{
    const char *prog = getenv("COHFRAC_GMSH");
    if (!prog || !*prog)
        prog = "gmsh";
    char *argv[] = {(char *)prog, "-3", "-format", "msh41", "-o", (char *)msh, (char *)geo, NULL};
    char cmd[3 * PATH_MAX];
    snprintf(cmd, sizeof cmd, "%s -3 -format msh41 -o %s %s", prog, msh, geo);
    pid_t pid;
    int rc = cf_spawn(argv, logp, &pid);
    if (rc != 0)
        return cf_error_set(err, CF_ERR_EXTERNAL,
                            "cannot run '%s' (%s): install Gmsh (Debian: apt install gmsh) or "
                            "point COHFRAC_GMSH at the program; command: %s",
                            prog, strerror(rc), cmd);
    int status;
    if (cf_wait(pid, &status, NULL) < 0)
        return cf_error_set(err, CF_ERR_EXTERNAL, "waiting for %s failed (%s)", prog,
                            strerror(errno));
    if (WIFEXITED(status) && WEXITSTATUS(status) == 127)
        return cf_error_set(err, CF_ERR_EXTERNAL,
                            "'%s' not found: install Gmsh (Debian: apt install gmsh) or point "
                            "COHFRAC_GMSH at the program; command: %s",
                            prog, cmd);
    struct stat st;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || stat(msh, &st) != 0) {
        char tail[500];
        cf_file_log_tail(logp, tail, sizeof tail);
        return cf_error_set(err, CF_ERR_EXTERNAL, "'%s' failed (%s %d); its output ends:\n%s",
                            cmd, WIFEXITED(status) ? "exit status" : "signal",
                            WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status), tail);
    }
    return CF_OK;
}

/* Mesh the primitive with gmsh into `path` (atomically), keeping the script
 * as `geo_path`. */
static cf_status mesh_with_gmsh(const char *script, const char *path, const char *geo_path,
                                cf_error *err)
{
    char tgeo[PATH_MAX + 32], tmsh[PATH_MAX + 32], tlog[PATH_MAX + 32];
    long pid = (long)getpid();
    snprintf(tgeo, sizeof tgeo, "%s.%ld.tmp.geo", path, pid);
    snprintf(tmsh, sizeof tmsh, "%s.%ld.tmp.msh", path, pid);
    snprintf(tlog, sizeof tlog, "%s.%ld.tmp.log", path, pid);
    cf_status st = write_text(tgeo, script, err);
    if (st == CF_OK)
        st = run_gmsh(tgeo, tmsh, tlog, err);
    if (st == CF_OK && (rename(tgeo, geo_path) != 0 || rename(tmsh, path) != 0))
        st = cf_error_set(err, CF_ERR_OUTPUT, "%s: cannot move the mesh into place (%s)", path,
                          strerror(errno));
    remove(tgeo);
    remove(tmsh);
    remove(tlog);
    return st;
}

/* Move the mesh so that its bounding-box centre is the origin. */
static void centre(cf_mesh *m)
{
    if (m->n_nodes == 0)
        return;
    for (int k = 0; k < 3; k++) {
        double lo = m->x[k], hi = m->x[k];
        for (int i = 1; i < m->n_nodes; i++) {
            double v = m->x[3 * i + k];
            lo = v < lo ? v : lo, hi = v > hi ? v : hi;
        }
        double c = 0.5 * (lo + hi);
        for (int i = 0; i < m->n_nodes; i++)
            m->x[3 * i + k] -= c;
    }
}

cf_status cf_mesh_primitive(const cf_primitive *p, const char *cache_dir, cf_mesh *m,
                            cf_error *err)
{
    memset(m, 0, sizeof *m);
    if (p->type == CF_PRIM_BOX)
        return cf_mesh_box(p->size, p->cells, p->tets_per_cell, m, err);
    const char *type = type_name(p->type);
    if (!type)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "unknown primitive type %d; expected box, sphere, hollow_sphere, "
                            "plate or notched_beam",
                            (int)p->type);
    cf_status st = check_params(p, type, err);
    if (st != CF_OK)
        return st;
    if (!cache_dir || !*cache_dir)
        cache_dir = ".";
    char *script = geo_script(p);
    if (!script)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    char path[PATH_MAX], geo_path[PATH_MAX];
    unsigned long long h = (unsigned long long)cf_fnv1a(CF_FNV1A_SEED, script, strlen(script));
    int n1 = snprintf(path, sizeof path, "%s/%s_%016llx.msh", cache_dir, type, h);
    int n2 = snprintf(geo_path, sizeof geo_path, "%s/%s_%016llx.geo", cache_dir, type, h);
    if (n1 >= (int)sizeof path - 32 || n2 >= (int)sizeof geo_path) {
        free(script);
        return cf_error_set(err, CF_ERR_OUTPUT, "mesh cache directory name too long: %s",
                            cache_dir);
    }
    struct stat sb;
    if (stat(path, &sb) != 0) {
        st = cf_mkdirs(cache_dir, "mesh cache directory", err);
        if (st == CF_OK)
            st = mesh_with_gmsh(script, path, geo_path, err);
    }
    free(script);
    if (st != CF_OK)
        return st;
    st = cf_mesh_load_gmsh(path, m, err);
    if (st != CF_OK) {
        char msg[sizeof err->msg];
        snprintf(msg, sizeof msg, "%s", err ? err->msg : "");
        return cf_error_set(err, st, "%s (a cached %s mesh: delete the file to rebuild it)", msg,
                            type);
    }
    centre(m);
    return CF_OK;
}
