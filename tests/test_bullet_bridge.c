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
#define PI 3.14159265358979323846

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
        assert_true(cfb_contact_impulse_static(w, id) == J); /* all of it from the plane */
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

    /* The moving box's impulse is none of it static: it is the cube's whole
     * momentum, m v = 2 N s (Bullet's contact is inelastic). */
    const int nsteps = 1000;
    double J = 0.0, J_static = 0.0;
    for (int i = 0; i < nsteps; ++i) {
        assert_int_equal(cfb_step(w, 1e-3, 5), 0);
        J += cfb_contact_impulse(w, id), J_static += cfb_contact_impulse_static(w, id);
    }
    print_message("kinematic push: contact impulse %.6f N s (m v = 2), from static bodies %g\n", J,
                  J_static);
    assert_true(J >= 1.9 && J_static == 0.0);
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

/* ---- Convex hulls, compounds, impulses, CCD, sleeping, queries, meshes ---- */

static void cross3(const double a[3], const double b[3], double c[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* Unit cube corners plus interior, face and edge points: the hull is the 8
 * corners, returned exactly, and its volume is 1. */
static void test_convex_hull(void **state)
{
    (void)state;
    double pts[40 * 3];
    cube_points(0.5, pts);
    int n = 8;
    const double extra[][3] = {{0, 0, 0},      {0.1, -0.2, 0.3}, {0.5, 0.1, 0.2},
                               {-0.3, 0.5, 0}, {0.5, 0.5, 0.25}, {-0.5, -0.5, -0.1},
                               {0.2, 0.2, -0.5}, {0.49, 0.49, 0.49}};
    for (size_t i = 0; i < sizeof extra / sizeof extra[0]; ++i, ++n)
        memcpy(pts + 3 * n, extra[i], sizeof extra[i]);
    double out[40 * 3], vol = -1.0;
    assert_int_equal(cfb_convex_hull(pts, n, out, &vol), 8);
    print_message("hull of %d cube points: volume %.17g\n", n, vol);
    assert_true(fabs(vol - 1.0) <= 1e-12);
    for (int i = 0; i < 8; ++i) {
        for (int c = 0; c < 3; ++c) assert_true(out[3 * i + c] == 0.5 || out[3 * i + c] == -0.5);
        for (int j = 0; j < i; ++j)
            assert_false(out[3 * i] == out[3 * j] && out[3 * i + 1] == out[3 * j + 1] &&
                         out[3 * i + 2] == out[3 * j + 2]);
    }
    /* Optional outputs. */
    assert_int_equal(cfb_convex_hull(pts, n, NULL, NULL), 8);

    /* Rotated and moved (corners and interior points only: a point on a face
     * may round to just outside it): volume 1 up to round-off. */
    n = 8;
    for (int i = 0; i < 3; ++i, ++n) {
        const double in[3][3] = {{0, 0, 0}, {0.1, -0.2, 0.3}, {0.49, 0.49, 0.49}};
        memcpy(pts + 3 * n, in[i], sizeof in[i]);
    }
    double R[9], q[4];
    const double axis[3] = {0.3, -1.0, 0.7};
    axis_angle(axis, 0.9, q);
    quat_matrix(q, R);
    double moved[40 * 3];
    for (int i = 0; i < n; ++i)
        for (int r = 0; r < 3; ++r)
            moved[3 * i + r] = 10.0 + R[3 * r] * pts[3 * i] + R[3 * r + 1] * pts[3 * i + 1] +
                               R[3 * r + 2] * pts[3 * i + 2];
    assert_int_equal(cfb_convex_hull(moved, n, out, &vol), 8);
    assert_true(fabs(vol - 1.0) <= 1e-12);

    /* Corner tetrahedron of the unit cube, plus its centroid: 1/6. */
    const double tet[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.25, 0.25, 0.25}};
    assert_int_equal(cfb_convex_hull(&tet[0][0], 5, out, &vol), 4);
    assert_true(fabs(vol - 1.0 / 6.0) <= 1e-15);

    /* Flat and degenerate sets: volume 0. */
    const double square[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 0}};
    assert_int_equal(cfb_convex_hull(&square[0][0], 5, out, &vol), 4);
    assert_true(vol == 0.0);
    const double one[3] = {1, 2, 3};
    assert_int_equal(cfb_convex_hull(one, 1, out, &vol), 1);
    assert_true(vol == 0.0 && out[0] == 1 && out[1] == 2 && out[2] == 3);

    assert_int_equal(cfb_convex_hull(pts, 0, out, &vol), -1);
    assert_true(strlen(cfb_last_error()) > 0);
    assert_int_equal(cfb_convex_hull(NULL, 3, out, &vol), -1);
    pts[4] = NAN;
    assert_int_equal(cfb_convex_hull(pts, n, out, &vol), -1);
    assert_non_null(strstr(cfb_last_error(), "non-finite"));
}

/* The L of two unit-density boxes, A = [0,2]x[0,1]x[0,1] and B =
 * [0,1]x[0,1]x[1,2]: mass 3, centre of mass (5/6, 1/2, 5/6).  It is
 * symmetric under x <-> z, so its principal axes are (1,0,1)/sqrt2, y and
 * (-1,0,1)/sqrt2, i.e. the world frame turned by -45 degrees about y. */
static const double L_COM[3] = {5.0 / 6.0, 0.5, 5.0 / 6.0};
static const double L_BOX[2][2][3] = {{{0, 0, 0}, {2, 1, 1}}, {{0, 0, 1}, {1, 1, 2}}};

static void l_axes(double e[3][3])
{
    const double r = sqrt(0.5);
    const double E[3][3] = {{r, 0, r}, {0, 1, 0}, {-r, 0, r}};
    memcpy(e, E, sizeof E);
}

/* Principal moments of the L (checking that the axes are principal), its
 * 16 corners in the principal frame ([2][8][3]), and its orientation. */
