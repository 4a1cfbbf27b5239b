/* The hybrid's coupling (docs/architecture.md, docs/physics.md §9): momentum across fracture-mode
 * contact with a Bullet body, re-entry of a fragment into fracture mode, and
 * bit-identical runs for any thread count. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "cohfrac/scene.h"
#include "cohfrac/sim.h"
#include "check.h"
#include "fixtures.h"
#include "handoff.h"
#include "linalg.h"
#include "tet4.h"
#include "world_impl.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define STORED_HASH 0x492d3c1805c4c47aull
#define STORED_HASH_COLOURED 0xf674aa0cdc222e74ull
#define STORED_HASH_COLOURED_SOURCE 0x9319b54df0ee93c6ull

static char dir[256];

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "%s/coupling_XXXXXX", COHFRAC_BINARY_DIR);
    if (!mkdtemp(dir))
        return -1;
    /* A single tet cannot crack: a rigid, unbreakable anvil whose face
     * x = 0.2 looks at -x. */
    char path[512];
    snprintf(path, sizeof path, "%s/anvil.node", dir);
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "4 3 0 0\n1 0.2 -0.5 -0.5\n2 0.2 0 0.5\n3 0.2 0.5 -0.5\n4 0.6 0 0\n");
    fclose(f);
    snprintf(path, sizeof path, "%s/anvil.ele", dir);
    f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "1 4 0\n1 1 3 2 4\n");
    fclose(f);
    /* A 4 m x 4 m ground of two triangles at z = 0, facing up. */
    snprintf(path, sizeof path, "%s/ground.obj", dir);
    f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "v -2 -2 0\nv 2 -2 0\nv 2 2 0\nv -2 2 0\nf 1 2 3\nf 1 3 4\n");
    fclose(f);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    fixture_remove_tree(dir);
    return 0;
}

/* A weak 10 cm box at 5 m/s hits the anvil in zero gravity; it breaks, and
 * its nodes push the anvil while it is in fracture mode. */
static const char *impact_scene =
    "return {\n"
    "  name = 'impact', duration = %g, gravity = {0, 0, 0},\n"
    "  material = {E = 1e5, nu = 0.3, rho = 1000, G_I = 1, sigma_max = 2e3,\n"
    "              friction = 0, restitution = 0},\n"
    "  bodies = {\n"
    "    {mesh = '%s/anvil', position = {0.45, 0, 0}},\n"
    "    {mesh = {type = 'box', size = {0.1, 0.1, 0.1}, cells = {2, 2, 2}, tets_per_cell = 5},\n"
    "     velocity = {5, 0, 0}},\n"
    "  },\n"
    "  solver = {dt_rigid = 1e-3, dt_fracture = 1e-4, quiet_steps = 100, threads = %d},\n"
    "  output = {file = ''},\n"
    "}\n";

/* The scene text loaded in memory (no file), and its run. */
static cf_sim *make_sim(const char *text, cf_scene *sc)
{
    cf_error err = {0};
    cf_status st = cf_scene_load_text("scene.lua", text, NULL, 0, COHFRAC_MESH_DIR, sc, &err);
    if (st != CF_OK)
        fail_msg("scene: %s", err.msg);
    cf_run_options opt = {.mesh_dir = COHFRAC_MESH_DIR};
    cf_sim *sim = NULL;
    st = cf_sim_create(sc, &opt, &sim, &err);
    if (st != CF_OK)
        fail_msg("sim: %s", err.msg);
    return sim;
}

/* One step of the run; an error fails the test. */
static void advance(cf_sim *sim)
{
    cf_error err = {0};
    if (cf_sim_advance(sim, &err) != CF_OK)
        fail_msg("run: %s", err.msg);
}

/* Advance sim to the scene's duration; a failed step fails the test. */
static void run_to_end(cf_sim *sim)
{
    while (!cf_sim_done(sim))
        advance(sim);
}

static cf_sim *impact_sim(double duration, int threads, cf_scene *sc)
{
    char text[2048];
    snprintf(text, sizeof text, impact_scene, duration, dir, threads);
    return make_sim(text, sc);
}

/* Momentum of the anvil (fragment 0, never broken), kg m/s along x. */
static double anvil_momentum(cf_sim *sim)
{
    cf_fragment_state fs[256];
    int n = cf_world_fragments(cf_sim_world(sim), fs, 256);
    for (int i = 0; i < n && i < 256; i++)
        if (fs[i].id == 0)
            return fs[i].momentum[0];
    fail_msg("the anvil is gone");
    return 0;
}

static int any_in_fracture_mode(cf_sim *sim)
{
    cf_fragment_state fs[256];
    int n = cf_world_fragments(cf_sim_world(sim), fs, 256);
    for (int i = 0; i < n && i < 256; i++)
        if (fs[i].mode == 1)
            return 1;
    return 0;
}

/* Total linear momentum is conserved to round-off through the Bullet
 * contact, the hand-offs and the node-on-hull contact of fracture mode; the
 * anvil gains a real share of it while the box is in fracture mode. */
