/* cohfrac — `cohfrac mesh`: closed surface -> checked Tet4 mesh.
 *
 * Pipeline: load the surface, report and repair self-intersections, check
 * it is closed, coarsen it (meshoptimizer, cf_surface_decimate) when the wanted tet count
 * needs a coarser boundary, run the `tetgen` program (never linked: AGPL),
 * orient every tet positively, check the tet volume against the surface's
 * enclosed volume, peel the boundary caps that would set the explicit step
 * (cf_mesh_peel_slivers, docs/physics.md §3.1), report the quality that sets
 * it, and write <output>.node/.ele plus a stamp for caching.
 *
 * Size selection for target_tets = N > 0 (everything is deterministic, so
 * the same input always gives the same mesh):
 *   - tetgen always runs with "-pYq2.0F": -Y keeps the (repaired or
 *     decimated) surface exactly, so the volume check is exact and the mesh
 *     is as fine at the boundary as the surface is; q2.0 is the radius-edge
 *     bound.
 *   - With -Y the count is dominated by the surface: about TETS_PER_TRI tets
 *     per surface triangle.  If the full surface would give more than 1.05 N,
 *     it is decimated to F = 0.9 N / TETS_PER_TRI triangles (then corrected
 *     from the measured count, at most 3 times), aiming a little low.
 *   - The remaining gap is closed with a maximum tet volume -a: modelling
 *     N(a) = N0 + C / a, the first guess is C = V (the enclosed volume) and
 *     later guesses fit the last two runs; accepted within ±5 %, at most 8
 *     runs, otherwise the closest run is kept.  If the first -a run barely
 *     adds tets, the surface is too coarse for -Y (every tet touches it) and
 *     the search goes on with "-pq2.0a<a>F", letting tetgen split facets.
 * target_tets = 0 runs plain "tetgen -pqF" on the full surface.
 */
#define _XOPEN_SOURCE 700 /* POSIX 2008 + realpath */

#include "clock.h"
#include "file_text.h"
#include "linalg.h"
#include "process.h"
#include "sort.h"
#include "cohfrac/mesh.h"
#include "cohfrac/surface.h"

#include "cf_cgal.h"

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <signal.h>
#include <time.h>
#include <unistd.h>

/* Bump when the pipeline changes in a way that changes its output, so old
 * cached meshes are rebuilt. */
#define PREP_VERSION                                                                          \
    "cohfrac-mesh 6 (assimp; repair valence3, CGAL; CGAL isotropic remeshing, of slivers "     \
    "too, else meshoptimizer, alpha wrap past 2x; tetgen -pYq2.0 [-a]; peel 0.25)"
#define TETS_PER_TRI 2.4 /* tetgen -pYq2.0 tets per surface triangle (bunny: 2.3-2.5) */
#define BASE_OPTS "pYq2.0"
#define TOL 0.05
#define MAX_A_RUNS 8
#define MAX_SUBDIVISIONS 3 /* 64 x the triangles at most */
#define MISS_ALLOWED 0.25  /* the target met within 25 %, or a warning */
#define PEEL_FRACTION 0.25 /* boundary caps thinner than this x the median h are peeled */

static char *str_cat(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    char *s = malloc(la + lb + 1);
    if (s) {
        memcpy(s, a, la);
        memcpy(s + la, b, lb + 1);
    }
    return s;
}

/* mkdir -p of the directory part of `path`. */
static cf_status make_parent_dirs(const char *path, cf_error *err)
{
    char *d = str_cat(path, "");
    if (!d)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    char *slash = strrchr(d, '/');
    cf_status st = CF_OK;
    if (slash && slash != d) {
        *slash = '\0';
        st = cf_mkdirs(d, "mesh output directory", err);
    }
    free(d);
    return st;
}

/* Remove the temporary directory and the files in it (all ours). */
static void remove_tree(const char *dir)
{
    DIR *D = opendir(dir);
    if (D) {
        struct dirent *e;
        while ((e = readdir(D))) {
            if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
                continue;
            char path[PATH_MAX];
            if (snprintf(path, sizeof path, "%s/%s", dir, e->d_name) < (int)sizeof path)
                remove(path);
        }
        closedir(D);
    }
    rmdir(dir);
}

/* ---- stamp -------------------------------------------------------------- */

/* The lines that decide whether a cached mesh is still valid. */
static cf_status stamp_key(const cf_mesh_prep_opts *o, char *key, size_t n, cf_error *err)
{
    struct stat st;
    if (stat(o->input, &st) != 0)
        return cf_error_set(err, CF_ERR_FILE_OPEN, "%s: cannot read (%s)", o->input,
                            strerror(errno));
    char *real = realpath(o->input, NULL);
    snprintf(key, n,
             "version %s\ninput %s\ninput_size %lld\ninput_mtime %lld.%09ld\ntarget_tets %d\n%s",
             PREP_VERSION, real ? real : o->input, (long long)st.st_size,
             (long long)st.st_mtim.tv_sec, (long)st.st_mtim.tv_nsec, o->target_tets,
             o->no_repair ? "no_repair\n" : "");
    free(real);
    return CF_OK;
}

/* Are <output>.node/.ele there, newer than the input, and was the stamp
 * written for exactly this key? */
static int cache_valid(const cf_mesh_prep_opts *o, const char *key)
{
    char *sp = str_cat(o->output, ".stamp"), *np = str_cat(o->output, ".node"),
         *ep = str_cat(o->output, ".ele");
    int ok = 0;
    struct stat si, sn, se;
    FILE *f = sp ? fopen(sp, "r") : NULL;
    if (f && np && ep && stat(o->input, &si) == 0 && stat(np, &sn) == 0 && stat(ep, &se) == 0 &&
        sn.st_mtime >= si.st_mtime && se.st_mtime >= si.st_mtime) {
        size_t kl = strlen(key);
        char *buf = malloc(kl + 1);
        if (buf && fread(buf, 1, kl, f) == kl) {
            buf[kl] = '\0';
            ok = !strcmp(buf, key);
        }
        free(buf);
    }
    if (f)
        fclose(f);
    free(sp);
    free(np);
    free(ep);
    return ok;
}

/* ---- running tetgen ---------------------------------------------------- */


/* One preparation: its options, temporary directory and deadline. */
typedef struct prep {
    const cf_mesh_prep_opts *o;
    const char *dir;
    double limit, deadline; /* s: the time limit, and when it runs out (wall clock) */
} prep;

/* Wait for tetgen, polling: stop it when the caller's stop flag is raised
 * (a signal) or at the deadline.  Returns 0 with *status set, or the reason
 * it was stopped: 1 the stop flag, 2 the deadline. */
