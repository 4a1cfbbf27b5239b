/* cohfrac study: error against run time over a grid of settings
 * (src/cli/study.h). */
#define _GNU_SOURCE
#include "cohfrac/version.h"
#include "study.h"
#include "study_metrics.h"
#include "cohfrac/surface.h"
#include "cohfrac/world.h"

#include "clock.h"
#include "cohfrac/scene.h"
#include "file_text.h"
#include "hash.h"
#include "linalg.h"
#include "mpi_cases.h"
#include "process.h"
#include "report.h"
#include "trajectory.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static const char *const default_reference[] = {"solver.constraints=\"none\"",
                                                "solver.cfl_fraction=0.5"};

/* One --vary axis: the key and its values (Lua expressions). */
typedef struct axis {
    char *key;
    char **values;
    int n;
} axis;

/* A case while it is set up and run. */
typedef struct job {
    const char **sets;  /* its overrides after the common ones */
    int n_sets;
    char *text;         /* the resolved scene */
    int same_as;        /* an earlier case with the same resolved scene, -1 none */
    char lua[1200], h5[1200], log[1200], meta[1200];
    pid_t pid;
    double t_start;
    double cost;        /* the work estimate that orders cases over MPI ranks */
} job;

/* Split "key=v1,v2" at the commas outside {}, (), [] and quotes. */
static cf_status parse_axis(const char *spec, axis *a, cf_error *err)
{
    memset(a, 0, sizeof *a);
    const char *eq = strchr(spec, '=');
    if (!eq || eq == spec || !eq[1])
        return cf_error_set(err, CF_ERR_USAGE,
                            "--vary '%s': expected KEY.PATH=V1,V2,... (Lua values)", spec);
    a->key = strndup(spec, (size_t)(eq - spec));
    a->values = calloc(strlen(eq), sizeof *a->values);
    if (!a->key || !a->values)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    int depth = 0;
    char quote = 0;
    const char *start = eq + 1;
    for (const char *c = start;; c++) {
        if (quote) {
            if (*c == '\\' && c[1])
                c++;
            else if (*c == quote)
                quote = 0;
            else if (!*c)
                return cf_error_set(err, CF_ERR_USAGE, "--vary '%s': unclosed quote", spec);
            continue;
        }
        if (*c == '"' || *c == '\'')
            quote = *c;
        else if (*c == '{' || *c == '(' || *c == '[')
            depth++;
        else if (*c == '}' || *c == ')' || *c == ']')
            depth--;
        else if ((*c == ',' && depth == 0) || !*c) {
            if (c == start)
                return cf_error_set(err, CF_ERR_USAGE, "--vary '%s': empty value", spec);
            if (!(a->values[a->n] = strndup(start, (size_t)(c - start))))
                return cf_error_set(err, CF_ERR_NOMEM, "--vary '%s': out of memory", spec);
            a->n++;
            start = c + 1;
            if (!*c)
                break;
        }
    }
    return CF_OK;
}

static void free_axis(axis *a)
{
    for (int i = 0; i < a->n; i++)
        free(a->values[i]);
    free(a->values), free(a->key);
}

static char *format(const char *fmt, const char *a, const char *b)
{
    size_t n = strlen(fmt) + strlen(a) + strlen(b) + 1;
    char *s = malloc(n);
    if (s)
        snprintf(s, n, fmt, a, b);
    return s;
}

/* The work a case asks for if it stayed in fracture mode throughout, to
 * hand out the largest cases first: tets x fracture steps (duration /
 * dt_fracture, or over cfl_fraction x dt_cfl) x (1 + PBD iterations).
 * Only an ordering: 0 when the meshes cannot be made (the run will say
 * why). */
