/* cf_bullet.h is plain C: this file is compiled as C11 with -pedantic and
 * drives every entry point through the header alone. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "cf_bullet.h"

static void test_header_calls(void **state)
{
    (void)state;
    const double g[3] = {0.0, 0.0, -9.81};
    cfb_world *w = cfb_world_create(g);
    assert_non_null(w);

    const double p0[3] = {0.0, 0.0, 0.0}, up[3] = {0.0, 0.0, 1.0};
    const int plane = cfb_add_plane(w, p0, up, 0.5, 0.1);
    const double c[3] = {3.0, 0.0, 0.5}, still[3] = {0.0, 0.0, 0.0};
    const int sphere = cfb_add_sphere(w, c, 0.5, still, 0.5, 0.1);
    const double c2[3] = {-3.0, 0.0, 0.5}, he[3] = {0.5, 0.5, 0.5}, v[3] = {0.0, 1.0, 0.0};
    const int box = cfb_add_box(w, c2, he, v, 0.5, 0.1);
    assert_true(plane >= 0 && sphere > plane && box > sphere);

    /* A tetrahedron: the smallest accepted hull. */
    const double tet[4][3] = {{0.1, 0.1, 0.1}, {-0.1, -0.1, 0.1}, {-0.1, 0.1, -0.1},
                              {0.1, -0.1, -0.1}};
    const double inertia[3] = {1e-3, 1e-3, 1e-3};
    const cfb_state s0 = {.pos = {0.0, 0.0, 1.0}, .quat = {1.0, 0.0, 0.0, 0.0}};
    const int a = cfb_add_hull_body(w, 0.5, inertia, &tet[0][0], 4, 0.005, &s0, 0.5, 0.0);
    const int b = cfb_add_hull_body(w, 0.5, inertia, &tet[0][0], 4, 0.005, &s0, 0.5, 0.0);
    assert_true(a >= 0 && b > a);
    assert_int_equal(cfb_body_count(w), 2);
    cfb_ignore_pair(w, a, b);
    assert_int_equal(cfb_set_family(w, a, 0), 0);

    assert_int_equal(cfb_step(w, 1e-2, 2), 0);
    cfb_state s;
    cfb_get_state(w, a, &s);
    assert_true(s.pos[2] < 1.0 && s.v[2] < 0.0);
    cfb_set_state(w, a, &s0);
    assert_true(cfb_contact_impulse(w, a) >= 0.0);

    cfb_remove_body(w, b);
    assert_int_equal(cfb_body_count(w), 1);
    assert_true(cfb_contact_impulse(w, b) < 0.0);
    assert_true(cfb_contact_impulse_static(w, b) < 0.0);
    const char *msg = cfb_last_error();
    assert_non_null(msg);
    assert_true(strlen(msg) > 0);
    cfb_world_destroy(w);
    cfb_world_destroy(NULL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_header_calls)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
