/* `cohfrac bench`: the fracture-mode step against the memory floor, the
 * thread speed-up and the btSoftBody peer (src/cli/bench.h). */
#include "bench.h"

#include "clock.h"
#include "cohfrac/mesh.h"
#include "cohfrac/sim.h"
#include "file_text.h"
#include "process.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static const char *criterion_name[] = {"traction", "source", "none"};

static double cpu_time(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* STREAM-like triad a = b + s c on `threads` threads: bytes/s (24 per
 * element), best of 5; 0 when the arrays cannot be had. */
static double triad_bandwidth(int threads)
{
    size_t n = (size_t)CF_BENCH_TRIAD_MB * 1048576 / sizeof(double);
    double *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b), *c = malloc(n * sizeof *c);
    double best = INFINITY;
    if (a && b && c) {
        omp_set_num_threads(threads);
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++) /* first touch by the threads that use them */
            a[i] = 0, b[i] = 1, c[i] = 2;
        for (int r = 0; r < 5; r++) {
            double t0 = cf_wall_time();
#pragma omp parallel for schedule(static)
            for (size_t i = 0; i < n; i++)
                a[i] = b[i] + 3.0 * c[i];
            best = fmin(best, cf_wall_time() - t0);
        }
    }
    int ok = a && b && c && a[n / 2] == 7.0;
    free(a), free(b), free(c);
    return ok ? 24.0 * (double)n / best : 0;
}

static int by_value(const void *x, const void *y)
{
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

/* The median of v[n], which it sorts. */
static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, by_value);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* The bench scene for the prepared mesh `name` under `criterion`, built in
 * C: the source's bunny drop (its material and PBD settings, Table 6.1),
 * in fracture mode from the first step, the body turned onto its side
 * with its lowest point on the floor, falling at 4.43 m/s.  The mesh is
 * loaded once, here, and kept in *mesh for every world made from the
 * scene (the engine copies it; cf_mesh_free releases it).  Errors: those
 * of cf_mesh_load_tetgen, named with the advice to prepare the mesh;
 * CF_ERR_NOMEM. */
static cf_status make_scene(const cf_bench_options *o, const char *name, cf_criterion criterion,
                            cf_scene *sc, cf_mesh *mesh, cf_error *err)
{
    *sc = cf_default_scene(); /* 1 s, no output file */
    memset(mesh, 0, sizeof *mesh);
    snprintf(sc->name, sizeof sc->name, "bench");
    cf_world_def *w = &sc->world;
    cf_material *mat = &w->material;
    mat->E = 0.6, mat->nu = 0.23, mat->rho = 2400;
    mat->G_I = mat->G_II = 22, mat->sigma_max = mat->tau_max = 1e-4, mat->alpha = mat->beta = 2;
    mat->friction = 0.5, mat->restitution = 0;
    cf_solver_settings *so = &w->solver;
    so->mode = CF_RUN_FRACTURE, so->criterion = criterion;
    so->dt_rigid = so->dt_fracture = 5e-6;
    so->k_stiffness = 0.9, so->iterations = 3, so->k_damping = 1;
    w->bodies = calloc(1, sizeof *w->bodies);
    w->obstacles = calloc(1, sizeof *w->obstacles);
    sc->sources = calloc(1, sizeof *sc->sources);
    if (!w->bodies || !w->obstacles || !sc->sources) {
        cf_scene_free(sc);
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory for the bench scene");
    }
    w->n_bodies = w->n_obstacles = 1;
    snprintf(sc->sources[0].mesh, sizeof sc->sources[0].mesh, "%s/%s", o->mesh_dir, name);
    cf_error why = {0};
    cf_status st = cf_mesh_load_tetgen(sc->sources[0].mesh, mesh, &why);
    if (st != CF_OK) {
        cf_scene_free(sc);
        return cf_error_set(err, st, "bench mesh '%s': %s (prepare it with `make meshes`, or "
                                     "`cohfrac mesh SURFACE -o %s/%s`)",
                            name, why.msg, o->mesh_dir, name);
    }
    /* Turned a quarter about x (the mesh's y axis up becomes z), so the
     * half height along y puts the lowest point on the plane z = 0. */
    double lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < mesh->n_nodes; i++)
        lo = fmin(lo, mesh->x[3 * i + 1]), hi = fmax(hi, mesh->x[3 * i + 1]);
    cf_body_def *b = &w->bodies[0];
    *b = cf_default_body();
    b->tet_mesh = mesh;
    b->orientation[0] = b->orientation[1] = 0.7071067811865476;
    b->orientation[2] = b->orientation[3] = 0;
    b->velocity[2] = -4.43;
    w->obstacles[0] = cf_default_obstacle(CF_OBSTACLE_PLANE);
    w->obstacles[0].point[2] = -0.5 * (hi - lo);
    return CF_OK;
}

