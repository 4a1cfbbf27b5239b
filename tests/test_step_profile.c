/* The step's profile and its scratch (docs/architecture.md, "The step,
 * stage by stage"): the stages' timers add up to the step's wall time
 * measured outside it; steps that insert nothing call no allocator once
 * the world has warmed up, in each of the step's modes (the arena keeps
 * the step's scratch); the arena spills when full and then grows so that
 * the same step needs no allocation again.
 *
 * The allocation count interposes malloc and its kin in this program and
 * forwards them to glibc's; the sanitizer build, whose runtime replaces
 * the allocator itself, skips the tests that count. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "arena.h"
#include "clock.h"
#include "cohfrac/mesh.h"
#include "cohfrac/world.h"

#include <errno.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__SANITIZE_ADDRESS__)
#define COUNTING 0
#else
#define COUNTING 1
#endif

static atomic_long allocations; /* calls since counting began */
static atomic_int counting;

#if COUNTING
void *__libc_malloc(size_t n);
void *__libc_calloc(size_t n, size_t size);
void *__libc_realloc(void *p, size_t n);
void *__libc_memalign(size_t align, size_t n);
void __libc_free(void *p);

static void count(void)
{
    if (atomic_load_explicit(&counting, memory_order_relaxed))
        atomic_fetch_add_explicit(&allocations, 1, memory_order_relaxed);
}

void *malloc(size_t n)
{
    count();
    return __libc_malloc(n);
}

void *calloc(size_t n, size_t size)
{
    count();
    return __libc_calloc(n, size);
}

void *realloc(void *p, size_t n)
{
    count();
    return __libc_realloc(p, n);
}

void *memalign(size_t align, size_t n)
{
    count();
    return __libc_memalign(align, n);
}

void *aligned_alloc(size_t align, size_t n)
{
    count();
    return __libc_memalign(align, n);
}

int posix_memalign(void **out, size_t align, size_t n)
{
    count();
    void *p = __libc_memalign(align, n);
    if (!p)
        return ENOMEM;
    *out = p;
    return 0;
}

void free(void *p) { __libc_free(p); }
#endif

static void count_from_now(void)
{
    atomic_store(&allocations, 0);
    atomic_store(&counting, 1);
}

static long counted(void)
{
    atomic_store(&counting, 0);
    return atomic_load(&allocations);
}

/* The step's modes, each a scene of its own. */
typedef enum {
    RIGID_BULLET, /* a box resting on the ground in Bullet */
    RIGID_PBD,    /* the same, in the damped-PBD rigid backend */
    FRACTURE,     /* fracture mode only: explicit Tet4, penalty contact */
    FRACTURE_PBD, /* fracture mode only: PBD bars, projected contact */
} scene_kind;

static const char *const kind_name[] = {"Bullet rigid mode", "pbd rigid backend",
                                        "explicit fracture mode", "PBD fracture mode"};

/* A 0.2 m box of n x n x n cells dropped onto a plane from 0.5 mm: too
 * strong to break (sigma_max 1 GPa), so its steps insert nothing.  *box
 * holds the mesh until the world is made. */
static cf_world *make_world(scene_kind kind, int threads, int n, cf_mesh *box)
{
    static cf_body_def body;
    static cf_obstacle ground;
    const double size[3] = {0.2, 0.2, 0.2};
    const int cells[3] = {n, n, n};
    cf_error err = {0};
    if (cf_mesh_box(size, cells, 6, box, &err) != CF_OK)
        fail_msg("box: %s", err.msg);
    cf_world_def def = cf_default_world_def();
    def.material.E = 1e6;
    def.material.sigma_max = def.material.tau_max = 1e9;
    def.solver.threads = threads;
    if (kind == RIGID_PBD)
        def.solver.rigid_backend = CF_RIGID_PBD;
    if (kind == FRACTURE || kind == FRACTURE_PBD) {
        def.solver.mode = CF_RUN_FRACTURE;
        def.solver.cfl_fraction = 0.5;
        def.solver.dt_rigid = 2e-4;
    }
    if (kind == FRACTURE) {
        def.solver.constraints = CF_CONSTRAINTS_NONE;
        def.solver.obstacle_contact = CF_OBSTACLE_CONTACT_PENALTY;
    } else {
        def.solver.constraints = CF_CONSTRAINTS_PBD;
    }
    body = cf_default_body();
    body.tet_mesh = box;
    body.position[2] = 0.1005; /* resting a half millimetre above the ground */
    ground = cf_default_obstacle(CF_OBSTACLE_PLANE);
    def.bodies = &body, def.n_bodies = 1;
    def.obstacles = &ground, def.n_obstacles = 1;
    cf_world *w = NULL;
    if (cf_world_create(&def, &w, &err) != CF_OK)
        fail_msg("%s: %s", kind_name[kind], err.msg);
    cf_mesh_free(box);
    return w;
}

static void step(cf_world *w)
{
    cf_error err = {0};
    if (cf_world_step(w, cf_world_dt_outer(w), &err) != CF_OK)
        fail_msg("step: %s", err.msg);
}

/* One try: 200 steps, the stages' timers against the wall time of the
 * calls to cf_world_step.  Each stage is at least 0, and the stages every
 * step of the mode runs took time.  Returns the untimed share, |sum - wall|
 * over wall. */
