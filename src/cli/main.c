/* cohfrac — command-line front end: run, compare, mesh, study, stability,
 * bench (each documented by `cohfrac SUB --help`, the table below).
 *
 * Exit codes: 0 success, 1 usage, 2 bad input (mesh, surface, scene),
 * 3 diverged, 4 output not written, 5 external program or memory failure
 * (see include/cohfrac/error.h). */
#include "cohfrac/version.h"
#include "bench.h"
#include "compare.h"
#include "cohfrac/error.h"
#include "cohfrac/export.h"
#include "cohfrac/scene.h"
#include "cohfrac/sim.h"
#include "stability.h"
#include "study.h"
#include "cohfrac/surface.h"

#include "mpi_cases.h"
#include "report.h"

#include <errno.h>
#include <getopt.h>
#include <signal.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>


/* Each subcommand's help: `cohfrac SUB --help` prints its entry, `cohfrac
 * --help` all of them.  One meaning per option letter across subcommands:
 * -s set, -m mesh directory, -o output, -t threads, -j jobs (study), -q
 * quiet, -V vary, -r reference, -h help. */
static const struct {
    const char *name, *help;
} commands[] = {
    {"run",
     "  cohfrac run SCENE.lua [options]     run a scene, write its HDF5 output (SIGINT or\n"
     "                                      SIGTERM: the output is closed, exit 130 or 143)\n"
     "      -s, --set KEY.PATH=VALUE        override a scene key (Lua value), repeatable\n"
     "      -m, --mesh-dir DIR              where prepared meshes live (default: $COHFRAC_MESH_DIR,\n"
     "                                      else ~/.cache/cohfrac/meshes)\n"
     "      -o, --output FILE               output file, relative to the working directory\n"
     "                                      (default: the scene's output.file, relative to the\n"
     "                                      scene file: out/<name>.h5 beside the scene)\n"
     "      -t, --threads N                 threads for element loops (default: all cores)\n"
     "      -q, --quiet                     no progress display\n"
     "          --force                     overwrite an output file that is not a cohfrac\n"
     "                                      output (refused otherwise)\n"},
    {"compare",
     "  cohfrac compare SCENE.lua [options] run the scene with both rigid backends (bullet,\n"
     "                                      pbd) in lockstep; write compare.md, compare.csv,\n"
     "                                      fragments.csv, compare.png; print the headline\n"
     "      -s, --set KEY.PATH=VALUE        override a scene key (Lua value), repeatable\n"
     "      -o, --output DIR                report directory (default build/compare/<scene name>)\n"
     "      -m, --mesh-dir DIR              as for 'run'\n"
     "      -t, --threads N                 threads for element loops (default: all cores)\n"
     "      -q, --quiet                     no progress display\n"},
    {"mesh",
     "  cohfrac mesh SURFACE -o OUT [options]\n"
     "                                      repair a surface (OBJ, OFF, STL, PLY, glTF, 3DS,\n"
     "                                      FBX... read with assimp; CGAL closes holes and\n"
     "                                      removes self-intersections, saying what it\n"
     "                                      changed), run tetgen, write OUT.node/OUT.ele\n"
     "                                      (cached)\n"
     "      -o, --output OUT                the TetGen base to write (OUT.node, OUT.ele)\n"
     "          --target-tets N             about this many tets (default: tetgen's own);\n"
     "                                      tetgen then adds at most N points (-S N)\n"
     "          --time-limit S              give up after S seconds (default 300)\n"
     "          --no-repair                 refuse a surface that is open or intersects\n"
     "                                      itself instead of repairing it with CGAL\n"
     "      -q, --quiet                     no progress lines\n"},
    {"study",
     "  cohfrac study SCENE.lua --vary KEY.PATH=V1,V2,... [options]\n"
     "                                      run every combination of the varied settings and\n"
     "                                      a reference; error against run time: study.md,\n"
     "                                      study.csv, study.png (runs cached in OUT/runs/)\n"
     "      -V, --vary KEY.PATH=V1,V2,...   a varied key and its Lua values, repeatable\n"
     "      -r, --reference KEY.PATH=VALUE  the reference's overrides, repeatable (default:\n"
     "                                      solver.constraints=\"none\" solver.cfl_fraction=0.5)\n"
     "      -s, --set KEY.PATH=VALUE        override for every case, repeatable\n"
     "      -o, --output DIR                report directory (default build/studies/<scene name>)\n"
     "      -j, --jobs N                    cases run at a time (default 1)\n"
     "      -t, --threads N                 threads per case (default cores / jobs)\n"
     "      -m, --mesh-dir DIR              as for 'run'\n"
     "          --tolerance F               trajectory error of the verdict (default 0.05)\n"
     "      -q, --quiet                     no line per finished case\n"},
    {"stability",
     "  cohfrac stability [--quick] [-o DIR] [-q]\n"
     "                                      stability map of fracture mode over E, dt/dt_cfl,\n"
     "                                      constraints, impact speed and mesh quality; write\n"
     "                                      stability.md, stability.csv, stability.png\n"
     "      --quick                         the corners only (under a minute)\n"
     "      -o, --output DIR                report directory (default build/stability)\n"
     "      -q, --quiet                     no line per case\n"},
    {"render",
     "  cohfrac render OUT.h5 [options]     PNG frames and an MP4 of a run (every fragment's\n"
     "                                      surface, obstacles, coloured by fragment)\n"
     "      -o, --output DIR                frames and movie here (default: frames in\n"
     "                                      OUT_frames/, the movie beside OUT as OUT.mp4)\n"
     "          --fps N                     frames per second of the movie (default 24)\n"
     "          --size WxH                  pixels (default 960x720)\n"
     "          --from T0, --to T1          the span shown, s (default the whole run)\n"
     "          --slow-motion F             play F times slower (default: a movie frame\n"
     "                                      per output frame, at least real time)\n"
     "          --engine auto|blender|matplotlib\n"
     "                                      blender: depth, lighting and a camera that\n"
     "                                      follows the pieces (default when blender and\n"
     "                                      xvfb are installed); matplotlib: fixed camera\n"},
    {"export",
     "  cohfrac export OUT.h5 --format gltf|pvd [-o PATH]\n"
     "                                      the fragments for other tools: gltf (Blender,\n"
     "                                      three.js, game engines: a mesh per fragment, one\n"
     "                                      animation of their poses) or pvd (ParaView: a\n"
     "                                      .vtu of the posed surfaces per frame, a .pvd)\n"
     "      -f, --format gltf|pvd           the format (default gltf: glTF 2.0 binary)\n"
     "      -o, --output PATH               gltf: the file (default OUT minus .h5, .glb);\n"
     "                                      pvd: the directory (default OUT minus .h5, _pvd)\n"
     "          --slow-motion F             gltf: play F times slower than the run (default 1;\n"
     "                                      100 makes a 2 ms break last 0.2 s)\n"},
    {"blender-setup",
     "  cohfrac blender-setup [--check]     let Debian 12's Blender 3.4 import glTF with its\n"
     "                                      default options: a startup script in Blender's\n"
     "                                      user scripts gives numpy 1.24 back the np.bool\n"
     "                                      alias its importer uses (never overwrites; writes\n"
     "                                      nothing where numpy still has it)\n"
     "          --check                     only say whether it is needed and there\n"},
    {"bench",
     "  cohfrac bench [options]             time the fracture-mode step (a mesh hit at 4.43 m/s)\n"
     "                                      against the memory floor, 1 against N threads\n"
     "      --mesh NAME                     prepared mesh or TetGen base (default bunny)\n"
     "      --steps N                       timed steps per repeat (default 60), after\n"
     "      --warmup N                      untimed steps into the impact (default 100)\n"
     "      --repeats N                     repeats per thread count (default 3)\n"
     "      -t, --threads N                 the N of the N-thread runs (default: all cores)\n"
     "      --criterion none|source|traction  insertion rule (default source)\n"
     "      --peer                          also step Bullet's btSoftBody on the same mesh\n"
     "      --scaling[=M1,M2,...]           step time and memory per tet over meshes (default\n"
     "                                      bunny_small,bunny_80k,bunny,bunny_800k)\n"
     "      --scene FILE                    instead: run a scene without output and give\n"
     "                                      the wall and CPU time per simulated ms of\n"
     "                                      fracture mode, Tet4 steps per second, and the\n"
     "                                      rigid-only step (min and median of --repeats,\n"
     "                                      default 1 here)\n"
     "      -s, --set KEY=VALUE             with --scene: as for 'run'\n"
     "      --fracture-ms X                 with --scene: stop after X simulated ms of\n"
     "                                      fracture mode (default: the scene's duration)\n"
     "      -m, --mesh-dir DIR              as for 'run'\n"},
};