static int wait_tetgen(pid_t pid, const prep *p, int *status)
{
    const struct timespec nap = {0, 20000000}; /* 20 ms */
    for (;;) {
        pid_t got = waitpid(pid, status, WNOHANG);
        if (got == pid || (got < 0 && errno != EINTR))
            return 0;
        int why = p->o->stop && *p->o->stop ? 1 : cf_wall_time() > p->deadline ? 2 : 0;
        if (why) {
            kill(pid, SIGKILL);
            while (waitpid(pid, status, 0) < 0 && errno == EINTR)
                ;
            return why;
        }
        nanosleep(&nap, NULL);
    }
}

/* Run `tetgen -<opts> <dir>/surf.off`, output to <dir>/surf.1.*; load it. */
static cf_status run_tetgen(const prep *p, const char *opts, cf_mesh *m, double *secs,
                            cf_error *err)
{
    const char *dir = p->dir;
    char in[PATH_MAX], logp[PATH_MAX], base[PATH_MAX], flag[128];
    snprintf(in, sizeof in, "%s/surf.off", dir);
    snprintf(logp, sizeof logp, "%s/tetgen.log", dir);
    snprintf(base, sizeof base, "%s/surf.1", dir);
    snprintf(flag, sizeof flag, "-%s", opts);
    const char *prog = getenv("COHFRAC_TETGEN");
    if (!prog || !*prog)
        prog = "tetgen";
    char *argv[] = {(char *)prog, flag, in, NULL};
    pid_t pid;
    double t0 = cf_wall_time();
    int rc = cf_spawn(argv, logp, &pid);
    if (rc != 0)
        return cf_error_set(err, CF_ERR_EXTERNAL,
                            "cannot run '%s' (%s): install TetGen (Debian: apt install tetgen) "
                            "or point COHFRAC_TETGEN at the program",
                            prog, strerror(rc));
    int status = 0;
    int stopped = wait_tetgen(pid, p, &status);
    *secs = cf_wall_time() - t0;
    if (stopped == 1)
        return cf_error_set(err, CF_ERR_INTERRUPTED, "tetgen %s stopped by a signal after %.1f s",
                            flag, *secs);
    if (stopped == 2)
        return cf_error_set(err, CF_ERR_EXTERNAL,
                            "cohfrac mesh did not finish within %g s (tetgen %s stopped): the "
                            "surface is probably much finer than --target-tets allows or has "
                            "slivers tetgen keeps refining; ask for fewer tets, simplify the "
                            "surface first, or allow more time (--time-limit)",
                            p->limit, flag);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        char tail[600];
        cf_file_log_tail(logp, tail, sizeof tail);
        if (WIFEXITED(status) && WEXITSTATUS(status) == 127)
            return cf_error_set(err, CF_ERR_EXTERNAL,
                                "'%s' not found: install TetGen (apt install tetgen) or set "
                                "COHFRAC_TETGEN",
                                prog);
        if (WIFSIGNALED(status))
            return cf_error_set(err, CF_ERR_EXTERNAL,
                                "'%s %s' crashed (signal %d). tetgen does this on surfaces "
                                "with nearly coincident or nearly intersecting facets, or "
                                "facets much thinner than their neighbours: try another "
                                "--target-tets (the surface is decimated differently), or "
                                "clean the surface (merge close vertices, remove slivers) "
                                "first.  Its output ends:\n%s",
                                prog, flag, WTERMSIG(status), tail);
        return cf_error_set(err, CF_ERR_EXTERNAL,
                            "'%s %s' failed (exit status %d); its output ends:\n%s", prog, flag,
                            WEXITSTATUS(status), tail);
    }
    cf_status st = cf_mesh_load_tetgen_unchecked(base, m, err);
    if (st != CF_OK) {
        char msg[1024];
        snprintf(msg, sizeof msg, "%s", err ? err->msg : "");
        return cf_error_set(err, CF_ERR_EXTERNAL, "tetgen %s wrote an unreadable mesh: %s", flag,
                            msg);
    }
    return CF_OK;
}

/* ---- surface stages ------------------------------------------------------ */

static cf_status copy_surface(const cf_surface *a, cf_surface *b, cf_error *err)
{
    b->n_verts = a->n_verts, b->n_tris = a->n_tris;
    b->v = malloc((size_t)a->n_verts * 3 * sizeof(double));
    b->tri = malloc((size_t)a->n_tris * 3 * sizeof(int));
    if (!b->v || !b->tri) {
        cf_surface_free(b);
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    }
    memcpy(b->v, a->v, (size_t)a->n_verts * 3 * sizeof(double));
    memcpy(b->tri, a->tri, (size_t)a->n_tris * 3 * sizeof(int));
    return CF_OK;
}

/* Message listing up to 6 intersecting pairs with their corner vertices. */
static void describe_pairs(const cf_surface *s, const int *pairs, int n, char *out, size_t len)
{
    size_t used = 0;
    out[0] = '\0';
    for (int k = 0; k < n && k < 6 && used < len; k++) {
        const int *A = &s->tri[3 * pairs[2 * k]], *B = &s->tri[3 * pairs[2 * k + 1]];
        int w = snprintf(out + used, len - used, "%sfaces %d (%d %d %d) and %d (%d %d %d)",
                         k ? "; " : "", pairs[2 * k], A[0], A[1], A[2], pairs[2 * k + 1], B[0],
                         B[1], B[2]);
        if (w < 0)
            break;
        used += (size_t)w;
    }
    if (n > 6 && used < len)
        snprintf(out + used, len - used, "; ... (%d pairs)", n);
}

/* Self-intersection check with a report; CF_ERR_SURFACE_INTERSECT if any. */
static cf_status check_intersections(const cf_surface *s, const char *what, int verbose,
                                     cf_error *err)
{
    int pairs[2 * 64];
    int n = cf_surface_self_intersections(s, pairs, 64);
    if (n < 0)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory in the self-intersection test");
    if (n == 0)
        return CF_OK;
    char list[700];
    describe_pairs(s, pairs, n, list, sizeof list);
    if (verbose)
        fprintf(stderr, "  %s: %d intersecting face pair(s) remain: %s\n", what, n, list);
    return cf_error_set(err, CF_ERR_SURFACE_INTERSECT,
                        "%s intersects itself (0-based faces and vertices): %s. Repair the "
                        "surface (e.g. remove the offending faces and close the hole) and retry",
                        what, list);
}

/* The widest span of a surface that tetgen meshes in double precision,
 * against its short edges: beyond it a stray vertex (one at 1e10 in a file
 * of metres) has stretched the box, and tetgen's predicates lose the small
 * features or tetgen crashes. */
#define CF_SURFACE_SPAN_RATIO 1e7

/* Refuses, naming the vertex, a surface whose bounding box is more than
 * CF_SURFACE_SPAN_RATIO times its short edges (the 10th percentile of the
 * edge lengths, so that a few degenerate edges of a scan do not count). */
