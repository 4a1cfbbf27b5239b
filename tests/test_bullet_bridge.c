/* Behaviour of the Bullet bridge (cf_bullet.h): integrator, contacts,
 * free-flight rotation, state round trip and error reporting. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "cf_bullet.h"

#define G 9.81

static const double GRAVITY[3] = {0.0, 0.0, -G};
static const double NO_GRAVITY[3] = {0.0, 0.0, 0.0};

/* The 8 corners of a cube of half size a, centred on the origin. */
static void cube_points(double a, double pts[24])
{
    int k = 0;
    for (int i = 0; i < 8; ++i) {
        pts[k++] = (i & 1) ? a : -a;
        pts[k++] = (i & 2) ? a : -a;
        pts[k++] = (i & 4) ? a : -a;
    }
}

static cfb_state state_at(double x, double y, double z)
{
    cfb_state s = {{x, y, z}, {1.0, 0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
    return s;
}

/* Unit cube (half size 0.5) of mass m: principal moments m (2a)^2 / 6. */
static int add_cube(cfb_world *w, double m, double margin, const cfb_state *s)
{
    double pts[24];
    cube_points(0.5, pts);
    const double I = m / 6.0;
    const double inertia[3] = {I, I, I};
    return cfb_add_hull_body(w, m, inertia, pts, 8, margin, s, 0.5, 0.0);
}

/* Rotation matrix of a unit quaternion (w,x,y,z), row-major. */
static void quat_matrix(const double q[4], double R[9])
{
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    R[0] = 1 - 2 * (y * y + z * z);
    R[1] = 2 * (x * y - w * z);
    R[2] = 2 * (x * z + w * y);
    R[3] = 2 * (x * y + w * z);
    R[4] = 1 - 2 * (x * x + z * z);
    R[5] = 2 * (y * z - w * x);
    R[6] = 2 * (x * z - w * y);
    R[7] = 2 * (y * z + w * x);
    R[8] = 1 - 2 * (x * x + y * y);
}

/* World angular momentum L = R diag(I) R^T w. */
static void angular_momentum(const cfb_state *s, const double I[3], double L[3])
{
    double R[9], wb[3];
    quat_matrix(s->quat, R);
    for (int i = 0; i < 3; ++i)
        wb[i] = I[i] * (R[0 + i] * s->w[0] + R[3 + i] * s->w[1] + R[6 + i] * s->w[2]);
    for (int i = 0; i < 3; ++i) L[i] = R[3 * i] * wb[0] + R[3 * i + 1] * wb[1] + R[3 * i + 2] * wb[2];
}

static double norm3(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/* Quaternion of a rotation by `angle` about `axis` (any length). */
static void axis_angle(const double axis[3], double angle, double q[4])
{
    const double n = norm3(axis), s = sin(0.5 * angle) / n;
    q[0] = cos(0.5 * angle);
    q[1] = axis[0] * s;
    q[2] = axis[1] * s;
    q[3] = axis[2] * s;
}

/* Semi-implicit Euler: v_k = -g k h, z_k = z0 - g h^2 k(k+1)/2, i.e.
 * z(t) = z0 - g t^2/2 - g t h/2.  The error term must show up as predicted. */
static void test_free_fall(void **state)
{
    (void)state;
    cfb_world *w = cfb_world_create(GRAVITY);
    assert_non_null(w);
    const double z0 = 10.0, dt = 1e-3;
    const int substeps = 5, nsteps = 500;
    const cfb_state s0 = state_at(0.25, -0.5, z0);
    const int id = add_cube(w, 1.0, 0.01, &s0);
    assert_true(id >= 0);
    for (int i = 0; i < nsteps; ++i) assert_int_equal(cfb_step(w, dt, substeps), 0);

    cfb_state s;
    cfb_get_state(w, id, &s);
    const double t = nsteps * dt, h = dt / substeps;
    const double err = (z0 - 0.5 * G * t * t) - s.pos[2];
    const double bound = 0.5 * G * t * h;
    print_message("free fall: z error %.9e, formula g*t*h/2 = %.9e (ratio %.12f)\n", err, bound,
                  err / bound);
    assert_true(fabs(err) <= bound * (1.0 + 1e-9));
    /* Signed: explicit Euler would give the same size with the other sign. */
    assert_true(fabs(err - bound) <= 0.2 * bound);
    assert_true(fabs(s.v[2] + G * t) <= 1e-12 * G * t);
    assert_true(s.pos[0] == 0.25 && s.pos[1] == -0.5);
    assert_true(s.v[0] == 0.0 && s.v[1] == 0.0);
    assert_true(s.w[0] == 0.0 && s.w[1] == 0.0 && s.w[2] == 0.0);
    assert_true(cfb_contact_impulse(w, id) == 0.0);
    cfb_world_destroy(w);
}

/* Sub-step counts whose dt/h rounds below the count (0.1/11, 0.003/23)
 * still run every sub-step: the velocity after the calls is -g t. */
static void test_awkward_substeps(void **state)
{
    (void)state;
    const double dts[3] = {0.1, 0.003, 0.3};
    const int subs[3] = {11, 23, 27};
    for (int k = 0; k < 3; ++k) {
        cfb_world *w = cfb_world_create(GRAVITY);
        assert_non_null(w);
        const cfb_state s0 = state_at(0, 0, 0);
        const int id = add_cube(w, 1.0, 0.01, &s0);
        assert_true(id >= 0);
        for (int i = 0; i < 10; ++i) assert_int_equal(cfb_step(w, dts[k], subs[k]), 0);
        cfb_state s;
        cfb_get_state(w, id, &s);
        const double t = 10 * dts[k], h = dts[k] / subs[k];
        assert_true(fabs(s.v[2] + G * t) <= 1e-12 * G * t);
        assert_true(fabs(s.pos[2] + 0.5 * G * t * t + 0.5 * G * t * h) <= 1e-12 * G * t * t);
        cfb_world_destroy(w);
    }
}

/* A cube dropped on a plane settles on it; the contact impulse per step is
 * m g dt at rest and of order m v_impact at impact. */
static void test_drop_on_plane(void **state)
{
    (void)state;
    cfb_world *w = cfb_world_create(GRAVITY);
    assert_non_null(w);
    const double origin[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    const int plane = cfb_add_plane(w, origin, up, 0.5, 0.0);
    assert_true(plane >= 0);
    const double m = 2.0, margin = 0.01, drop = 1.0, dt = 1e-3;
    const cfb_state s0 = state_at(0.0, 0.0, 0.5 + margin + drop);
    const int id = add_cube(w, m, margin, &s0);
    assert_true(id >= 0);
    assert_int_equal(cfb_body_count(w), 1);

    const int nsteps = 2000, nrest = 500;
    double peak = 0.0, rest_min = 1e30, rest_max = 0.0, rest_sum = 0.0;
    for (int i = 0; i < nsteps; ++i) {
        assert_int_equal(cfb_step(w, dt, 5), 0);
        const double J = cfb_contact_impulse(w, id);
        assert_true(J >= 0.0);
        assert_true(fabs(cfb_contact_impulse(w, plane) - J) <= 1e-12 * (1.0 + J));
        if (J > peak) peak = J;
        if (i >= nsteps - nrest) {
            rest_sum += J;
            if (J < rest_min) rest_min = J;
            if (J > rest_max) rest_max = J;
        }
    }
    const double rest = m * G * dt, v_impact = sqrt(2.0 * G * drop);
    cfb_state s;
    cfb_get_state(w, id, &s);
    print_message("drop: final z %.9f, impact peak %.6f N s (m v = %.6f), rest impulse per step "
                  "%.9e .. %.9e (m g dt = %.9e)\n",
                  s.pos[2], peak, m * v_impact, rest_min, rest_max, rest);
    assert_true(fabs(s.pos[2] - 0.5) <= 1.5 * margin);
    /* The sequential-impulse solver treats the four corner contacts one after
     * another, so a flat impact slides and yaws the cube a little (about 3 cm
     * and 3 degrees here); it must still land flat. */
    print_message("drop: sideways drift (%.3e, %.3e) m\n", s.pos[0], s.pos[1]);
    assert_true(fabs(s.pos[0]) < 0.1 && fabs(s.pos[1]) < 0.1);
    assert_true(fabs(s.quat[1]) < 1e-6 && fabs(s.quat[2]) < 1e-6);
    assert_true(norm3(s.v) < 1e-3 && norm3(s.w) < 1e-3);
    assert_true(fabs(rest_sum / nrest - rest) <= 1e-3 * rest);
    assert_true(rest_min >= 0.95 * rest && rest_max <= 1.05 * rest);
    assert_true(peak >= 0.5 * m * v_impact);
    assert_true(peak >= 100.0 * rest);
    cfb_world_destroy(w);
}

/* Run a torque-free body for 1 s and return the largest relative change of
 * |L| (and of L itself) seen after any step. */
static void spin(const double I[3], const cfb_state *s0, double *d_abs, double *d_vec)
{
    cfb_world *w = cfb_world_create(NO_GRAVITY);
    assert_non_null(w);
    double pts[24];
    cube_points(0.5, pts);
    const int id = cfb_add_hull_body(w, 1.0, I, pts, 8, 0.01, s0, 0.5, 0.0);
    assert_true(id >= 0);
    double L0[3], L[3];
    cfb_state s;
    cfb_get_state(w, id, &s);
    angular_momentum(&s, I, L0);
    const double n0 = norm3(L0);
    *d_abs = *d_vec = 0.0;
    for (int i = 0; i < 1000; ++i) {
        assert_int_equal(cfb_step(w, 1e-3, 5), 0);
        cfb_get_state(w, id, &s);
        angular_momentum(&s, I, L);
        const double d[3] = {L[0] - L0[0], L[1] - L0[1], L[2] - L0[2]};
        const double ra = fabs(norm3(L) - n0) / n0, rv = norm3(d) / n0;
        if (ra > *d_abs) *d_abs = ra;
        if (rv > *d_vec) *d_vec = rv;
    }
    cfb_world_destroy(w);
}

/* Only spins where the gyroscopic term vanishes are held to 1e-9: a top
 * precessing about an off-axis spin goes through Bullet's implicit
 * gyroscopic step, which is first-order (|L| drifts ~2e-4 over 1 s at
 * |w| ~ 10 rad/s with these sub-steps). */
static void test_free_spin_momentum(void **state)
{
    (void)state;
    const double axis[3] = {1.0, 2.0, -0.5};
    double da, dv;

    /* Isotropic inertia (the cube's own), tumbling about a generic axis. */
    const double Iso[3] = {1.0 / 6.0, 1.0 / 6.0, 1.0 / 6.0};
    cfb_state s = state_at(0, 0, 0);
    axis_angle(axis, 0.7, s.quat);
    s.w[0] = 3.0;
    s.w[1] = -7.0;
    s.w[2] = 11.0;
    spin(Iso, &s, &da, &dv);
    print_message("isotropic spin: max |dL|/|L| %.3e, max ||L|-|L0||/|L0| %.3e\n", dv, da);
    assert_true(da <= 1e-9);
    assert_true(dv <= 1e-9);

    /* Symmetric top (I1 = I2 != I3) spinning about its symmetry axis, which
     * is tilted in the world. */
    const double Top[3] = {0.2, 0.2, 0.35};
    double R[9];
    quat_matrix(s.quat, R);
    for (int i = 0; i < 3; ++i) s.w[i] = 20.0 * R[3 * i + 2];
    spin(Top, &s, &da, &dv);
    print_message("symmetric top: max |dL|/|L| %.3e, max ||L|-|L0||/|L0| %.3e\n", dv, da);
    assert_true(da <= 1e-9);
    assert_true(dv <= 1e-9);
}

static void test_state_round_trip(void **state)
{
    (void)state;
    cfb_world *w = cfb_world_create(GRAVITY);
    assert_non_null(w);
    const cfb_state s0 = state_at(0, 0, 0);
    const int id = add_cube(w, 1.0, 0.01, &s0);
    assert_true(id >= 0);

    const double axes[2][3] = {{0.3, -1.1, 0.8}, {-2.0, 0.1, 0.4}};
    const double angles[2] = {1.234, 5.9}; /* the second gives w < 0 */
    for (int k = 0; k < 2; ++k) {
        cfb_state in = {{1.5, -2.25, 3.125}, {0, 0, 0, 0}, {0.1, -0.2, 0.3}, {-4.0, 5.5, 0.125}};
        axis_angle(axes[k], angles[k], in.quat);
        cfb_set_state(w, id, &in);
        cfb_state out;
        memset(&out, 0xff, sizeof out);
        cfb_get_state(w, id, &out);
        assert_memory_equal(&in, &out, sizeof in);
    }

    /* After a step the state is Bullet's own; it must round-trip too. */
    assert_int_equal(cfb_step(w, 1e-3, 5), 0);
    cfb_state a, b;
    cfb_get_state(w, id, &a);
    cfb_set_state(w, id, &a);
    cfb_get_state(w, id, &b);
    assert_memory_equal(&a, &b, sizeof a);
    cfb_world_destroy(w);
}

/* Overlapping bodies are pushed apart, unless the pair is ignored. */
static void test_ignore_pair(void **state)
{
    (void)state;
    for (int ignore = 0; ignore < 2; ++ignore) {
        cfb_world *w = cfb_world_create(NO_GRAVITY);
        assert_non_null(w);
        const cfb_state sa = state_at(0.0, 0, 0), sb = state_at(0.8, 0, 0);
        const int a = add_cube(w, 1.0, 0.01, &sa), b = add_cube(w, 1.0, 0.01, &sb);
        assert_true(a >= 0 && b >= 0);
        if (ignore) cfb_ignore_pair(w, a, b);
        double total = 0.0;
        for (int i = 0; i < 50; ++i) {
            assert_int_equal(cfb_step(w, 1e-3, 5), 0);
            total += cfb_contact_impulse(w, a);
        }
        cfb_state s;
        cfb_get_state(w, b, &s);
        if (ignore) {
            assert_true(total == 0.0);
            assert_true(s.pos[0] == 0.8 && s.v[0] == 0.0);
        } else {
            assert_true(total > 0.0);
            assert_true(s.v[0] > 0.0);
        }
        cfb_world_destroy(w);
    }
}

/* Bodies of one family do not collide, also when the family is set while
 * they are already in contact; leaving the family restores contact. */
static void test_family(void **state)
{
    (void)state;
    cfb_world *w = cfb_world_create(NO_GRAVITY);
    assert_non_null(w);
    /* Overlap 0.02 m: shallow enough for Bullet to correct it with velocity
     * impulses (deeper ones go to the split-impulse position pass, which
     * applies no normal impulse). */
    const cfb_state sa = state_at(0.0, 0, 0), sb = state_at(1.0, 0, 0), sc = state_at(0, 5, 0);
    const int a = add_cube(w, 1.0, 0.01, &sa), b = add_cube(w, 1.0, 0.01, &sb);
    const int c = add_cube(w, 1.0, 0.01, &sc);
    assert_true(a >= 0 && b >= 0 && c >= 0);
    assert_int_equal(cfb_step(w, 1e-3, 5), 0);
    assert_true(cfb_contact_impulse(w, a) > 0.0);

    assert_int_equal(cfb_set_family(w, a, 3), 0);
    assert_int_equal(cfb_set_family(w, b, 3), 0);
    assert_int_equal(cfb_set_family(w, c, 4), 0);
    cfb_state before, after;
    cfb_get_state(w, b, &before);
    for (int i = 0; i < 20; ++i) {
        assert_int_equal(cfb_step(w, 1e-3, 5), 0);
        assert_true(cfb_contact_impulse(w, a) == 0.0 && cfb_contact_impulse(w, b) == 0.0);
    }
    cfb_get_state(w, b, &after);
    assert_true(after.v[0] == before.v[0]);

    /* Overlapping again at rest: still nothing until b leaves the family. */
    cfb_set_state(w, a, &sa);
    cfb_set_state(w, b, &sb);
    assert_int_equal(cfb_step(w, 1e-3, 5), 0);
    assert_true(cfb_contact_impulse(w, a) == 0.0);
    cfb_get_state(w, b, &after);
    assert_true(after.pos[0] == sb.pos[0] && after.v[0] == 0.0);
    assert_int_equal(cfb_set_family(w, b, -1), 0);
    assert_int_equal(cfb_step(w, 1e-3, 5), 0);
    assert_true(cfb_contact_impulse(w, a) > 0.0);

    assert_int_equal(cfb_set_family(w, 99, 1), -1);
    assert_non_null(strstr(cfb_last_error(), "invalid body id 99"));
    assert_int_equal(cfb_set_family(w, a, -2), -1);
    cfb_world_destroy(w);
}

/* A kinematic box moves at its velocity and drags what it hits along. */
static void test_kinematic_push(void **state)
{
    (void)state;
    cfb_world *w = cfb_world_create(NO_GRAVITY);
    assert_non_null(w);
    const double c[3] = {-2.0, 0, 0}, he[3] = {0.5, 2.0, 2.0}, v[3] = {2.0, 0, 0};
    const int box = cfb_add_box(w, c, he, v, 0.0, 0.0);
    assert_true(box >= 0);
    const cfb_state s0 = state_at(0, 0, 0);
    const int id = add_cube(w, 1.0, 0.01, &s0);
    assert_true(id >= 0);
    assert_int_equal(cfb_body_count(w), 1);

    const int nsteps = 1000;
    for (int i = 0; i < nsteps; ++i) assert_int_equal(cfb_step(w, 1e-3, 5), 0);
    cfb_state kb, s;
    cfb_get_state(w, box, &kb);
    cfb_get_state(w, id, &s);
    assert_true(fabs(kb.pos[0] - (c[0] + v[0] * nsteps * 1e-3)) <= 1e-9);
    assert_true(kb.v[0] == v[0]);
    assert_true(kb.quat[0] == 1.0 && kb.quat[1] == 0.0 && kb.quat[2] == 0.0 && kb.quat[3] == 0.0);
    /* The cube is ahead of the box and moves at least as fast as it. */
    assert_true(s.pos[0] >= kb.pos[0] + 0.9);
    assert_true(s.v[0] >= 0.99 * v[0]);

    /* Once removed, the obstacle is gone and the cube coasts on. */
    cfb_remove_body(w, box);
    assert_int_equal(cfb_step(w, 1e-3, 5), 0);
    assert_true(cfb_contact_impulse(w, id) == 0.0);
    cfb_world_destroy(w);
}

static void test_errors(void **state)
{
    (void)state;
    cfb_world *w = cfb_world_create(GRAVITY);
    assert_non_null(w);
    double pts[24];
    cube_points(0.5, pts);
    const double I[3] = {1.0 / 6, 1.0 / 6, 1.0 / 6};
    const cfb_state s0 = state_at(0, 0, 1);

    assert_int_equal(cfb_add_hull_body(w, 0.0, I, pts, 8, 0.01, &s0, 0.5, 0.0), -1);
    assert_non_null(strstr(cfb_last_error(), "mass"));
    assert_int_equal(cfb_add_hull_body(w, -1.0, I, pts, 8, 0.01, &s0, 0.5, 0.0), -1);
    assert_true(strlen(cfb_last_error()) > 0);
    assert_int_equal(cfb_add_hull_body(w, 1.0, I, pts, 3, 0.01, &s0, 0.5, 0.0), -1);
    assert_non_null(strstr(cfb_last_error(), "4 points"));
    pts[5] = NAN;
    assert_int_equal(cfb_add_hull_body(w, 1.0, I, pts, 8, 0.01, &s0, 0.5, 0.0), -1);
    assert_true(strlen(cfb_last_error()) > 0);
    cube_points(0.5, pts);
    cfb_state bad = s0;
    bad.v[1] = NAN;
    assert_int_equal(cfb_add_hull_body(w, 1.0, I, pts, 8, 0.01, &bad, 0.5, 0.0), -1);
    const double flat_I[3] = {1.0, 0.0, 1.0};
    assert_int_equal(cfb_add_hull_body(w, 1.0, flat_I, pts, 8, 0.01, &s0, 0.5, 0.0), -1);
    /* Collinear points have no hull. */
    const double line[12] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0};
    assert_int_equal(cfb_add_hull_body(w, 1.0, I, line, 4, 0.01, &s0, 0.5, 0.0), -1);
    assert_non_null(strstr(cfb_last_error(), "degenerate"));
    assert_int_equal(cfb_body_count(w), 0);

    const int id = add_cube(w, 1.0, 0.01, &s0);
    assert_int_equal(id, 0);

    /* Bad ids. */
    cfb_state s = state_at(7, 7, 7), keep = s;
    cfb_get_state(w, 42, &s);
    assert_non_null(strstr(cfb_last_error(), "invalid body id 42"));
    assert_memory_equal(&s, &keep, sizeof s);
    cfb_get_state(w, -1, &s);
    assert_non_null(strstr(cfb_last_error(), "invalid body id -1"));
    assert_true(cfb_contact_impulse(w, 5) == -1.0);
    cfb_set_state(w, 3, &s0);
    assert_non_null(strstr(cfb_last_error(), "invalid body id 3"));
    cfb_ignore_pair(w, id, 9);
    assert_non_null(strstr(cfb_last_error(), "invalid body id 9"));

    /* NaN state is refused and leaves the body alone. */
    cfb_set_state(w, id, &bad);
    assert_non_null(strstr(cfb_last_error(), "non-finite"));
    cfb_get_state(w, id, &s);
    assert_memory_equal(&s, &s0, sizeof s);

    /* Bad step arguments. */
    assert_int_equal(cfb_step(w, 0.0, 5), -1);
    assert_int_equal(cfb_step(w, -1e-3, 5), -1);
    assert_int_equal(cfb_step(w, NAN, 5), -1);
    assert_int_equal(cfb_step(w, 1e-3, 0), -1);
    assert_true(strlen(cfb_last_error()) > 0);
    assert_int_equal(cfb_step(NULL, 1e-3, 1), -1);

    /* Removed ids stay invalid and are not reused. */
    cfb_remove_body(w, id);
    assert_int_equal(cfb_body_count(w), 0);
    cfb_get_state(w, id, &s);
    assert_non_null(strstr(cfb_last_error(), "invalid body id 0"));
    cfb_remove_body(w, id);
    assert_non_null(strstr(cfb_last_error(), "invalid body id 0"));
    assert_int_equal(add_cube(w, 1.0, 0.01, &s0), 1);

    const double nan3[3] = {NAN, 0, 0};
    assert_null(cfb_world_create(nan3));
    cfb_world_destroy(w);
}

/* A hull given thousands of points (a finely sampled cube surface) keeps only
 * its 8 corners and behaves like the plain cube. */
static void test_many_point_hull(void **state)
{
    (void)state;
    enum { N = 21 };
    static double pts[6 * N * N * 3];
    int k = 0;
    for (int f = 0; f < 6; ++f)
        for (int i = 0; i < N; ++i)
            for (int j = 0; j < N; ++j) {
                const double u = -0.5 + (double)i / (N - 1), v = -0.5 + (double)j / (N - 1);
                const double side = (f & 1) ? 0.5 : -0.5;
                double *p = pts + 3 * k++;
                p[f / 2] = side;
                p[(f / 2 + 1) % 3] = u;
                p[(f / 2 + 2) % 3] = v;
            }
    cfb_world *w = cfb_world_create(GRAVITY);
    const double origin[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    assert_true(cfb_add_plane(w, origin, up, 0.5, 0.0) >= 0);
    const double I[3] = {1.0 / 6, 1.0 / 6, 1.0 / 6};
    const cfb_state s0 = state_at(0, 0, 1.0);
    const int id = cfb_add_hull_body(w, 1.0, I, pts, k, 0.01, &s0, 0.5, 0.0);
    assert_true(id >= 0);
    for (int i = 0; i < 1000; ++i) assert_int_equal(cfb_step(w, 1e-3, 5), 0);
    cfb_state s;
    cfb_get_state(w, id, &s);
    assert_true(fabs(s.pos[2] - 0.5) <= 0.015);
    cfb_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_free_fall),        cmocka_unit_test(test_awkward_substeps),
        cmocka_unit_test(test_drop_on_plane),
        cmocka_unit_test(test_free_spin_momentum), cmocka_unit_test(test_state_round_trip),
        cmocka_unit_test(test_ignore_pair),      cmocka_unit_test(test_family),      cmocka_unit_test(test_kinematic_push),
        cmocka_unit_test(test_errors),           cmocka_unit_test(test_many_point_hull),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