static double case_cost(cf_scene *scene, const char *mesh_dir)
{
    cf_world_def *sc = &scene->world;
    cf_world_meshes wm;
    cf_error e;
    if (cf_world_meshes_load(sc, scene->sources, mesh_dir, &wm, &e) != CF_OK)
        return 0;
    double tets = 0, dt_cfl = INFINITY;
    for (int b = 0; b < sc->n_bodies; b++) {
        const cf_body_def *body = &sc->bodies[b];
        tets += body->tet_mesh->n_tets;
        dt_cfl = fmin(dt_cfl, cf_mesh_dt_cfl(body->tet_mesh, body->scale, &sc->material));
    }
    cf_world_meshes_free(&wm);
    const cf_solver_settings *so = &sc->solver;
    double dt = so->cfl_fraction > 0 ? so->cfl_fraction * dt_cfl : so->dt_fracture;
    double cost = tets * scene->duration / dt * (1 + so->iterations);
    return isfinite(cost) ? cost : 0;
}

/* Load the case's scene (common overrides, its own, no output file) and
 * hash the resolved text; the scene's name into `name` (128 bytes). */
static cf_status resolve_case(const cf_study_options *o, job *j, cf_study_case *c, char *name,
                              cf_error *err)
{
    int n = o->n_overrides + j->n_sets + 1;
    const char **all = malloc((size_t)n * sizeof *all);
    if (!all)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    for (int i = 0; i < o->n_overrides; i++)
        all[i] = o->overrides[i];
    for (int i = 0; i < j->n_sets; i++)
        all[o->n_overrides + i] = j->sets[i];
    all[n - 1] = "output.file=\"\"";
    cf_scene sc;
    cf_error e2 = {0};
    cf_status st = cf_scene_load(o->scene, all, n, o->mesh_dir, &sc, &e2);
    free(all);
    if (st != CF_OK)
        return cf_error_set(err, st, "case '%s': %s", c->label, e2.msg);
    uint64_t h = cf_fnv1a(CF_FNV1A_SEED, sc.resolved, strlen(sc.resolved));
    h = cf_fnv1a(h, COHFRAC_VERSION_STRING, strlen(COHFRAC_VERSION_STRING));
    snprintf(c->hash, sizeof c->hash, "%016" PRIx64, h);
    snprintf(name, 128, "%s", sc.name);
    if (cf_mpi_size() > 1 && cf_mpi_rank() == 0)
        j->cost = case_cost(&sc, o->mesh_dir);
    j->text = strdup(sc.resolved);
    cf_scene_free(&sc);
    return j->text ? CF_OK : cf_error_set(err, CF_ERR_NOMEM, "out of memory");
}

/* Write runs/<hash>.<ext>, whole or not at all, from a printf format. */
static cf_status write_run_file(const char *runs, const char *hash, const char *ext,
                                cf_error *err, const char *fmt, ...)
{
    char fname[32];
    snprintf(fname, sizeof fname, "%s.%s", hash, ext);
    cf_outfile f;
    cf_status st = cf_out_open(&f, runs, fname, err);
    if (st != CF_OK)
        return st;
    va_list ap;
    va_start(ap, fmt);
    vfprintf(f.f, fmt, ap);
    va_end(ap);
    return cf_out_close(&f, err);
}

/* Name the case's files under `runs`. */
static void name_case(job *j, const cf_study_case *c, const char *runs)
{
    snprintf(j->lua, sizeof j->lua, "%s/%s.lua", runs, c->hash);
    snprintf(j->h5, sizeof j->h5, "%s/%s.h5", runs, c->hash);
    snprintf(j->log, sizeof j->log, "%s/%s.log", runs, c->hash);
    snprintf(j->meta, sizeof j->meta, "%s/%s.meta", runs, c->hash);
}

/* Write runs/<hash>.lua. */
static cf_status write_case(const job *j, const cf_study_case *c, const char *runs,
                            cf_error *err)
{
    return write_run_file(runs, c->hash, "lua", err, "-- %s (resolved by cohfrac %s)\n%s",
                          c->label, COHFRAC_VERSION_STRING, j->text);
}

/* A cached case: runs/<hash>.meta holds "exit wall cpu peak_rss". */
static int read_meta(const job *j, cf_study_case *c)
{
    FILE *f = fopen(j->meta, "r");
    if (!f)
        return 0;
    int ok = fscanf(f, "%d %lf %lf %lf", &c->exit_code, &c->wall, &c->cpu, &c->peak_rss) == 4;
    fclose(f);
    return ok;
}