static cf_status check_span(const cf_surface *s, const char *what, cf_error *err)
{
    int ne = 3 * s->n_tris;
    double *len = malloc((size_t)(ne > 0 ? ne : 1) * sizeof *len);
    if (!len)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    for (int t = 0; t < s->n_tris; t++)
        for (int k = 0; k < 3; k++) {
            const double *a = &s->v[3 * s->tri[3 * t + k]], *b = &s->v[3 * s->tri[3 * t + (k + 1) % 3]];
            len[3 * t + k] = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                                  (a[2] - b[2]) * (a[2] - b[2]));
        }
    cf_doubles_sort(len, ne);
    double edge = ne > 0 ? len[ne / 10] : 0;
    free(len);
    double lo[3], hi[3], span = 0;
    points_bbox(s->v, s->n_verts, lo, hi);
    for (int k = 0; k < 3; k++)
        span = fmax(span, hi[k] - lo[k]);
    if (!(span <= CF_SURFACE_SPAN_RATIO * edge) || !isfinite(span)) {
        /* The vertex farthest from the median point names the likely stray
         * (the box's centre would sit halfway to it). */
        double c[3], *x = malloc((size_t)s->n_verts * sizeof *x);
        if (!x)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
        for (int k = 0; k < 3; k++) {
            for (int i = 0; i < s->n_verts; i++)
                x[i] = s->v[3 * i + k];
            cf_doubles_sort(x, s->n_verts);
            c[k] = x[s->n_verts / 2];
        }
        free(x);
        int far = 0;
        double best = -1;
        for (int i = 0; i < s->n_verts; i++) {
            double d = 0;
            for (int k = 0; k < 3; k++)
                d = fmax(d, fabs(s->v[3 * i + k] - c[k]));
            if (d > best)
                best = d, far = i;
        }
        const double *p = &s->v[3 * far];
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s spans %.3g (file units) but its short edges are %.3g long, "
                            "more than %.0e times shorter: vertex %d (0-based) at (%.6g, %.6g, "
                            "%.6g) is the farthest out. Move or remove stray vertices, then retry",
                            what, span, edge, CF_SURFACE_SPAN_RATIO, far, p[0], p[1], p[2]);
    }
    return CF_OK;
}

/* The area of a surface (file units squared). */
static double surface_area(const cf_surface *s)
{
    double a = 0;
    for (int t = 0; t < s->n_tris; t++) {
        const int *T = &s->tri[3 * t];
        double u[3], w[3], c[3];
        v3_sub(&s->v[3 * T[1]], &s->v[3 * T[0]], u);
        v3_sub(&s->v[3 * T[2]], &s->v[3 * T[0]], w);
        v3_cross(u, w, c);
        a += 0.5 * v3_norm(c);
    }
    return a;
}

/* The diagonal of a surface's bounding box (file units). */
static double bbox_diagonal(const cf_surface *s)
{
    double lo[3], hi[3], d[3];
    points_bbox(s->v, s->n_verts, lo, hi);
    for (int k = 0; k < 3; k++)
        d[k] = hi[k] - lo[k];
    return v3_norm(d);
}

/* Replaces `s` by its alpha wrap at the size CGAL's repair uses
 * (bullet_bridge/cf_cgal.h), saying why on stderr. */
static cf_status wrap_whole(const cf_mesh_prep_opts *o, cf_surface *s, const char *why,
                            cf_error *err)
{
    double diag = bbox_diagonal(s);
    double alpha = diag / CFC_WRAP_ALPHA_DIVISOR, offset = diag / CFC_WRAP_OFFSET_DIVISOR;
    int n0 = s->n_tris;
    cf_status st = cf_surface_wrap(s, alpha, offset, err);
    if (st == CF_OK)
        fprintf(stderr,
                "cohfrac mesh: %s %s; wrapped it instead (CGAL alpha wrapping, alpha %.4g, "
                "offset %.4g file units: the solid is that much larger all round); %d -> %d "
                "triangles\n",
                o->input, why, alpha, offset, n0, s->n_tris);
    return st;
}

/* Repairs the surface with CGAL (cf_surface_repair) and says what changed,
 * on stderr: a user must know that the mesh is not of the file as it was. */
static cf_status repair_surface(const cf_mesh_prep_opts *o, cf_surface *s, const char *defect,
                                cf_error *err)
{
    char report[512];
    cf_error why;
    cf_status st = cf_surface_repair(s, report, sizeof report, &why);
    if (st != CF_OK)
        return cf_error_set(err, st, "%s %s, and CGAL's repair failed: %s. Repair the surface "
                            "in a modeller (close it, remove overlapping parts), then retry",
                            o->input, defect, why.msg);
    fprintf(stderr, "cohfrac mesh: %s %s; repaired with CGAL: %s\n", o->input, defect, report);
    return CF_OK;
}

/* Load, repair, close-check and orient the input surface.  The cheap
 * valence-3 repair goes first, so that surfaces it fixes mesh as before;
 * what is still open or intersecting goes through CGAL's repair, once. */
