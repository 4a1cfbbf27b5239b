/* cohfrac — command-line front end.
 *
 *   cohfrac run SCENE.lua [--set key.path=value]... [--mesh-dir DIR]
 *               [--output FILE] [--threads N] [--quiet]
 *   cohfrac compare SCENE.lua [--set key.path=value]... [-o DIR] [-j N]
 *                   [-m MESH_DIR] [-q]
 *   cohfrac mesh SURFACE.{obj,off,stl} -o OUT [--target-tets N]
 *   cohfrac --help | --version
 *
 * Exit codes: 0 success, 1 usage, 2 bad input (mesh, surface, scene),
 * 3 diverged, 4 output not written, 5 external program or memory failure
 * (see include/cohfrac/error.h). */
#include "cohfrac/compare.h"
#include "cohfrac/error.h"
#include "cohfrac/scene.h"
#include "cohfrac/sim.h"
#include "cohfrac/surface.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef COHFRAC_VERSION
#define COHFRAC_VERSION "0.0.0"
#endif

static const char usage[] =
    "usage:\n"
    "  cohfrac run SCENE.lua [options]     run a scene, write its HDF5 output\n"
    "      -s, --set KEY.PATH=VALUE        override a scene key (Lua value), repeatable\n"
    "      -m, --mesh-dir DIR              where prepared meshes live (default build/meshes,\n"
    "                                      or $COHFRAC_MESH_DIR)\n"
    "      -o, --output FILE               output file (same as --set output.file=\"FILE\")\n"
    "      -j, --threads N                 threads for element loops (default: all cores)\n"
    "      -q, --quiet                     no progress display\n"
    "  cohfrac compare SCENE.lua [options] run the scene with both rigid backends (bullet,\n"
    "                                      pbd) in lockstep; write compare.md, compare.csv,\n"
    "                                      fragments.csv, compare.png; print the headline\n"
    "      -s, --set KEY.PATH=VALUE        override a scene key (Lua value), repeatable\n"
    "      -o, --output DIR                report directory (default build/compare/<scene name>)\n"
    "      -m, --mesh-dir DIR              as for 'run'\n"
    "      -j, --threads N                 threads for element loops (default: all cores)\n"
    "      -q, --quiet                     no progress display\n"
    "  cohfrac mesh SURFACE -o OUT [--target-tets N]\n"
    "                                      repair a closed surface (OBJ/OFF/STL), run tetgen,\n"
    "                                      write OUT.node/OUT.ele (cached)\n"
    "  cohfrac --help | --version\n"
    "exit codes: 0 ok, 1 usage, 2 bad input, 3 diverged, 4 output failed, 5 external/memory\n";

static int fail(const cf_error *e)
{
    fprintf(stderr, "cohfrac: error [%s]: %s\n", cf_status_name(e->code), e->msg);
    return cf_status_exit_code(e->code);
}

static int usage_error(const char *msg)
{
    fprintf(stderr, "cohfrac: %s\n%s", msg, usage);
    return cf_status_exit_code(CF_ERR_USAGE);
}

static int cmd_mesh(int argc, char **argv)
{
    static const struct option lo[] = {{"output", required_argument, 0, 'o'},
                                       {"target-tets", required_argument, 0, 't'},
                                       {"quiet", no_argument, 0, 'q'},
                                       {0, 0, 0, 0}};
    cf_mesh_prep_opts o = {0};
    o.verbose = 1;
    int c;
    while ((c = getopt_long(argc, argv, "o:t:q", lo, NULL)) != -1) {
        switch (c) {
        case 'o': o.output = optarg; break;
        case 't': o.target_tets = atoi(optarg); break;
        case 'q': o.verbose = 0; break;
        default: return usage_error("bad option for 'mesh'");
        }
    }
    if (optind != argc - 1 || !o.output)
        return usage_error("'mesh' needs one surface file and -o OUT");
    o.input = argv[optind];
    cf_error err = {0};
    if (cf_mesh_prepare(&o, &err) != CF_OK)
        return fail(&err);
    return 0;
}