static cf_status start_case(const cf_study_options *o, job *j, int threads, cf_error *err)
{
    char th[16];
    snprintf(th, sizeof th, "%d", threads);
    const char *argv[] = {o->exe, "run", j->lua, "-q", "-t", th, "-m", o->mesh_dir,
                          "-o", j->h5, NULL};
    unlink(j->meta);
    unlink(j->h5);
    j->t_start = cf_wall_time();
    int rc = cf_spawn((char *const *)argv, j->log, &j->pid);
    if (rc != 0)
        return cf_error_set(err, CF_ERR_EXTERNAL, "cannot run '%s' (%s)", o->exe, strerror(rc));
    return CF_OK;
}

/* Record a finished case's figures and write its .meta. */
static cf_status record_case(const job *j, cf_study_case *c, int status, const struct rusage *ru,
                             const char *runs, cf_error *err)
{
    c->wall = cf_wall_time() - j->t_start;
    c->cpu = ru->ru_utime.tv_sec + 1e-6 * ru->ru_utime.tv_usec + ru->ru_stime.tv_sec +
             1e-6 * ru->ru_stime.tv_usec;
    c->peak_rss = 1024.0 * (double)ru->ru_maxrss;
    c->exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return write_run_file(runs, c->hash, "meta", err, "%d %.6f %.6f %.0f\n", c->exit_code,
                          c->wall, c->cpu, c->peak_rss);
}

/* Wait for any running case; record it. */
static cf_status reap_case(job *jobs, cf_study_case *cases, int n, const char *runs, int *done,
                           cf_error *err)
{
    int status;
    struct rusage ru;
    pid_t pid = cf_wait(-1, &status, &ru);
    if (pid < 0)
        return cf_error_set(err, CF_ERR_EXTERNAL, "waiting for a case failed (%s)",
                            strerror(errno));
    for (int i = 0; i < n; i++) {
        if (jobs[i].pid != pid)
            continue;
        jobs[i].pid = 0;
        *done = i;
        return record_case(&jobs[i], &cases[i], status, &ru, runs, err);
    }
    *done = -1;
    return CF_OK;
}

/* ---- Report ------------------------------------------------------------ */

static void csv_quoted(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"')
            fputc('"', f); /* a quote is doubled */
        fputc(*s, f);
    }
    fputc('"', f);
}

static const char *status_word(int code)
{
    return code == 0 ? "ok" : code == 3 ? "diverged" : code >= 128 ? "killed" : "failed";
}

static cf_status write_csv(const char *dir, const cf_study_case *c, int n, const axis *ax,
                           int n_ax, char ***values, int best, cf_error *err)
{
    cf_outfile f;
    cf_status st = cf_out_open(&f, dir, "study.csv", err);
    if (st != CF_OK)
        return st;
    fputs("case,label", f.f);
    for (int a = 0; a < n_ax; a++)
        fputc(',', f.f), csv_quoted(f.f, ax[a].key);
    fputs(",hash,exit_code,status,cached,t_end,wall,cpu,peak_rss_mib,n_fragments,traj_rms,"
          "traj_rel,mass_ks,crack_area,dissipated,p_err,l_err,residual_rel,speedup,pareto,best\n",
          f.f);
    for (int i = 0; i < n; i++) {
        fprintf(f.f, "%d,", i);
        csv_quoted(f.f, c[i].label);
        for (int a = 0; a < n_ax; a++)
            fputc(',', f.f), csv_quoted(f.f, i ? values[i][a] : "");
        fprintf(f.f,
                ",%s,%d,%s,%d,%.9g,%.4f,%.4f,%.2f,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,"
                "%.4g,%d,%d\n",
                c[i].hash, c[i].exit_code, status_word(c[i].exit_code), c[i].cached, c[i].t_end,
                c[i].wall, c[i].cpu, c[i].peak_rss / 1048576.0, c[i].n_fragments, c[i].traj_rms,
                c[i].traj_rel, c[i].mass_ks, c[i].crack_area, c[i].dissipated, c[i].p_err,
                c[i].l_err, c[i].residual_rel, c[i].speedup, c[i].pareto, i == best);
    }
    return cf_out_close(&f, err);
}