typedef struct sample {
    double ms, cpu_ms, stage[CF_STAGE_COUNT]; /* per step */
    long insertions;
    cf_step_stats stats;
    double memory; /* engine bytes */
} sample;

/* One repeat: build the world, `warmup` steps, then `steps` timed ones. */
static cf_status time_steps(const cf_bench_options *o, const cf_scene *sc, int threads,
                            sample *out, cf_error *err)
{
    cf_run_options ro = {.progress = 0, .threads = threads, .mesh_dir = o->mesh_dir};
    cf_sim *sim = NULL;
    cf_status st = cf_sim_create(sc, &ro, &sim, err);
    for (int k = 0; st == CF_OK && k < o->warmup; k++)
        st = cf_sim_advance(sim, err);
    cf_step_stats a, b;
    if (st == CF_OK)
        cf_world_step_stats(cf_sim_world(sim), &a);
    double w0 = cf_wall_time(), c0 = cpu_time();
    for (int k = 0; st == CF_OK && k < o->steps; k++)
        st = cf_sim_advance(sim, err);
    double wall = cf_wall_time() - w0, cpu = cpu_time() - c0;
    if (st == CF_OK) {
        cf_world_step_stats(cf_sim_world(sim), &b);
        double n = (double)(b.fracture_steps - a.fracture_steps);
        out->ms = 1e3 * wall / n, out->cpu_ms = 1e3 * cpu / n;
        for (int i = 0; i < CF_STAGE_COUNT; i++)
            out->stage[i] = 1e3 * (b.stage[i] - a.stage[i]) / n;
        out->insertions = b.cohesive - a.cohesive;
        out->stats = b;
        cf_memory m;
        cf_sim_memory(sim, &m);
        out->memory = (double)(m.solid + m.fracture + m.cohesive + m.fragments + m.collision);
    }
    cf_sim_destroy(sim);
    return st;
}

/* The peer on the same mesh, steps and dt: its ms per step (min), or a
 * negative number when it failed (the log is kept and named). */
static double run_peer(const cf_bench_options *o, const cf_scene *sc, cf_error *err)
{
    char log[] = "/tmp/cohfrac_peer_XXXXXX", steps[32], dt[32];
    int fd = mkstemp(log);
    if (fd < 0)
        return cf_error_set(err, CF_ERR_EXTERNAL, "cannot create a log for the peer"), -1;
    close(fd);
    snprintf(steps, sizeof steps, "%d", o->steps);
    snprintf(dt, sizeof dt, "%.17g", sc->world.solver.dt_fracture);
    char *argv[] = {(char *)o->peer, (char *)sc->sources[0].mesh, "--steps", steps, "--dt", dt,
                    "--iterations", "3", NULL};
    pid_t pid;
    int status = 0;
    if (cf_spawn(argv, log, &pid) != 0 || cf_wait(pid, &status, NULL) < 0 ||
        !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        cf_error_set(err, CF_ERR_EXTERNAL, "the btSoftBody peer %s failed: see %s", o->peer, log);
        return -1;
    }
    char *text = cf_file_read(log, NULL);
    const char *line = text ? strstr(text, "peer: ") : NULL;
    const char *ms = line ? strstr(line, "ms_min=") : NULL;
    double v = ms ? atof(ms + 7) : -1;
    free(text);
    if (v <= 0)
        return cf_error_set(err, CF_ERR_EXTERNAL, "no 'peer:' line from %s: see %s", o->peer,
                            log), -1;
    unlink(log);
    return v;
}