static const char tail[] =
    "  cohfrac --help | --version          (also after any subcommand: cohfrac run --help)\n"
    "exit codes: 0 ok, 1 usage, 2 bad input, 3 diverged, 4 output failed, 5 external/memory\n";

static void print_usage(FILE *out, const char *only)
{
    fputs("usage:\n", out);
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (!only || !strcmp(only, commands[i].name))
            fputs(commands[i].help, out);
    fputs(tail, out);
}

static int fail(const cf_error *e)
{
    fprintf(stderr, "cohfrac: error [%s]: %s\n", cf_status_name(e->code), e->msg);
    return cf_status_exit_code(e->code);
}

/* The front end's own allocations (argument lists) failing. */
static int out_of_memory(const char *what)
{
    cf_error e;
    cf_error_set(&e, CF_ERR_NOMEM, "out of memory %s", what);
    return fail(&e);
}

/* The subcommand being parsed, for usage errors. */
static const char *current = NULL;

static int usage_error(const char *msg)
{
    fprintf(stderr, "cohfrac: %s\n", msg);
    print_usage(stderr, current);
    return cf_status_exit_code(CF_ERR_USAGE);
}

/* A whole number >= lo from an option's text, or -1 with a message. */
static int count_arg(const char *opt, const char *text, int lo)
{
    char *end;
    long v = strtol(text, &end, 10);
    if (end == text || *end || v < lo || v > 1000000) {
        fprintf(stderr, "cohfrac: %s needs a whole number from %d to 1000000, got '%s'\n", opt,
                lo, text);
        return -1;
    }
    return (int)v;
}

/* A finite number >= lo from an option's text into *out; 0, or -1 with a
 * message. */
static int real_arg(const char *opt, const char *text, double lo, double *out)
{
    char *end;
    double v = strtod(text, &end);
    if (end == text || *end || !isfinite(v) || v < lo) {
        fprintf(stderr, "cohfrac: %s needs a number >= %g, got '%s'\n", opt, lo, text);
        return -1;
    }
    *out = v;
    return 0;
}