static cf_status write_md(const cf_study_options *o, const cf_study_result *res,
                          const char *const *ref, int n_ref, const axis *ax, int n_ax,
                          char ***values, int threads, cf_error *err)
{
    cf_outfile f;
    cf_status st = cf_out_open(&f, res->out_dir, "study.md", err);
    if (st != CF_OK)
        return st;
    FILE *m = f.f;
    const cf_study_case *c = res->cases, *r = &c[0];
    char mach[512], date[32];
    cf_report_stamp(mach, sizeof mach, date);
    fprintf(m, "<!-- cohfrac study, %s, %s; regenerate with: %s -->\n", date, mach,
            o->command ? o->command : "cohfrac study");
    fprintf(m, "# Study: %s\n\n", res->scene_name);
    fprintf(m, "Scene `%s`", o->scene);
    for (int i = 0; i < o->n_overrides; i++)
        fprintf(m, "%s `%s`", i ? "," : " with", o->overrides[i]);
    char spread[64];
    if (cf_mpi_size() > 1)
        snprintf(spread, sizeof spread, "over %d MPI ranks", cf_mpi_size());
    else
        snprintf(spread, sizeof spread, "%d at a time", o->jobs);
    fprintf(m, ". Machine: %s; cohfrac %s; %s. %d cases, %s with %d thread%s each; %d "
               "reused from the cache.\n\n",
            mach, COHFRAC_VERSION_STRING, date, res->n_cases, spread, threads, threads > 1 ? "s" : "",
            res->n_cached);
    fputs("**Reference**:", m);
    for (int i = 0; i < n_ref; i++)
        fprintf(m, "%s `%s`", i ? "," : "", ref[i]);
    fprintf(m, "; %s, reached t = %.4g s in %.1f s of wall time, %d fragments; the "
               "initial bodies' centres of mass travel D = %.4g m (RMS over the frames).\n\n",
            status_word(r->exit_code), r->t_end, r->wall, r->n_fragments, res->travel);
    if (r->exit_code != 0)
        fprintf(m, "**The reference did not finish (%s, exit %d; see runs/%s.log)**: the "
                   "errors below cover only the frames it reached, and no verdict is given.\n\n",
                status_word(r->exit_code), r->exit_code, r->hash);
    fputs("Metrics against the reference: *traj rel* the mass-weighted RMS distance between "
          "matched fragments' centres of mass over time (*traj RMS*, m) divided by D; *mass "
          "KS* the Kolmogorov-Smirnov distance of the final fragment-mass distributions; "
          "*P err*, *L err* the relative difference of the final linear and angular momentum; "
          "*residual* the case's own energy-ledger residual over its initial energy plus work "
          "input; wall time and peak resident memory of the run's process "
          "(src/cli/study.h gives the exact definitions).\n\n",
          m);
    fputs("| case |", m);
    for (int a = 0; a < n_ax; a++)
        fprintf(m, " %s |", ax[a].key);
    fputs(" status | wall (s) | speed-up | peak RSS (MiB) | fragments | traj RMS (m) | traj rel "
          "| mass KS | crack area (m^2) | dissipated (J) | P err | L err | residual | Pareto |\n|",
          m);
    for (int a = 0; a < n_ax + 15; a++)
        fputs("---|", m);
    fputc('\n', m);
    for (int i = 0; i < res->n_cases; i++) {
        if (i)
            fprintf(m, "| %d |", i);
        else
            fputs("| reference |", m);
        for (int a = 0; a < n_ax; a++)
            fprintf(m, " %s |", i ? values[i][a] : "");
        fprintf(m,
                " %s%s | %.2f | %.3g | %.0f | %d | %.3g | %s%.3g%s | %.3g | %.4g | %.4g | %.2g | "
                "%.2g | %.2g | %s |\n",
                status_word(c[i].exit_code), c[i].cached ? " (cached)" : "", c[i].wall,
                c[i].speedup, c[i].peak_rss / 1048576.0, c[i].n_fragments, c[i].traj_rms,
                i == res->best ? "**" : "", c[i].traj_rel, i == res->best ? "**" : "",
                c[i].mass_ks, c[i].crack_area, c[i].dissipated, c[i].p_err, c[i].l_err,
                c[i].residual_rel, c[i].pareto ? "yes" : "");
    }
    fputs("\n**Pareto front** (no other finished case is both faster and closer to the "
          "reference), fastest first:\n\n",
          m);
    double last = -1;
    for (int k = 0; k < res->n_cases; k++) { /* by wall time, ascending */
        int next = -1;
        for (int i = 1; i < res->n_cases; i++)
            if (c[i].pareto && c[i].wall > last && (next < 0 || c[i].wall < c[next].wall))
                next = i;
        if (next < 0)
            break;
        fprintf(m, "- case %d, `%s`: %.2f s (speed-up %.3g), traj rel %.3g, %d fragments\n",
                next, c[next].label, c[next].wall, c[next].speedup, c[next].traj_rel,
                c[next].n_fragments);
        last = c[next].wall;
    }
    double tol = o->tolerance > 0 ? o->tolerance : 0.05;
    if (r->exit_code != 0)
        fputs("\n**Verdict**: none (the reference did not finish).\n", m);
    else if (res->best >= 0)
        fprintf(m, "\n**Verdict**: the cheapest setting within %.3g%% trajectory error of the "
                   "reference is case %d, `%s`: %.2f s against the reference's %.2f s "
                   "(speed-up %.3g), traj rel %.3g.\n",
                100 * tol, res->best, c[res->best].label, c[res->best].wall, r->wall,
                c[res->best].speedup, c[res->best].traj_rel);
    else
        fprintf(m, "\n**Verdict**: no finished case is within %.3g%% trajectory error of the "
                   "reference.\n",
                100 * tol);
    return cf_out_close(&f, err);
}