static void summarize(sample *s, int n, cf_bench_timing *t)
{
    double v[64];
    for (int i = 0; i < n; i++)
        v[i] = s[i].ms;
    qsort(v, (size_t)n, sizeof *v, by_value);
    t->ms_min = v[0];
    t->ms_median = median(v, n);
    int mid = 0; /* the repeat whose time is the median: its stage split */
    for (int i = 0; i < n; i++)
        if (fabs(s[i].ms - t->ms_median) < fabs(s[mid].ms - t->ms_median))
            mid = i;
    for (int i = 0; i < n; i++)
        v[i] = s[i].cpu_ms;
    t->cpu_ms = median(v, n);
    memcpy(t->stage, s[mid].stage, sizeof t->stage);
    t->insertions = s[mid].insertions;
}

static void print_row(FILE *f, const char *what, const cf_bench_timing *t, int tets)
{
    fprintf(f, "  %-10s %8.2f %9.2f %8.2f %9.1f", what, t->ms_min, t->ms_median, t->cpu_ms,
            1e6 * t->ms_min / tets);
    for (int i = CF_STAGE_SOLVER_FIRST; i <= CF_STAGE_SOLVER_LAST; i++)
        fprintf(f, " %*.2f", (int)strlen(cf_stage_name((cf_stage)i)), t->stage[i]);
    fprintf(f, " %10ld\n", t->insertions);
}