/* A slow-motion factor (render, export): a number > 0, or -1 with a
 * message. */
static int slow_motion_arg(const char *text, double *out)
{
    if (real_arg("--slow-motion", text, 0, out))
        return -1;
    if (!(*out > 0)) {
        fprintf(stderr, "cohfrac: --slow-motion needs a factor > 0 (1: real time), got '%s'\n",
                text);
        return -1;
    }
    return 0;
}

/* The signal that asked a run or a mesh preparation to stop (0: none). */
static volatile sig_atomic_t stop_signal = 0;

static void on_stop_signal(int sig) { stop_signal = sig; }

/* SIGINT, SIGTERM raise stop_signal; the work stops cleanly (a second one
 * kills at once). */
static void catch_stop_signals(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop_signal;
    sa.sa_flags = SA_RESETHAND;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

/* The exit code and one-line note of work stopped by a signal. */
static int stopped(const cf_error *err)
{
    fprintf(stderr, "cohfrac: %s: %s\n", stop_signal == SIGTERM ? "SIGTERM" : "SIGINT",
            err->msg);
    return 128 + (stop_signal ? stop_signal : SIGINT);
}

static int cmd_mesh(int argc, char **argv)
{
    static const struct option lo[] = {{"output", required_argument, 0, 'o'},
                                       {"target-tets", required_argument, 0, 't'},
                                       {"time-limit", required_argument, 0, 'L'},
                                       {"no-repair", no_argument, 0, 'R'},
                                       {"quiet", no_argument, 0, 'q'},
                                       {0, 0, 0, 0}};
    cf_mesh_prep_opts o = {0};
    o.verbose = 1;
    int c;
    while ((c = getopt_long(argc, argv, "o:q", lo, NULL)) != -1) {
        switch (c) {
        case 'o': o.output = optarg; break;
        case 't':
            if ((o.target_tets = count_arg("--target-tets", optarg, 0)) < 0)
                return cf_status_exit_code(CF_ERR_USAGE);
            if (o.target_tets > 0 && o.target_tets < 4)
                return usage_error("--target-tets needs 0 (tetgen's own choice) or a whole "
                                   "number from 4 to 1000000");
            break;
        case 'L':
            if (real_arg("--time-limit", optarg, 0, &o.time_limit))
                return cf_status_exit_code(CF_ERR_USAGE);
            if (!(o.time_limit > 0))
                return usage_error("--time-limit needs a number of seconds > 0");
            break;
        case 'R': o.no_repair = 1; break;
        case 'q': o.verbose = 0; break;
        default: return usage_error("bad option for 'mesh'");
        }
    }
    if (optind != argc - 1 || !o.output)
        return usage_error("'mesh' needs one surface file and -o OUT");
    o.input = argv[optind];
    o.stop = &stop_signal;
    catch_stop_signals(); /* tetgen stopped, temporary files removed */
    cf_error err = {0};
    cf_status st = cf_mesh_prepare(&o, &err);
    if (st == CF_ERR_INTERRUPTED)
        return stopped(&err);
    return st == CF_OK ? 0 : fail(&err);
}

static char *command_line(const char *prefix, int argc, char **argv);

static int cmd_stability(int argc, char **argv)
{
    static const struct option lo[] = {{"quick", no_argument, 0, 'Q'},
                                       {"output", required_argument, 0, 'o'},
                                       {"quiet", no_argument, 0, 'q'},
                                       {0, 0, 0, 0}};
    cf_stability_options o = {.progress = 1, .plot = 1};
    int c;
    while ((c = getopt_long(argc, argv, "o:q", lo, NULL)) != -1) {
        switch (c) {
        case 'Q': o.quick = 1; break;
        case 'o': o.out_dir = optarg; break;
        case 'q': o.progress = 0; break;
        default: return usage_error("bad option for 'stability'");
        }
    }
    if (optind != argc)
        return usage_error("'stability' takes no positional argument");
    char *cmd = command_line("cohfrac stability", argc - 1, argv + 1);
    o.command = cmd;
    cf_error err = {0};
    cf_stability_result res;
    int rc = 0;
    if (cf_stability_run(&o, &res, &err) != CF_OK) {
        rc = fail(&err);
    } else if (cf_mpi_rank() == 0) {
        int unstable = 0;
        for (int i = 0; i < res.n; i++)
            unstable += !res.cases[i].stable;
        printf("%d cases, %d stable, %d unstable\nreport: %s/stability.md%s\n", res.n,
               res.n - unstable, unstable, res.out_dir,
               res.plot_made ? " (heatmaps: stability.png)" : "");
    }
    cf_stability_free(&res);
    free(cmd);
    return rc;
}

/* The options `run` and `compare` share: --set (repeatable), --mesh-dir,
 * --output (a file for `run`, a directory for `compare`), --threads,
 * --quiet, and one scene file. */
typedef struct scene_args {
    const char **sets; /* [argc + 1]: room for one more --set */
    int n_sets;
    const char *mesh_dir, *output, *scene;
    int output_at; /* --sets given before the last --output */
    int threads, progress, force;
} scene_args;

/* Returns 0, or the usage exit code (a message printed); free a->sets. */
static int parse_scene_args(int argc, char **argv, const char *cmd, scene_args *a)
{
    static const struct option lo[] = {{"set", required_argument, 0, 's'},
                                       {"mesh-dir", required_argument, 0, 'm'},
                                       {"output", required_argument, 0, 'o'},
                                       {"threads", required_argument, 0, 't'},
                                       {"quiet", no_argument, 0, 'q'},
                                       {"force", no_argument, 0, 'F'},
                                       {0, 0, 0, 0}};
    char msg[64];
    memset(a, 0, sizeof *a);
    a->sets = calloc((size_t)argc + 2, sizeof *a->sets);
    if (!a->sets)
        return out_of_memory("reading the command line");
    a->mesh_dir = cf_default_mesh_dir();
    a->progress = 1;
    int c;
    while ((c = getopt_long(argc, argv, "s:m:o:t:q", lo, NULL)) != -1) {
        switch (c) {
        case 's': a->sets[a->n_sets++] = optarg; break;
        case 'm': a->mesh_dir = optarg; break;
        case 'o': a->output = optarg, a->output_at = a->n_sets; break;
        case 't':
            if ((a->threads = count_arg("--threads", optarg, 1)) < 0)
                return cf_status_exit_code(CF_ERR_USAGE);
            break;
        case 'q': a->progress = 0; break;
        case 'F': a->force = 1; break;
        default:
            snprintf(msg, sizeof msg, "bad option for '%s'", cmd);
            return usage_error(msg);
        }
    }
    if (optind != argc - 1) {
        snprintf(msg, sizeof msg, "'%s' needs exactly one scene file", cmd);
        return usage_error(msg);
    }
    a->scene = argv[optind];
    return 0;
}

static int cmd_run(int argc, char **argv)
{
    scene_args a;
    char *out_set = NULL;
    int rc = parse_scene_args(argc, argv, "run", &a);
    if (rc == 0 && a.output) { /* -o FILE is --set output.file="FILE" in its place */
        /* A command-line path is relative to the working directory. */
        char cwd[4096] = "";
        if (a.output[0] && a.output[0] != '/' && !getcwd(cwd, sizeof cwd))
            cwd[0] = '\0';
        out_set = malloc(strlen(cwd) + strlen(a.output) + 32);
        if (!out_set) {
            free(a.sets);
            return out_of_memory("reading the command line");
        }
        sprintf(out_set, "output.file=[==[%s%s%s]==]", cwd, cwd[0] ? "/" : "", a.output);
        memmove(&a.sets[a.output_at + 1], &a.sets[a.output_at],
                (size_t)(a.n_sets - a.output_at) * sizeof *a.sets);
        a.sets[a.output_at] = out_set;
        a.n_sets++;
    }
    if (rc != 0) {
        free(a.sets);
        return rc;
    }
    cf_error err = {0};
    cf_scene scene;
    cf_sim *sim = NULL;
    cf_run_options opt = {.progress = a.progress, .threads = a.threads, .mesh_dir = a.mesh_dir,
                          .force = a.force, .stop = &stop_signal};
    catch_stop_signals(); /* finish the step, close the file */
    if (cf_scene_load(a.scene, a.sets, a.n_sets, a.mesh_dir, &scene, &err) != CF_OK) {
        rc = fail(&err);
    } else {
        cf_status st = cf_sim_create(&scene, &opt, &sim, &err);
        if (st == CF_OK)
            st = cf_sim_run(sim, &err);
        if (sim)
            cf_sim_print_summary(sim, stdout);
        if (st == CF_ERR_INTERRUPTED) {
            rc = stopped(&err);
        } else if (st != CF_OK) {
            rc = fail(&err);
        }
        cf_sim_destroy(sim);
        cf_scene_free(&scene);
    }
    free(a.sets), free(out_set);
    return rc;
}

static int cmd_compare(int argc, char **argv)
{
    scene_args a;
    int rc = parse_scene_args(argc, argv, "compare", &a);
    if (rc != 0) {
        free(a.sets);
        return rc;
    }
    cf_compare_options opt = {.progress = a.progress, .plot = 1, .headline = stdout};
    opt.mesh_dir = a.mesh_dir;
    opt.out_dir = a.output;
    opt.threads = a.threads;
    opt.scene = a.scene;
    opt.overrides = a.sets;
    opt.n_overrides = a.n_sets;
    cf_error err = {0};
    cf_compare_result res;
    if (cf_compare_run(&opt, &res, &err) != CF_OK)
        rc = fail(&err);
    else
        printf("\nreport: %s/compare.md%s\n", res.out_dir,
               res.plot_made ? " (plots: compare.png)" : "");
    free(a.sets);
    return rc;
}

/* `prefix` and the arguments as one shell command line (arguments with a
 * space or a quote in single quotes), for a report's "regenerate with". */
static char *command_line(const char *prefix, int argc, char **argv)
{
    size_t len = strlen(prefix) + 1;
    for (int i = 0; i < argc; i++)
        len += strlen(argv[i]) + 3;
    char *cmd = malloc(len);
    if (!cmd)
        return NULL;
    char *end = cmd + sprintf(cmd, "%s", prefix);
    for (int i = 0; i < argc; i++) {
        int quote = strpbrk(argv[i], " \"") != NULL;
        end += sprintf(end, quote ? " '%s'" : " %s", argv[i]);
    }
    return cmd;
}

static int cmd_study(int argc, char **argv)
{
    static const struct option lo[] = {{"vary", required_argument, 0, 'V'},
                                       {"reference", required_argument, 0, 'r'},
                                       {"set", required_argument, 0, 's'},
                                       {"output", required_argument, 0, 'o'},
                                       {"jobs", required_argument, 0, 'j'},
                                       {"threads", required_argument, 0, 't'},
                                       {"mesh-dir", required_argument, 0, 'm'},
                                       {"tolerance", required_argument, 0, 'T'},
                                       {"quiet", no_argument, 0, 'q'},
                                       {0, 0, 0, 0}};
    const char **vary = calloc((size_t)argc, sizeof *vary);
    const char **ref = calloc((size_t)argc, sizeof *ref);
    const char **sets = calloc((size_t)argc, sizeof *sets);
    if (!vary || !ref || !sets) {
        free(vary), free(ref), free(sets);
        return out_of_memory("reading the command line");
    }
    cf_study_options o = {.progress = 1, .plot = 1, .jobs = 1};
    o.mesh_dir = cf_default_mesh_dir();
    int c, rc = 0;
    while (rc == 0 && (c = getopt_long(argc, argv, "V:r:s:o:j:t:m:q", lo, NULL)) != -1) {
        switch (c) {
        case 'V': vary[o.n_vary++] = optarg; break;
        case 'r': ref[o.n_reference++] = optarg; break;
        case 's': sets[o.n_overrides++] = optarg; break;
        case 'o': o.out_dir = optarg; break;
        case 'j': rc = (o.jobs = count_arg("--jobs", optarg, 1)) < 0; break;
        case 't': rc = (o.threads = count_arg("--threads", optarg, 1)) < 0; break;
        case 'm': o.mesh_dir = optarg; break;
        case 'T': rc = real_arg("--tolerance", optarg, 0, &o.tolerance); break;
        case 'q': o.progress = 0; break;
        default: rc = usage_error("bad option for 'study'");
        }
    }
    if (rc != 0)
        rc = cf_status_exit_code(CF_ERR_USAGE);
    else if (optind != argc - 1)
        rc = usage_error("'study' needs exactly one scene file");
    else if (o.n_vary == 0)
        rc = usage_error("'study' needs at least one --vary KEY.PATH=V1,V2,...");
    else if (rc == 0 && (o.jobs < 1 || o.threads < 0 || o.tolerance < 0))
        rc = usage_error("'study': --jobs must be >= 1, --threads and --tolerance >= 0");
    char *cmd = rc == 0 ? command_line("cohfrac study", argc - 1, argv + 1) : NULL;
    if (rc == 0) {
        o.scene = argv[optind];
        o.vary = vary, o.overrides = sets, o.command = cmd;
        o.reference = o.n_reference ? ref : NULL;
        cf_error err = {0};
        cf_study_result res;
        if (cf_study_run(&o, &res, &err) != CF_OK) {
            rc = fail(&err);
        } else if (cf_mpi_rank() == 0) {
            printf("%d cases; report: %s/study.md%s\n", res.n_cases, res.out_dir,
                   res.plot_made ? " (plot: study.png)" : "");
            if (res.best >= 0)
                printf("cheapest within %g%% trajectory error: case %d, %s: %.2f s (speed-up "
                       "%.3g)\n",
                       100 * (o.tolerance > 0 ? o.tolerance : 0.05), res.best,
                       res.cases[res.best].label, res.cases[res.best].wall,
                       res.cases[res.best].speedup);
        }
        cf_study_free(&res);
    }
    free(vary), free(ref), free(sets), free(cmd);
    return rc;
}

/* The peer program beside this executable (built from bench/). */
static char *peer_path(void)
{
    static char path[4096];
    ssize_t n = readlink("/proc/self/exe", path, sizeof path - 64);
    if (n <= 0)
        return NULL;
    path[n] = 0;
    char *slash = strrchr(path, '/');
    strcpy(slash ? slash + 1 : path, "cohfrac_softbody_peer");
    return access(path, X_OK) == 0 ? path : NULL;
}

static int cmd_bench(int argc, char **argv)
{
    enum { O_MESH = 256, O_STEPS, O_REPEATS, O_CRITERION, O_PEER, O_SCALING, O_WARMUP, O_SCENE,
           O_FRACTURE_MS };
    static const struct option lo[] = {{"mesh", required_argument, 0, O_MESH},
                                       {"steps", required_argument, 0, O_STEPS},
                                       {"warmup", required_argument, 0, O_WARMUP},
                                       {"repeats", required_argument, 0, O_REPEATS},
                                       {"threads", required_argument, 0, 't'},
                                       {"criterion", required_argument, 0, O_CRITERION},
                                       {"peer", no_argument, 0, O_PEER},
                                       {"scaling", optional_argument, 0, O_SCALING},
                                       {"mesh-dir", required_argument, 0, 'm'},
                                       {"scene", required_argument, 0, O_SCENE},
                                       {"set", required_argument, 0, 's'},
                                       {"fracture-ms", required_argument, 0, O_FRACTURE_MS},
                                       {0, 0, 0, 0}};
    static const char *sets[64];
    cf_bench_scene_options so = {.overrides = sets};
    int repeats_given = 0;
    cf_bench_options o = {.mesh = "bunny", .mesh_dir = cf_default_mesh_dir(), .steps = 60,
                          .warmup = 100, .repeats = 3, .criterion = CF_CRITERION_SOURCE,
                          .log = stdout};
    const char *scaling = NULL;
    int c, peer = 0;
    while ((c = getopt_long(argc, argv, "m:t:s:", lo, NULL)) != -1) {
        switch (c) {
        case O_SCENE: so.scene = optarg; break;
        case 's':
            if (so.n_overrides == 64)
                return usage_error("at most 64 --set options");
            sets[so.n_overrides++] = optarg;
            break;
        case O_FRACTURE_MS: {
            char *end;
            so.fracture_ms = strtod(optarg, &end);
            if (*end || !(so.fracture_ms > 0) || !isfinite(so.fracture_ms))
                return usage_error("--fracture-ms needs a number of milliseconds > 0");
            break;
        }
        case O_MESH: o.mesh = optarg; break;
        case O_STEPS: o.steps = count_arg("--steps", optarg, 1); break;
        case O_WARMUP: o.warmup = count_arg("--warmup", optarg, 0); break;
        case O_REPEATS: o.repeats = count_arg("--repeats", optarg, 1), repeats_given = 1; break;
        case 't': o.threads = count_arg("--threads", optarg, 1); break;
        case O_CRITERION:
            if (!strcmp(optarg, "none")) o.criterion = CF_CRITERION_NONE;
            else if (!strcmp(optarg, "source")) o.criterion = CF_CRITERION_SOURCE;
            else if (!strcmp(optarg, "traction")) o.criterion = CF_CRITERION_TRACTION;
            else return usage_error("--criterion is none, source or traction");
            break;
        case O_PEER: peer = 1; break;
        case O_SCALING: scaling = optarg ? optarg : "bunny_small,bunny_80k,bunny,bunny_800k"; break;
        case 'm': o.mesh_dir = optarg; break;
        default: return usage_error("bad option for 'bench'");
        }
        if (o.steps < 0 || o.warmup < 0 || o.repeats < 0 || o.threads < 0)
            return cf_status_exit_code(CF_ERR_USAGE);
    }
    if (optind != argc)
        return usage_error("'bench' takes no positional argument");
    if (peer && !(o.peer = peer_path())) {
        fprintf(stderr, "cohfrac: --peer needs cohfrac_softbody_peer beside this program (built "
                        "from bench/ by cmake)\n");
        return cf_status_exit_code(CF_ERR_EXTERNAL);
    }
    cf_error err = {0};
    if (so.scene) {
        cf_bench_scene_result r;
        if (!repeats_given)
            o.repeats = 1;
        return cf_bench_scene(&o, &so, &r, &err) == CF_OK ? 0 : fail(&err);
    }
    if (so.n_overrides > 0 || so.fracture_ms > 0)
        return usage_error("--set and --fracture-ms go with --scene");
    if (scaling) {
        char *list = strdup(scaling), *save = NULL;
        if (!list)
            return out_of_memory("reading the command line");
        const char *meshes[32];
        int n = 0;
        for (char *t = strtok_r(list, ",", &save); t && n < 32; t = strtok_r(NULL, ",", &save))
            meshes[n++] = t;
        double b, bytes;
        cf_status st = cf_bench_scaling(&o, meshes, n, &b, &bytes, &err);
        free(list);
        return st == CF_OK ? 0 : fail(&err);
    }
    cf_bench_result r;
    return cf_bench_run(&o, &r, &err) == CF_OK ? 0 : fail(&err);
}

/* python/cohfrac/render.py on an output file (matplotlib frames, ffmpeg movie). */
static int cmd_render(int argc, char **argv)
{
    static const struct option lo[] = {{"output", required_argument, 0, 'o'},
                                       {"fps", required_argument, 0, 'f'},
                                       {"size", required_argument, 0, 'S'},
                                       {"from", required_argument, 0, 'a'},
                                       {"to", required_argument, 0, 'b'},
                                       {"slow-motion", required_argument, 0, 'm'},
                                       {"engine", required_argument, 0, 'e'},
                                       {0, 0, 0, 0}};
    const char *out = NULL, *fps = NULL, *size = NULL, *from = NULL, *to = NULL;
    const char *slow = NULL, *engine = NULL;
    int c, w, h;
    double v;
    while ((c = getopt_long(argc, argv, "o:", lo, NULL)) != -1) {
        switch (c) {
        case 'o': out = optarg; break;
        case 'f':
            if (count_arg("--fps", optarg, 1) < 0)
                return cf_status_exit_code(CF_ERR_USAGE);
            fps = optarg;
            break;
        case 'S':
            if (sscanf(optarg, "%dx%d", &w, &h) != 2 || w < 16 || h < 16 || w > 8192 || h > 8192)
                return usage_error("--size is WxH in pixels, 16 to 8192 each (e.g. 960x720)");
            size = optarg;
            break;
        case 'a':
        case 'b':
            if (real_arg(c == 'a' ? "--from" : "--to", optarg, 0, &v))
                return cf_status_exit_code(CF_ERR_USAGE);
            *(c == 'a' ? &from : &to) = optarg;
            break;
        case 'm':
            if (slow_motion_arg(optarg, &v))
                return cf_status_exit_code(CF_ERR_USAGE);
            slow = optarg;
            break;
        case 'e':
            if (strcmp(optarg, "auto") && strcmp(optarg, "blender") && strcmp(optarg, "matplotlib"))
                return usage_error("--engine is auto, blender or matplotlib");
            engine = optarg;
            break;
        default: return usage_error("bad option for 'render'");
        }
    }
    if (optind != argc - 1)
        return usage_error("'render' needs one output file (.h5)");
    if (access(argv[optind], R_OK) != 0) {
        fprintf(stderr, "cohfrac: error [file]: cannot read %s: %s\n", argv[optind],
                strerror(errno));
        return cf_status_exit_code(CF_ERR_FILE_OPEN);
    }
    /* Blender renders the glTF export: written to a temporary file first
     * (an older file without geometry falls back to matplotlib). */
    char dir[600] = "", glb[620] = "";
    if (!engine || strcmp(engine, "matplotlib")) {
        const char *tmpdir = getenv("TMPDIR");
        snprintf(dir, sizeof dir, "%s/cohfrac-render-XXXXXX",
                 tmpdir && *tmpdir && strlen(tmpdir) < 500 ? tmpdir : "/tmp");
        cf_error err = {0};
        if (!mkdtemp(dir))
            dir[0] = '\0';
        else if (snprintf(glb, sizeof glb, "%s/run.glb", dir),
                 cf_export_gltf(argv[optind], glb, 1.0, &err) != CF_OK)
            unlink(glb), glb[0] = '\0';
    }
    const char *args[20] = {argv[optind]};
    int n = 1;
    const char *opt[][2] = {{"-o", out},           {"--fps", fps},   {"--size", size},
                            {"--from", from},      {"--to", to},     {"--slow-motion", slow},
                            {"--engine", engine},  {"--glb", glb[0] ? glb : NULL}};
    for (size_t i = 0; i < sizeof opt / sizeof opt[0]; i++)
        if (opt[i][1])
            args[n++] = opt[i][0], args[n++] = opt[i][1];
    args[n] = NULL;
    int ok = cf_report_plot("render.py", NULL, args, "no frames or movie");
    if (glb[0])
        unlink(glb);
    if (dir[0])
        rmdir(dir);
    return ok ? 0 : cf_status_exit_code(CF_ERR_EXTERNAL);
}

/* The fragments of an output file as glTF (cf_export_gltf). */
static int cmd_export(int argc, char **argv)
{
    static const struct option lo[] = {{"format", required_argument, 0, 'f'},
                                       {"output", required_argument, 0, 'o'},
                                       {"slow-motion", required_argument, 0, 'S'},
                                       {0, 0, 0, 0}};
    const char *out = NULL;
    int c, pvd = 0;
    double slow = 1;
    while ((c = getopt_long(argc, argv, "f:o:", lo, NULL)) != -1) {
        switch (c) {
        case 'f':
            pvd = strcmp(optarg, "pvd") == 0;
            if (!pvd && strcmp(optarg, "gltf") != 0 && strcmp(optarg, "glb") != 0)
                return usage_error("--format is gltf (glTF 2.0 binary, .glb) or pvd (ParaView)");
            break;
        case 'o': out = optarg; break;
        case 'S':
            if (slow_motion_arg(optarg, &slow))
                return cf_status_exit_code(CF_ERR_USAGE);
            break;
        default: return usage_error("bad option for 'export'");
        }
    }
    if (optind != argc - 1)
        return usage_error("'export' needs one output file (.h5)");
    const char *in = argv[optind];
    char def[4096];
    if (!out) {
        const char *dot = strrchr(in, '.');
        int len = dot && !strchr(dot, '/') ? (int)(dot - in) : (int)strlen(in);
        snprintf(def, sizeof def, "%.*s%s", len, in, pvd ? "_pvd" : ".glb");
        out = def;
    }
    if (pvd) { /* python/cohfrac/h5.py writes it (meshio) */
        const char *args[] = {in, "--pvd", out, NULL};
        return cf_report_plot("h5.py", NULL, args, "no ParaView series")
                   ? 0
                   : cf_status_exit_code(CF_ERR_EXTERNAL);
    }
    cf_error err = {0};
    if (cf_export_gltf(in, out, slow, &err) != CF_OK)
        return fail(&err);
    printf("wrote %s\n", out);
    return 0;
}

/* Where Debian's Blender 3.4 cannot import glTF with its default options,
 * a startup script of its own mends it (python/cohfrac/blender_setup.py). */
static int cmd_blender_setup(int argc, char **argv)
{
    static const struct option lo[] = {{"check", no_argument, 0, 'c'}, {0, 0, 0, 0}};
    int c, check = 0;
    while ((c = getopt_long(argc, argv, "", lo, NULL)) != -1) {
        if (c != 'c')
            return usage_error("bad option for 'blender-setup'");
        check = 1;
    }
    if (optind != argc)
        return usage_error("'blender-setup' takes no file");
    const char *args[] = {check ? "--check" : NULL, NULL};
    int status = cf_run_helper("blender_setup.py", NULL, args);
    if (status == 4)
        return cf_status_exit_code(CF_ERR_OUTPUT);
    return status == 0 ? 0 : cf_status_exit_code(CF_ERR_EXTERNAL);
}

/* --help / -h or --version among a subcommand's arguments (before "--"). */
static int asks(int argc, char **argv, const char *a, const char *b)
{
    for (int i = 1; i < argc && strcmp(argv[i], "--"); i++)
        if (!strcmp(argv[i], a) || (b && !strcmp(argv[i], b)))
            return 1;
    return 0;
}

/* Set once main returns: an exit() before then is a library's. */
static volatile sig_atomic_t main_returned = 0;

/* Some libraries end the process themselves when an allocation fails,
 * instead of returning an error: libgomp (gomp_malloc: "out of memory
 * allocating N bytes", or a thread it cannot start) with exit(1), and
 * HDF5 1.10 (its identifier table) with exit(-1), silently.  Status 1
 * means a bad command line here and 255 means nothing.  Registered first,
 * this runs first of the exit handlers: it says what happened and ends
 * with exit code 5 at once (_exit: other threads are still running, and
 * destructors run under them could crash).  The output file is then as
 * after SIGKILL: every frame written is whole. */
static void library_exit(void)
{
    static const char msg[] =
        "cohfrac: error [CF_ERR_EXTERNAL]: a library ended the process itself (libgomp and "
        "HDF5 do so when out of memory; libgomp also when it cannot start a thread; its "
        "message, if it gave one, is above)\n";
    if (main_returned)
        return;
    if (write(2, msg, sizeof msg - 1) < 0) { /* nothing more to say it with */ }
    _exit(cf_status_exit_code(CF_ERR_EXTERNAL));
}

static int dispatch(int argc, char **argv);

/* OpenMP's threads meet at every barrier of a step, and libgomp spins
 * 300,000 times by default before a waiting thread sleeps.  On a host whose
 * cores are busy the thread it waits for is often descheduled, and the
 * spinning takes the core it needs: beside two busy processes the first
 * 10 ms of the plaster drop took 19-29 s on two threads against 14 s on
 * one.  A spin of 5,000 takes 15 s there, as a passive wait does, and
 * keeps the idle speed, which a passive wait loses (`cohfrac bench`:
 * 1.7-1.9 times on two threads, against 1.2 passive; docs/performance.md).
 * libgomp reads the setting when it loads, before main, so the program
 * sets it and starts itself again, unless the user chose a spin or a wait
 * policy. */
static void limit_openmp_spin(char **argv)
{
    if (getenv("GOMP_SPINCOUNT") || getenv("OMP_WAIT_POLICY"))
        return;
    if (setenv("GOMP_SPINCOUNT", "5000", 1) == 0)
        execv("/proc/self/exe", argv); /* returns only when it failed: run as we are */
}

int main(int argc, char **argv)
{
    limit_openmp_spin(argv);
    atexit(library_exit);
    int rc = dispatch(argc, argv);
    main_returned = 1;
    return rc;
}

/* A subcommand: its name and what runs it. */
typedef struct {
    const char *name;
    int (*run)(int, char **);
} cli_command;

/* Edit distance between two short words (insertions, deletions and
 * substitutions), for the suggestion after an unknown command. */
static int edit_distance(const char *a, const char *b)
{
    enum { MAX = 32 };
    size_t na = strlen(a), nb = strlen(b);
    if (na >= MAX || nb >= MAX)
        return MAX;
    int row[MAX + 1];
    for (size_t j = 0; j <= nb; j++)
        row[j] = (int)j;
    for (size_t i = 1; i <= na; i++) {
        int diag = row[0];
        row[0] = (int)i;
        for (size_t j = 1; j <= nb; j++) {
            int up = row[j], best = diag + (a[i - 1] != b[j - 1]);
            best = up + 1 < best ? up + 1 : best;
            best = row[j - 1] + 1 < best ? row[j - 1] + 1 : best;
            diag = up, row[j] = best;
        }
    }
    return row[nb];
}

/* One line for a word that is no command: it, the nearest command when one
 * is near (at most two edits, or a prefix), and where the usage is. */
static int unknown_command(const char *word, const cli_command *table, size_t n)
{
    const char *near = NULL;
    int best = 3;
    for (size_t i = 0; i < n; i++) {
        int d = edit_distance(word, table[i].name);
        if (*word && !strncmp(table[i].name, word, strlen(word)))
            d = 1; /* a prefix of the command */
        if (d < best)
            best = d, near = table[i].name;
    }
    if (near)
        fprintf(stderr, "cohfrac: unknown command '%s'; did you mean '%s'? (cohfrac --help lists "
                        "the commands)\n", word, near);
    else
        fprintf(stderr, "cohfrac: unknown command '%s' (cohfrac --help lists the commands)\n",
                word);
    return cf_status_exit_code(CF_ERR_USAGE);
}

static int dispatch(int argc, char **argv)
{
    static const cli_command table[] = {{"run", cmd_run},         {"compare", cmd_compare},     {"mesh", cmd_mesh},
                 {"study", cmd_study},     {"stability", cmd_stability}, {"bench", cmd_bench},
                 {"render", cmd_render},   {"export", cmd_export},
                 {"blender-setup", cmd_blender_setup}};
    if (argc < 2)
        return usage_error("no command given");
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) {
        print_usage(stdout, argc > 2 ? argv[2] : NULL);
        return 0;
    }
    if (asks(argc, argv, "--version", NULL)) {
        printf("cohfrac %s\n", COHFRAC_VERSION_STRING);
        return 0;
    }
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++) {
        if (strcmp(argv[1], table[i].name))
            continue;
        current = table[i].name;
        if (asks(argc - 1, argv + 1, "--help", "-h")) {
            print_usage(stdout, current);
            return 0;
        }
        /* study and stability spread their cases over MPI ranks when an
         * MPI launcher started them (mpi_cases.h) */
        int spread = !strcmp(current, "study") || !strcmp(current, "stability");
        cf_error err = {0};
        if (spread && cf_mpi_start(&argc, &argv, &err) < 0)
            return fail(&err);
        int rc = table[i].run(argc - 1, argv + 1);
        if (spread)
            cf_mpi_finish();
        return rc;
    }
    return unknown_command(argv[1], table, sizeof table / sizeof table[0]);
}