/* ---- The study ----------------------------------------------------------- */

/* Start every case not cached, `jobs` at a time, and wait for them all. */
static cf_status run_cases(const cf_study_options *o, job *jobs, cf_study_case *c, int n,
                           const char *runs, int threads, cf_error *err)
{
    int running = 0, finished = 0, to_run = 0;
    cf_status st = CF_OK;
    for (int i = 0; i < n; i++)
        to_run += !c[i].cached && jobs[i].same_as < 0;
    for (int i = 0; i <= n && st == CF_OK; i++) {
        while (running > 0 && (running >= o->jobs || i == n)) {
            int k;
            st = reap_case(jobs, c, n, runs, &k, err);
            if (st != CF_OK || k < 0)
                break;
            running--, finished++;
            if (o->progress)
                fprintf(stderr, "[%d/%d] %s: %s, %.1f s\n", finished, to_run, c[k].label,
                        status_word(c[k].exit_code), c[k].wall);
        }
        if (i < n && !c[i].cached && jobs[i].same_as < 0 && st == CF_OK) {
            st = start_case(o, &jobs[i], threads, err);
            running += st == CF_OK;
        }
    }
    while (running > 0) { /* after an error: do not leave children behind */
        int status;
        if (cf_wait(-1, &status, NULL) < 0)
            break;
        running--;
    }
    return st;
}

/* ---- Over MPI ranks (mpi_cases.h) ---------------------------------------- */

/* A case's figures as the ranks send them: exit code, wall, CPU, peak RSS. */
enum { CASE_FIGURES = 4 };

typedef struct ranked {
    const cf_study_options *o;
    job *jobs;
    cf_study_case *c;
    const char *runs;
    int threads, finished, to_run;
} ranked;

/* On any rank: run case i as a child process and write its .meta. */
static void run_ranked(int i, double *out, void *user)
{
    ranked *r = user;
    cf_study_case c = r->c[i];
    cf_error e = {0};
    int status = 127 << 8; /* "could not run" unless it did */
    struct rusage ru = {0};
    cf_status st = start_case(r->o, &r->jobs[i], r->threads, &e);
    if (st == CF_OK && cf_wait(r->jobs[i].pid, &status, &ru) < 0)
        st = cf_error_set(&e, CF_ERR_EXTERNAL, "waiting for the case failed (%s)",
                          strerror(errno));
    if (st == CF_OK)
        st = record_case(&r->jobs[i], &c, status, &ru, r->runs, &e);
    if (st != CF_OK) {
        fprintf(stderr, "cohfrac study (rank %d): case %d (%s): %s\n", cf_mpi_rank(), i,
                c.label, e.msg);
        c.exit_code = 127, c.wall = c.cpu = c.peak_rss = 0;
    }
    double fig[CASE_FIGURES] = {c.exit_code, c.wall, c.cpu, c.peak_rss};
    memcpy(out, fig, sizeof fig);
}