static cf_status load_clean_surface(const cf_mesh_prep_opts *o, cf_surface *s, int *repaired,
                                    cf_error *err)
{
    *repaired = 0;
    cf_status st = cf_surface_load(o->input, s, err);
    if (st != CF_OK)
        return st;
    int v = o->verbose;
    if (v)
        fprintf(stderr, "cohfrac mesh: %s: %d vertices, %d triangles\n", o->input, s->n_verts,
                s->n_tris);
    if ((st = check_span(s, o->input, err)) != CF_OK)
        return st;
    int pairs[2 * 64];
    int n = cf_surface_self_intersections(s, pairs, 64);
    if (n < 0)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    if (n > 0) {
        if (v) {
            fprintf(stderr, "  %d intersecting face pair(s) (0-based faces and vertices):\n", n);
            for (int k = 0; k < n && k < 64; k++) {
                const int *A = &s->tri[3 * pairs[2 * k]], *B = &s->tri[3 * pairs[2 * k + 1]];
                fprintf(stderr, "    faces %d (%d %d %d) and %d (%d %d %d)\n", pairs[2 * k],
                        A[0], A[1], A[2], pairs[2 * k + 1], B[0], B[1], B[2]);
            }
        }
        int r = cf_surface_repair_valence3(s);
        if (r < 0)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
        if (v)
            fprintf(stderr, "  repair: removed %d valence-3 vertex(es); now %d vertices, %d "
                            "triangles\n",
                    r, s->n_verts, s->n_tris);
        n = cf_surface_self_intersections(s, pairs, 64);
        if (n < 0)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    }
    if (cf_surface_remove_unused(s) < 0)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    char why[300];
    int closed = cf_surface_check_closed(s, why, sizeof why);
    if (closed < 0)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    if ((n > 0 || !closed) && !o->no_repair) {
        char defect[400];
        if (n > 0)
            snprintf(defect, sizeof defect, "intersects itself (%d%s pair(s) of faces)", n,
                     n >= 64 ? " or more" : "");
        else
            snprintf(defect, sizeof defect, "is not a closed manifold surface (%s)", why);
        /* An open sheet is not a solid: its repair (the wrap) is a shell
         * the wrap's offset d thick on both sides, 2 d A for its area A; a
         * closed plate of thickness t encloses t A / 2.  Open surfaces
         * that enclose no more than 2.5 d A once repaired are sheets. */
        double sheet = closed ? 0.0
                              : 2.5 * surface_area(s) * bbox_diagonal(s) / CFC_WRAP_OFFSET_DIVISOR;
        if ((st = repair_surface(o, s, defect, err)) != CF_OK)
            return st;
        *repaired = 1;
        double vol = fabs(cf_surface_volume(s));
        if (!(vol > sheet))
            return cf_error_set(err, CF_ERR_MESH_PARSE,
                                "%s is an open sheet, not a solid: repaired, it encloses %.3g "
                                "(file units cubed), no more than a shell as thin as the repair's "
                                "offset around its faces.  Give a closed surface (a solid with "
                                "thickness), then retry",
                                o->input, vol);
        /* Exact intersection points rounded to double can cross again. */
        cf_error left;
        if ((st = check_intersections(s, o->input, v, &left)) == CF_ERR_SURFACE_INTERSECT &&
            (st = wrap_whole(o, s, "intersects itself again once the repair is rounded to "
                                   "double", err)) == CF_OK)
            st = check_intersections(s, o->input, v, &left);
        if (st != CF_OK)
            return cf_error_set(err, st, "after CGAL's repair, %s", left.msg);
        if ((closed = cf_surface_check_closed(s, why, sizeof why)) < 0)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    }
    if (n > 0 && o->no_repair)
        return check_intersections(s, o->input, v, err);
    if (!closed)
        return cf_error_set(err, CF_ERR_MESH_PARSE,
                            "%s is not a closed manifold surface%s: %s (0-based indices). Close "
                            "the holes and fix the orientation%s, then retry",
                            o->input, o->no_repair ? "" : ", even after CGAL's repair", why,
                            o->no_repair ? " (or drop --no-repair)" : "");
    if (v)
        fprintf(stderr, "  no intersections left\n");
    double vol = cf_surface_volume(s);
    if (vol < 0) {
        cf_surface_flip(s); /* inside-out: tetgen does not care, our volume check does */
        vol = -vol;
        if (v)
            fprintf(stderr, "  surface was oriented inwards; flipped\n");
    }
    if (!(vol > 0))
        return cf_error_set(err, CF_ERR_MESH_PARSE, "%s encloses no volume", o->input);
    if (v)
        fprintf(stderr, "  closed manifold, enclosed volume %.9g\n", vol);
    return CF_OK;
}

/* The next decimation's triangle count: 15 % more, even, and at least two
 * more (below 14, 15 % more rounds back down to the same even count, and
 * the retries would never reach the full surface). */
static int more_tris(int tris)
{
    int n = (int)(tris * 1.15) & ~1;
    return n > tris ? n : tris + 2;
}

/* A coarsened surface `out` with n self-intersecting pairs and closed
 * (cf_surface_check_closed's answer): 1 when it is clean and kept;
 * otherwise freed, and 0, or -1 with `err` set when a check ran out of
 * memory. */
static int keep_if_clean(cf_surface *out, int n, int closed, cf_error *err)
{
    if (n == 0 && closed == 1)
        return 1;
    cf_surface_free(out);
    if (n < 0 || closed < 0) {
        cf_error_set(err, CF_ERR_NOMEM, "out of memory");
        return -1;
    }
    return 0;
}

/* Decimate a copy of `full` to about `tris` triangles, without
 * self-intersections or folds: retried with 15 % more triangles each time
 * (meshoptimizer does not promise either) while the count stays below
 * `limit`.  1 with `out` set when one was clean, 0 when none was, or -1
 * with `err` set. */
static int decimate_clean(const cf_surface *full, int tris, int limit, cf_surface *out,
                          int verbose, cf_error *err)
{
    for (; tris < limit; tris = more_tris(tris)) {
        if (copy_surface(full, out, err) != CF_OK)
            return -1;
        double t0 = cf_wall_time();
        int got = cf_surface_decimate(out, tris);
        if (got < 0) {
            cf_surface_free(out);
            cf_error_set(err, CF_ERR_NOMEM, "out of memory in decimation");
            return -1;
        }
        int n = cf_surface_self_intersections(out, NULL, 0);
        char why[300];
        int closed = cf_surface_check_closed(out, why, sizeof why);
        if (verbose)
            fprintf(stderr,
                    "  decimated to %d triangles, %d vertices (asked %d) in %.2f s; volume "
                    "%.9g; %d intersecting pairs%s\n",
                    got, out->n_verts, tris, cf_wall_time() - t0, cf_surface_volume(out), n,
                    closed == 0 ? "; folded (not a closed manifold)" : "");
        int kept = keep_if_clean(out, n, closed, err);
        if (kept != 0)
            return kept;
    }
    return 0;
}

/* The most a remeshed surface's enclosed volume may differ from the
 * decimated surface's (relative) for it to be used instead. */
#define REMESH_VOLUME_TOL 0.02

/* The edge length of `tris` equilateral triangles over the area of `s`. */
static double edge_for(const cf_surface *s, int tris)
{
    return sqrt(4.0 * surface_area(s) / (sqrt(3.0) * tris));
}

/* `full` remeshed isotropically (cf_surface_remesh) to about `tris`
 * triangles, near equilateral, so that no tet with a face on the surface
 * is a sliver that sets the explicit step (docs/physics.md §3.1).  1 with
 * `out` set when the result is closed, does not intersect itself and
 * encloses `volume` within the relative `tol` (the surface it would
 * replace, named `what` in the verbose lines); 0 with `out` freed when it
 * does not or CGAL failed (the caller keeps that surface), -1 with `err`
 * set when memory ran out. */
static int remesh_clean(const cf_surface *full, int tris, double volume, double tol,
                        const char *what, cf_surface *out, int verbose, cf_error *err)
{
    double edge = edge_for(full, tris), t0 = cf_wall_time();
    if (copy_surface(full, out, err) != CF_OK)
        return -1;
    cf_error why = {0};
    cf_status st = cf_surface_remesh(out, edge, &why);
    if (st == CF_ERR_NOMEM) {
        cf_surface_free(out);
        *err = why;
        return -1;
    }
    int n = 0, closed = 0;
    char open[300];
    if (st == CF_OK) {
        n = cf_surface_self_intersections(out, NULL, 0);
        closed = cf_surface_check_closed(out, open, sizeof open);
    }
    if (verbose && st == CF_OK)
        fprintf(stderr,
                "  remeshed to %d triangles, %d vertices (edge %.4g, asked %d) in %.2f s; "
                "volume %.9g; %d intersecting pairs%s\n",
                out->n_tris, out->n_verts, edge, tris, cf_wall_time() - t0,
                cf_surface_volume(out), n, closed == 0 ? "; not a closed manifold" : "");
    else if (verbose)
        fprintf(stderr, "  no remeshing (%s): the %s surface kept\n", why.msg, what);
    int kept = keep_if_clean(out, n, closed, err);
    if (kept <= 0)
        return kept;
    double vr = cf_surface_volume(out);
    if (fabs(vr - volume) <= tol * fabs(volume))
        return 1;
    if (verbose)
        fprintf(stderr, "  the remeshed surface's volume is %.2f %% off the %s one's: the %s "
                        "surface kept\n", 100 * (vr - volume) / volume, what, what);
    cf_surface_free(out);
    return 0;
}