static int cmd_run(int argc, char **argv)
{
    static const struct option lo[] = {{"set", required_argument, 0, 's'},
                                       {"mesh-dir", required_argument, 0, 'm'},
                                       {"output", required_argument, 0, 'o'},
                                       {"threads", required_argument, 0, 'j'},
                                       {"quiet", no_argument, 0, 'q'},
                                       {0, 0, 0, 0}};
    const char **sets = calloc((size_t)argc + 1, sizeof *sets);
    char *out_set = NULL;
    int n_sets = 0, c, rc = 0;
    const char *mesh_dir = getenv("COHFRAC_MESH_DIR");
    if (!mesh_dir)
        mesh_dir = "build/meshes";
    cf_run_options opt = {.progress = 1};
    while ((c = getopt_long(argc, argv, "s:m:o:j:q", lo, NULL)) != -1) {
        switch (c) {
        case 's': sets[n_sets++] = optarg; break;
        case 'm': mesh_dir = optarg; break;
        case 'o':
            free(out_set);
            out_set = malloc(strlen(optarg) + 32);
            sprintf(out_set, "output.file=[==[%s]==]", optarg);
            sets[n_sets++] = out_set;
            break;
        case 'j': opt.threads = atoi(optarg); break;
        case 'q': opt.progress = 0; break;
        default: free(sets), free(out_set); return usage_error("bad option for 'run'");
        }
    }
    if (optind != argc - 1) {
        free(sets), free(out_set);
        return usage_error("'run' needs exactly one scene file");
    }
    cf_error err = {0};
    cf_scene scene;
    cf_sim *sim = NULL;
    opt.mesh_dir = mesh_dir;
    if (cf_scene_load(argv[optind], sets, n_sets, mesh_dir, &scene, &err) != CF_OK) {
        rc = fail(&err);
    } else {
        cf_status st = cf_sim_create(&scene, &opt, &sim, &err);
        if (st == CF_OK)
            st = cf_sim_run(sim, &err);
        if (sim)
            cf_sim_print_summary(sim, stdout);
        if (st != CF_OK)
            rc = fail(&err);
        cf_sim_destroy(sim);
        cf_scene_free(&scene);
    }
    free(sets), free(out_set);
    return rc;
}

static int cmd_compare(int argc, char **argv)
{
    static const struct option lo[] = {{"set", required_argument, 0, 's'},
                                       {"mesh-dir", required_argument, 0, 'm'},
                                       {"output", required_argument, 0, 'o'},
                                       {"threads", required_argument, 0, 'j'},
                                       {"quiet", no_argument, 0, 'q'},
                                       {0, 0, 0, 0}};
    const char **sets = calloc((size_t)argc + 1, sizeof *sets);
    int n_sets = 0, c;
    const char *mesh_dir = getenv("COHFRAC_MESH_DIR");
    cf_compare_options opt = {.progress = 1, .plot = 1, .headline = stdout};
    opt.mesh_dir = mesh_dir ? mesh_dir : "build/meshes";
    while ((c = getopt_long(argc, argv, "s:m:o:j:q", lo, NULL)) != -1) {
        switch (c) {
        case 's': sets[n_sets++] = optarg; break;
        case 'm': opt.mesh_dir = optarg; break;
        case 'o': opt.out_dir = optarg; break;
        case 'j': opt.threads = atoi(optarg); break;
        case 'q': opt.progress = 0; break;
        default: free(sets); return usage_error("bad option for 'compare'");
        }
    }
    if (optind != argc - 1) {
        free(sets);
        return usage_error("'compare' needs exactly one scene file");
    }
    opt.scene = argv[optind];
    opt.overrides = sets;
    opt.n_overrides = n_sets;
    cf_error err = {0};
    cf_compare_result res;
    int rc = 0;
    if (cf_compare_run(&opt, &res, &err) != CF_OK)
        rc = fail(&err);
    else
        printf("\nreport: %s/compare.md%s\n", res.out_dir,
               res.plot_made ? " (plots: compare.png)" : "");
    free(sets);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc < 2)
        return usage_error("no command given");
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) {
        fputs(usage, stdout);
        return 0;
    }
    if (!strcmp(argv[1], "--version")) {
        printf("cohfrac %s\n", COHFRAC_VERSION);
        return 0;
    }
    if (!strcmp(argv[1], "run"))
        return cmd_run(argc - 1, argv + 1);
    if (!strcmp(argv[1], "compare"))
        return cmd_compare(argc - 1, argv + 1);
    if (!strcmp(argv[1], "mesh"))
        return cmd_mesh(argc - 1, argv + 1);
    return usage_error("unknown command");
}