cf_status cf_bench_run(const cf_bench_options *o, cf_bench_result *r, cf_error *err)
{
    memset(r, 0, sizeof *r);
    int nt = o->threads > 0 ? o->threads : omp_get_num_procs();
    int reps = o->repeats < 1 ? 1 : o->repeats > 64 ? 64 : o->repeats;
    FILE *log = o->log;
    cf_scene sc;
    cf_mesh mesh;
    cf_status st = make_scene(o, o->mesh, o->criterion, &sc, &mesh, err);
    if (st != CF_OK)
        return st;
    r->threads = nt;
    if (log)
        fprintf(log,
                "cohfrac bench: mesh %s, criterion %s, %d steps x %d repeats after %d warm-up "
                "steps, dt %.3g s\n",
                o->mesh, criterion_name[o->criterion], o->steps, reps, o->warmup,
                sc.world.solver.dt_fracture);
    sample s1[64], sn[64];
    double peer[64];
    int np = 0;
    for (int i = 0; i < reps && st == CF_OK; i++) {
        /* The bandwidth in every repeat too, best over the run like the
         * step's minimum, so that the floor and the step sample the same
         * minutes of a machine whose memory speed moves with its load. */
        double bw_1t = triad_bandwidth(1), bw_nt = triad_bandwidth(nt);
        r->bw_1t = fmax(r->bw_1t, bw_1t), r->bw_nt = fmax(r->bw_nt, bw_nt);
        st = time_steps(o, &sc, 1, &s1[i], err);
        if (st == CF_OK)
            st = time_steps(o, &sc, nt, &sn[i], err);
        if (st == CF_OK && o->peer) {
            peer[np] = run_peer(o, &sc, err);
            st = peer[np++] > 0 ? CF_OK : CF_ERR_EXTERNAL;
        }
        if (st == CF_OK && log) {
            fprintf(log, "repeat %d/%d: triad %.1f GB/s; 1 thread %.2f ms, %d threads %.2f ms", i + 1,
                    reps, bw_nt / 1e9, s1[i].ms, nt, sn[i].ms);
            if (o->peer)
                fprintf(log, ", btSoftBody %.2f ms", peer[np - 1]);
            fprintf(log, " per step\n");
            fflush(log);
        }
    }
    if (st != CF_OK) {
        cf_scene_free(&sc), cf_mesh_free(&mesh);
        return st;
    }
    cf_step_stats *z = &sn[0].stats;
    r->tets = z->tets, r->nodes = z->nodes, r->bars = z->bars;
    r->colours = z->colours, r->serial_bars = z->serial_bars;
    r->bytes = cf_step_traffic(z);
    summarize(s1, reps, &r->t1);
    summarize(sn, reps, &r->tn);
    r->floor_ms = r->bw_nt > 0 ? 1e3 * r->bytes / r->bw_nt : 0;
    r->ratio = r->floor_ms > 0 ? r->tn.ms_min / r->floor_ms : 0;
    r->speedup = r->t1.ms_min / r->tn.ms_min;
    r->memory_per_tet = sn[0].memory / z->tets;
    if (np) {
        qsort(peer, (size_t)np, sizeof *peer, by_value);
        r->peer_ms = peer[0];
        r->peer_ratio = r->peer_ms / r->t1.ms_min;
    }
    if (log) {
        fprintf(log,
                "memory bandwidth (triad, 3 x %d MiB, best of the repeats): 1 thread %.1f GB/s, "
                "%d threads %.1f GB/s\n"
                "solid: %d tets, %d nodes, %d bars (%d colours, %d bars on one thread) in fracture "
                "mode at the end; engine memory %.0f B per tet\n"
                "traffic model: %.1f MB per step -> floor %.3f ms at %.1f GB/s (docs/performance.md)\n"
                "  %-10s %8s %9s %8s %9s",
                CF_BENCH_TRIAD_MB, r->bw_1t / 1e9, nt, r->bw_nt / 1e9, r->tets, r->nodes, r->bars,
                r->colours, r->serial_bars, r->memory_per_tet,
                r->bytes / 1e6, r->floor_ms, r->bw_nt / 1e9, "threads", "min ms", "median ms",
                "CPU ms", "ns/tet");
        for (int i = CF_STAGE_SOLVER_FIRST; i <= CF_STAGE_SOLVER_LAST; i++)
            fprintf(log, " %s", cf_stage_name((cf_stage)i));
        fprintf(log, " %10s\n", "insertions");
        char what[32];
        print_row(log, "1", &r->t1, r->tets);
        snprintf(what, sizeof what, "%d", nt);
        print_row(log, what, &r->tn, r->tets);
        fprintf(log, "  (stage columns: ms per step in the median repeat; insertions: cohesive "
                     "elements inserted in the timed steps)\n");
        if (np)
            fprintf(log,
                    "peer_ratio = %.2f (btSoftBody %.2f ms / cohfrac %.2f ms per step, both on 1 "
                    "thread; min of %d); btSoftBody steps on one thread only: against cohfrac on "
                    "%d threads %.2f\n",
                    r->peer_ratio, r->peer_ms, r->t1.ms_min, np, nt, r->peer_ms / r->tn.ms_min);
        fprintf(log, "bench: tets=%d step_ms=%.3f floor_ms=%.3f ratio=%.2f speedup_%dt=%.2f", r->tets,
                r->tn.ms_min, r->floor_ms, r->ratio, nt, r->speedup);
        if (np)
            fprintf(log, " peer_ratio=%.2f", r->peer_ratio);
        fputc('\n', log);
    }
    cf_scene_free(&sc), cf_mesh_free(&mesh);
    return CF_OK;
}