/* A surface triangle with an angle below this makes the tets on it thin:
 * with -Y tetgen keeps the surface as it is, and the scanned bunny's 70k
 * triangles (9 below 5 degrees, the smallest 0.007) gave its 201,778-tet
 * mesh a tet 4e-5 times the median's step (docs/physics.md §3.1). */
#define SLIVER_TRIANGLE_DEG 5.0

/* The smallest angle of any triangle of `s`, degrees. */
static double smallest_angle(const cf_surface *s)
{
    double least = 180;
    for (int t = 0; t < s->n_tris; t++)
        for (int k = 0; k < 3; k++) {
            const double *a = &s->v[3 * s->tri[3 * t + k]];
            const double *b = &s->v[3 * s->tri[3 * t + (k + 1) % 3]];
            const double *c = &s->v[3 * s->tri[3 * t + (k + 2) % 3]];
            double u[3], w[3], x[3];
            v3_sub(b, a, u);
            v3_sub(c, a, w);
            v3_cross(u, w, x);
            least = fmin(least, atan2(v3_norm(x), v3_dot(u, w)) * 180 / M_PI);
        }
    return least;
}

/* How far the full surface's remeshing may move its enclosed volume
 * (relative).  The remeshing keeps its vertices on the surface but cuts
 * across sharp edges, which it does not protect: a part's feature lines
 * rounded by a triangle's width lose about a percent of a coarse part's
 * volume, where the scanned bunny's remeshing moves it by 0.03 %.  So a
 * part whose edges the remeshing would round keeps its own triangles. */
#define FULL_REMESH_VOLUME_TOL 0.001

/* The full surface `s` at its own triangle count, remeshed (remesh_clean)
 * into `out` when it has a triangle with an angle below
 * SLIVER_TRIANGLE_DEG and the remeshed surface is clean and keeps its
 * volume within FULL_REMESH_VOLUME_TOL: 1 then, 0 when `s` stays, -1 with
 * `err` set when memory ran out. */
static int even_out(const cf_surface *s, cf_surface *out, int verbose, cf_error *err)
{
    double least = smallest_angle(s);
    if (least >= SLIVER_TRIANGLE_DEG)
        return 0;
    if (verbose)
        fprintf(stderr, "  a surface triangle has an angle of %.3g degrees: remeshing it at "
                        "%d triangles\n", least, s->n_tris);
    return remesh_clean(s, s->n_tris, cf_surface_volume(s), FULL_REMESH_VOLUME_TOL, "full",
                        out, verbose, err);
}

/* A clean decimation that needs more than WRAP_AFTER times the triangles
 * asked for means features (thin parts, close sheets) finer than the
 * triangles asked for: tetgen would resolve them with tets far smaller than
 * the rest, which set the explicit step.  The surface is then wrapped at
 * that triangle size first (cf_surface_wrap), closing over them, and the
 * wrap is decimated instead. */
#define WRAP_AFTER 2.0

/* Coarsen `full` to about `tris` triangles: decimated without
 * self-intersections or folds (decimate_clean), then, unless `may_wrap`
 * is 0 (--no-repair keeps the surface's own vertices), remeshed
 * isotropically instead (remesh_clean) where that is clean and keeps the
 * decimation's volume within REMESH_VOLUME_TOL; failing the decimation
 * within WRAP_AFTER times as many,
 * its alpha wrap at the edge length of `tris` equilateral triangles over
 * its area (offset a thirtieth of that, CGAL's advice); failing that, with
 * more triangles up to the full surface, which is clean
 * (load_clean_surface) and is then what `out` gets.  No wrap unless
 * `may_wrap` (--no-repair keeps the surface's shape). */
static cf_status coarsen(const cf_surface *full, int tris, cf_surface *out, int may_wrap,
                         int verbose, cf_error *err)
{
    int got = decimate_clean(full, tris, (int)fmin(full->n_tris, WRAP_AFTER * tris), out,
                             verbose, err);
    if (got > 0 && may_wrap) {
        /* The remeshed surface when it keeps the decimation's volume: on
         * a surface too coarse for its curvature, near-equilateral
         * triangles cut across it (the 1,000-tet bunny loses 7 % more). */
        cf_surface r = {0};
        int ok = remesh_clean(full, tris, cf_surface_volume(out), REMESH_VOLUME_TOL,
                              "decimated", &r, verbose, err);
        if (ok != 0)
            cf_surface_free(out);
        if (ok < 0)
            return err->code;
        if (ok > 0)
            *out = r;
    }
    if (got != 0)
        return got > 0 ? CF_OK : err->code;
    if (may_wrap && WRAP_AFTER * tris < full->n_tris) {
        double edge = edge_for(full, tris);
        cf_surface w = {0};
        cf_status st = copy_surface(full, &w, err);
        if (st == CF_OK)
            st = cf_surface_wrap(&w, edge, edge / 30.0, err);
        if (st == CF_OK) {
            got = decimate_clean(&w, tris, w.n_tris, out, verbose, err);
            if (got > 0)
                fprintf(stderr,
                        "cohfrac mesh: the surface cannot be decimated to %d triangles without "
                        "intersecting itself (parts thinner than its triangles): wrapped it "
                        "first (CGAL alpha wrapping, alpha %.4g, offset %.4g file units)\n",
                        tris, edge, edge / 30.0);
        }
        cf_surface_free(&w);
        if (st == CF_ERR_NOMEM || got < 0)
            return err->code;
        if (got > 0)
            return CF_OK;
        tris = (int)(WRAP_AFTER * tris);
    }
    if ((got = decimate_clean(full, tris, full->n_tris, out, verbose, err)) != 0)
        return got > 0 ? CF_OK : err->code;
    if (verbose)
        fprintf(stderr, "  no decimation without intersections or folds: the full surface (%d "
                        "triangles) is used\n",
                full->n_tris);
    return copy_surface(full, out, err);
}

/* One tetgen run on `s` written to <dir>/surf.off. */
typedef struct trial {
    char opts[64];
    cf_mesh m;
} trial;