static void l_body(double I[3], double pts[48], double quat[4])
{
    double T[3][3] = {{0}};
    for (int k = 0; k < 2; ++k) {
        double size[3], d[3];
        for (int i = 0; i < 3; ++i) {
            size[i] = L_BOX[k][1][i] - L_BOX[k][0][i];
            d[i] = 0.5 * (L_BOX[k][0][i] + L_BOX[k][1][i]) - L_COM[i];
        }
        const double m = size[0] * size[1] * size[2];
        const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        for (int i = 0; i < 3; ++i) {
            const double s2 = size[0] * size[0] + size[1] * size[1] + size[2] * size[2];
            T[i][i] += m * (s2 - size[i] * size[i]) / 12.0;
            for (int j = 0; j < 3; ++j) T[i][j] += m * ((i == j ? dd : 0.0) - d[i] * d[j]);
        }
    }
    double e[3][3];
    l_axes(e);
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
            double s = 0.0;
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) s += e[a][i] * T[i][j] * e[b][j];
            if (a == b) I[a] = s;
            else assert_true(fabs(s) < 1e-14);
        }
    int n = 0;
    for (int k = 0; k < 2; ++k)
        for (int c = 0; c < 8; ++c, ++n) {
            double x[3];
            for (int i = 0; i < 3; ++i) x[i] = L_BOX[k][(c >> i) & 1][i] - L_COM[i];
            for (int a = 0; a < 3; ++a)
                pts[3 * n + a] = e[a][0] * x[0] + e[a][1] * x[1] + e[a][2] * x[2];
        }
    const double yaxis[3] = {0, 1, 0};
    axis_angle(yaxis, -PI / 4, quat);
}

/* Drop the L on a plane, then a small cube into its notch.  As a compound
 * the L rests on its long box with the centre of mass at 5/6 + margin, and
 * the small cube lands on the long box's top (z = 1, + the L's margin under
 * and over its core, + the cube's margin + its half size); the convex hull of the
 * same points has a 45 degree roof over the notch, where the cube cannot
 * land at z = 1. */