static void test_momentum_across_fracture_mode_contact(void **state)
{
    (void)state;
    cf_scene sc;
    cf_sim *sim = impact_sim(0.12, 0, &sc);
    cf_ledger l0, l;
    cf_world_ledger(cf_sim_world(sim), &l0);
    double P0 = l0.momentum[0], pushed = 0, worst = 0;
    int fracture_steps = 0;
    while (!cf_sim_done(sim)) {
        double before = anvil_momentum(sim);
        advance(sim);
        if (any_in_fracture_mode(sim)) {
            fracture_steps++;
            pushed += anvil_momentum(sim) - before;
        }
        cf_world_ledger(cf_sim_world(sim), &l);
        for (int k = 0; k < 3; k++)
            worst = fmax(worst, fabs(l.momentum[k] - l0.momentum[k]) / P0);
    }
    printf("FIGURE coupling: box momentum %.6g kg m/s, anvil gained %.6g kg m/s while the "
           "box was in fracture mode (%d rigid steps), worst total momentum drift %.3g\n",
           P0, pushed, fracture_steps, worst);
    assert_true(fracture_steps > 0);
    assert_true(pushed > 0.05 * P0);
    assert_true(worst < 1e-9);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* The same run with one thread and with two gives the same bits, and the
 * bits of the version this test was written against. */
static void test_determinism_hash(void **state)
{
    (void)state;
    uint64_t h[2];
    for (int r = 0; r < 2; r++) {
        cf_scene sc;
        cf_sim *sim = impact_sim(0.06, r + 1, &sc);
        run_to_end(sim);
        h[r] = cf_world_state_hash(cf_sim_world(sim));
        cf_sim_destroy(sim);
        cf_scene_free(&sc);
    }
    printf("FIGURE determinism: hash %016llx (1 thread), %016llx (2 threads)\n",
           (unsigned long long)h[0], (unsigned long long)h[1]);
    assert_true(h[0] == h[1]);
    /* The hash of this run on x86-64 with Debian 12's Bullet 3.24: a change
     * here means the engine's results changed (update it deliberately). */
    assert_true(h[0] == STORED_HASH);
}

/* Heartbeats of one rigid step: how many, and the latest time given. */
typedef struct {
    int calls;
    double latest;
} heartbeat;

static void count_tick(void *user, double t)
{
    heartbeat *h = user;
    h->calls++, h->latest = fmax(h->latest, t);
}

/* The world's heartbeat (cf_world_set_tick, what keeps a progress display
 * moving inside a long step): in every rigid step that a fragment spends
 * in fracture mode it comes after each of the dt_rigid / dt_fracture = 10
 * sub-steps, the latest at the end of the step; and it changes nothing
 * (the state hash of test_determinism_hash). */
static void test_heartbeat_inside_a_step(void **state)
{
    (void)state;
    cf_scene sc;
    cf_sim *sim = impact_sim(0.06, 1, &sc);
    cf_world *w = (cf_world *)cf_sim_world(sim);
    heartbeat h;
    cf_world_set_tick(w, count_tick, &h);
    int spells = 0, short_of = 0, beats = 0;
    while (!cf_sim_done(sim)) {
        int fracture = any_in_fracture_mode(sim);
        h.calls = 0, h.latest = -INFINITY;
        advance(sim);
        beats += h.calls;
        if (!fracture)
            continue;
        spells++;
        short_of += h.calls < 10 || fabs(h.latest - cf_world_time(w)) > 1e-12;
    }
    printf("FIGURE heartbeat: %d steps in fracture mode, %d heartbeats, %d steps short of 10 "
           "or of the step's end\n", spells, beats, short_of);
    assert_true(spells > 0);
    assert_int_equal(short_of, 0);
    assert_true(cf_world_state_hash(w) == STORED_HASH);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* Reading every fragment's pose before each step (cf_world_fragments, as
 * output frames do) changes nothing: the state hash of
 * test_determinism_hash.  (Reading a pose in fracture mode once moved the
 * shape matching's warm start, and the default drop's bits changed with
 * output.frame_interval.) */
static void test_reading_poses_changes_nothing(void **state)
{
    (void)state;
    cf_scene sc;
    cf_sim *sim = impact_sim(0.06, 1, &sc);
    int read_in_fracture = 0;
    while (!cf_sim_done(sim)) {
        read_in_fracture += any_in_fracture_mode(sim);
        advance(sim);
    }
    printf("FIGURE poses read: in fracture mode before %d steps, hash %016llx\n",
           read_in_fracture, (unsigned long long)cf_world_state_hash(cf_sim_world(sim)));
    assert_true(read_in_fracture > 0);
    assert_true(cf_world_state_hash(cf_sim_world(sim)) == STORED_HASH);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* A 8,640-tet box (more bars than CF_BARS_PARALLEL_MIN, so the coloured
 * PBD sweep, the element loop, the insertion scan and the node gather all
 * run on the threads) hits the ground at 5 m/s in fracture mode and cracks,
 * under the traction and under the source's rule: 1 and 2 threads give the
 * same bits, and those this test was written against. */
static const char *coloured_scene =
    "return {\n"
    "  name = 'coloured', duration = 1e-3, gravity = {0, 0, -9.81},\n"
    "  material = {E = 1e6, nu = 0.3, rho = 1000, G_I = 1, sigma_max = %g,\n"
    "              friction = 0.5, restitution = 0, nucleation_radius = 0.01},\n"
    "  bodies = {{mesh = {type = 'box', size = {0.12, 0.12, 0.12}, cells = {12, 12, 12},\n"
    "                     tets_per_cell = 5},\n"
    "             position = {0, 0, 0.0605}, velocity = {0, 0, -5}}},\n"
    "  obstacles = {{type = 'plane', point = {0, 0, 0}, normal = {0, 0, 1}}},\n"
    "  solver = {mode = 'fracture', criterion = '%s', dt_rigid = 1e-4, dt_fracture = 5e-6,\n"
    "            threads = %d},\n"
    "  output = {file = ''},\n"
    "}\n";

/* The coloured scene with strength sigma_max (Pa) under `criterion` on 1
 * and 2 threads: hashes and cohesive element counts. */
static void run_coloured(double sigma_max, const char *criterion, uint64_t h[2], int coh[2])
{
    for (int r = 0; r < 2; r++) {
        char text[2048];
        snprintf(text, sizeof text, coloured_scene, sigma_max, criterion, r + 1);
        cf_scene sc;
        cf_sim *sim = make_sim(text, &sc);
        assert_true(cf_sim_world(sim)->frag[0].bars.n >= CF_BARS_PARALLEL_MIN); /* the coloured sweep runs */
        run_to_end(sim);
        h[r] = cf_world_state_hash(cf_sim_world(sim));
        coh[r] = cf_sim_world(sim)->solid.n_coh;
        cf_sim_destroy(sim);
        cf_scene_free(&sc);
    }
    printf("FIGURE determinism (coloured PBD, criterion %s): hash %016llx (1 thread), %016llx "
           "(2 threads), %d cohesive elements\n",
           criterion, (unsigned long long)h[0], (unsigned long long)h[1], coh[0]);
}

static void test_determinism_hash_coloured(void **state)
{
    (void)state;
    uint64_t h[2];
    int coh[2];
    run_coloured(1e3, "traction", h, coh);
    assert_true(h[0] == h[1]);
    assert_true(coh[0] > 0);
    assert_true(h[0] == STORED_HASH_COLOURED);
    /* The source's rule (weaker, so that it inserts: it needs 0.9 sigma_max
     * at all three nodes of a facet): its nodal averages and the face test
     * run on the threads from 4096 tets on (this box has 8,640). */
    run_coloured(200.0, "source", h, coh);
    assert_true(h[0] == h[1]);
    assert_true(coh[0] > 0);
    assert_true(h[0] == STORED_HASH_COLOURED_SOURCE);
}

/* A weak box whose cohesive law never lets go (a final opening of 10 km)
 * lands, cracks and goes back to rigid mode.  Its cracks cut it into
 * pieces that share no node, but every one is still held by a cohesive
 * element with unfailed node pairs: it goes back as one body, and the
 * elements stay in the solid with their state for the next impact. */
static const char *bonded_scene =
    "return {\n"
    "  name = 'bonded', duration = 0.05,\n"
    "  material = {E = 1e5, nu = 0.3, rho = 1000, G_I = 1e6, sigma_max = 200,\n"
    "              friction = 0.5, restitution = 0},\n"
    "  bodies = {\n"
    "    {mesh = {type = 'box', size = {0.15, 0.15, 0.15}, cells = {3, 3, 3}, tets_per_cell = 5},\n"
    "     position = {0, 0, 0.08}, velocity = {0, 0, -4}},\n"
    "  },\n"
    "  obstacles = {{type = 'plane', point = {0, 0, 0}, normal = {0, 0, 1}}},\n"
    "  solver = {dt_rigid = 1e-3, dt_fracture = 1e-4, quiet_steps = 100,\n"
    "            crack_growth = 'all', min_piece_tets = 0},\n"
    "  output = {file = ''},\n"
    "}\n";

static void test_handoff_keeps_bonded_pieces_together(void **state)
{
    (void)state;
    cf_scene sc;
    cf_sim *sim = make_sim(bonded_scene, &sc);
    run_to_end(sim);
    const cf_world *w = cf_sim_world(sim);
    int alive = 0, rigid = 0, fi = -1;
    for (int i = 0; i < w->n_frag; i++)
        if (w->frag[i].mode != CF_MODE_DEAD)
            alive++, rigid += w->frag[i].mode == CF_MODE_RIGID, fi = i;
    int failed = 0;
    for (int c = 0; c < w->solid.n_coh; c++)
        failed += cf_cohesive_all_failed(&w->solid.coh[c]);
    int *comp = malloc((size_t)w->frag[fi].nt * sizeof(int));
    int by_nodes = cf_label_components(&w->solid, w->frag[fi].tets, w->frag[fi].nt, comp);
    printf("FIGURE bonded: %d cohesive elements (%d failed), %d hand-offs, %d fragment(s) alive, "
           "%d pieces by shared nodes alone\n",
           w->solid.n_coh, failed, w->n_handoffs, alive, by_nodes);
    assert_true(w->n_handoffs >= 2); /* rigid -> fracture -> rigid */
    assert_int_equal(failed, 0);
    assert_true(by_nodes >= 2); /* the cracks do cut it */
    assert_int_equal(alive, 1);
    assert_int_equal(rigid, 1);
    free(comp);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* A weak box lands on the ground at 4 m/s and breaks; a sweeper box then
 * runs along the ground at 6 m/s into its pieces.  Its cohesive length
 * (2.5 m) is far above its size, so the front rule would grow one crack
 * from one nucleus: the source's rule (every qualifying facet) breaks it
 * into the many pieces the sweeper is there to hit. */
static const char *reentry_scene =
    "return {\n"
    "  name = 'reentry', duration = 0.3,\n"
    "  material = {E = 1e5, nu = 0.3, rho = 1000, G_I = 1, sigma_max = 200,\n"
    "              friction = 0.5, restitution = 0},\n"
    "  bodies = {\n"
    "    {mesh = {type = 'box', size = {0.15, 0.15, 0.15}, cells = {3, 3, 3}, tets_per_cell = 5},\n"
    "     position = {0, 0, 0.08}, velocity = {0, 0, -4}},\n"
    "  },\n"
    "  obstacles = {\n"
    "    {type = 'plane', point = {0, 0, 0}, normal = {0, 0, 1}},\n"
    "    {type = 'box', center = {1.2, 0, 0.06}, half_extents = {0.05, 0.5, 0.05},\n"
    "     velocity = {-6, 0, 0}},\n"
    "  },\n"
    "  solver = {dt_rigid = 1e-3, dt_fracture = 1e-4, quiet_steps = 100,\n"
    "            crack_growth = 'all', min_piece_tets = 0, %s},\n"
    "  output = {file = ''},\n"
    "}\n";

/* The re-entry scene without debris (so its pieces can break again), or
 * with every piece of at most 64 tets debris (the box has 135). */
static cf_sim *reentry_sim(int debris, cf_scene *sc)
{
    char text[2048];
    snprintf(text, sizeof text, reentry_scene,
             debris ? "debris_tets = 64" : "debris_tets = 0");
    return make_sim(text, sc);
}

/* A fragment born of the first break is hit again, returns to fracture
 * mode and breaks further: its children name it as parent, are born later
 * than it, and every tet still belongs to exactly one alive fragment. */
static void test_reentry_keeps_the_family_tree(void **state)
{
    (void)state;
    cf_scene sc;
    cf_sim *sim = reentry_sim(0, &sc);
    enum { CAP = 4096 };
    static int parent[CAP];
    static double birth[CAP];
    static cf_fragment_state fs[CAP];
    for (int i = 0; i < CAP; i++)
        parent[i] = -2;
    static cf_landing land[CAP];
    int reentered = 0, under_way = 0;
    while (!cf_sim_done(sim)) {
        advance(sim);
        cf_world *w = cf_sim_world(sim);
        int n = cf_world_fragments(w, fs, CAP), landing = 0, own = 0;
        assert_true(n <= CAP);
        for (int i = 0; i < n; i++) {
            assert_true(fs[i].id < CAP);
            parent[fs[i].id] = fs[i].parent;
            birth[fs[i].id] = fs[i].birth_time;
            if (fs[i].mode == 1 && fs[i].parent >= 0)
                reentered = 1;
            /* a piece struck on its own: a landing under way (the forecast) */
            own += fs[i].mode == 1 && fs[i].parent >= 0 &&
                   w->frag[fs[i].id].t_enter >= fs[i].birth_time;
        }
        int m = cf_world_landings(w, 10.0, land, CAP);
        for (int i = 0; i < m && i < CAP; i++)
            landing += land[i].under_way;
        assert_int_equal(landing, own);
        under_way += landing;
    }
    int n = cf_world_fragments(cf_sim_world(sim), fs, CAP), tets = 0, grandchildren = 0;
    for (int i = 0; i < n; i++) {
        int p = fs[i].parent;
        tets += fs[i].n_tets;
        if (p < 0)
            continue;
        /* A fragment that existed (it may have been born and split again
         * within one rigid step, never seen alive between two), born before. */
        assert_true(p < cf_sim_world(sim)->n_frag);
        assert_true(parent[p] == -2 || fs[i].birth_time > birth[p] || parent[p] < 0);
        if (parent[p] >= 0) {
            grandchildren++;
            assert_true(fs[i].birth_time > birth[p]);
        }
    }
    /* Only fracture mode holds scratch, and the dead hold nothing: the
     * pieces of the 202,231-tet drop kept 786 MiB of it to the end. */
    const cf_world *w = cf_sim_world(sim);
    long held = 0;
    for (int i = 0; i < w->n_frag; i++) {
        const cf_fragment *f = &w->frag[i];
        if (f->mode != CF_MODE_FRACTURE)
            held += f->scratch_cap + f->pairs_cap;
        if (f->mode == CF_MODE_DEAD)
            held += f->nodes.cap + f->coh.cap;
    }
    printf("FIGURE reentry: %d fragments alive, %d born of a fragment that was itself born "
           "of a split; %d rigid steps' pieces in fracture mode on strikes of their own; %d "
           "fragments ever, %ld scratch items held outside fracture mode\n", n,
           grandchildren, under_way, w->n_frag, held);
    assert_int_equal(held, 0);
    assert_true(reentered);
    assert_true(under_way > 0);
    assert_true(grandchildren > 0);
    assert_int_equal(tets, cf_world_tet_count(cf_sim_world(sim)));
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* The same scene with debris (docs/physics.md §9.2): the pieces of at
 * most 64 tets are debris, spheres in Bullet with no convex
 * decomposition; the sweeper hits them, and none goes back to fracture
 * mode.  Mass and momentum pass the hand-offs to round-off, the debris
 * stays above the ground, and the ledger balances: its spheres take
 * contact without energy that no load put in. */
static void test_debris_stays_rigid_and_conserves(void **state)
{
    (void)state;
    cf_scene sc;
    cf_sim *sim = reentry_sim(1, &sc);
    const cf_world *w = cf_sim_world(sim);
    double mass0 = w->frag[0].mass;
    int debris_in_fracture = 0;
    while (!cf_sim_done(sim)) {
        advance(sim);
        for (int i = 0; i < w->n_frag; i++)
            debris_in_fracture +=
                cf_fragment_is_debris(&w->frag[i], &w->def.solver) && w->frag[i].mode == CF_MODE_FRACTURE;
    }
    cf_world_stats st;
    cf_world_stats_get(w, &st);
    cf_ledger l;
    cf_world_ledger(w, &l);
    double input = l.initial + l.work_gravity + l.work_obstacles;
    double mass = 0, debris_mass = 0, lowest = INFINITY;
    int debris = 0, hulls = 0;
    for (int i = 0; i < w->n_frag; i++) {
        const cf_fragment *f = &w->frag[i];
        if (f->mode == CF_MODE_DEAD)
            continue;
        mass += f->mass;
        if (!cf_fragment_is_debris(f, &w->def.solver))
            continue;
        debris++, debris_mass += f->mass;
        hulls += f->hulls.n_hulls;
        double com[3], R[9], v[3], om[3];
        cf_fragment_pose_peek(&w->frag[i], &w->solid, w->bullet, com, R, v, om);
        lowest = fmin(lowest, com[2]);
    }
    printf("FIGURE debris: %d of %d pieces debris (%.4g kg of %.4g), %d convex hulls among "
           "them, %d steps with debris in fracture mode; momentum error at the hand-offs "
           "%.2g; lowest debris centre %.3g m; ledger residual %.3g of the input %.4g J\n",
           debris, st.alive, debris_mass, mass0, hulls, debris_in_fracture,
           st.max_momentum_error, lowest, l.residual / input, input);
    assert_true(debris >= 10);
    assert_int_equal(st.debris, debris);
    assert_true(fabs(st.debris_mass - debris_mass) < 1e-12 * mass0);
    assert_true(fabs(mass - mass0) < 1e-12 * mass0);
    assert_int_equal(hulls, 0);
    assert_int_equal(debris_in_fracture, 0);
    assert_true(st.max_momentum_error < 1e-12);
    assert_true(lowest > 0);
    assert_true(fabs(l.residual) < 0.01 * input);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* A block lands at 3 m/s on the ground with a compressive strength far
 * below the impact stress rho c v (docs/physics.md §2.2): the tets under
 * the contact flow, and those whose plastic strain reaches the crushing
 * strain are crushed.  Each leaves as a one-tet debris piece that carries
 * no stress; none of them is thrown faster than the block landed (its
 * strain energy and the floor's springs under its nodes go to the crushing
 * work instead of into its motion), mass and momentum pass the hand-offs
 * to round-off and the ledger balances. */
static const char *crush_scene =
    "return {\n"
    "  name = 'crush', duration = 0.08,\n"
    "  material = {E = 1e8, nu = 0.3, rho = 1000, G_I = 100, sigma_max = 1e7,\n"
    "              compressive_strength = %g, crushing_strain = %g},\n"
    "  bodies = {{mesh = {type = 'box', size = {0.1, 0.1, 0.1}, cells = {3, 3, 3},\n"
    "                     tets_per_cell = 5},\n"
    "             position = {0, 0, 0.0502}, velocity = {0, 0, -3}}},\n"
    "  obstacles = {{type = 'plane', point = {0, 0, 0}, normal = {0, 0, 1}}},\n"
    "  solver = {dt_rigid = 2e-4, cfl_fraction = 0.5, quiet_steps = 200,\n"
    "            constraints = 'none', obstacle_contact = 'penalty'},\n"
    "  output = {file = ''},\n"
    "}\n";

static void crush_run(double sc_strength, double eps, int *crushed, double *fastest,
                      double *residual, double *plastic)
{
    char text[2048];
    snprintf(text, sizeof text, crush_scene, sc_strength, eps);
    cf_scene sc;
    cf_sim *sim = make_sim(text, &sc);
    const cf_world *w = cf_sim_world(sim);
    double mass0 = w->frag[0].mass;
    run_to_end(sim);
    *crushed = 0, *fastest = 0;
    double mass = 0;
    for (int i = 0; i < w->n_frag; i++) {
        const cf_fragment *f = &w->frag[i];
        if (f->mode == CF_MODE_DEAD)
            continue;
        mass += f->mass;
        int powder = w->solid.crushed && w->solid.crushed[f->tets[0]];
        if (!powder)
            continue;
        (*crushed)++;
        assert_int_equal(f->nt, 1);
        assert_true(cf_fragment_is_debris(f, &w->def.solver));
        assert_int_equal(f->mode, CF_MODE_RIGID);
        double com[3], R[9], v[3], om[3];
        cf_fragment_pose_peek(&w->frag[i], &w->solid, w->bullet, com, R, v, om);
        *fastest = fmax(*fastest, sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
    }
    cf_world_stats st;
    cf_world_stats_get(w, &st);
    cf_ledger l;
    cf_world_ledger(w, &l);
    *residual = l.residual / (l.initial + l.work_gravity + l.work_obstacles);
    *plastic = l.plastic_dissipated;
    assert_true(fabs(mass - mass0) < 1e-12 * mass0);
    assert_true(st.max_momentum_error < 1e-12);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

static void test_crushed_tets_leave_as_powder(void **state)
{
    (void)state;
    int crushed, none;
    double fastest, residual, plastic, fastest0, residual0, plastic0;
    crush_run(3e5, 0.005, &crushed, &fastest, &residual, &plastic);
    crush_run(3e5, 0, &none, &fastest0, &residual0, &plastic0);
    printf("FIGURE crushing: %d tets crushed into one-tet debris, the fastest at %.3g m/s "
           "(landing 3 m/s); crushing work %.4g J (%.4g J without the crushing strain); "
           "ledger residual %.2g (%.2g)\n",
           crushed, fastest, plastic, plastic0, residual, residual0);
    assert_true(crushed > 0);
    assert_int_equal(none, 0);
    assert_true(fastest < 3.0);
    assert_true(fabs(residual) < 0.01);
    assert_true(fabs(residual0) < 0.01);
}

/* An elastic box in fracture mode dropped on the ground: as a plane, and
 * as a triangle mesh through FCL. */
static const char *ground_scene =
    "return {\n"
    "  name = 'ground', duration = 0.25,\n"
    "  material = {E = 1e5, nu = 0.3, rho = 1000, friction = 0.5, restitution = 0},\n"
    "  bodies = {{mesh = {type = 'box', size = {0.1, 0.1, 0.1}, cells = {2, 2, 2}},\n"
    "             position = {0.3, -0.2, 0.1}, velocity = {0.5, 0, 0}}},\n"
    "  obstacles = {%s},\n"
    "  solver = {mode = 'fracture', criterion = 'none', dt_rigid = 1e-3, dt_fracture = 1e-4},\n"
    "  output = {file = ''},\n"
    "}\n";

static void run_ground(const char *obstacle, cf_fragment_state *out)
{
    char text[2048];
    snprintf(text, sizeof text, ground_scene, obstacle);
    cf_scene sc;
    cf_sim *sim = make_sim(text, &sc);
    run_to_end(sim);
    assert_int_equal(cf_world_fragments(cf_sim_world(sim), out, 1), 1);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* The mesh ground holds the box exactly where the plane does: the closest
 * point on a flat triangle is the plane's projection, with the same normal,
 * friction and restitution. */
static void test_mesh_obstacle_matches_plane(void **state)
{
    (void)state;
    cf_fragment_state plane, mesh;
    char obstacle[600];
    run_ground("{type = 'plane', point = {0, 0, 0}, normal = {0, 0, 1}}", &plane);
    snprintf(obstacle, sizeof obstacle, "{type = 'mesh', file = '%s/ground.obj'}", dir);
    run_ground(obstacle, &mesh);
    double d = 0;
    for (int k = 0; k < 3; k++)
        d = fmax(d, fabs(plane.com[k] - mesh.com[k]));
    printf("FIGURE mesh obstacle: resting centre of mass z = %.9f m (plane), %.9f m (mesh), "
           "largest difference %.3g m\n", plane.com[2], mesh.com[2], d);
    assert_true(plane.com[2] > 0.045 && plane.com[2] < 0.055); /* resting on its face */
    assert_true(d < 1e-9);
}

/* A box handed to fracture mode while it overlaps the ground by 2 mm (a
 * rigid pose resting within a contact margin) is moved out of it first:
 * pushed out at dt_fracture instead, the overlap would throw its bottom
 * nodes off at 20 m/s.  No work is put in, so the kinetic energy never
 * exceeds the 2 J it starts with. */
static const char *overlap_scene =
    "return {\n"
    "  name = 'overlap', duration = 0.05, gravity = {0, 0, 0},\n"
    "  material = {E = 1e5, nu = 0.3, rho = 1000, G_I = 1, sigma_max = 1e9,\n"
    "              friction = 0.5, restitution = 0},\n"
    "  bodies = {{mesh = {type = 'box', size = {0.1, 0.1, 0.1}, cells = {2, 2, 2}},\n"
    "             position = {0, 0, 0.048}, velocity = {0, 0, -2}}},\n"
    "  obstacles = {{type = 'plane', point = {0, 0, 0}, normal = {0, 0, 1}}},\n"
    "  solver = {rigid_backend = 'pbd', dt_rigid = 1e-3, dt_fracture = 1e-4,\n"
    "            impact_threshold = 1, quiet_steps = 1000},\n"
    "  output = {file = ''},\n"
    "}\n";

static void test_handoff_clears_obstacle_overlap(void **state)
{
    (void)state;
    cf_scene sc;
    cf_sim *sim = make_sim(overlap_scene, &sc);
    double ke_max = 0;
    int entered = 0;
    while (!cf_sim_done(sim)) {
        advance(sim);
        cf_ledger l;
        cf_world_ledger(cf_sim_world(sim), &l);
        ke_max = fmax(ke_max, l.kinetic);
        entered |= any_in_fracture_mode(sim);
    }
    printf("FIGURE overlap at hand-off: largest kinetic energy %.4f J (2 J at the start)\n",
           ke_max);
    assert_true(entered);
    assert_true(ke_max <= 2.0 * (1 + 1e-9));
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* A box wedged between the floor and a ceiling 10 mm lower than its top
 * (explicit fracture mode, penalty contact): no translation clears it, so
 * the hand-off into fracture mode puts the nodes still inside on the
 * planes, squeezing the box by 10 %.  That strain energy is what the
 * obstacles did to the box, and the ledger books it as a hand-off gain:
 * the residual stays at round-off of the 2 J it starts with.  Left inside,
 * the penalty springs (k = 0.01 m / dt^2 at 5 mm) would throw the nodes at
 * hundreds of m/s. */
static const char *wedge_scene =
    "return {\n"
    "  name = 'wedge', duration = 0.004, gravity = {0, 0, 0},\n"
    "  material = {E = 1e5, nu = 0.25, rho = 1000, G_I = 1, sigma_max = 1e9,\n"
    "              friction = 0, restitution = 0},\n"
    "  bodies = {{mesh = {type = 'box', size = {0.1, 0.1, 0.1}, cells = {2, 2, 2}},\n"
    "             position = {0, 0, 0.0505}, velocity = {0, 0, -2}}},\n"
    "  obstacles = {{type = 'plane', point = {0, 0, 0}, normal = {0, 0, 1}},\n"
    "               {type = 'plane', point = {0, 0, 0.09}, normal = {0, 0, -1}}},\n"
    "  solver = {dt_rigid = 1e-3, impact_threshold = 1, quiet_steps = 100000,\n"
    "            constraints = 'none', cfl_fraction = 0.5, obstacle_contact = 'penalty'},\n"
    "  output = {file = ''},\n"
    "}\n";

static void test_wedged_piece_enters_clear(void **state)
{
    (void)state;
    cf_scene sc;
    cf_sim *sim = make_sim(wedge_scene, &sc);
    double worst = 0, ke_max = 0;
    int entered = 0;
    cf_ledger l;
    while (!cf_sim_done(sim)) {
        advance(sim);
        cf_world_ledger(cf_sim_world(sim), &l);
        worst = fmax(worst, fabs(l.residual) / l.initial);
        ke_max = fmax(ke_max, l.kinetic);
        entered |= any_in_fracture_mode(sim);
    }
    printf("FIGURE wedged hand-off: strain energy put in %.4f J, largest kinetic %.4f J, "
           "largest |residual| / input %.2e\n",
           -l.handoff, ke_max, worst);
    assert_true(entered);
    assert_true(-l.handoff > 0.05);             /* the squeeze was booked */
    assert_true(ke_max <= 2.0 - l.handoff + 1e-9);
    assert_true(worst <= 1e-3);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* An unbreakable elastic box lands at 2 m/s, and its quiet period (2 ms)
 * ends long before the impact does (a wave crosses it and back in 20 ms).
 * It stays in fracture mode while it still drives into the ground, and
 * goes back to rigid mode once, when the rebound has begun: one entry and
 * one return.  Handed back while still driving in, it would re-enter at
 * the next rigid step, round trip after round trip. */
static const char *chatter_scene =
    "return {\n"
    "  name = 'chatter', duration = 0.08, gravity = {0, 0, 0},\n"
    "  material = {E = 1e5, nu = 0.25, rho = 1000, G_I = 1, sigma_max = 1e9,\n"
    "              friction = 0, restitution = 0},\n"
    "  bodies = {{mesh = {type = 'box', size = {0.1, 0.1, 0.1}, cells = {2, 2, 2}},\n"
    "             position = {0, 0, 0.052}, velocity = {0, 0, -2}}},\n"
    "  obstacles = {{type = 'plane', point = {0, 0, 0}, normal = {0, 0, 1}}},\n"
    "  solver = {dt_rigid = 1e-3, dt_fracture = 1e-4, impact_threshold = 1,\n"
    "            quiet_steps = 20, constraints = 'none'},\n"
    "  output = {file = ''},\n"
    "}\n";

static void test_no_return_while_driving_in(void **state)
{
    (void)state;
    cf_scene sc;
    cf_sim *sim = make_sim(chatter_scene, &sc);
    int entries = 0, was = 0;
    while (!cf_sim_done(sim)) {
        advance(sim);
        int now = any_in_fracture_mode(sim);
        entries += now && !was;
        was = now;
    }
    cf_fragment_state fs[4];
    int n = cf_world_fragments(cf_sim_world(sim), fs, 4);
    printf("FIGURE landing at 2 m/s, quiet period 2 ms: %d entries into fracture mode, %d "
           "hand-offs, final vz %.3f m/s\n",
           entries, cf_sim_world(sim)->n_handoffs, n > 0 ? fs[0].v[2] : 0.0);
    assert_int_equal(n, 1);
    assert_int_equal(entries, 1);
    assert_int_equal(cf_sim_world(sim)->n_handoffs, 2);
    assert_true(fs[0].v[2] > -1.0); /* no longer driving in */
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* A box lands at 1 m/s under gravity, bounces on its own elasticity (each
 * bounce a new impact), and then rests on the ground (docs/physics.md
 * §9).  Resting contact is no impact: Bullet's contact impulse on a
 * resting body is m g dt per step, far below the impact threshold's m v,
 * so once at rest it never goes back to fracture mode; the resting piece
 * of examples/drop.c used to switch modes every 2 ms. */
static const char *resting_scene =
    "return {\n"
    "  name = 'resting', duration = 1.0,\n"
    "  material = {E = 1e5, nu = 0.25, rho = 1000, G_I = 1, sigma_max = 1e9,\n"
    "              friction = 0.5, restitution = 0},\n"
    "  bodies = {{mesh = {type = 'box', size = {0.1, 0.1, 0.1}, cells = {2, 2, 2}},\n"
    "             position = {0, 0, 0.101}}},\n"
    "  obstacles = {{type = 'plane', point = {0, 0, 0}, normal = {0, 0, 1}}},\n"
    "  solver = {dt_rigid = 1e-3, dt_fracture = 1e-4, quiet_steps = 100,\n"
    "            constraints = 'xpbd'},\n"
    "  output = {file = ''},\n"
    "}\n";

static void test_resting_body_stays_rigid(void **state)
{
    (void)state;
    cf_scene sc;
    cf_sim *sim = make_sim(resting_scene, &sc);
    int entries = 0, was = 0, after_rest = 0, handoffs_at_rest = -1;
    double rest_time = -1;
    while (!cf_sim_done(sim)) {
        advance(sim);
        cf_world *w = cf_sim_world(sim);
        int now = any_in_fracture_mode(sim);
        entries += now && !was;
        after_rest += now && !was && rest_time >= 0;
        was = now;
        cf_fragment_state f[1];
        cf_world_fragments(w, f, 1);
        double speed = sqrt(f[0].v[0] * f[0].v[0] + f[0].v[1] * f[0].v[1] + f[0].v[2] * f[0].v[2]);
        if (rest_time < 0 && !now && speed < 0.01 && fabs(f[0].com[2] - 0.05) < 1e-3)
            rest_time = cf_world_time(w), handoffs_at_rest = w->n_handoffs;
    }
    const cf_world *w = cf_sim_world(sim);
    printf("FIGURE resting: %d entries into fracture mode (landing and bounces), at rest from "
           "t = %.3f s, then %d entries and %d hand-offs to t = 1 s\n",
           entries, rest_time, after_rest, w->n_handoffs - handoffs_at_rest);
    assert_true(entries >= 1); /* the landing is an impact */
    assert_true(rest_time >= 0 && rest_time < 0.6);
    assert_int_equal(after_rest, 0);
    assert_int_equal(w->n_handoffs, handoffs_at_rest);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* A cube thrown spinning onto the floor tumbles, slides and rocks to rest,
 * striking the floor face after face (docs/physics.md §9).  Each strike
 * passes the impact threshold, and each spell ends, quiet and clear of the
 * impact, without breaking the cube: before the rule it went back to
 * fracture mode at 7 of them, to t = 0.95 s.  Now a strike sends it back
 * only when it is stronger than the strongest the cube has taken whole:
 * every entry's impact exceeds the last, and the strikes in rigid mode that
 * pass the threshold but not the taken impact stay rigid. */
static const char *tumble_scene =
    "return {\n"
    "  name = 'tumble', duration = 1.0,\n"
    "  material = {E = 1e5, nu = 0.25, rho = 1000, G_I = 1, sigma_max = 1e9,\n"
    "              friction = 0.5, restitution = 0},\n"
    "  bodies = {{mesh = {type = 'box', size = {0.1, 0.1, 0.1}, cells = {2, 2, 2}},\n"
    "             position = {0, 0, 0.08}, velocity = {1.5, 0, -0.5},\n"
    "             angular_velocity = {0, 30, 0}}},\n"
    "  obstacles = {{type = 'plane', point = {0, 0, 0}, normal = {0, 0, 1}}},\n"
    "  solver = {dt_rigid = 1e-3, dt_fracture = 1e-4, quiet_steps = 100,\n"
    "            constraints = 'xpbd'},\n"
    "  output = {file = ''},\n"
    "}\n";

static void test_reentry_only_on_a_stronger_impact(void **state)
{
    (void)state;
    cf_scene sc;
    cf_sim *sim = make_sim(tumble_scene, &sc);
    int entries = 0, was = 0, declined = 0, rising = 1;
    double last = 0, threshold = cf_sim_world(sim)->def.solver.impact_threshold;
    while (!cf_sim_done(sim)) {
        advance(sim);
        cf_world *w = cf_sim_world(sim);
        const cf_fragment *f = &w->frag[0];
        int now = f->mode == CF_MODE_FRACTURE;
        if (now && !was) {
            printf("FIGURE tumble: entry %d at t = %.3f s, impact %.3f m/s\n", entries + 1,
                   cf_world_time(w), f->dv_enter);
            rising &= f->dv_enter > last;
            last = f->dv_enter, entries++;
        } else if (!now && f->body >= 0 &&
                   cfb_contact_impulse(w->bullet, f->body) / f->mass > threshold) {
            declined++;
            assert_true(cfb_contact_impulse(w->bullet, f->body) / f->mass <= f->dv_taken);
        }
        was = now;
    }
    cf_world *w = cf_sim_world(sim);
    cf_fragment_state fs[1];
    assert_int_equal(cf_world_fragments(w, fs, 1), 1);
    double speed = sqrt(fs[0].v[0] * fs[0].v[0] + fs[0].v[1] * fs[0].v[1] + fs[0].v[2] * fs[0].v[2]);
    printf("FIGURE tumble: %d entries into fracture mode, %d hand-offs; %d strikes past the "
           "threshold taken in rigid mode, none stronger than %.3f m/s; at t = 1 s %.2e m/s\n",
           entries, w->n_handoffs, declined, w->frag[0].dv_taken, speed);
    assert_true(entries >= 2); /* the first landing, and a stronger slap */
    assert_true(entries <= 3);
    assert_true(rising);
    assert_true(declined >= 3); /* the strikes the old rule re-entered at */
    assert_true(speed < 0.01);  /* at rest */
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* A cube lands on a corner at 2 m/s and crushes it (compressive strength
 * 20 kPa), sinking into the floor for longer than any elastic landing
 * lasts.  The floor holds it in fracture mode no longer than its landing
 * time (docs/physics.md §9): twice Hertz's contact time of a sphere of its
 * mass and volume at the impact threshold's speed, 21 ms; then rigid mode
 * takes the contact.  Before, the floor held it 42 ms and it went back to
 * fracture mode three times more, each time held again. */
static const char *sink_scene_fmt =
    "return {\n"
    "  name = 'sink', duration = 0.3, gravity = {0, 0, %g},\n"
    "  material = {E = 1e7, nu = 0.25, rho = 1000, G_I = 1, sigma_max = 1e9,\n"
    "              compressive_strength = 2e4, friction = 0.5, restitution = 0},\n"
    "  bodies = {{mesh = {type = 'box', size = {0.1, 0.1, 0.1}, cells = {2, 2, 2}},\n"
    "             position = {0, 0, 0.09}, velocity = {0, 0, %g},\n"
    "             orientation = {0.8804762392171493, 0.2798481564548788,\n"
    "                            0.3647051996310009, 0.1159169123637259}}},\n"
    "  obstacles = {{type = 'plane', point = {0, 0, 0}, normal = {0, 0, 1}}},\n"
    "  solver = {dt_rigid = %g, dt_fracture = %g, quiet_steps = 20,\n"
    "            constraints = 'none', obstacle_contact = 'penalty'},\n"
    "  output = {file = ''},\n"
    "}\n";

/* The sink scene under gravity g (m/s^2, along z), landing at vz (m/s),
 * with the rigid step dt_rigid (s; fracture mode's is a tenth, at most
 * 1e-4 s). */
static cf_sim *sink_sim(double g, double vz, double dt_rigid, cf_scene *sc)
{
    char text[1024];
    snprintf(text, sizeof text, sink_scene_fmt, g, vz, dt_rigid, fmin(1e-4, 0.1 * dt_rigid));
    return make_sim(text, sc);
}

static void test_floor_holds_no_longer_than_a_landing(void **state)
{
    (void)state;
    cf_scene sc;
    cf_sim *sim = sink_sim(-9.81, -2, 1e-3, &sc);
    cf_world *w = cf_sim_world(sim);
    /* Hertz: 2 x 2.94 d / v, d = (15 m v^2 / (16 E* sqrt(R)))^(2/5) */
    double m = 1.0, R = cbrt(3 * 1e-3 / (4 * acos(-1.0))), E = 1e7 / (1 - 0.25 * 0.25);
    double v = w->def.solver.impact_threshold;
    double landing = 2 * 2.94 * pow(15 * m * v * v / (16 * E * sqrt(R)), 0.4) / v;
    int entries = 0, was = 0;
    double t_in = -1, t_out = -1;
    while (!cf_sim_done(sim)) {
        advance(sim);
        int now = any_in_fracture_mode(sim);
        if (now && !was)
            entries++, t_in = t_in < 0 ? cf_world_time(w) - w->def.solver.dt_rigid : t_in;
        if (was && !now && t_out < 0)
            t_out = cf_world_time(w);
        was = now;
    }
    cf_ledger l;
    cf_world_ledger(w, &l);
    printf("FIGURE sink: landing time %.4f s; in fracture mode from t = %.3f to %.3f s, %d "
           "entries; plastic work %.3g J, contact removed %.3g J, residual %.2e of %.3g J\n",
           landing, t_in, t_out, entries, l.plastic_dissipated, l.contact, fabs(l.residual),
           l.initial);
    assert_int_equal(entries, 1);
    assert_true(t_out - t_in >= landing - 1e-12);
    assert_true(t_out - t_in <= landing + 2 * w->def.solver.dt_rigid);
    assert_true(l.plastic_dissipated > 0); /* it crushed */
    assert_true(fabs(l.residual) <= 1e-3 * l.initial);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* The cube of the sink scene lands on its corner at 1 m/s under ten times
 * gravity: crushing, it drives into the floor faster than it landed.  Its
 * landing time hands it to rigid mode while its rigid motion still drives
 * its corner in at about 2 m/s, and Bullet's first step on that contact is
 * an impulse of about 2 m/s, more than the 0.87 m/s it entered with.  That
 * is the contact rigid mode took on, not a new or stronger impact
 * (docs/physics.md §9); before, it went back to fracture mode at once, 3
 * entries in all. */
static void test_sustained_contact_stays_rigid(void **state)
{
    (void)state;
    cf_scene sc;
    cf_sim *sim = sink_sim(-98.1, -1, 1e-3, &sc);
    cf_world *w = cf_sim_world(sim);
    int entries = 0, was = 0;
    double dv_enter = 0, t_back = -1;
    while (!cf_sim_done(sim)) {
        advance(sim);
        int now = any_in_fracture_mode(sim);
        entries += now && !was;
        if (now && !was && entries == 1)
            dv_enter = w->frag[0].dv_enter;
        if (was && !now && t_back < 0)
            t_back = cf_world_time(w);
        was = now;
    }
    cf_ledger l;
    cf_world_ledger(w, &l);
    cf_fragment_state fs[1];
    assert_int_equal(cf_world_fragments(w, fs, 1), 1);
    double speed = sqrt(fs[0].v[0] * fs[0].v[0] + fs[0].v[1] * fs[0].v[1] + fs[0].v[2] * fs[0].v[2]);
    printf("FIGURE sustained: entered at %.3f m/s, back in rigid mode at t = %.3f s having taken "
           "%.3f m/s; %d entries; at t = 0.3 s %.2e m/s; residual %.2e of the input\n",
           dv_enter, t_back, w->frag[0].dv_taken, entries, speed,
           fabs(l.residual) / (l.initial + fmax(0.0, l.work_gravity)));
    assert_true(t_back > 0);
    assert_true(w->frag[0].dv_taken > 2 * dv_enter); /* it drove in faster than it landed */
    assert_int_equal(entries, 1);
    assert_true(speed < 0.01); /* at rest on the floor */
    assert_true(fabs(l.residual) <= 1e-2 * (l.initial + fmax(0.0, l.work_gravity)));
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* The cube of the sink scene lands on its corner at 1 m/s with the rigid
 * step of the plaster drops, 50 us, and goes back to rigid mode crushed,
 * its corner still on the floor.  Bullet's shape is the hull grown by its
 * collision margin (0.1 mm here), and a margin left inside the floor is a
 * penetration its solver removes as velocity, 0.2 x 0.1 mm / 50 us =
 * 0.4 m/s: Bullet's floor gave the cube 1.5 J, and the run stopped at the
 * energy guard 4 ms in, with 2.0 J against the 0.54 J put in.  The
 * hand-off lifts the pose clear by the margin (docs/physics.md §9), so the
 * floor only ever takes energy.  And the cube enters fracture mode once:
 * landing at 1 m/s, 50 um a rigid step, less than its margin, it enters
 * with its corner still in the margin's gap above the floor.  Its landing
 * used to count that as clear, so it went back after its quiet period and
 * Bullet's contact sent it in again (2 entries; a 0.3 m cube, 926). */
static void test_handback_on_the_floor_puts_in_nothing(void **state)
{
    (void)state;
    cf_scene sc;
    cf_sim *sim = sink_sim(-9.81, -1, 5e-5, &sc);
    cf_world *w = cf_sim_world(sim);
    int entries = 0, was = 0;
    double contact_min = 0;
    while (!cf_sim_done(sim)) {
        advance(sim);
        int now = any_in_fracture_mode(sim);
        entries += now && !was;
        was = now;
        cf_ledger l;
        cf_world_ledger(w, &l);
        contact_min = fmin(contact_min, l.contact);
    }
    cf_ledger l;
    cf_world_ledger(w, &l);
    double input = l.initial + fmax(0.0, l.work_gravity);
    printf("FIGURE hand-back on the floor: %d entries into fracture mode, %d hand-offs; contact "
           "removed %.4g J (least %.3g J); kinetic %.3g J at t = 0.3 s; residual %.2e of the "
           "input\n", entries, w->n_handoffs, l.contact, contact_min, l.kinetic,
           fabs(l.residual) / input);
    assert_true(l.plastic_dissipated > 0); /* it crushed */
    assert_int_equal(entries, 1);
    assert_true(contact_min >= -1e-6 * input); /* a fixed floor gives nothing */
    assert_true(fabs(l.residual) <= 1e-2 * input);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* The cube of examples/drop.c lands from 1 m, takes the impact in fracture
 * mode without breaking, and goes back to rigid mode on its way up.  A
 * fragment that stays whole keeps the principal frame its hulls were built
 * in: computed again at the hand-back, the cube's equal principal moments
 * gave other axes from round-off, its hulls were posed turned 5 cm deep in
 * the ground, Bullet's push-out read as a 20 m/s impact, and the cube went
 * back to fracture mode at every rigid step (28 hand-offs in 0.6 s).  Now
 * it hands off twice and then flies: v_z = v_back - g (t - t_back). */
static const char *cube_drop_scene =
    "return {\n"
    "  name = 'cube_drop', duration = 0.55,\n"
    "  material = {E = 1e5, sigma_max = 3e3, tau_max = 3e3},\n"
    "  bodies = {{mesh = {type = 'box', size = {0.2, 0.2, 0.2}, cells = {4, 4, 4}},\n"
    "             position = {0, 0, 1.0}}},\n"
    "  obstacles = {{type = 'plane', point = {0, 0, 0}, normal = {0, 0, 1}}},\n"
    "  solver = {constraints = 'xpbd'},\n"
    "  output = {file = ''},\n"
    "}\n";

static void test_handback_in_flight_stays_rigid(void **state)
{
    (void)state;
    cf_scene sc;
    cf_sim *sim = make_sim(cube_drop_scene, &sc);
    int entries = 0, was = 0;
    double t_back = -1, v_back = 0, worst = 0;
    while (!cf_sim_done(sim)) {
        advance(sim);
        cf_world *w = cf_sim_world(sim);
        int now = any_in_fracture_mode(sim);
        entries += now && !was;
        cf_fragment_state f[1];
        assert_int_equal(cf_world_fragments(w, f, 1), 1);
        if (was && !now && t_back < 0)
            t_back = cf_world_time(w), v_back = f[0].v[2];
        else if (t_back >= 0 && !now)
            worst = fmax(worst, fabs(f[0].v[2] - (v_back - 9.81 * (cf_world_time(w) - t_back))));
        was = now;
    }
    const cf_world *w = cf_sim_world(sim);
    printf("FIGURE hand-back in flight: %d entry into fracture mode, %d hand-offs; back at "
           "t = %.3f s rising at %.3f m/s, then |v_z - (v_back - g t)| <= %.2e m/s\n",
           entries, w->n_handoffs, t_back, v_back, worst);
    assert_int_equal(entries, 1);
    assert_int_equal(w->n_handoffs, 2);
    assert_true(t_back > 0 && v_back > 0.5); /* it rebounds */
    assert_true(worst < 1e-6);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* The landing forecast (cf_world_landings) on the same cube: dropped with
 * its lowest face 0.9 m above the floor, it lands at t = sqrt(2 h / g) at
 * sqrt(2 g h), the forecast of every rigid step of its fall within two
 * rigid steps of that (Bullet's integration), none before a horizon short
 * of it; none under way while it takes the impact (a body's break, not a
 * piece's landing).  Back in rigid mode and rising, its next landing, past the
 * impact threshold, is no stronger than the one it took whole, so the
 * impact rule would not send it back: no landing to come. */
static void test_landing_forecast_follows_the_fall(void **state)
{
    (void)state;
    cf_scene sc;
    cf_sim *sim = make_sim(cube_drop_scene, &sc);
    cf_world *w = cf_sim_world(sim);
    double h = 0.9, g = 9.81, t_land = sqrt(2 * h / g), v_land = sqrt(2 * g * h);
    double dt = cf_world_dt_outer(w);
    cf_landing l[2];
    assert_int_equal(cf_world_landings(w, 0.3, l, 2), 0);
    assert_int_equal(cf_world_landings(w, 1.0, l, 2), 1);
    cf_frag_info info;
    cf_world_fragment_info(w, 0, &info);
    double m = info.mass, R = cbrt(3 * 0.008 / (4 * acos(-1.0)));
    double E = w->solid.mat.E / (1 - w->solid.mat.nu * w->solid.mat.nu);
    double v = w->def.solver.impact_threshold;
    double hold = 2 * 2.94 * pow(15 * m * v * v / (16 * E * sqrt(R)), 0.4) / v;
    double e = w->solid.mat.restitution * w->obs.o[0].restitution;
    printf("FIGURE landing forecast at t = 0: %d tets land at t = %.6f s (closed form %.6f) "
           "at %.4f m/s (%.4f), impact %.4f m/s ((1 + e) v, flat: %.4f), held at most %.4g s "
           "(%.4g)\n", l[0].n_tets, l[0].time, t_land, l[0].speed, v_land, l[0].impact,
           (1 + e) * v_land, l[0].hold, hold);
    assert_int_equal(l[0].fragment, 0);
    assert_int_equal(l[0].n_tets, w->solid.n_tets);
    assert_near(l[0].time, t_land, 1e-9);
    assert_near(l[0].speed, v_land, 1e-9);
    assert_near(l[0].impact, (1 + e) * v_land, 1e-9); /* a face lands flat: no turn */
    assert_near(l[0].hold, hold, 1e-12 * hold);
    int was = 0, flights = 0;
    double worst = 0, t_back = -1;
    while (!cf_sim_done(sim)) {
        advance(sim);
        int now = any_in_fracture_mode(sim), n = cf_world_landings(w, 1.0, l, 2);
        if (was && !now && t_back < 0)
            t_back = cf_world_time(w);
        if (!now && t_back < 0 && cf_world_time(w) < t_land - dt) { /* falling */
            assert_int_equal(n, 1);
            assert_int_equal(l[0].under_way, 0);
            worst = fmax(worst, fabs(l[0].time - t_land));
        }
        if (now) /* the body's own impact: its cracks tell its length, not a landing */
            assert_int_equal(n, 0);
        /* clear of the floor and rising: its next landing is weaker */
        if (t_back >= 0 && !now && cf_world_time(w) > t_back + dt) {
            assert_int_equal(n, 0);
            double taken = w->frag[0].dv_taken; /* one it had not taken would count */
            w->frag[0].dv_taken = 0;
            assert_int_equal(cf_world_landings(w, 1.0, l, 2), 1);
            assert_true(l[0].impact > w->def.solver.impact_threshold && l[0].impact < taken);
            w->frag[0].dv_taken = taken;
            flights++;
        }
        was = now;
    }
    printf("FIGURE falling: forecast within %.2e s of the closed form (rigid step %.0e s); "
           "%d rigid steps back in flight with no landing to come, dv_taken %.3f m/s\n",
           worst, dt, flights, w->frag[0].dv_taken);
    assert_true(worst <= 2 * dt);
    assert_true(flights > 10);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* scenes/expanding_bar.lua (fracture mode only) at twice its length, the
 * same cells (1,920 tets, so that its pieces are enough work to step side
 * by side): pieces alive at the end and the state hash, for a strength
 * setting and a thread count; *side: the fragment steps taken side by
 * side, one per thread (NULL: not asked). */
static int expanding_bar(const char *strength, int threads, uint64_t *hash, long *side)
{
    char path[1024], set_strength[256], set_threads[64];
    snprintf(path, sizeof path, "%s/scenes/expanding_bar.lua", COHFRAC_SOURCE_DIR);
    snprintf(set_strength, sizeof set_strength, "material.strength=%s", strength);
    snprintf(set_threads, sizeof set_threads, "solver.threads=%d", threads);
    const char *sets[] = {set_strength, set_threads, "output.file=\"\"",
                          "bodies[1].mesh.size={0.4,0.01,0.01}", "bodies[1].mesh.cells={80,2,2}"};
    cf_scene sc;
    cf_error err = {0};
    if (cf_scene_load(path, sets, 5, COHFRAC_MESH_DIR, &sc, &err) != CF_OK)
        fail_msg("scene: %s", err.msg);
    cf_run_options opt = {.mesh_dir = COHFRAC_MESH_DIR};
    cf_sim *sim = NULL;
    if (cf_sim_create(&sc, &opt, &sim, &err) != CF_OK)
        fail_msg("sim: %s", err.msg);
    run_to_end(sim);
    int alive = 0;
    for (int i = 0; i < cf_sim_world(sim)->n_frag; i++)
        alive += cf_sim_world(sim)->frag[i].mode != CF_MODE_DEAD;
    *hash = cf_world_state_hash(cf_sim_world(sim));
    if (side)
        *side = cf_sim_world(sim)->steps_side_by_side;
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
    return alive;
}

/* A fracture-only run falls into fragments; Weibull strength changes how
 * many, the same for a seed on 1 and 2 threads: on 2 the pieces step side
 * by side, one per thread (cf_fracture_pass), with the bits of 1. */
static void test_fracture_only_fragments_and_weibull(void **state)
{
    (void)state;
    uint64_t h1, h2, hu, hs;
    long side1, side2;
    const char *w1 = "{distribution='weibull', modulus=6, seed=1}";
    int n1 = expanding_bar(w1, 1, &h1, &side1), n2 = expanding_bar(w1, 2, &h2, &side2);
    int nu = expanding_bar("{distribution='uniform'}", 2, &hu, NULL);
    int ns = expanding_bar("{distribution='weibull', modulus=6, seed=2}", 2, &hs, NULL);
    printf("FIGURE expanding bar: fragments uniform %d, Weibull seed 1 %d (1 thread) %d (2 "
           "threads, %ld fragment steps side by side), seed 2 %d\n", nu, n1, n2, side2, ns);
    assert_true(nu > 1 && n1 > 1);
    assert_int_equal(n1, n2);
    assert_true(side1 == 0 && side2 > 0);
    assert_true(h1 == h2);
    assert_true(n1 != nu && h1 != hu);
    assert_true(h1 != hs);
}

/* A body that turned close to half a turn in rigid mode enters fracture
 * mode unstrained: each tet's corotational rotation starts at the body's
 * pose (place_rigid), not at the one it last had, from which ten turns of
 * the polar iteration stop short near a half turn and leave a strain no
 * motion made (a tumbling piece of the 15k-tet plaster drop booked 4.7 J of
 * plastic work that way, docs/physics.md §14.22). */
static void test_turned_body_enters_fracture_mode_unstrained(void **state)
{
    (void)state;
    cf_mesh box;
    fixture_box(&box, 2, 2, 2, 0.1, 0.1, 0.1);
    cf_world_def def = cf_default_world_def();
    def.gravity[2] = 0;
    def.material.E = 1e6;
    def.solver.threads = 1;
    cf_body_def body = cf_default_body();
    body.tet_mesh = &box;
    def.bodies = &body, def.n_bodies = 1;
    cf_world *w = NULL;
    cf_error err = {0};
    assert_int_equal(cf_world_create(&def, &w, &err), CF_OK);
    cf_mesh_free(&box);
    assert_int_equal(w->frag[0].mode, CF_MODE_RIGID);
    /* The rest shape turned 179.999 degrees about a skew axis; Bullet's
     * quaternion turns the principal frame Q. */
    double axis[3] = {0.3, 0.5, 0.81}, angle = 179.999 * acos(-1.0) / 180, Rt[9], Rb[9];
    double len = v3_norm(axis), q[4] = {cos(angle / 2), 0, 0, 0};
    for (int k = 0; k < 3; k++)
        q[k + 1] = sin(angle / 2) * axis[k] / len;
    quat_to_mat(q, Rt);
    m3_mul(Rt, w->frag[0].Q, Rb);
    cfb_state st;
    cfb_get_state(w->bullet, w->frag[0].body, &st);
    mat_to_quat(Rb, st.quat);
    cf_handoff_record rec;
    assert_int_equal(cf_handoff_to_fracture(w, 0, &st, &rec, &err), CF_OK);
    const cf_fragment *f = &w->frag[0];
    double e = cf_tet4_energy_now(&w->solid, f->tets, f->nt, w->def.solver.elasticity);
    printf("FIGURE turned body: strain energy %.3g J on entering fracture mode (%d tets)\n", e,
           f->nt);
    assert_int_equal(f->mode, CF_MODE_FRACTURE);
    assert_true(e < 1e-12);
    cf_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_momentum_across_fracture_mode_contact),
        cmocka_unit_test(test_determinism_hash),
        cmocka_unit_test(test_reading_poses_changes_nothing),
        cmocka_unit_test(test_heartbeat_inside_a_step),
        cmocka_unit_test(test_turned_body_enters_fracture_mode_unstrained),
        cmocka_unit_test(test_determinism_hash_coloured),
        cmocka_unit_test(test_reentry_keeps_the_family_tree),
        cmocka_unit_test(test_debris_stays_rigid_and_conserves),
        cmocka_unit_test(test_crushed_tets_leave_as_powder),
        cmocka_unit_test(test_resting_body_stays_rigid),
        cmocka_unit_test(test_handback_in_flight_stays_rigid),
        cmocka_unit_test(test_landing_forecast_follows_the_fall),
        cmocka_unit_test(test_mesh_obstacle_matches_plane),
        cmocka_unit_test(test_handoff_clears_obstacle_overlap),
        cmocka_unit_test(test_wedged_piece_enters_clear),
        cmocka_unit_test(test_no_return_while_driving_in),
        cmocka_unit_test(test_reentry_only_on_a_stronger_impact),
        cmocka_unit_test(test_floor_holds_no_longer_than_a_landing),
        cmocka_unit_test(test_sustained_contact_stays_rigid),
        cmocka_unit_test(test_handback_on_the_floor_puts_in_nothing),
        cmocka_unit_test(test_fracture_only_fragments_and_weibull),
        cmocka_unit_test(test_handoff_keeps_bonded_pieces_together),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
