/* cohfrac — the fracture-mode step benchmark (`cohfrac bench`, `make bench`).
 *
 * The scene: a prepared mesh (default "bunny", 203k tets) rotated y-up to
 * z-up as in scenes/bunny_drop.lua, its lowest point on a rigid plane,
 * moving into it at 3.1 m/s (the bunny drop's impact speed) with the
 * bunny drop's material (E 0.6 Pa, nu 0.23, rho 2400 kg/m^3, sigma_max
 * 0.1 mPa, G_I 22 N/m) and solver (dt 5 us, PBD k 0.9, 3 iterations), in
 * fracture mode only, so that cohesive insertion really happens under
 * criterion "source" or "traction".  Every repeat builds the scene anew and
 * times `steps` fracture steps after `warmup` untimed ones; stage times are
 * the run profile's (cf_stage: the solver's stages, elasticity to the
 * velocity update).
 *
 * In the same run it measures the machine's memory bandwidth with a
 * STREAM-like triad a = b + s c over three arrays of CF_BENCH_TRIAD_MB MiB
 * each (far beyond the last-level cache), counting 24 bytes per element,
 * best of 5, at 1 thread and at the step's thread count, in every repeat
 * beside the steps and the best over the repeats kept (as the step's
 * minimum is); the floor is the traffic model's
 * bytes (cf_sim_step_traffic in sim.h, docs/performance.md) over that
 * bandwidth.
 *
 * Times are min and median over the repeats (wall clock), with the process
 * CPU time per step beside them; runs at 1 thread and at `threads` are
 * interleaved (1, N, 1, N, ...) so that a load on the machine hits both. */
#ifndef COHFRAC_BENCH_H
#define COHFRAC_BENCH_H

#include <stdio.h>

#include "cohfrac/error.h"
#include "cohfrac/scene.h"
#include "cohfrac/world.h"

#define CF_BENCH_TRIAD_MB 256

typedef struct cf_bench_options {
    const char *mesh;       /* prepared mesh name or TetGen base path ["bunny"] */
    const char *mesh_dir;   /* where prepared meshes live */
    int steps;              /* timed fracture steps per repeat [60] */
    int warmup;             /* untimed steps before them [100]: insertion starts */
    int repeats;            /* per thread count [3] */
    int threads;            /* N of the N-thread runs; 0: all cores */
    cf_criterion criterion; /* [CF_CRITERION_SOURCE] */
    const char *peer;       /* path of the btSoftBody peer program, or NULL for none */
    FILE *log;              /* progress and tables (stdout), or NULL */
} cf_bench_options;

/* One timed configuration: ms per step (min, median over repeats), CPU ms
 * per step (median), stage shares (median repeat), insertions per repeat. */
typedef struct cf_bench_timing {
    double ms_min, ms_median, cpu_ms;
    double stage[CF_STAGE_COUNT]; /* ms per step in each stage, median repeat */
    long insertions;
} cf_bench_timing;

typedef struct cf_bench_result {
    int tets, nodes, bars;
    int colours, serial_bars; /* bar colours, bars in the one-thread group (cf_step_stats) */
    double bytes;           /* traffic model, bytes per step */
    double bw_1t, bw_nt;    /* triad bandwidth, bytes/s, 1 and N threads */
    int threads;
    cf_bench_timing t1, tn; /* 1 thread, N threads */
    double floor_ms;        /* bytes / bw_nt */
    double ratio;           /* tn.ms_min / floor_ms */
    double speedup;         /* t1.ms_min / tn.ms_min */
    double peer_ms;         /* btSoftBody ms per step (min), 0 when not run */
    double peer_ratio;      /* peer_ms / t1.ms_min: one core each */
    double memory_per_tet;  /* engine memory (cf_sim_memory) / tets, bytes */
} cf_bench_result;

/* Run the benchmark.  Errors: those of loading the mesh and building the
 * scene, CF_ERR_EXTERNAL (the peer failed), CF_ERR_NOMEM. */
cf_status cf_bench_run(const cf_bench_options *o, cf_bench_result *r, cf_error *err);

/* A whole scene, as `cohfrac run` runs it without output: what a
 * simulated millisecond of fracture mode costs (`cohfrac bench --scene`,
 * docs/performance.md).  Each of `repeats` runs loads the scene with its
 * overrides, runs it to its duration, or until `fracture_ms` (> 0) of
 * simulated time has had a fragment in fracture mode, and reads the wall
 * time of the rigid steps with and without fracture mode.  The rows: wall
 * per simulated ms of fracture mode, Tet4 steps per second of that wall,
 * and wall per rigid-only step, min and median over the repeats, with the
 * process CPU time beside the wall. */
typedef struct cf_bench_scene_options {
    const char *scene;                /* path of the scene script */
    const char *const *overrides;     /* --set KEY=VALUE, as for `cohfrac run` */
    int n_overrides;
    double fracture_ms;               /* stop after this much fracture mode; 0: the duration */
} cf_bench_scene_options;

typedef struct cf_bench_scene_result {
    double fracture_ms;               /* simulated ms with a fragment in fracture mode */
    double s_per_fracture_ms_min, s_per_fracture_ms_median; /* wall s per simulated ms */
    double cpu_s_per_fracture_ms;     /* CPU s per simulated ms (median repeat) */
    double tet_steps_per_s;           /* Tet4 steps per second of fracture-mode wall (best) */
    double rigid_step_ms;             /* wall ms per rigid-only step (median) */
    double wall_min, wall_median;     /* s, the whole run */
} cf_bench_scene_result;

/* Errors: those of loading the scene and of the run. */
cf_status cf_bench_scene(const cf_bench_options *o, const cf_bench_scene_options *so,
                         cf_bench_scene_result *r, cf_error *err);

/* Scaling: the step (criterion "none", N threads, min of `repeats`) on each
 * of `n` meshes; prints a table (tets, ms per step, ns per tet-step, bytes
 * of engine memory per tet) and the least-squares exponent b of
 * ms = a tets^b.  Writes the exponent and the largest bytes per tet. */
cf_status cf_bench_scaling(const cf_bench_options *o, const char *const *meshes, int n,
                           double *exponent, double *bytes_per_tet, cf_error *err);

#endif