/* On rank 0, as each case finishes. */
static void ranked_done(int i, const double *fig, int rank, void *user)
{
    ranked *r = user;
    cf_study_case *c = &r->c[i];
    c->exit_code = (int)fig[0], c->wall = fig[1], c->cpu = fig[2], c->peak_rss = fig[3];
    r->finished++;
    if (r->o->progress)
        fprintf(stderr, "[%d/%d] %s: %s, %.1f s (rank %d)\n", r->finished, r->to_run, c->label,
                status_word(c->exit_code), c->wall, rank);
}

static int by_cost(const void *a, const void *b, void *jobs)
{
    const job *j = jobs;
    int x = *(const int *)a, y = *(const int *)b;
    return j[x].cost < j[y].cost ? 1 : j[x].cost > j[y].cost ? -1 : x - y;
}

/* Every case not cached over the MPI ranks, the largest first. */
static cf_status run_ranks(const cf_study_options *o, job *jobs, cf_study_case *c, int n,
                           const char *runs, int threads, cf_error *err)
{
    ranked r = {o, jobs, c, runs, threads, 0, 0};
    int *order = malloc(((size_t)n + 1) * sizeof *order);
    double *fig = malloc(((size_t)n + 1) * CASE_FIGURES * sizeof *fig);
    cf_status st = CF_OK;
    if (!order || !fig)
        st = cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    for (int i = 0; st == CF_OK && cf_mpi_rank() == 0 && i < n; i++)
        if (!c[i].cached && jobs[i].same_as < 0)
            order[r.to_run++] = i;
    if (st == CF_OK) {
        qsort_r(order, (size_t)r.to_run, sizeof *order, by_cost, jobs);
        st = cf_mpi_cases(r.to_run, order, CASE_FIGURES, fig, run_ranked, ranked_done, &r, err);
    }
    free(order), free(fig);
    return st;
}