/* With a target, tetgen may add at most STEINER_PER_TARGET_TET x target
 * points (-S): about 4 x target tets at its 0.25 nodes per tet, so a
 * surface it keeps refining cannot run to millions of tets. */
#define STEINER_PER_TARGET_TET 1.0

static cf_status tetgen_trial(const prep *p, const char *opts, trial *t, cf_error *err)
{
    const cf_mesh_prep_opts *o = p->o;
    if (o->target_tets > 0)
        snprintf(t->opts, sizeof t->opts, "%sS%.0f", opts,
                 ceil(STEINER_PER_TARGET_TET * o->target_tets));
    else
        snprintf(t->opts, sizeof t->opts, "%s", opts);
    double secs = 0;
    cf_status st = run_tetgen(p, t->opts, &t->m, &secs, err);
    if (st == CF_OK && o->verbose)
        fprintf(stderr, "  tetgen -%s: %d nodes, %d tets (%.2f s)\n", t->opts, t->m.n_nodes,
                t->m.n_tets, secs);
    return st;
}

static double miss(int n, int target) { return fabs(log((double)n / (double)target)); }

/* Whether the size search may go on after a tetgen trial that failed with
 * `st`: it crashed or failed on this surface and options (not a stop or
 * the time limit, which end the search) while a valid mesh is in hand,
 * which is then kept.  Says so on stderr, with tetgen's reason. */
static int survive_failed_trial(cf_status st, const prep *p, int have_mesh, cf_error *err)
{
    if (st != CF_ERR_EXTERNAL || !have_mesh || cf_wall_time() >= p->deadline)
        return 0;
    char first[200];
    snprintf(first, sizeof first, "%.199s", err ? err->msg : "");
    char *end = strstr(first, ". "); /* its first sentence: what happened */
    if (end)
        *end = 0;
    if ((end = strchr(first, '\n')) != NULL)
        *end = 0;
    fprintf(stderr, "cohfrac mesh: warning: a tetgen trial failed (%s); the size search goes on "
                    "with the closest valid mesh so far\n", first);
    return 1;
}

/* Surface choice and tetgen runs for target_tets > 0; see the top comment.
 * `s` is the clean full surface; on success `best` holds the mesh and
 * `used` the surface it was made from (a decimated copy or `s` itself). */
static cf_status fit_size(const cf_surface *s, const prep *p, trial *best, cf_surface *dec,
                          const cf_surface **used, cf_error *err)
{
    const char *dir = p->dir;
    int target = p->o->target_tets, verbose = p->o->verbose;
    char off[PATH_MAX];
    snprintf(off, sizeof off, "%s/surf.off", dir);
    const cf_surface *cur = s;
    cf_status st;
    trial t = {{0}, {0}};
    *used = s;
    int n_tris = s->n_tris;
    int n = -1; /* tets of the last -pYq2.0 run on `cur` */
    if (TETS_PER_TRI * s->n_tris > 2.0 * target) {
        /* Clearly too fine: decimate right away from the estimate. */
        n_tris = (int)(0.9 * target / TETS_PER_TRI) & ~1;
    }
    trial prev = {{0}, {0}}; /* the last valid trial, kept if the next one fails */
    cf_surface prev_dec = {0};
    const cf_surface *prev_cur = NULL;
    for (int round = 0; round < 4; round++) {
        if (t.m.n_tets > 0) {
            cf_mesh_free(&prev.m);
            cf_surface_free(&prev_dec);
            prev = t, t = (trial){{0}, {0}};
            prev_cur = cur == s ? s : &prev_dec;
            if (cur != s && (st = copy_surface(cur, &prev_dec, err)) != CF_OK)
                break;
        }
        if (n_tris < s->n_tris) {
            cf_surface_free(dec);
            if ((st = coarsen(s, n_tris < 8 ? 8 : n_tris, dec, !p->o->no_repair, verbose, err)) != CF_OK)
                break;
            cur = dec;
        } else if (round == 0 && !p->o->no_repair) {
            /* the full surface, evened out where its own triangles are
             * slivers */
            cf_surface_free(dec);
            int even = even_out(s, dec, verbose, err);
            if (even < 0) {
                st = err->code;
                break;
            }
            cur = even ? dec : s;
        } else {
            cur = s;
        }
        if ((st = cf_surface_write_off(cur, off, err)) != CF_OK)
            break;
        if ((st = tetgen_trial(p, BASE_OPTS "F", &t, err)) != CF_OK) {
            if (!survive_failed_trial(st, p, prev.m.n_tets > 0, err))
                break;
            st = CF_OK; /* back to the previous trial and its surface */
            cf_mesh_free(&t.m);
            t = prev, prev = (trial){{0}, {0}};
            if (prev_cur == s) {
                cur = s;
            } else {
                cf_surface_free(dec);
                *dec = prev_dec, prev_dec = (cf_surface){0};
                cur = dec;
            }
            n = t.m.n_tets;
            break;
        }
        n = t.m.n_tets;
        if (n <= (1 + TOL) * target || cur->n_tris <= 8)
            break;
        if (cur != s && cur->n_tris > n_tris + n_tris / 10)
            break; /* decimation stalled: cannot get coarser */
        /* tets grow about linearly with surface triangles at fixed q */
        n_tris = (int)((double)cur->n_tris * 0.9 * target / n) & ~1;
    }
    cf_mesh_free(&prev.m);
    cf_surface_free(&prev_dec);
    if (st != CF_OK) {
        cf_mesh_free(&t.m);
        return st;
    }
    *used = cur;
    *best = t;
    /* Too coarse for the target even with -Y: split every triangle in four
     * (the same surface, so the same enclosed volume) while the tets stay
     * short of it and do not overshoot. */
    for (int k = 0; k < MAX_SUBDIVISIONS && n < (1 - TOL) * target; k++) {
        cf_surface fine = {0};
        trial f = {{0}, {0}};
        if ((st = copy_surface(cur, &fine, err)) != CF_OK)
            return st;
        if (cf_surface_subdivide(&fine) != 0) {
            cf_surface_free(&fine);
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory subdividing the surface");
        }
        if ((st = cf_surface_write_off(&fine, off, err)) != CF_OK ||
            (st = tetgen_trial(p, BASE_OPTS "F", &f, err)) != CF_OK) {
            cf_surface_free(&fine);
            cf_mesh_free(&f.m);
            if (!survive_failed_trial(st, p, 1, err))
                return st;
            /* the closest so far is `best`, from `cur`: tetgen's surface
             * file goes back to it for the fill below */
            if ((st = cf_surface_write_off(cur, off, err)) != CF_OK)
                return st;
            break;
        }
        if (verbose)
            fprintf(stderr, "  subdivided the surface to %d triangles\n", fine.n_tris);
        int over = f.m.n_tets > (1 + TOL) * target;
        if (over && miss(f.m.n_tets, target) >= miss(n, target)) {
            /* overshoots by more than the coarse one falls short: fill that */
            cf_mesh_free(&f.m);
            cf_surface_free(&fine);
            if ((st = cf_surface_write_off(cur, off, err)) != CF_OK)
                return st;
            break;
        }
        cf_mesh_free(&best->m);
        *best = f;
        n = f.m.n_tets;
        cf_surface_free(dec);
        *dec = fine;
        cur = dec;
        *used = cur;
        if (over)
            return CF_OK; /* the closest there is: filling only adds tets */
    }
    if (n >= (1 - TOL) * target)
        return CF_OK;
    /* Fill with a maximum volume: N(a) ~ N0 + C / a. */
    double V = cf_surface_volume(cur);
    double a_prev = INFINITY, n_prev = n;
    double a = V / (target - n);
    const char *base_opts = BASE_OPTS;
    for (int run = 0; run < MAX_A_RUNS; run++) {
        char opts[64];
        snprintf(opts, sizeof opts, "%sa%.3gF", base_opts, a);
        a = strtod(strchr(opts, 'a') + 1, NULL); /* exactly the value tetgen gets */
        trial u = {{0}, {0}};
        if ((st = tetgen_trial(p, opts, &u, err)) != CF_OK) {
            cf_mesh_free(&u.m);
            if (survive_failed_trial(st, p, 1, err))
                break; /* `best` stays the closest */
            cf_mesh_free(&best->m);
            return st;
        }
        int nu = u.m.n_tets;
        if (miss(nu, target) < miss(best->m.n_tets, target)) {
            cf_mesh_free(&best->m);
            *best = u;
        } else {
            cf_mesh_free(&u.m);
        }
        if (fabs((double)nu / target - 1) <= TOL)
            break;
        if (run == 0 && nu - n < 0.1 * (target - n)) {
            /* -Y blocks the fill: on a coarse surface every tet touches
             * the boundary and cannot be split without splitting a facet.
             * Let tetgen add points on the facets (the shape is kept: they
             * lie in the facets' planes). */
            base_opts = "pq2.0";
            if (verbose)
                fprintf(stderr, "  the surface is too coarse to fill with -Y; letting tetgen "
                                "refine it\n");
            continue;
        }
        /* Fit N = N0 + C / a through this run and the previous one. */
        double inv_p = isinf(a_prev) ? 0.0 : 1.0 / a_prev, inv = 1.0 / a;
        double Cfit = (nu - n_prev) / (inv - inv_p);
        double N0 = nu - Cfit * inv;
        double next = (Cfit > 0 && target > N0) ? Cfit / (target - N0)
                                                : (nu < target ? a / 2 : a * 2);
        /* keep steps moderate: within a factor of 4 */
        if (next > 4 * a)
            next = 4 * a;
        if (next < a / 4)
            next = a / 4;
        a_prev = a, n_prev = nu, a = next;
    }
    return CF_OK;
}

