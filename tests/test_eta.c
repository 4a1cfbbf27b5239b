/* The ETA's model (src/io/eta.h): the end of a spell whose cracks grow
 * exponentially fewer at a time against its closed form, as much again
 * where they do not decay, the quiet and held cases, the cap; the rest of
 * the run at the rate measured outside long spells; the spells of the
 * landings to come; the history thinned. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "check.h"
#include "eta.h"

#include <math.h>

#define Q 1e-4   /* s, quiet time */
#define G 0.01   /* quiet growth */
#define TAU 5e-4 /* s, the cracks' decay time */
#define NINF 8e4 /* cohesive elements at the end */

static const cf_eta_rule RULE = {.dt = 2e-7, .quiet_time = Q, .quiet_growth = G, .max_spell = 0.05};

static double spell_left(const cf_eta *e, double held)
{
    int by_landing;
    return cf_eta_spell_left(e, held, &by_landing);
}

/* A spell from t = 0 whose cracks grow as NINF (1 - exp(-t/TAU)), sampled
 * every 10 us of simulated time (one second of wall each) up to `until`. */
static void exponential_spell(cf_eta *e, double until)
{
    cf_eta_init(e, &RULE);
    for (double t = 0; t <= until + 1e-12; t += 1e-5) {
        cf_eta_sample s = {.wall = 1e5 * t, .t = t, .cracks = NINF * (1 - exp(-t / TAU)),
                           .spell = t};
        cf_eta_add(e, &s);
    }
}

/* The rate NINF/TAU exp(-t/TAU) falls to the one the rule takes for none
 * at the end, G NINF/Q, at t* = TAU ln(Q/(G TAU)); the spell ends a quiet
 * time later.  From the spell's last half the model gets that end, up to
 * the linear interpolation between samples (or twice the spell so far
 * where that is sooner), and gives the geometric mean of the time to it
 * and as much again as the spell has run. */
static void test_spell_end_of_an_exponential_decay(void **state)
{
    (void)state;
    double end = TAU * log(Q / (G * TAU)) + Q;
    assert_near(end, 1.598e-3, 1e-6);
    cf_eta e;
    for (double s = 6e-4; s < end - Q; s += 2e-4) {
        exponential_spell(&e, s);
        double left = spell_left(&e, -INFINITY), expected = sqrt(fmin(end - s, s) * s);
        assert_near(left / expected, 1.0, 2e-3); /* the samples interpolated */
    }
}

/* A landing under way holds a decaying spell at least as long as its
 * landing time has left, and then the answer is the landing's; a hold
 * shorter than the decay's end leaves it as it was. */
static void test_decaying_spell_held_by_a_landing(void **state)
{
    (void)state;
    cf_eta e;
    exponential_spell(&e, 1e-3);
    int by_landing;
    double free_left = spell_left(&e, -INFINITY);
    assert_true(free_left > 5e-4 && free_left < 1e-3); /* the decay's answer */
    assert_near(cf_eta_spell_left(&e, 1.2e-3, &by_landing), 1.2e-3, 1e-15);
    assert_int_equal(by_landing, 1);
    assert_near(cf_eta_spell_left(&e, 1e-4, &by_landing), free_left, 1e-15);
    assert_int_equal(by_landing, 0);
}

/* Cracks that grow at a steady rate say nothing of the end: as much
 * again as the spell has run. */
static void test_spell_without_decay_runs_as_much_again(void **state)
{
    (void)state;
    cf_eta e;
    cf_eta_init(&e, &RULE);
    for (double t = 0; t <= 1e-3 + 1e-12; t += 1e-5) {
        cf_eta_sample s = {.wall = 1e5 * t, .t = t, .cracks = 1e7 * t, .spell = t};
        cf_eta_add(&e, &s);
    }
    assert_near(spell_left(&e, -INFINITY), 1e-3, 1e-12);
}

/* Cracks that grew at a steady rate and then stopped.  Quiet for less
 * than a quiet time (since the sample at 0.23 ms, the last one a quiet
 * growth of 24 cracks back): the rule ends the spell within one.  Quiet
 * for longer and still running, an impact holds it: as long again as it
 * has been quiet (since 1 ms).  Never past max_spell. */
static void grow_then_stop(cf_eta *e, const cf_eta_rule *rule, double stop, double until)
{
    cf_eta_init(e, rule);
    for (double t = 0; t <= until + 1e-12; t += 1e-5) {
        cf_eta_sample s = {.wall = 1e5 * t, .t = t, .cracks = 1e7 * fmin(t, stop), .spell = t};
        cf_eta_add(e, &s);
    }
}