cf_status cf_study_run(const cf_study_options *opt, cf_study_result *res, cf_error *err)
{
    cf_study_options o = *opt;
    char exe[4096];
    memset(res, 0, sizeof *res);
    res->best = -1;
    if (!o.mesh_dir)
        o.mesh_dir = cf_default_mesh_dir();
    if (o.jobs < 1)
        o.jobs = 1;
    if (!(o.tolerance > 0))
        o.tolerance = 0.05;
    if (!o.exe) {
        ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
        if (len <= 0)
            return cf_error_set(err, CF_ERR_EXTERNAL, "cannot find this program's path (%s)",
                                strerror(errno));
        exe[len] = 0;
        o.exe = exe;
    }
    /* Under MPI every rank runs one case at a time: the ranks on one
     * machine share its cores. */
    int ranks = cf_mpi_size(), report = cf_mpi_rank() == 0;
    int share = ranks > 1 ? cf_mpi_local_size() : o.jobs;
    int threads = o.threads > 0 ? o.threads : (int)sysconf(_SC_NPROCESSORS_ONLN) / share;
    threads = threads < 1 ? 1 : threads;
    const char *const *ref = o.reference ? o.reference : default_reference;
    int n_ref = o.reference ? o.n_reference : 2;
    for (int i = 0; i < n_ref; i++)
        if (!strchr(ref[i], '='))
            return cf_error_set(err, CF_ERR_USAGE, "--reference '%s': expected KEY.PATH=VALUE",
                                ref[i]);

    cf_status st = CF_OK;
    axis *ax = calloc((size_t)o.n_vary + 1, sizeof *ax);
    long n = 1;
    for (int a = 0; a < o.n_vary && st == CF_OK; a++) {
        st = ax ? parse_axis(o.vary[a], &ax[a], err)
                : cf_error_set(err, CF_ERR_NOMEM, "out of memory");
        n *= ax ? ax[a].n : 1;
        if (n > 10000)
            st = cf_error_set(err, CF_ERR_USAGE, "--vary: %ld cases or more; at most 10000", n);
    }
    n += 1; /* the reference */
    job *jobs = st == CF_OK ? calloc((size_t)n, sizeof *jobs) : NULL;
    char ***values = st == CF_OK ? calloc((size_t)n, sizeof *values) : NULL;
    res->cases = st == CF_OK ? calloc((size_t)n, sizeof *res->cases) : NULL;
    if (st == CF_OK && (!jobs || !values || !res->cases))
        st = cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    if (st == CF_OK)
        res->n_cases = (int)n;
    cf_study_case *c = res->cases;

    /* Every case's overrides and label; the last axis varies fastest. */
    for (int i = 0; i < n && st == CF_OK; i++) {
        jobs[i].sets = calloc((size_t)o.n_vary + (size_t)n_ref + 1, sizeof(char *));
        values[i] = calloc((size_t)o.n_vary + 1, sizeof(char *));
        if (!jobs[i].sets || !values[i]) {
            st = cf_error_set(err, CF_ERR_NOMEM, "out of memory");
            break;
        }
        if (i == 0) {
            memcpy(jobs[0].sets, ref, (size_t)n_ref * sizeof *ref);
            jobs[0].n_sets = n_ref;
            snprintf(c[0].label, sizeof c[0].label, "reference");
            continue;
        }
        long idx = i - 1;
        size_t len = 0;
        if (o.n_vary == 0)
            snprintf(c[i].label, sizeof c[i].label, "the scene as written");
        for (int a = o.n_vary - 1; a >= 0; a--) {
            values[i][a] = ax[a].values[idx % ax[a].n];
            idx /= ax[a].n;
        }
        for (int a = 0; a < o.n_vary; a++) {
            char *s = format("%s=%s", ax[a].key, values[i][a]);
            if (!s) {
                st = cf_error_set(err, CF_ERR_NOMEM, "out of memory");
                break;
            }
            jobs[i].sets[jobs[i].n_sets++] = s;
            len += (size_t)snprintf(c[i].label + len, len < sizeof c[i].label ?
                                    sizeof c[i].label - len : 0, "%s%s", a ? " " : "", s);
        }
    }
    for (int i = 0; i < n && st == CF_OK; i++)
        st = resolve_case(&o, &jobs[i], &c[i], res->scene_name, err);

    /* Files: OUT/runs/<hash>.*; a case with a .meta and an output is cached. */
    char runs[1100];
    if (st == CF_OK) {
        if (o.out_dir)
            snprintf(res->out_dir, sizeof res->out_dir, "%s", o.out_dir);
        else
            snprintf(res->out_dir, sizeof res->out_dir, "build/studies/%s", res->scene_name);
        snprintf(runs, sizeof runs, "%s/runs", res->out_dir);
        if (report)
            st = cf_mkdirs(runs, "study directory", err);
    }
    for (int i = 0; i < n && st == CF_OK; i++) {
        jobs[i].same_as = -1; /* the same scene twice: run it once */
        for (int k = 0; k < i && jobs[i].same_as < 0; k++)
            if (!strcmp(c[k].hash, c[i].hash))
                jobs[i].same_as = k;
        name_case(&jobs[i], &c[i], runs);
        if (!report)
            continue; /* rank 0 writes the cases and knows the cache */
        st = write_case(&jobs[i], &c[i], runs, err);
        struct stat sb;
        c[i].cached = st == CF_OK && read_meta(&jobs[i], &c[i]) && stat(jobs[i].h5, &sb) == 0;
        res->n_cached += c[i].cached && jobs[i].same_as < 0;
    }
    if (st == CF_OK && o.progress && report && ranks > 1)
        fprintf(stderr, "study %s: %d cases (%d cached) over %d MPI ranks, %d thread%s each\n",
                res->scene_name, res->n_cases, res->n_cached, ranks, threads,
                threads > 1 ? "s" : "");
    else if (st == CF_OK && o.progress && report)
        fprintf(stderr, "study %s: %d cases (%d cached), %d at a time, %d thread%s each\n",
                res->scene_name, res->n_cases, res->n_cached, o.jobs, threads,
                threads > 1 ? "s" : "");
    if (st == CF_OK)
        st = ranks > 1 ? run_ranks(&o, jobs, c, res->n_cases, runs, threads, err)
                       : run_cases(&o, jobs, c, res->n_cases, runs, threads, err);
    if (!report)
        goto done; /* the other ranks only run cases */
    for (int i = 0; i < n && st == CF_OK; i++) {
        const cf_study_case *k = jobs[i].same_as >= 0 ? &c[jobs[i].same_as] : NULL;
        if (k) {
            c[i].exit_code = k->exit_code, c[i].cached = k->cached;
            c[i].wall = k->wall, c[i].cpu = k->cpu, c[i].peak_rss = k->peak_rss;
        }
    }

    /* Metrics against the reference. */
    cf_trajectory rt = {0};
    if (st == CF_OK) {
        cf_error e2;
        if (cf_trajectory_read(jobs[0].h5, &rt, &e2) != CF_OK) {
            char tail[600];
            cf_file_log_tail(jobs[0].log, tail, sizeof tail);
            st = cf_error_set(err, CF_ERR_EXTERNAL,
                              "the reference run (exit %d) left no readable output: %s; "
                              "its log %s ends:\n%s",
                              c[0].exit_code, e2.msg, jobs[0].log, tail);
        }
    }
    if (st == CF_OK) {
        res->travel = cf_study_travel(&rt);
        for (int i = 0; i < n; i++) {
            cf_trajectory vt;
            cf_error e2;
            c[i].traj_rms = c[i].traj_rel = c[i].mass_ks = NAN;
            c[i].crack_area = c[i].dissipated = c[i].p_err = c[i].l_err = NAN;
            c[i].residual_rel = NAN;
            if (cf_trajectory_read(jobs[i].h5, &vt, &e2) == CF_OK) {
                cf_study_case_measure(&c[i], &vt, &rt, res->travel);
                cf_trajectory_free(&vt);
            } else if (o.progress) {
                fprintf(stderr, "case %d (%s): %s\n", i, c[i].label, e2.msg);
            }
            c[i].speedup = c[i].wall > 0 ? c[0].wall / c[i].wall : NAN;
        }
        res->best = cf_study_pareto(c, res->n_cases, o.tolerance);
        if (c[0].exit_code != 0)
            res->best = -1;
        cf_trajectory_free(&rt);
        st = write_csv(res->out_dir, c, res->n_cases, ax, o.n_vary, values, res->best, err);
    }
    if (st == CF_OK)
        st = write_md(&o, res, ref, n_ref, ax, o.n_vary, values, threads, err);
    if (st == CF_OK && o.plot) {
        char csv[1100], png[1100], tol[32];
        snprintf(csv, sizeof csv, "%s/study.csv", res->out_dir);
        snprintf(png, sizeof png, "%s/study.png", res->out_dir);
        snprintf(tol, sizeof tol, "%g", o.tolerance);
        const char *args[] = {csv, png, tol, res->scene_name, NULL};
        res->plot_made = cf_report_plot("study_plot.py", o.plot_script, args,
                                        "study.md and study.csv");
    }

done:
    for (int i = 0; jobs && i < n; i++) {
        for (int k = 0; i > 0 && jobs[i].sets && k < jobs[i].n_sets; k++)
            free((char *)jobs[i].sets[k]); /* the reference's are the caller's */
        free(jobs[i].sets), free(jobs[i].text);
        if (values)
            free(values[i]);
    }
    for (int a = 0; ax && a < o.n_vary; a++)
        free_axis(&ax[a]);
    free(jobs), free(values), free(ax);
    return st;
}

void cf_study_free(cf_study_result *res)
{
    free(res->cases);
    memset(res, 0, sizeof *res);
    res->best = -1;
}