/* ---- the command ---------------------------------------------------------- */

/* Prints what sets the mesh's explicit step (cf_mesh_quality_of). */
static void report_quality(const cf_mesh *m)
{
    cf_mesh_quality q = cf_mesh_quality_of(m);
    fprintf(stderr,
            "  quality: smallest dihedral angle %.2f deg; dt_cfl of the worst tet (%d) / the "
            "median's %.3f\n",
            q.min_dihedral, q.worst_tet, q.dt_ratio);
}

static cf_status write_stamp(const cf_mesh_prep_opts *o, const char *key, const char *opts,
                             int n_tris, const cf_mesh *m, cf_error *err)
{
    char *sp = str_cat(o->output, ".stamp"), *tmp = str_cat(o->output, ".stamp.tmp");
    FILE *f = sp && tmp ? fopen(tmp, "w") : NULL;
    cf_status st = CF_OK;
    if (!f) { /* str_cat or fopen out of memory is memory, not the disk */
        st = !sp || !tmp ? cf_error_set(err, CF_ERR_NOMEM, "out of memory writing the stamp")
                  : cf_error_set(err, cf_status_of_errno(errno, CF_ERR_OUTPUT),
                                 "%s: cannot write (%s)", tmp, strerror(errno));
    } else {
        fprintf(f, "%s", key);
        cf_mesh_quality q = cf_mesh_quality_of(m);
        fprintf(f,
                "# informational\ntetgen -%s\nsurface_triangles %d\nnodes %d\ntets %d\n"
                "min_dihedral_deg %.4g\ndt_cfl_worst_over_median %.4g\n",
                opts, n_tris, m->n_nodes, m->n_tets, q.min_dihedral, q.dt_ratio);
        int bad = ferror(f);
        bad |= fclose(f) != 0;
        if (bad || rename(tmp, sp) != 0)
            st = cf_error_set(err, CF_ERR_OUTPUT, "%s: write failed", sp);
    }
    free(sp);
    free(tmp);
    return st;
}

/* Drops a trial's mesh and decimated surface, for another try. */
static void forget_trial(trial *best, cf_surface *dec)
{
    cf_mesh_free(&best->m);
    *best = (trial){{0}, {0}};
    cf_surface_free(dec);
}

/* Tetgen on the clean surface `s` (to the target, fit_size), the tets
 * oriented and checked (non-degenerate, filling the surface's volume):
 * *best, on *used (s or its decimation, kept in *dec). */