cf_status cf_bench_scaling(const cf_bench_options *o, const char *const *meshes, int n,
                           double *exponent, double *bytes_per_tet, cf_error *err)
{
    int nt = o->threads > 0 ? o->threads : omp_get_num_procs();
    int reps = o->repeats < 1 ? 1 : o->repeats > 64 ? 64 : o->repeats;
    FILE *log = o->log;
    *bytes_per_tet = 0;
    cf_scene *sc = calloc((size_t)(n > 0 ? n : 1), sizeof *sc);
    cf_mesh *mesh = calloc((size_t)(n > 0 ? n : 1), sizeof *mesh);
    sample *last = calloc((size_t)(n > 0 ? n : 1), sizeof *last);
    double *best = malloc((size_t)(n > 0 ? n : 1) * sizeof *best);
    if (!sc || !mesh || !last || !best) {
        free(sc), free(mesh), free(last), free(best);
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory for the scaling bench");
    }
    int made = 0; /* scenes made (a failed one holds nothing) */
    cf_status st = CF_OK;
    while (made < n && st == CF_OK) {
        best[made] = INFINITY;
        st = make_scene(o, meshes[made], CF_CRITERION_NONE, &sc[made], &mesh[made], err);
        made += st == CF_OK;
    }
    if (st == CF_OK && log)
        fprintf(log, "cohfrac bench --scaling: criterion none, %d threads, %d steps, min of %d "
                     "(the meshes interleaved in each repeat)\n",
                nt, o->steps, reps);
    /* Each repeat runs every mesh, so that a load on the shared machine
     * hits all of them alike and the exponent does not follow it. */
    for (int k = 0; k < reps && st == CF_OK; k++) {
        for (int i = 0; i < n && st == CF_OK; i++) {
            st = time_steps(o, &sc[i], nt, &last[i], err);
            best[i] = st == CF_OK ? fmin(best[i], last[i].ms) : best[i];
        }
        if (st == CF_OK && log) {
            fprintf(log, "repeat %d/%d:", k + 1, reps);
            for (int i = 0; i < n; i++)
                fprintf(log, " %.2f", last[i].ms);
            fprintf(log, " ms per step\n");
            fflush(log);
        }
    }
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    if (st == CF_OK && log)
        fprintf(log, "  %-28s %9s %9s %11s %13s\n", "mesh", "tets", "step ms", "ns/tet-step",
                "memory B/tet");
    for (int i = 0; i < n && st == CF_OK; i++) {
        double tets = last[i].stats.tets, bpt = last[i].memory / tets;
        *bytes_per_tet = fmax(*bytes_per_tet, bpt);
        double x = log10(tets), y = log10(best[i]);
        sx += x, sy += y, sxx += x * x, sxy += x * y;
        if (log)
            fprintf(log, "  %-28s %9d %9.2f %11.1f %13.0f\n", meshes[i], last[i].stats.tets,
                    best[i], 1e6 * best[i] / tets, bpt);
    }
    for (int i = 0; i < made; i++)
        cf_scene_free(&sc[i]), cf_mesh_free(&mesh[i]);
    free(sc), free(mesh), free(last), free(best);
    if (st != CF_OK)
        return st;
    *exponent = n > 1 ? (n * sxy - sx * sy) / (n * sxx - sx * sx) : 1;
    if (log)
        fprintf(log, "bench scaling: exponent=%.3f (ms ~ tets^b, least squares) bytes_per_tet=%.0f\n",
                *exponent, *bytes_per_tet);
    return CF_OK;
}

/* One run of a scene (cf_bench_scene): wall and CPU s with and without
 * fracture mode, simulated s of fracture mode, tet-steps, rigid-only steps. */
typedef struct scene_sample {
    double wall, fracture_wall, fracture_cpu, fracture_t, rigid_wall;
    long long tet_steps;
    long rigid_steps;
} scene_sample;