static double untimed_share(cf_world *w, scene_kind kind)
{
    cf_world_stats a, b;
    cf_world_stats_get(w, &a);
    double wall = 0;
    for (int k = 0; k < 200; k++) {
        double t0 = cf_wall_time();
        step(w);
        wall += cf_wall_time() - t0;
    }
    cf_world_stats_get(w, &b);
    double sum = 0;
    printf("FIGURE %s, 200 steps: wall %.4g s;", kind_name[kind], wall);
    for (int i = 0; i < CF_STAGE_COUNT; i++) {
        double d = b.stage[i] - a.stage[i];
        assert_true(d >= 0);
        sum += d;
        if (d > 0)
            printf(" %s %.3g", cf_stage_name((cf_stage)i), d);
    }
    printf("; stages add up to %.5f of it\n", sum / wall);
    int fracture = kind == FRACTURE || kind == FRACTURE_PBD;
    const cf_stage ran[] = {fracture ? CF_STAGE_ELASTICITY : CF_STAGE_RIGID_STEP,
                            CF_STAGE_BOOKKEEPING};
    for (size_t i = 0; i < sizeof ran / sizeof *ran; i++)
        assert_true(b.stage[ran[i]] > a.stage[ran[i]]);
    if (kind != RIGID_BULLET) /* the solver's own stages */
        for (int i = CF_STAGE_COLLISION; i <= CF_STAGE_VELOCITY_UPDATE; i++)
            if (i != CF_STAGE_PBD_PROJECTION || kind != FRACTURE)
                assert_true(b.stage[i] > a.stage[i]);
    return fabs(sum - wall) / wall;
}

/* The stages' timers add up to the step's wall time within 2 %.  A try is
 * 5 ms of wall time, so one preemption of the process between two stages on
 * a loaded host shows as a quarter of it untimed; such a try is repeated,
 * up to five tries.  Work outside every stage is in every try, so it still
 * fails. */
static void stages_add_up(scene_kind kind)
{
    cf_mesh box;
    cf_world *w = make_world(kind, 1, 3, &box);
    for (int k = 0; k < 20; k++)
        step(w);
    double best = 1;
    for (int t = 0; t < 5 && best > 0.02; t++)
        best = fmin(best, untimed_share(w, kind));
    assert_true(best <= 0.02);
    cf_world_destroy(w);
}

static void test_stages_add_up_to_the_step(void **state)
{
    (void)state;
    for (scene_kind k = RIGID_BULLET; k <= FRACTURE_PBD; k++)
        stages_add_up(k);
    assert_string_equal(cf_stage_name(CF_STAGE_ELASTICITY), "elasticity");
    assert_string_equal(cf_stage_name(CF_STAGE_COUNT), "?");
}

/* After 100 steps to warm up (Bullet's pools, the caches, the arena), 400
 * steps that insert nothing call no allocator: a 162-tet box on one
 * thread, and on two a 10,368-tet one whose loops run on the threads
 * (more tets, nodes and bars than the *_PARALLEL_MIN of tet4.h, solid.h
 * and pbd.h). */
static void test_steps_that_insert_nothing_allocate_nothing(void **state)
{
    (void)state;
    if (!COUNTING)
        skip();
    for (int threads = 1; threads <= 2; threads++)
        for (scene_kind k = RIGID_BULLET; k <= FRACTURE_PBD; k++) {
            cf_mesh box;
            cf_world *w = make_world(k, threads, threads == 1 ? 3 : 12, &box);
            for (int i = 0; i < 100; i++)
                step(w);
            int n_coh = cf_world_cohesive_count(w);
            count_from_now();
            for (int i = 0; i < 400; i++)
                step(w);
            long n = counted();
            printf("FIGURE %s, %d thread(s): %ld allocations in 400 steps\n", kind_name[k],
                   threads, n);
            assert_int_equal(cf_world_cohesive_count(w), n_coh);
            assert_int_equal(n, 0);
            cf_world_destroy(w);
        }
}

/* The arena: what a stage takes comes back at its release; a step that
 * needs more than the block spills (the marks stay valid), and once the
 * step has ended the block holds it all, so the same step again calls no
 * allocator. */
static void test_arena_grows_to_the_largest_step(void **state)
{
    (void)state;
    cf_arena a = {0};
    for (int round = 0; round < 3; round++) {
        count_from_now();
        size_t mark = cf_arena_mark(&a);
        double *x = cf_arena_take(&a, 1000 * sizeof *x);
        int *y = cf_arena_take(&a, 333 * sizeof *y);
        assert_non_null(x);
        assert_non_null(y);
        assert_true((uintptr_t)x % _Alignof(max_align_t) == 0);
        assert_true((uintptr_t)y % _Alignof(max_align_t) == 0);
        for (int i = 0; i < 1000; i++)
            x[i] = i;
        for (int i = 0; i < 333; i++) /* y does not overlap x */
            y[i] = -1;
        for (int i = 0; i < 1000; i++)
            assert_true(x[i] == i);
        cf_arena_release(&a, mark);
        assert_int_equal(cf_arena_mark(&a), mark);
        assert_int_equal(cf_arena_end_step(&a), 0);
        long n = counted();
        if (COUNTING)
            assert_int_equal(n, round == 0 ? 2 /* two spills */ + 1 /* the block */ : 0);
    }
    assert_true(a.cap >= 1000 * sizeof(double) + 333 * sizeof(int));
    cf_arena_free(&a);
    assert_null(a.base);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stages_add_up_to_the_step),
        cmocka_unit_test(test_steps_that_insert_nothing_allocate_nothing),
        cmocka_unit_test(test_arena_grows_to_the_largest_step),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