static void drop_l(int compound, double *l_z, double *l_zmin, double c_pos[3], double l_quat[4])
{
    cfb_world *w = cfb_world_create(GRAVITY);
    assert_non_null(w);
    const double origin[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    assert_true(cfb_add_plane(w, origin, up, 0.5, 0.0) >= 0);
    double I[3], pts[48], q[4];
    l_body(I, pts, q);
    const double margin = 0.01, lift = 0.3;
    cfb_state s = state_at(L_COM[0], L_COM[1], L_COM[2] + margin + lift);
    memcpy(s.quat, q, sizeof q);
    const int start[3] = {0, 8, 16};
    const int id = compound ? cfb_add_compound_body(w, 3.0, I, pts, start, 2, margin, &s, 0.5, 0.0)
                            : cfb_add_hull_body(w, 3.0, I, pts, 16, margin, &s, 0.5, 0.0);
    assert_true(id >= 0);
    assert_int_equal(cfb_body_count(w), 1);
    *l_zmin = 1e30;
    for (int i = 0; i < 1500; ++i) {
        assert_int_equal(cfb_step(w, 1e-3, 5), 0);
        cfb_state t;
        cfb_get_state(w, id, &t);
        if (t.pos[2] < *l_zmin) *l_zmin = t.pos[2];
    }
    /* The small cube (side 0.2, margin 0.005) over the notch. */
    const double a = 0.1, mc = 0.008;
    double cp[24];
    cube_points(a, cp);
    const double Ic[3] = {mc * 4 * a * a / 6, mc * 4 * a * a / 6, mc * 4 * a * a / 6};
    const cfb_state sc = state_at(1.5, 0.5, 2.2);
    const int c = cfb_add_hull_body(w, mc, Ic, cp, 8, 0.005, &sc, 0.5, 0.0);
    assert_true(c >= 0);
    for (int i = 0; i < 1500; ++i) assert_int_equal(cfb_step(w, 1e-3, 5), 0);
    cfb_state t;
    cfb_get_state(w, id, &t);
    *l_z = t.pos[2];
    memcpy(l_quat, t.quat, sizeof t.quat);
    cfb_get_state(w, c, &t);
    memcpy(c_pos, t.pos, sizeof t.pos);
    cfb_remove_body(w, id); /* frees the compound and its children */
    assert_int_equal(cfb_body_count(w), 1);
    cfb_world_destroy(w);
}

/* 1 - cos(angle between the world z axis before and after): R(q) R(q0)^T
 * maps z to z when the body only yawed. */
static double tilt(const double q[4], const double q0[4])
{
    double R[9], R0[9];
    quat_matrix(q, R);
    quat_matrix(q0, R0);
    /* (R R0^T)_zz = row z of R . row z of R0. */
    return 1.0 - (R[6] * R0[6] + R[7] * R0[7] + R[8] * R0[8]);
}

static void test_compound_l_shape(void **state)
{
    (void)state;
    const double margin = 0.01;
    double z, zmin, cpos[3], q[4], q0[4], I[3], pts[48];
    l_body(I, pts, q0);
    print_message("L principal moments %.6f %.6f %.6f\n", I[0], I[1], I[2]);
    drop_l(1, &z, &zmin, cpos, q);
    print_message("compound L: rest z %.6f (5/6 + margin = %.6f), lowest %.6f; small cube at "
                  "(%.4f, %.4f, %.4f), expected z %.4f\n",
                  z, L_COM[2] + margin, zmin, cpos[0], cpos[1], cpos[2], 1.0 + 2 * margin + 0.105);
    assert_true(fabs(z - (L_COM[2] + margin)) <= 0.5 * margin);
    assert_true(zmin >= L_COM[2] + margin - 0.5 * margin);
    /* Still upright (it may yaw a little on impact, like the cube of
     * test_drop_on_plane): the world z axis is where it was. */
    assert_true(tilt(q, q0) < 1e-4);
    assert_true(fabs(cpos[2] - (1.0 + 2 * margin + 0.105)) <= 0.002);
    /* Where it was dropped, give or take the L's own drift on landing. */
    assert_true(fabs(cpos[0] - 1.5) < 0.1 && fabs(cpos[1] - 0.5) < 0.1);

    /* The hull of the same points stands the same way, but the cube does
     * not reach the floor of the notch. */
    drop_l(0, &z, &zmin, cpos, q);
    print_message("hull L: rest z %.6f; small cube at (%.4f, %.4f, %.4f)\n", z, cpos[0], cpos[1],
                  cpos[2]);
    assert_true(fabs(z - (L_COM[2] + margin)) <= 0.5 * margin);
    assert_false(fabs(cpos[2] - (1.0 + 2 * margin + 0.105)) <= 0.002 && fabs(cpos[0] - 1.5) < 0.1);
}

static void test_compound_errors(void **state)
{
    (void)state;
    cfb_world *w = cfb_world_create(GRAVITY);
    assert_non_null(w);
    double I[3], pts[48], q[4];
    l_body(I, pts, q);
    cfb_state s = state_at(0, 0, 1);
    const int good[3] = {0, 8, 16}, first[3] = {1, 8, 16}, small[3] = {0, 3, 16};
    assert_int_equal(cfb_add_compound_body(w, 3.0, I, pts, good, 0, 0.01, &s, 0.5, 0.0), -1);
    assert_int_equal(cfb_add_compound_body(w, 3.0, I, pts, first, 2, 0.01, &s, 0.5, 0.0), -1);
    assert_non_null(strstr(cfb_last_error(), "begin at 0"));
    assert_int_equal(cfb_add_compound_body(w, 3.0, I, pts, small, 2, 0.01, &s, 0.5, 0.0), -1);
    assert_non_null(strstr(cfb_last_error(), "hull 0"));
    assert_int_equal(cfb_add_compound_body(w, 0.0, I, pts, good, 2, 0.01, &s, 0.5, 0.0), -1);
    assert_non_null(strstr(cfb_last_error(), "mass"));
    assert_int_equal(cfb_add_compound_body(w, 3.0, I, NULL, good, 2, 0.01, &s, 0.5, 0.0), -1);
    assert_int_equal(cfb_add_compound_body(w, 3.0, I, pts, good, 2, -0.01, &s, 0.5, 0.0), -1);
    /* A second hull whose points are collinear. */
    double flat[48];
    memcpy(flat, pts, sizeof flat);
    for (int i = 8; i < 16; ++i) flat[3 * i + 1] = flat[3 * i + 2] = 0.25;
    assert_int_equal(cfb_add_compound_body(w, 3.0, I, flat, good, 2, 0.01, &s, 0.5, 0.0), -1);
    assert_non_null(strstr(cfb_last_error(), "hull 1 is degenerate"));
    pts[30] = NAN;
    assert_int_equal(cfb_add_compound_body(w, 3.0, I, pts, good, 2, 0.01, &s, 0.5, 0.0), -1);
    assert_non_null(strstr(cfb_last_error(), "non-finite"));
    assert_int_equal(cfb_body_count(w), 0);
    /* One hull: a plain hull body. */
    l_body(I, pts, q);
    const int id = cfb_add_compound_body(w, 3.0, I, pts, good, 1, 0.01, &s, 0.5, 0.0);
    assert_true(id >= 0);
    assert_int_equal(cfb_body_count(w), 1);
    cfb_world_destroy(w);
}

/* World inverse inertia applied to a vector: R diag(1/I) R^T x. */
static void inv_inertia_world(const double quat[4], const double I[3], const double x[3],
                              double out[3])
{
    double R[9], b[3];
    quat_matrix(quat, R);
    for (int i = 0; i < 3; ++i)
        b[i] = (R[0 + i] * x[0] + R[3 + i] * x[1] + R[6 + i] * x[2]) / I[i];
    for (int i = 0; i < 3; ++i) out[i] = R[3 * i] * b[0] + R[3 * i + 1] * b[1] + R[3 * i + 2] * b[2];
}

/* An impulse J at the centre of mass changes v by J/m and nothing else; at
 * an offset r it also changes w by I_world^-1 (r x J). */
static void test_apply_impulse(void **state)
{
    (void)state;
    cfb_world *w = cfb_world_create(NO_GRAVITY);
    assert_non_null(w);
    const double m = 2.0, I[3] = {0.3, 0.5, 0.7};
    double pts[24];
    cube_points(0.5, pts);
    cfb_state s = {{1, 2, 3}, {1, 0, 0, 0}, {0.5, -1, 2}, {0.3, 0.2, -0.1}};
    const double axis[3] = {1, -2, 0.5};
    axis_angle(axis, 1.1, s.quat);
    const int id = cfb_add_hull_body(w, m, I, pts, 8, 0.01, &s, 0.5, 0.0);
    assert_true(id >= 0);
    cfb_state a, b;
    cfb_get_state(w, id, &a);

    const double J[3] = {0.4, -1.2, 2.5};
    assert_int_equal(cfb_apply_impulse(w, id, J, a.pos), 0);
    cfb_get_state(w, id, &b);
    for (int i = 0; i < 3; ++i) {
        assert_true(fabs(b.v[i] - (a.v[i] + J[i] / m)) <= 1e-15);
        assert_true(b.w[i] == a.w[i]);
        assert_true(b.pos[i] == a.pos[i]);
    }

    const double r[3] = {0.3, -0.2, 0.45};
    const double p[3] = {b.pos[0] + r[0], b.pos[1] + r[1], b.pos[2] + r[2]};
    double rxJ[3], dw[3];
    cross3(r, J, rxJ);
    inv_inertia_world(b.quat, I, rxJ, dw);
    assert_int_equal(cfb_apply_impulse(w, id, J, p), 0);
    cfb_state c;
    cfb_get_state(w, id, &c);
    for (int i = 0; i < 3; ++i) {
        assert_true(fabs(c.v[i] - (b.v[i] + J[i] / m)) <= 1e-15);
        if (fabs(c.w[i] - (b.w[i] + dw[i])) > 1e-12)
            fail_msg("w[%d] %.17g, expected %.17g", i, c.w[i], b.w[i] + dw[i]);
    }
    print_message("impulse at offset: dw = (%.6f, %.6f, %.6f)\n", c.w[0] - b.w[0],
                  c.w[1] - b.w[1], c.w[2] - b.w[2]);

    /* Refused: static and kinematic bodies, bad ids, non-finite input. */
    const double o[3] = {0, 0, -5}, n[3] = {0, 0, 1}, v[3] = {1, 0, 0}, he[3] = {1, 1, 1};
    const int plane = cfb_add_plane(w, o, n, 0.5, 0.0);
    const int kin = cfb_add_box(w, o, he, v, 0.5, 0.0);
    assert_int_equal(cfb_apply_impulse(w, plane, J, p), -1);
    assert_non_null(strstr(cfb_last_error(), "not dynamic"));
    assert_int_equal(cfb_apply_impulse(w, kin, J, p), -1);
    assert_int_equal(cfb_apply_impulse(w, 77, J, p), -1);
    const double bad[3] = {0, INFINITY, 0};
    assert_int_equal(cfb_apply_impulse(w, id, bad, p), -1);
    assert_int_equal(cfb_apply_impulse(w, id, J, bad), -1);
    assert_int_equal(cfb_apply_impulse(w, id, NULL, p), -1);
    cfb_state d;
    cfb_get_state(w, id, &d);
    assert_memory_equal(&c, &d, sizeof c);
    cfb_world_destroy(w);
}

/* Momentum of a set of bodies: P = sum m v, L = sum x x m v + I_w w. */
static void momentum(const cfb_state *s, const double *m, const double (*I)[3], int n,
                     double P[3], double L[3])
{
    memset(P, 0, 3 * sizeof *P);
    memset(L, 0, 3 * sizeof *L);
    for (int k = 0; k < n; ++k) {
        double mv[3], xmv[3], Lk[3];
        for (int i = 0; i < 3; ++i) mv[i] = m[k] * s[k].v[i];
        cross3(s[k].pos, mv, xmv);
        angular_momentum(&s[k], I[k], Lk);
        for (int i = 0; i < 3; ++i) {
            P[i] += mv[i];
            L[i] += xmv[i] + Lk[i];
        }
    }
}

/* Equal and opposite impulses at one point (an internal force) leave the
 * total linear and angular momentum of two bodies unchanged. */
static void test_impulse_pair_momentum(void **state)
{
    (void)state;
    cfb_world *w = cfb_world_create(NO_GRAVITY);
    assert_non_null(w);
    const double m[2] = {2.0, 3.5}, I[2][3] = {{0.3, 0.5, 0.7}, {0.6, 0.6, 0.9}};
    double pts[24];
    cube_points(0.5, pts);
    cfb_state s[2] = {{{-1, 0.5, 0}, {1, 0, 0, 0}, {0.2, 0, 0}, {0, 0.4, 0.1}},
                      {{1.2, -0.3, 0.4}, {1, 0, 0, 0}, {-0.1, 0.3, 0}, {0.5, 0, -0.2}}};
    const double ax[3] = {0.2, 1, -0.4};
    axis_angle(ax, 0.6, s[1].quat);
    int id[2];
    for (int k = 0; k < 2; ++k) {
        id[k] = cfb_add_hull_body(w, m[k], I[k], pts, 8, 0.01, &s[k], 0.5, 0.0);
        assert_true(id[k] >= 0);
    }
    double P0[3], L0[3], P1[3], L1[3];
    for (int k = 0; k < 2; ++k) cfb_get_state(w, id[k], &s[k]);
    momentum(s, m, I, 2, P0, L0);
    const double J[3] = {3.0, -1.5, 0.8}, mJ[3] = {-3.0, 1.5, -0.8}, p[3] = {0.1, 0.2, 0.3};
    assert_int_equal(cfb_apply_impulse(w, id[0], J, p), 0);
    assert_int_equal(cfb_apply_impulse(w, id[1], mJ, p), 0);
    for (int k = 0; k < 2; ++k) cfb_get_state(w, id[k], &s[k]);
    momentum(s, m, I, 2, P1, L1);
    print_message("impulse pair: |dP| %.3e, |dL| %.3e (|J| %.3f)\n",
                  sqrt((P1[0] - P0[0]) * (P1[0] - P0[0]) + (P1[1] - P0[1]) * (P1[1] - P0[1]) +
                       (P1[2] - P0[2]) * (P1[2] - P0[2])),
                  sqrt((L1[0] - L0[0]) * (L1[0] - L0[0]) + (L1[1] - L0[1]) * (L1[1] - L0[1]) +
                       (L1[2] - L0[2]) * (L1[2] - L0[2])),
                  norm3(J));
    for (int i = 0; i < 3; ++i) {
        assert_true(fabs(P1[i] - P0[i]) <= 1e-14);
        assert_true(fabs(L1[i] - L0[i]) <= 1e-13);
    }
    /* Each body did change. */
    assert_true(fabs(s[0].v[0] - 0.2 - J[0] / m[0]) <= 1e-15);
    /* Free flight keeps the linear momentum. */
    for (int i = 0; i < 100; ++i) assert_int_equal(cfb_step(w, 1e-3, 5), 0);
    for (int k = 0; k < 2; ++k) cfb_get_state(w, id[k], &s[k]);
    momentum(s, m, I, 2, P1, L1);
    for (int i = 0; i < 3; ++i) assert_true(fabs(P1[i] - P0[i]) <= 1e-13);
    cfb_world_destroy(w);
}

/* A 1 cm cube at 200 m/s (4 cm per sub-step) towards a 2 mm static wall:
 * no sub-step ends in contact, so it tunnels without CCD and stops at the
 * wall with it.  `other` != 0 puts a dynamic cube in the way instead, in
 * the fast cube's family (other = 1) or ignored with it (other = 2). */
static double shoot(int ccd, int other, double *wall_impulse)
{
    cfb_world *w = cfb_world_create(NO_GRAVITY);
    assert_non_null(w);
    const double c[3] = {0, 0, 0}, he[3] = {0.001, 0.5, 0.5};
    int wall;
    if (other) {
        const cfb_state so = state_at(0, 0, 0);
        wall = add_cube(w, 1.0, 0.001, &so);
    } else {
        wall = cfb_add_box(w, c, he, NULL, 0.5, 0.0);
    }
    assert_true(wall >= 0);
    const double a = 0.005, m = 1e-3;
    double pts[24];
    cube_points(a, pts);
    const double I[3] = {m * 4 * a * a / 6, m * 4 * a * a / 6, m * 4 * a * a / 6};
    cfb_state s = state_at(-0.5 - (other ? 0.5 : 0.0), 0, 0);
    s.v[0] = 200.0;
    const int id = cfb_add_hull_body(w, m, I, pts, 8, 0.001, &s, 0.5, 0.0);
    assert_true(id >= 0);
    if (ccd) assert_int_equal(cfb_set_ccd(w, id, a, 0.8 * a), 0);
    if (other == 1) {
        assert_int_equal(cfb_set_family(w, id, 7), 0);
        assert_int_equal(cfb_set_family(w, wall, 7), 0);
    } else if (other == 2) {
        cfb_ignore_pair(w, id, wall);
    }
    *wall_impulse = 0.0;
    for (int i = 0; i < 20; ++i) {
        assert_int_equal(cfb_step(w, 1e-3, 5), 0);
        *wall_impulse += cfb_contact_impulse(w, wall);
    }
    cfb_state t;
    cfb_get_state(w, id, &t);
    cfb_world_destroy(w);
    return t.pos[0];
}

static void test_ccd(void **state)
{
    (void)state;
    double J;
    const double x_off = shoot(0, 0, &J);
    print_message("CCD off: x = %.4f, wall impulse %.3e\n", x_off, J);
    assert_true(x_off > 1.0 && J == 0.0);
    const double x_on = shoot(1, 0, &J);
    print_message("CCD on: x = %.6f, wall impulse %.3e (m v = 0.2)\n", x_on, J);
    assert_true(x_on < 0.0 && x_on > -0.05);
    assert_true(J > 0.1);
    /* A family member or an ignored body in the way is not hit. */
    const double x_fam = shoot(1, 1, &J);
    print_message("CCD on through a family member: x = %.12f, impulse %.3e\n", x_fam, J);
    assert_true(x_fam > 1.0 && J == 0.0);
    const double x_ign = shoot(1, 2, &J);
    assert_true(x_ign > 1.0 && J == 0.0);

    cfb_world *w = cfb_world_create(NO_GRAVITY);
    const cfb_state s0 = state_at(0, 0, 0);
    const int id = add_cube(w, 1.0, 0.01, &s0);
    assert_int_equal(cfb_set_ccd(w, id, 0.1, 0.05), 0);
    assert_int_equal(cfb_set_ccd(w, id, 0.0, 0.0), 0);
    assert_int_equal(cfb_set_ccd(w, id, 0.1, 0.0), -1);
    assert_non_null(strstr(cfb_last_error(), "both"));
    assert_int_equal(cfb_set_ccd(w, id, -0.1, 0.05), -1);
    assert_int_equal(cfb_set_ccd(w, id, NAN, 0.05), -1);
    assert_int_equal(cfb_set_ccd(w, 9, 0.1, 0.05), -1);
    const double o[3] = {0, 0, -5}, n[3] = {0, 0, 1};
    const int plane = cfb_add_plane(w, o, n, 0.5, 0.0);
    assert_int_equal(cfb_set_ccd(w, plane, 0.1, 0.05), -1);
    double I[3], pts[48], q[4];
    l_body(I, pts, q);
    const int start[3] = {0, 8, 16};
    const cfb_state sl = state_at(5, 5, 5);
    const int l = cfb_add_compound_body(w, 3.0, I, pts, start, 2, 0.01, &sl, 0.5, 0.0);
    assert_int_equal(cfb_set_ccd(w, l, 0.1, 0.05), -1);
    assert_non_null(strstr(cfb_last_error(), "compound"));
    cfb_world_destroy(w);
}

/* Cubes resting on a plane fall asleep within a few seconds when sleeping
 * is on (also the one added before it was switched on), never when it is
 * off; an impulse, cfb_set_state or a kinematic body wakes them. */
static void test_sleeping(void **state)
{
    (void)state;
    const double origin[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    for (int on = 0; on < 2; ++on) {
        cfb_world *w = cfb_world_create(GRAVITY);
        assert_non_null(w);
        assert_true(cfb_add_plane(w, origin, up, 0.5, 0.0) >= 0);
        const cfb_state sa = state_at(0, 0, 0.6), sb = state_at(3, 0, 0.7);
        const int a = add_cube(w, 1.0, 0.01, &sa);
        if (on) assert_int_equal(cfb_set_sleeping(w, 0.05, 0.05), 0);
        const int b = add_cube(w, 1.0, 0.01, &sb);
        int slept_a = -1, slept_b = -1;
        for (int i = 0; i < 6000; ++i) {
            assert_int_equal(cfb_step(w, 1e-3, 5), 0);
            if (slept_a < 0 && cfb_is_sleeping(w, a) == 1) slept_a = i;
            if (slept_b < 0 && cfb_is_sleeping(w, b) == 1) slept_b = i;
        }
        print_message("sleeping %s: asleep after %d and %d steps of 1 ms\n", on ? "on" : "off",
                      slept_a, slept_b);
        if (!on) {
            assert_true(slept_a < 0 && slept_b < 0);
            assert_true(cfb_contact_impulse(w, a) > 0.0);
            cfb_world_destroy(w);
            continue;
        }
        /* Slow for 2 s after settling. */
        assert_true(slept_a >= 2000 && slept_a < 4000);
        assert_true(slept_b >= 2000 && slept_b < 4000);
        cfb_state s;
        cfb_get_state(w, a, &s);
        assert_true(fabs(s.pos[2] - 0.51) < 0.01 && norm3(s.v) == 0.0);
        /* Asleep, the contacts are no longer solved, and the manifold keeps
         * reporting the impulses of the last solve: the resting load. */
        print_message("impulse reported while asleep %.9e (m g dt %.9e)\n",
                      cfb_contact_impulse(w, a), G * 1e-3);
        assert_true(fabs(cfb_contact_impulse(w, a) - G * 1e-3) <= 0.01 * G * 1e-3);

        /* An impulse wakes a (b sleeps on); it jumps and falls asleep again. */
        const double J[3] = {0, 0, 2.0};
        assert_int_equal(cfb_apply_impulse(w, a, J, s.pos), 0);
        assert_int_equal(cfb_is_sleeping(w, a), 0);
        assert_int_equal(cfb_step(w, 1e-3, 5), 0);
        cfb_get_state(w, a, &s);
        assert_true(s.pos[2] > 0.511 && s.v[2] > 1.0);
        assert_int_equal(cfb_is_sleeping(w, b), 1);
        for (int i = 0; i < 5000 && cfb_is_sleeping(w, a) != 1; ++i)
            assert_int_equal(cfb_step(w, 1e-3, 5), 0);
        assert_int_equal(cfb_is_sleeping(w, a), 1);

        /* cfb_set_state wakes. */
        cfb_get_state(w, a, &s);
        cfb_set_state(w, a, &s);
        assert_int_equal(cfb_is_sleeping(w, a), 0);

        /* A kinematic box pushing into sleeping b wakes it and moves it. */
        const double kc[3] = {1.9, 0, 0.5}, khe[3] = {0.3, 0.3, 0.3}, kv[3] = {1.0, 0, 0};
        const int kin = cfb_add_box(w, kc, khe, kv, 0.5, 0.0);
        assert_int_equal(cfb_is_sleeping(w, kin), 0);
        cfb_state sb0, sb1;
        cfb_get_state(w, b, &sb0);
        for (int i = 0; i < 1000; ++i) assert_int_equal(cfb_step(w, 1e-3, 5), 0);
        assert_int_equal(cfb_is_sleeping(w, kin), 0);
        cfb_get_state(w, b, &sb1);
        print_message("pushed sleeper moved %.3f m\n", sb1.pos[0] - sb0.pos[0]);
        assert_true(sb1.pos[0] - sb0.pos[0] > 0.5);

        /* 0, 0 wakes everyone for good. */
        for (int i = 0; i < 4000; ++i) assert_int_equal(cfb_step(w, 1e-3, 5), 0);
        assert_int_equal(cfb_set_sleeping(w, 0.0, 0.0), 0);
        for (int i = 0; i < 3000; ++i) {
            assert_int_equal(cfb_step(w, 1e-3, 5), 0);
            assert_int_equal(cfb_is_sleeping(w, a), 0);
        }
        assert_true(cfb_contact_impulse(w, a) > 0.0);

        assert_int_equal(cfb_set_sleeping(w, -1.0, 1.0), -1);
        assert_int_equal(cfb_set_sleeping(w, 0.1, 0.0), -1);
        assert_non_null(strstr(cfb_last_error(), "both"));
        assert_int_equal(cfb_set_sleeping(w, NAN, 0.1), -1);
        assert_int_equal(cfb_set_sleeping(NULL, 0.1, 0.1), -1);
        assert_int_equal(cfb_is_sleeping(w, 99), -1);
        assert_int_equal(cfb_is_sleeping(w, 0), 0); /* the plane */
        cfb_world_destroy(w);
    }
}

/* Penetration depth of the margin-inflated shapes: two unit cubes 0.8 apart
 * overlap by 0.2 + 2 margins; measured also for ignored pairs and members
 * of one family, which never collide. */
static void test_pair_penetration(void **state)
{
    (void)state;
    cfb_world *w = cfb_world_create(NO_GRAVITY);
    assert_non_null(w);
    const double m = 0.01;
    const cfb_state sa = state_at(0, 0, 0), sb = state_at(0.8, 0, 0), sc = state_at(0, 3, 0);
    const int a = add_cube(w, 1.0, m, &sa), b = add_cube(w, 1.0, m, &sb);
    const int c = add_cube(w, 1.0, m, &sc);
    const double pen = cfb_pair_penetration(w, a, b);
    print_message("penetration of cubes 0.8 apart: %.12f (overlap 0.2, + 2 margins 0.22)\n", pen);
    assert_true(fabs(pen - (0.2 + 2 * m)) <= 1e-6);
    assert_true(cfb_pair_penetration(w, b, a) == pen);
    assert_true(cfb_pair_penetration(w, a, c) == 0.0);

    cfb_ignore_pair(w, a, b);
    assert_true(fabs(cfb_pair_penetration(w, a, b) - pen) <= 1e-9);
    cfb_unignore_pair(w, a, b);
    assert_int_equal(cfb_set_family(w, a, 2), 0);
    assert_int_equal(cfb_set_family(w, b, 2), 0);
    assert_true(fabs(cfb_pair_penetration(w, a, b) - pen) <= 1e-9);

    /* Cores just touching: the margins overlap, 2 m. */
    cfb_state t = state_at(1.0, 0, 0);
    cfb_set_state(w, b, &t);
    const double touch = cfb_pair_penetration(w, a, b);
    print_message("cores touching: %.12f (2 margins %.3f)\n", touch, 2 * m);
    assert_true(fabs(touch - 2 * m) <= 1e-6);
    t = state_at(1.0 + 2 * m + 1e-3, 0, 0);
    cfb_set_state(w, b, &t);
    assert_true(cfb_pair_penetration(w, a, b) == 0.0);

    /* Against a plane (no margin): the cube 0.1 into it, + its margin. */
    const double o[3] = {0, 0, -0.4}, n[3] = {0, 0, 1};
    const int plane = cfb_add_plane(w, o, n, 0.5, 0.0);
    const double pp = cfb_pair_penetration(w, a, plane);
    print_message("cube 0.1 into a plane: %.12f\n", pp);
    assert_true(fabs(pp - (0.1 + m)) <= 1e-6);

    /* Compound L against a cube in its notch, and an ignored compound. */
    double I[3], pts[48], q[4];
    l_body(I, pts, q);
    const int start[3] = {0, 8, 16};
    cfb_state sl = state_at(L_COM[0] + 10, L_COM[1], L_COM[2]);
    memcpy(sl.quat, q, sizeof q);
    const int l = cfb_add_compound_body(w, 3.0, I, pts, start, 2, m, &sl, 0.5, 0.0);
    assert_true(l >= 0);
    /* A unit cube centred at (11.5, 0.5, 1.45) sits 0.05 into the long box's
     * top, 0.5 from the tall box: overlap 0.05 + 2 m. */
    t = state_at(11.5 + 0.05, 0.5, 1.45);
    cfb_set_state(w, c, &t);
    const double pl = cfb_pair_penetration(w, l, c);
    print_message("cube in the L's notch: %.12f (expected 0.07)\n", pl);
    assert_true(fabs(pl - (0.05 + 2 * m)) <= 1e-6);
    cfb_ignore_pair(w, l, c);
    assert_true(fabs(cfb_pair_penetration(w, c, l) - pl) <= 1e-9);
    /* Two Ls, the second moved 1.9 along x: its long box overlaps the
     * first's by 0.1 (the deepest of the hull pairs), its tall box sits on
     * the first's long box (cores touching). */
    cfb_state sl2 = sl;
    sl2.pos[0] += 1.9;
    const int l2 = cfb_add_compound_body(w, 3.0, I, pts, start, 2, m, &sl2, 0.5, 0.0);
    assert_true(l2 >= 0);
    assert_int_equal(cfb_set_family(w, l, 5), 0);
    assert_int_equal(cfb_set_family(w, l2, 5), 0);
    const double ll = cfb_pair_penetration(w, l, l2);
    print_message("L against L: %.12f (expected 0.12)\n", ll);
    assert_true(fabs(ll - (0.1 + 2 * m)) <= 1e-6);

    assert_true(cfb_pair_penetration(w, a, a) == -1.0);
    assert_true(cfb_pair_penetration(w, a, 99) == -1.0);
    assert_non_null(strstr(cfb_last_error(), "invalid body id 99"));
    cfb_world_destroy(w);
}

/* Ignoring then unignoring a pair: no contact in between, contact after,
 * bookkeeping consistent (ignore again, removal). */
static void test_unignore_pair(void **state)
{
    (void)state;
    cfb_world *w = cfb_world_create(NO_GRAVITY);
    assert_non_null(w);
    const cfb_state sa = state_at(0, 0, 0), sb = state_at(1.0, 0, 0);
    const int a = add_cube(w, 1.0, 0.01, &sa), b = add_cube(w, 1.0, 0.01, &sb);
    cfb_ignore_pair(w, a, b);
    cfb_ignore_pair(w, b, a); /* duplicate: no effect */
    for (int i = 0; i < 5; ++i) {
        assert_int_equal(cfb_step(w, 1e-3, 5), 0);
        assert_true(cfb_contact_impulse(w, a) == 0.0);
    }
    cfb_unignore_pair(w, b, a);
    assert_int_equal(cfb_step(w, 1e-3, 5), 0);
    assert_true(cfb_contact_impulse(w, a) > 0.0);
    /* Unignoring twice, or a pair never ignored, is harmless. */
    cfb_unignore_pair(w, a, b);
    const cfb_state sc = state_at(0, 5, 0);
    const int c = add_cube(w, 1.0, 0.01, &sc);
    cfb_unignore_pair(w, a, c);
    /* Ignore again, then remove one: the other body stays usable. */
    cfb_set_state(w, a, &sa);
    cfb_set_state(w, b, &sb);
    cfb_ignore_pair(w, a, b);
    assert_int_equal(cfb_step(w, 1e-3, 5), 0);
    assert_true(cfb_contact_impulse(w, a) == 0.0);
    cfb_remove_body(w, b);
    cfb_unignore_pair(w, a, b);
    assert_non_null(strstr(cfb_last_error(), "invalid body id 1"));
    cfb_unignore_pair(w, a, a);
    assert_non_null(strstr(cfb_last_error(), "itself"));
    assert_int_equal(cfb_step(w, 1e-3, 5), 0);
    cfb_world_destroy(w);
}

/* Bounding boxes, margin included: exact for a turned hull. */
static void test_get_aabb(void **state)
{
    (void)state;
    cfb_world *w = cfb_world_create(NO_GRAVITY);
    assert_non_null(w);
    const double m = 0.01;
    cfb_state s = state_at(1, 2, 3);
    const double z[3] = {0, 0, 1};
    axis_angle(z, PI / 4, s.quat);
    const int a = add_cube(w, 1.0, m, &s);
    double lo[3], hi[3];
    assert_int_equal(cfb_get_aabb(w, a, lo, hi), 0);
    const double h = sqrt(0.5) + m;
    print_message("turned cube box: [%.15f %.15f] x [%.15f %.15f] x [%.15f %.15f]\n", lo[0], hi[0],
                  lo[1], hi[1], lo[2], hi[2]);
    assert_true(fabs(lo[0] - (1 - h)) <= 1e-12 && fabs(hi[0] - (1 + h)) <= 1e-12);
    assert_true(fabs(lo[1] - (2 - h)) <= 1e-12 && fabs(hi[1] - (2 + h)) <= 1e-12);
    assert_true(fabs(lo[2] - (3 - 0.5 - m)) <= 1e-12 && fabs(hi[2] - (3 + 0.5 + m)) <= 1e-12);

    const double c[3] = {-1, 0, 2}, he[3] = {0.5, 0.25, 1.0};
    const int sph = cfb_add_sphere(w, c, 0.3, NULL, 0.5, 0.0);
    const int box = cfb_add_box(w, c, he, NULL, 0.5, 0.0);
    assert_int_equal(cfb_get_aabb(w, sph, lo, hi), 0);
    for (int i = 0; i < 3; ++i) assert_true(lo[i] == c[i] - 0.3 && hi[i] == c[i] + 0.3);
    assert_int_equal(cfb_get_aabb(w, box, lo, hi), 0);
    for (int i = 0; i < 3; ++i)
        assert_true(fabs(lo[i] - (c[i] - he[i])) <= 1e-15 && fabs(hi[i] - (c[i] + he[i])) <= 1e-15);

    /* The L in its world pose: [0,2] x [0,1] x [0,2] (+ margin), lifted. */
    double I[3], pts[48], q[4];
    l_body(I, pts, q);
    const int start[3] = {0, 8, 16};
    cfb_state sl = state_at(L_COM[0], L_COM[1], L_COM[2] + 5);
    memcpy(sl.quat, q, sizeof q);
    const int l = cfb_add_compound_body(w, 3.0, I, pts, start, 2, m, &sl, 0.5, 0.0);
    assert_int_equal(cfb_get_aabb(w, l, lo, hi), 0);
    const double elo[3] = {-m, -m, 5 - m}, ehi[3] = {2 + m, 1 + m, 7 + m};
    for (int i = 0; i < 3; ++i)
        assert_true(fabs(lo[i] - elo[i]) <= 1e-12 && fabs(hi[i] - ehi[i]) <= 1e-12);

    /* A triangle mesh: its vertices' box. */
    const double v[4][3] = {{-1, -2, 0}, {3, -2, 0.5}, {3, 4, 0}, {-1, 4, -0.25}};
    const int t[2][3] = {{0, 1, 2}, {0, 2, 3}};
    const int mesh = cfb_add_trimesh(w, &v[0][0], 4, &t[0][0], 2, 0.5, 0.0);
    assert_int_equal(cfb_get_aabb(w, mesh, lo, hi), 0);
    assert_true(fabs(lo[0] + 1) <= 1e-12 && fabs(lo[1] + 2) <= 1e-12 && fabs(lo[2] + 0.25) <= 1e-12);
    assert_true(fabs(hi[0] - 3) <= 1e-12 && fabs(hi[1] - 4) <= 1e-12 && fabs(hi[2] - 0.5) <= 1e-12);

    /* A floor: the half-space z <= -1, and the contact breaking threshold
     * (1 mm) above it, so that Bullet pairs only the bodies near it. */
    const double po[3] = {0, 0, -1}, pn[3] = {0, 0, 1};
    const int plane = cfb_add_plane(w, po, pn, 0.5, 0.0);
    assert_int_equal(cfb_get_aabb(w, plane, lo, hi), 0);
    for (int i = 0; i < 3; ++i) assert_true(lo[i] <= -1e29);
    assert_true(hi[0] >= 1e29 && hi[1] >= 1e29 && fabs(hi[2] - (-1 + 1e-3)) <= 1e-12);
    /* A wall facing -x at x = 2: the half-space x >= 2, 1 mm before it. */
    const double wo[3] = {2, 0, 0}, wn[3] = {-1, 0, 0};
    const int wall = cfb_add_plane(w, wo, wn, 0.5, 0.0);
    assert_int_equal(cfb_get_aabb(w, wall, lo, hi), 0);
    assert_true(fabs(lo[0] - (2 - 1e-3)) <= 1e-12 && lo[1] <= -1e29 && lo[2] <= -1e29);
    for (int i = 0; i < 3; ++i) assert_true(hi[i] >= 1e29);
    /* A tilted plane: unbounded. */
    const double tn[3] = {0, 1, 1};
    const int tilted = cfb_add_plane(w, po, tn, 0.5, 0.0);
    assert_int_equal(cfb_get_aabb(w, tilted, lo, hi), 0);
    for (int i = 0; i < 3; ++i) assert_true(lo[i] <= -1e29 && hi[i] >= 1e29);

    assert_int_equal(cfb_get_aabb(w, 42, lo, hi), -1);
    assert_int_equal(cfb_get_aabb(w, a, NULL, hi), -1);
    cfb_world_destroy(w);
}

/* Points on a sphere of radius r (Fibonacci lattice). */
static void ball_points(double r, int n, double *pts)
{
    const double golden = PI * (3.0 - sqrt(5.0));
    for (int i = 0; i < n; ++i) {
        const double z = 1.0 - (2.0 * i + 1.0) / n, rho = sqrt(1.0 - z * z);
        pts[3 * i] = r * rho * cos(golden * i);
        pts[3 * i + 1] = r * rho * sin(golden * i);
        pts[3 * i + 2] = r * z;
    }
}

/* A ground of two triangles: a cube and a ball dropped on it come to rest
 * on it (the caller's arrays may change afterwards: the body has copies). */
static void test_trimesh_ground(void **state)
{
    (void)state;
    cfb_world *w = cfb_world_create(GRAVITY);
    assert_non_null(w);
    double v[4][3] = {{-5, -5, 0}, {5, -5, 0}, {5, 5, 0}, {-5, 5, 0}};
    int t[2][3] = {{0, 1, 2}, {0, 2, 3}};
    const int ground = cfb_add_trimesh(w, &v[0][0], 4, &t[0][0], 2, 0.5, 0.0);
    assert_true(ground >= 0);
    assert_int_equal(cfb_body_count(w), 0);
    memset(v, 0, sizeof v);
    t[1][1] = 77;

    const double m = 0.01, r = 0.25;
    const cfb_state sc = state_at(1, -2, 1.5);
    const int cube = add_cube(w, 1.0, m, &sc);
    enum { NB = 40 };
    double bp[NB * 3];
    ball_points(r, NB, bp);
    const double Ib = 0.4 * r * r;
    const double Iball[3] = {Ib, Ib, Ib};
    const cfb_state sb = state_at(-2, 1.5, 1.0);
    const int ball = cfb_add_hull_body(w, 1.0, Iball, bp, NB, m, &sb, 0.5, 0.0);
    assert_true(cube >= 0 && ball >= 0);
    double zmin_c = 1e30, zmin_b = 1e30;
    for (int i = 0; i < 3000; ++i) {
        assert_int_equal(cfb_step(w, 1e-3, 5), 0);
        cfb_state s;
        cfb_get_state(w, cube, &s);
        if (s.pos[2] < zmin_c) zmin_c = s.pos[2];
        cfb_get_state(w, ball, &s);
        if (s.pos[2] < zmin_b) zmin_b = s.pos[2];
    }
    cfb_state c, b;
    cfb_get_state(w, cube, &c);
    cfb_get_state(w, ball, &b);
    print_message("trimesh ground: cube rests at z %.6f (0.5 + margin = %.3f, lowest %.6f), "
                  "ball at (%.3f, %.3f, %.6f) (radius + margin %.3f, lowest %.6f)\n",
                  c.pos[2], 0.5 + m, zmin_c, b.pos[0], b.pos[1], b.pos[2], r + m, zmin_b);
    assert_true(fabs(c.pos[2] - (0.5 + m)) <= 0.5 * m);
    assert_true(zmin_c >= 0.5 + m - 0.5 * m);
    assert_true(norm3(c.v) < 1e-3);
    /* The ball is a 40-vertex polyhedron: it rests on a facet, a little
     * below its radius (its inradius is above 0.9 r). */
    assert_true(b.pos[2] <= r + m + 0.5 * m && b.pos[2] >= 0.9 * r + m - 0.5 * m);
    assert_true(zmin_b >= 0.9 * r + m - 0.5 * m);
    assert_true(fabs(b.pos[0]) < 5 && fabs(b.pos[1]) < 5 && norm3(b.v) < 1e-2);
    assert_true(cfb_contact_impulse(w, ground) > 0.0);
    /* Penetration against the mesh. */
    cfb_state d = state_at(1, -2, 0.4);
    cfb_set_state(w, cube, &d);
    const double pm = cfb_pair_penetration(w, cube, ground);
    print_message("cube 0.1 into the mesh: %.9f\n", pm);
    assert_true(fabs(pm - (0.1 + m)) <= 1e-6);
    cfb_remove_body(w, ground);
    cfb_world_destroy(w);
}

static void test_trimesh_errors(void **state)
{
    (void)state;
    cfb_world *w = cfb_world_create(GRAVITY);
    assert_non_null(w);
    const double v[4][3] = {{-5, -5, 0}, {5, -5, 0}, {5, 5, 0}, {-5, 5, 0}};
    int t[2][3] = {{0, 1, 2}, {0, 2, 3}};
    assert_int_equal(cfb_add_trimesh(w, &v[0][0], 4, &t[0][0], 0, 0.5, 0.0), -1);
    assert_non_null(strstr(cfb_last_error(), "triangle"));
    assert_int_equal(cfb_add_trimesh(w, NULL, 4, &t[0][0], 2, 0.5, 0.0), -1);
    assert_int_equal(cfb_add_trimesh(w, &v[0][0], 4, NULL, 2, 0.5, 0.0), -1);
    t[1][2] = 4;
    assert_int_equal(cfb_add_trimesh(w, &v[0][0], 4, &t[0][0], 2, 0.5, 0.0), -1);
    assert_non_null(strstr(cfb_last_error(), "out of range"));
    t[1][2] = -1;
    assert_int_equal(cfb_add_trimesh(w, &v[0][0], 4, &t[0][0], 2, 0.5, 0.0), -1);
    t[1][2] = 0;
    assert_int_equal(cfb_add_trimesh(w, &v[0][0], 4, &t[0][0], 2, 0.5, 0.0), -1);
    assert_non_null(strstr(cfb_last_error(), "repeats"));
    t[1][2] = 3;
    assert_int_equal(cfb_add_trimesh(w, &v[0][0], 4, &t[0][0], 2, -0.5, 0.0), -1);
    double vn[4][3];
    memcpy(vn, v, sizeof v);
    vn[2][1] = NAN;
    assert_int_equal(cfb_add_trimesh(w, &vn[0][0], 4, &t[0][0], 2, 0.5, 0.0), -1);
    assert_non_null(strstr(cfb_last_error(), "non-finite"));
    assert_int_equal(cfb_add_trimesh(w, &v[0][0], 4, &t[0][0], 2, 0.5, 0.0), 0);
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
        cmocka_unit_test(test_convex_hull),      cmocka_unit_test(test_compound_l_shape),
        cmocka_unit_test(test_compound_errors),  cmocka_unit_test(test_apply_impulse),
        cmocka_unit_test(test_impulse_pair_momentum), cmocka_unit_test(test_ccd),
        cmocka_unit_test(test_sleeping),         cmocka_unit_test(test_pair_penetration),
        cmocka_unit_test(test_unignore_pair),    cmocka_unit_test(test_get_aabb),
        cmocka_unit_test(test_trimesh_ground),   cmocka_unit_test(test_trimesh_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