static cf_status scene_once(const cf_bench_options *o, const cf_bench_scene_options *so,
                            scene_sample *out, cf_error *err)
{
    cf_scene def;
    const char **sets = malloc((size_t)(so->n_overrides + 1) * sizeof *sets);
    if (!sets)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    for (int i = 0; i < so->n_overrides; i++)
        sets[i] = so->overrides[i];
    sets[so->n_overrides] = "output.file=\"\"";
    cf_status st = cf_scene_load(so->scene, sets, so->n_overrides + 1, o->mesh_dir, &def, err);
    free(sets);
    if (st != CF_OK)
        return st;
    cf_run_options ro = {.progress = 0, .threads = o->threads, .mesh_dir = o->mesh_dir};
    cf_sim *sim = NULL;
    st = cf_sim_create(&def, &ro, &sim, err);
    memset(out, 0, sizeof *out);
    double w0 = cf_wall_time();
    while (st == CF_OK && !cf_sim_done(sim) &&
           !(so->fracture_ms > 0 && out->fracture_t >= 1e-3 * so->fracture_ms)) {
        cf_step_stats a, b;
        cf_world_step_stats(cf_sim_world(sim), &a);
        double w = cf_wall_time(), c = cpu_time();
        st = cf_sim_advance(sim, err);
        w = cf_wall_time() - w, c = cpu_time() - c;
        cf_world_step_stats(cf_sim_world(sim), &b);
        if (b.fracture_steps > a.fracture_steps) {
            out->fracture_wall += w, out->fracture_cpu += c;
            out->fracture_t += b.fracture_time - a.fracture_time;
            out->tet_steps += b.tet_steps - a.tet_steps;
        } else {
            out->rigid_wall += w, out->rigid_steps++;
        }
    }
    out->wall = cf_wall_time() - w0;
    cf_sim_destroy(sim);
    cf_scene_free(&def);
    return st;
}

cf_status cf_bench_scene(const cf_bench_options *o, const cf_bench_scene_options *so,
                         cf_bench_scene_result *r, cf_error *err)
{
    int n = o->repeats > 0 ? o->repeats : 1;
    scene_sample *s = calloc((size_t)n, sizeof *s);
    double *v = malloc((size_t)n * sizeof *v);
    if (!s || !v) {
        free(s), free(v);
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    }
    memset(r, 0, sizeof *r);
    cf_status st = CF_OK;
    for (int k = 0; k < n && st == CF_OK; k++) {
        st = scene_once(o, so, &s[k], err);
        if (st == CF_OK && o->log)
            fprintf(o->log, "repeat %d: %.2f s, fracture mode %.3f ms simulated in %.2f s\n", k + 1,
                    s[k].wall, 1e3 * s[k].fracture_t, s[k].fracture_wall);
    }
    if (st == CF_OK) {
        r->fracture_ms = 1e3 * s[0].fracture_t;
        for (int k = 0; k < n; k++)
            v[k] = s[k].fracture_t > 0 ? s[k].fracture_wall / (1e3 * s[k].fracture_t) : 0;
        r->s_per_fracture_ms_median = median(v, n);
        r->s_per_fracture_ms_min = v[0]; /* median sorted them */
        for (int k = 0; k < n; k++)
            r->tet_steps_per_s = fmax(r->tet_steps_per_s, s[k].fracture_wall > 0
                                      ? (double)s[k].tet_steps / s[k].fracture_wall : 0);
        for (int k = 0; k < n; k++)
            v[k] = s[k].fracture_t > 0 ? s[k].fracture_cpu / (1e3 * s[k].fracture_t) : 0;
        r->cpu_s_per_fracture_ms = median(v, n);
        for (int k = 0; k < n; k++)
            v[k] = s[k].rigid_steps > 0 ? 1e3 * s[k].rigid_wall / (double)s[k].rigid_steps : 0;
        r->rigid_step_ms = median(v, n);
        for (int k = 0; k < n; k++)
            v[k] = s[k].wall;
        r->wall_median = median(v, n);
        r->wall_min = v[0];
        if (o->log)
            fprintf(o->log,
                    "bench-scene: %s fracture_ms=%.3f s_per_fracture_ms_min=%.3f "
                    "s_per_fracture_ms_median=%.3f cpu_s_per_fracture_ms=%.3f "
                    "tet_steps_per_s=%.4g rigid_step_ms=%.4f wall_min=%.2f wall_median=%.2f "
                    "repeats=%d\n",
                    so->scene, r->fracture_ms, r->s_per_fracture_ms_min,
                    r->s_per_fracture_ms_median, r->cpu_s_per_fracture_ms, r->tet_steps_per_s,
                    r->rigid_step_ms, r->wall_min, r->wall_median, n);
    }
    free(s), free(v);
    return st;
}