static cf_status tetrahedralise(const prep *p, const cf_surface *s, trial *best, cf_surface *dec,
                                const cf_surface **used, cf_error *err)
{
    const cf_mesh_prep_opts *o = p->o;
    cf_status st;
    if (o->target_tets == 0) {
        char off[PATH_MAX];
        snprintf(off, sizeof off, "%s/surf.off", p->dir);
        if ((st = cf_surface_write_off(s, off, err)) != CF_OK ||
            (st = tetgen_trial(p, "pqF", best, err)) != CF_OK)
            return st;
    } else if ((st = fit_size(s, p, best, dec, used, err)) != CF_OK) {
        return st;
    }
    double off_by = o->target_tets > 0 ? (double)best->m.n_tets / o->target_tets - 1 : 0;
    if (fabs(off_by) > MISS_ALLOWED) /* the closest valid mesh is kept, and said to be off */
        fprintf(stderr,
                "cohfrac mesh: warning: --target-tets %d missed by more than %.0f%% for %s: "
                "kept the closest mesh tetgen made, %d tets (%+.0f%%; %s).  Ask for about %d "
                "to make it again without this warning, or 0 for tetgen's own choice\n",
                o->target_tets, 100 * MISS_ALLOWED, o->input, best->m.n_tets, 100 * off_by,
                off_by > 0 ? "thin parts need smaller tets than that at tetgen's quality bound"
                           : "refining further needs more points than --target-tets allows "
                             "tetgen to add",
                best->m.n_tets);

    /* Orientation: flip what tetgen wrote the other way round, then insist
     * on positive, non-degenerate tets. */
    int flipped = cf_mesh_orient_positive(&best->m);
    if (o->verbose)
        fprintf(stderr, "  orientation: %d of %d tets flipped to det[x1-x0,x2-x0,x3-x0] > 0\n",
                flipped, best->m.n_tets);
    double vs = cf_surface_volume(*used), vm = cf_mesh_volume(&best->m);
    double rel = fabs(vm - vs) / vs;
    if (o->verbose)
        fprintf(stderr, "  volume: tets %.12g, surface %.12g (relative difference %.2g)\n", vm,
                vs, rel);
    if (!(rel <= 1e-5)) /* round-off is 1e-16 with -Y, ~1e-6 where tetgen splits facets */
        return cf_error_set(err, CF_ERR_EXTERNAL,
                            "tetgen -%s: tet volume %.12g differs from the surface's enclosed "
                            "volume %.12g by %.2g (relative): tetgen did not fill the surface; "
                            "check the surface is closed and does not intersect itself",
                            best->opts, vm, vs, rel);
    /* Boundary caps set the explicit step where -Y keeps the surface
     * (src/mesh/mesh_quality.c); peeling them changes the volume by theirs.
     * Flat caps on nearly coplanar facets go with them, before the check. */
    int peeled;
    double peeled_volume;
    if ((st = cf_mesh_peel_slivers(&best->m, PEEL_FRACTION, &peeled, &peeled_volume, err)) !=
        CF_OK)
        return st;
    if (o->verbose)
        fprintf(stderr,
                "  slivers: %d boundary cap(s) thinner than %.2g x the median tet peeled "
                "(%.2g of the volume)\n",
                peeled, PEEL_FRACTION, peeled_volume / vm);
    cf_error bad;
    if ((st = cf_mesh_check(&best->m, "tetgen output", &bad)) != CF_OK) {
        char *advice = strstr(bad.msg, ": re-run tetgen"); /* for a user's own files */
        if (advice)
            *advice = '\0';
        return cf_error_set(err, st,
                            "%s.  tetgen made it from the surface as decimated for "
                            "--target-tets %d: ask for another --target-tets (the surface is "
                            "decimated differently), or 0 for tetgen's own choice",
                            bad.msg, o->target_tets);
    }
    return CF_OK;
}

cf_status cf_mesh_prepare(const cf_mesh_prep_opts *o, cf_error *err)
{
    if (!o || !o->input || !o->output || !*o->output)
        return cf_error_set(err, CF_ERR_USAGE, "cohfrac mesh needs an input surface and -o OUT");
    if (o->target_tets < 0)
        return cf_error_set(err, CF_ERR_USAGE, "--target-tets must be >= 0 (got %d)",
                            o->target_tets);
    double t_start = cf_wall_time();
    char key[PATH_MAX + 512];
    cf_status st = stamp_key(o, key, sizeof key, err);
    if (st != CF_OK)
        return st;
    if (cache_valid(o, key)) {
        if (o->verbose) {
            fprintf(stderr, "cohfrac mesh: %s.node/.ele up to date (cached)\n", o->output);
            cf_mesh m = {0};
            cf_error ignored;
            if (cf_mesh_load_tetgen(o->output, &m, &ignored) == CF_OK)
                report_quality(&m);
            cf_mesh_free(&m);
        }
        return CF_OK;
    }
    if ((st = make_parent_dirs(o->output, err)) != CF_OK)
        return st;

    cf_surface s = {0}, dec = {0};
    const cf_surface *used = &s;
    trial best = {{0}, {0}};
    char dir[512] = ""; /* short, so every path built from it fits PATH_MAX */
    int repaired;
    if ((st = load_clean_surface(o, &s, &repaired, err)) != CF_OK)
        goto out;
    const char *tmpdir = getenv("TMPDIR");
    if (!tmpdir || !*tmpdir || strlen(tmpdir) > 400)
        tmpdir = "/tmp";
    snprintf(dir, sizeof dir, "%s/cohfrac-mesh-XXXXXX", tmpdir);
    if (!mkdtemp(dir)) {
        st = cf_error_set(err, CF_ERR_OUTPUT, "cannot create a temporary directory %s (%s)", dir,
                          strerror(errno));
        dir[0] = '\0';
        goto out;
    }
    double limit = o->time_limit > 0 ? o->time_limit : CF_MESH_TIME_LIMIT;
    prep pr = {o, dir, limit, t_start + limit};
    st = tetrahedralise(&pr, &s, &best, &dec, &used, err);
    if ((st == CF_ERR_MESH_PARSE || st == CF_ERR_MESH_INVERTED || st == CF_ERR_EXTERNAL) &&
        repaired && !o->no_repair &&
        cf_wall_time() < pr.deadline) {
        /* The union or autorefinement leaves slivers of triangles along the
         * cuts, which tetgen can turn into flat tets or crash on. */
        char why[1200];
        snprintf(why, sizeof why, "as repaired, gives tetgen trouble (%s)", err->msg);
        forget_trial(&best, &dec);
        used = &s;
        if ((st = wrap_whole(o, &s, why, err)) == CF_OK)
            st = tetrahedralise(&pr, &s, &best, &dec, &used, err);
    }
    /* A flat tet comes from how the surface was decimated for the target:
     * a target 15 % either side decimates it differently. */
    static const double nudge[] = {0.85, 1.15};
    cf_mesh_prep_opts alt = *o;
    prep pr_alt = pr;
    pr_alt.o = &alt;
    for (int k = 0; k < 2 && st == CF_ERR_MESH_INVERTED && o->target_tets > 0 &&
                    cf_wall_time() < pr.deadline;
         k++) {
        alt.target_tets = (int)lround(o->target_tets * nudge[k]);
        fprintf(stderr, "cohfrac mesh: warning: %s; trying --target-tets %d\n", err->msg,
                alt.target_tets);
        forget_trial(&best, &dec);
        used = &s;
        st = tetrahedralise(&pr_alt, &s, &best, &dec, &used, err);
    }
    if (st != CF_OK)
        goto out;
    if (o->verbose)
        report_quality(&best.m);
    if ((st = cf_mesh_write_tetgen(&best.m, o->output, err)) != CF_OK ||
        (st = write_stamp(o, key, best.opts, used->n_tris, &best.m, err)) != CF_OK)
        goto out;
    if (o->verbose)
        fprintf(stderr, "cohfrac mesh: wrote %s.node/.ele: %d nodes, %d tets (tetgen -%s) in "
                        "%.1f s\n",
                o->output, best.m.n_nodes, best.m.n_tets, best.opts, cf_wall_time() - t_start);
out:
    if (dir[0])
        remove_tree(dir);
    cf_mesh_free(&best.m);
    cf_surface_free(&dec);
    cf_surface_free(&s);
    return st;
}