static void test_quiet_held_and_capped_spells(void **state)
{
    (void)state;
    cf_eta e;
    grow_then_stop(&e, &RULE, 0.24e-3, 0.32e-3);
    assert_near(spell_left(&e, -INFINITY), Q, 1e-15);
    grow_then_stop(&e, &RULE, 1e-3, 2e-3);
    assert_near(spell_left(&e, -INFINITY), 1e-3, 5e-5); /* to the samples kept */
    cf_eta_rule capped = RULE;
    capped.max_spell = 2.5e-3;
    grow_then_stop(&e, &capped, 1e-3, 2e-3);
    assert_near(spell_left(&e, -INFINITY), 5e-4, 1e-12);
}

/* Rigid steps at 2 s of wall per simulated second; a long spell (1 ms,
 * 10 quiet times) of 100 s; a short one (0.2 ms) of 1 s, a piece landing
 * again.  The rest of the run costs what the rigid steps and the short
 * spell cost per simulated second; the long spell's wall is not in it,
 * nor the rigid step it ends in (its pieces' hand-offs). */
static void test_rest_counts_short_spells_not_long_ones(void **state)
{
    (void)state;
    cf_eta e;
    cf_eta_init(&e, &RULE);
    double wall = 0, t = 0;
#define AT(spell_)                                                                          \
    do {                                                                                    \
        cf_eta_sample s_ = {.wall = wall, .t = t, .fracture_wall = 0, .spell = (spell_)};   \
        cf_eta_add(&e, &s_);                                                                \
    } while (0)
    for (int i = 0; i <= 10; i++, t += 1e-3, wall += 2e-3) /* rigid to t = 0.01 */
        AT(0);
    t -= 1e-3, wall -= 2e-3;
    for (int i = 1; i <= 10; i++) { /* the long spell, 10 s each 0.1 ms */
        t += 1e-4, wall += 10;
        AT(i * 1e-4);
    }
    t += 1e-3, wall += 2e-3; /* back to rigid */
    AT(0);
    for (int i = 1; i <= 2; i++) { /* the short spell, 0.5 s each 0.1 ms */
        t += 1e-4, wall += 0.5;
        AT(i * 1e-4);
    }
    t += 1e-3, wall += 2e-3;
    AT(0);
#undef AT
    double rest_wall = 0.02 + 1.0 + 2e-3, rest_t = 0.01 + 2e-4 + 1e-3;
    assert_near(e.rest_wall, rest_wall, 1e-12);
    assert_near(e.rest_t, rest_t, 1e-12);
    assert_near(cf_eta_left(&e, 0.1, 0, NULL, 0, 3.0), 0.1 * rest_wall / rest_t + 3.0, 1e-9);
}

/* A run that broke (1e8 tet-steps in 20 s of fracture wall, 0.2 us each)
 * and now flies (rigid steps at 2 s per simulated second).  Each landing
 * to come adds its spell, its landing time at the cost per tet-step: a
 * 30,000-tet piece held 1.7 ms (17 quiet times) costs 30,000 x 1.7 ms /
 * dt x 0.2 us = 51 s.  A short one (2 quiet times: the rest's rate holds
 * those) and one after the end add nothing; one near the end counts up
 * to the end.  Once the piece has landed, its landing time holds the
 * spell now running. */
static void test_landings_add_their_spells(void **state)
{
    (void)state;
    cf_eta e;
    cf_eta_init(&e, &RULE);
    cf_eta_sample a = {.wall = 0, .t = 0}, b = {.wall = 20, .t = 2e-3, .fracture_wall = 20,
                                              .tet_steps = 1e8, .spell = 2e-3};
    cf_eta_add(&e, &a);
    cf_eta_add(&e, &b);
    for (int i = 1; i <= 60; i++) { /* the flight, 60 quiet times of rigid steps */
        cf_eta_sample s = {.wall = 20 + 2 * i * Q, .t = 2e-3 + i * Q, .fracture_wall = 20,
                           .tet_steps = 1e8};
        cf_eta_add(&e, &s);
    }
    double per = 20 / 1e8, t_left = 0.1, base = cf_eta_left(&e, t_left, 0, NULL, 0, 0);
    assert_near(base, t_left * 2, 1e-9);
    cf_eta_landing l[4] = {{.t = 0.05, .tets = 3e4, .hold = 17 * Q},
                           {.t = 0.01, .tets = 3e4, .hold = 2 * Q},
                           {.t = 0.2, .tets = 3e4, .hold = 17 * Q},
                           {.t = t_left - 5 * Q, .tets = 1e3, .hold = 10 * Q}};
    assert_near(cf_eta_landing_spell(&e, &l[0], t_left), 17 * Q, 1e-15);
    assert_near(cf_eta_landing_spell(&e, &l[1], t_left), 0, 0);
    assert_near(cf_eta_landing_spell(&e, &l[2], t_left), 0, 0);
    assert_near(cf_eta_landing_spell(&e, &l[3], t_left), 5 * Q, 1e-15);
    double spells = 3e4 * 17 * Q / RULE.dt * per + 1e3 * 5 * Q / RULE.dt * per;
    assert_near(cf_eta_left(&e, t_left, 0, l, 4, 0), base + spells, 1e-9);
    assert_near(3e4 * 17 * Q / RULE.dt * per, 51, 1e-9);

    /* The first piece lands: 2 quiet times into its spell, no crack, the
     * growth says as much again; its landing time says 15 more. */
    double wall = 20 + 120 * Q, t = 2e-3 + 60 * Q, steps = 1e8, fw = 20;
    for (int i = 1; i <= 2; i++) {
        double d = 3e4 * Q / RULE.dt; /* its tet-steps over a quiet time */
        wall += d * per, fw += d * per, steps += d, t += Q;
        cf_eta_sample s = {.wall = wall, .t = t, .fracture_wall = fw, .tet_steps = steps,
                           .spell = i * Q};
        cf_eta_add(&e, &s);
    }
    assert_near(spell_left(&e, -INFINITY), 2 * Q, 1e-15);
    cf_eta_landing held = {.under_way = 1, .t = -2 * Q, .tets = 3e4, .hold = 17 * Q};
    assert_near(cf_eta_landing_spell(&e, &held, t_left), 0, 0); /* the spell's own */
    double rest = e.rest_wall / e.rest_t, fracture = 3e4 / RULE.dt * per; /* s per s */
    double without = cf_eta_left(&e, t_left, 3e4, NULL, 0, 0);
    assert_near(cf_eta_left(&e, t_left, 3e4, &held, 1, 0) - without, 13 * Q * (fracture - rest),
                1e-9);
    /* Quiet for 6 quiet times: as long again, or what the landing holds
     * (11 more), or, its landing time over, a quiet time. */
    for (int i = 3; i <= 6; i++) {
        double d = 3e4 * Q / RULE.dt;
        wall += d * per, fw += d * per, steps += d, t += Q;
        cf_eta_sample s = {.wall = wall, .t = t, .fracture_wall = fw, .tet_steps = steps,
                           .spell = i * Q};
        cf_eta_add(&e, &s);
    }
    assert_near(spell_left(&e, -INFINITY), 6 * Q, 1e-15);
    assert_near(spell_left(&e, 11 * Q), 11 * Q, 1e-15);
    assert_near(spell_left(&e, -Q), Q, 1e-15);
}

/* A long run's history is thinned, never lost: the first sample stays,
 * the newest is the last added. */
static void test_history_is_thinned(void **state)
{
    (void)state;
    cf_eta e;
    cf_eta_init(&e, &RULE);
    for (int i = 0; i < 10000; i++) {
        cf_eta_sample s = {.wall = 0.3 * i, .t = 1e-4 * i};
        cf_eta_add(&e, &s);
    }
    assert_true(e.n <= CF_ETA_KEEP && e.n > CF_ETA_KEEP / 2);
    assert_near(e.s[0].wall, 0, 0);
    assert_near(e.s[e.n - 1].wall, 0.3 * 9999, 1e-9);
    for (int i = 1; i < e.n; i++)
        assert_true(e.s[i].wall > e.s[i - 1].wall);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_spell_end_of_an_exponential_decay),
        cmocka_unit_test(test_decaying_spell_held_by_a_landing),
        cmocka_unit_test(test_spell_without_decay_runs_as_much_again),
        cmocka_unit_test(test_quiet_held_and_capped_spells),
        cmocka_unit_test(test_rest_counts_short_spells_not_long_ones),
        cmocka_unit_test(test_landings_add_their_spells),
        cmocka_unit_test(test_history_is_thinned),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
