/* Tet4 elasticity: gradients, volume, lumped mass, stress, CFL estimate. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "check.h"

#include "chunks.h"

#include "fixtures.h"
#include "linalg.h"
#include "sort.h"
#include "solid.h"
#include "tet4.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

static cf_material material(double E, double nu, double rho)
{
    cf_material m = {E, nu, rho, 22, 22, 1e4, 1e4, 2, 2, 0.5, 0, 0, 10, 1, 0, 0, 0, 0, 0, 0, 0};
    return m;
}

static void one_tet(cf_solid *s, const double x[4][3], const cf_material *mat)
{
    cf_mesh m = {.n_nodes = 4, .n_tets = 1};
    double xs[12];
    int t[4] = {0, 1, 2, 3}, body = 0;
    memcpy(xs, x, sizeof xs);
    m.x = xs, m.tets = t;
    assert_int_equal(cf_solid_init(s, &m, mat, &body, NULL), CF_OK);
}

static const double skew[4][3] = {{0.1, 0.2, 0.0}, {1.3, 0.1, 0.2}, {0.2, 0.9, 0.1}, {0.3, 0.4, 1.1}};

/* Gradients sum to zero and reproduce linear fields: sum_i x_i (x) grad N_i = I. */
static void test_gradients_reproduce_linear_fields(void **state)
{
    (void)state;
    cf_material mat = material(1e6, 0.3, 1000);
    cf_solid s;
    one_tet(&s, skew, &mat);
    double g[4][3];
    cf_tet4_gradients(&s, 0, g);
    for (int c = 0; c < 3; c++)
        assert_near(g[0][c] + g[1][c] + g[2][c] + g[3][c], 0.0, 1e-12);
    for (int p = 0; p < 3; p++)
        for (int q = 0; q < 3; q++) {
            double acc = 0;
            for (int i = 0; i < 4; i++)
                acc += skew[i][p] * g[i][q];
            assert_near(acc, p == q ? 1.0 : 0.0, 1e-12);
        }
    double V = cf_tet_volume(skew[0], skew[1], skew[2], skew[3]);
    assert_near(s.vol[0], V, 1e-15);
    for (int i = 0; i < 4; i++) /* lumped mass rho V / 4 per node */
        assert_near(s.m[i], 1000 * V / 4, 1e-12);
    cf_solid_free(&s);
}

/* A box of 3 x 2 x nz hexahedra (0.3 x 0.2 x lz m) split into Tet4, E 1 MPa,
 * nu 0.3, density rho; body receives the body index per tet (free it). */
static void box_solid(cf_solid *s, cf_mesh *m, int **body, int nz, double lz, double rho)
{
    fixture_box(m, 3, 2, nz, 0.3, 0.2, lz);
    *body = calloc((size_t)m->n_tets, sizeof(int));
    cf_material mat = material(1e6, 0.3, rho);
    assert_int_equal(cf_solid_init(s, m, &mat, *body, NULL), CF_OK);
}

/* The lumped masses of a box add up to rho * volume. */
static void test_lumped_mass_of_box(void **state)
{
    (void)state;
    cf_mesh m;
    cf_solid s;
    int *body;
    box_solid(&s, &m, &body, 4, 0.5, 2400);
    double M = 0;
    for (int i = 0; i < s.n_nodes; i++)
        M += s.m[i];
    assert_near(M, 2400 * 0.3 * 0.2 * 0.5, 1e-12);
    cf_solid_free(&s), cf_mesh_free(&m), free(body);
}

/* Uniaxial stretch F = diag(1+e,1,1): sigma_xx = (lambda+2mu) e, sigma_yy = lambda e;
 * the nodal forces balance (sum zero). */
static void stretch_case(cf_elasticity kind)
{
    cf_material mat = material(2e6, 0.25, 1000);
    cf_solid s;
    one_tet(&s, skew, &mat);
    double e = 1e-4;
    for (int i = 0; i < 4; i++)
        s.x[3 * i] = (1 + e) * s.X[3 * i];
    int t = 0;
    cf_tet4_forces(&s, &t, 1, kind, NULL, 0, NULL);
    double sigma[9];
    cf_tet4_stress(&s, 0, kind, sigma);
    double lam = s.lambda, mu = s.mu;
    assert_near(sigma[0], (lam + 2 * mu) * e, 1e-6 * (lam + 2 * mu) * e);
    assert_near(sigma[4], lam * e, 1e-6 * (lam + 2 * mu) * e);
    assert_near(sigma[8], lam * e, 1e-6 * (lam + 2 * mu) * e);
    for (int c = 0; c < 3; c++)
        assert_near(s.tf[c] + s.tf[3 + c] + s.tf[6 + c] + s.tf[9 + c], 0.0, 1e-9);
    /* f_i = -V sigma grad N_i */
    double g[4][3];
    cf_tet4_gradients(&s, 0, g);
    for (int a = 0; a < 4; a++)
        assert_near(s.tf[3 * a], -s.vol[0] * sigma[0] * g[a][0], 1e-6 * fabs(sigma[0]));
    cf_solid_free(&s);
}
static void test_uniaxial_stretch_corotational(void **state) { (void)state; stretch_case(CF_ELASTICITY_COROTATIONAL); }
static void test_uniaxial_stretch_linear(void **state) { (void)state; stretch_case(CF_ELASTICITY_LINEAR); }

/* Crushing (von Mises perfect plasticity at sigma_c): uniaxial strain
 * F = diag(1+e,1,1), e < 0, has the deviatoric part e diag(2/3,-1/3,-1/3)
 * and the equivalent trial stress 2 mu |e|.  Beyond e_y = sigma_c / (2 mu)
 * the stress returns to the yield surface: sigma_xx - sigma_yy = -sigma_c,
 * the mean stress K e unchanged, and the plastic work is
 * (2/3) sigma_c (|e| - e_y) V.  At the same strain again nothing more
 * flows; unloading by less than 2 e_y is elastic; once the hand-off to
 * rigid mode has dropped the plastic strain the rest shape is unstressed. */
static void test_crushing_uniaxial_strain(void **state)
{
    (void)state;
    cf_material mat = material(5e9, 0.2, 1200);
    mat.compressive_strength = 15e6;
    cf_solid s;
    one_tet(&s, skew, &mat);
    double sc = mat.compressive_strength, ey = sc / (2 * s.mu), e = -3 * ey;
    double K = s.lambda + 2 * s.mu / 3, V = s.vol[0];
    int t = 0;
    cf_tet4_forces(&s, &t, 1, CF_ELASTICITY_COROTATIONAL, NULL, 0, NULL);
    assert_true(s.wp[0] == 0); /* at rest: elastic */
    for (int i = 0; i < 4; i++)
        s.x[3 * i] = (1 + e) * s.X[3 * i];
    cf_tet4_forces(&s, &t, 1, CF_ELASTICITY_COROTATIONAL, NULL, 0, NULL);
    double sigma[9];
    cf_tet4_stress(&s, 0, CF_ELASTICITY_COROTATIONAL, sigma);
    assert_near(sigma[0] - sigma[4], -sc, 1e-9 * sc);
    assert_near(sigma[4], sigma[8], 1e-9 * sc);
    assert_near((sigma[0] + sigma[4] + sigma[8]) / 3, K * e, 1e-9 * sc);
    double w_closed = 2.0 / 3.0 * sc * (fabs(e) - ey) * V;
    assert_near(s.wp[0], w_closed, 1e-9 * w_closed);
    /* strain energy: the elastic part only, 1/2 sigma : (eps - eps_p) V */
    assert_near(s.tw[0], 0.5 * V * (K * e * e + sc * sc / (3 * s.mu)), 1e-9 * s.tw[0]);
    cf_tet4_forces(&s, &t, 1, CF_ELASTICITY_COROTATIONAL, NULL, 0, NULL);
    assert_near(s.wp[0], w_closed, 1e-9 * w_closed); /* on the surface: no more flow */
    for (int i = 0; i < 4; i++) /* unloading by 1.5 e_y (< 2 e_y): elastic */
        s.x[3 * i] = (1 + e / 2) * s.X[3 * i];
    cf_tet4_forces(&s, &t, 1, CF_ELASTICITY_COROTATIONAL, NULL, 0, NULL);
    cf_tet4_stress(&s, 0, CF_ELASTICITY_COROTATIONAL, sigma);
    assert_near(s.wp[0], w_closed, 1e-9 * w_closed);
    assert_near(sigma[0] - sigma[4], 0.5 * sc, 1e-9 * sc);
    cf_tet4_to_rigid(&s, &t, 1);
    for (int i = 0; i < 4; i++)
        memcpy(&s.x[3 * i], &s.X[3 * i], 3 * sizeof(double));
    cf_tet4_forces(&s, &t, 1, CF_ELASTICITY_COROTATIONAL, NULL, 0, NULL);
    assert_near(s.wp[0], w_closed, 1e-9 * w_closed); /* the work done stays booked */
    assert_near(s.tw[0], 0.0, 1e-20);
    cf_solid_free(&s);
}

/* Linear bulk viscosity (docs/physics.md §2.3): a tet turned rigidly by
 * R (stress free) whose nodes move with the velocity a (x - c) + w x (x - c),
 * a uniform dilatation rate and a spin, has the volumetric strain rate
 * D = 3a, whatever the spin, and carries the viscous pressure -eta D with
 * eta = b1 rho c_d h, h = 6 V / (face area): the force on node a is
 * -V eta D R grad N_a, and the forces take V eta D^2 of power.  The
 * work booked over a step of length dt is the leapfrog's trapezoid,
 * 1/2 V eta dt (D' D + D^2) with D' the last pass's rate: 1/2 V eta dt D^2
 * at the first pass, V eta dt D^2 more at the second; a rigid motion alone
 * takes nothing, and the check's stress stays the material's (zero). */
static void test_bulk_viscosity_of_a_dilatation(void **state)
{
    (void)state;
    cf_material mat = material(5e9, 0.2, 1200);
    cf_solid s;
    one_tet(&s, skew, &mat);
    double b1 = 0.06, R[9], q[4] = {cos(0.2), sin(0.2) * 0.6, sin(0.2) * 0.0, sin(0.2) * 0.8};
    quat_to_mat(q, R);
    assert_int_equal(cf_solid_init_bulk_viscosity(&s, b1, NULL), CF_OK);
    double c_d = sqrt((s.lambda + 2 * s.mu) / mat.rho), V = s.vol[0];
    double area = 0;
    for (int k = 0; k < 4; k++) { /* the faces opposite each corner */
        const double *a = skew[(k + 1) % 4], *b = skew[(k + 2) % 4], *c = skew[(k + 3) % 4];
        double e1[3], e2[3], n[3];
        v3_sub(b, a, e1), v3_sub(c, a, e2), v3_cross(e1, e2, n);
        area += 0.5 * v3_norm(n);
    }
    double eta = b1 * mat.rho * c_d * 6 * V / area;
    assert_near(s.bv_eta[0], eta, 1e-12 * eta);
    double rate = 40, spin[3] = {30, -20, 50}, c[3] = {0.4, 0.4, 0.35}, D = 3 * rate, dt = 1e-7;
    for (int i = 0; i < 4; i++) {
        double r[3], w[3];
        v3_sub(skew[i], c, r);
        m3_mulv(R, r, w); /* turned about c */
        for (int k = 0; k < 3; k++)
            s.x[3 * i + k] = c[k] + w[k], r[k] = w[k];
        v3_cross(spin, r, w);
        for (int k = 0; k < 3; k++)
            s.v[3 * i + k] = rate * r[k] + w[k];
    }
    int t = 0;
    double g[4][3];
    cf_tet4_gradients(&s, 0, g);
    cf_tet4_forces(&s, &t, 1, CF_ELASTICITY_COROTATIONAL, NULL, dt, NULL);
    double power = 0, scale = V * eta * D * 10;
    for (int a = 0; a < 4; a++) {
        double Rg[3];
        m3_mulv(R, g[a], Rg);
        for (int k = 0; k < 3; k++)
            assert_near(s.tf[3 * a + k], -V * eta * D * Rg[k], 1e-5 * scale);
        power += v3_dot(&s.tf[3 * a], &s.v[3 * a]);
    }
    assert_near(power, -V * eta * D * D, 1e-4 * V * eta * D * D);
    assert_near(s.bv_rate[0], D, 1e-4 * D);
    double w1 = 0.5 * V * eta * dt * D * D;
    assert_near(s.bv_work[0], w1, 1e-4 * w1);
    cf_tet4_forces(&s, &t, 1, CF_ELASTICITY_COROTATIONAL, NULL, dt, NULL);
    assert_near(s.bv_work[0], 3 * w1, 3e-4 * w1);
    double sigma[9];
    cf_tet4_stress(&s, 0, CF_ELASTICITY_COROTATIONAL, sigma);
    for (int k = 0; k < 9; k++)
        assert_near(sigma[k], 0.0, 1e-6 * eta * D);
    /* the spin alone: no force, no work (the rotation found to its
     * tolerance, 1e-7, leaves a rate of 1e-5 of the spin) */
    for (int i = 0; i < 4; i++) {
        double r[3];
        v3_sub(&s.x[3 * i], c, r);
        v3_cross(spin, r, &s.v[3 * i]);
    }
    cf_tet4_to_rigid(&s, &t, 1); /* a hand-off: the last rate is zeroed */
    assert_near(s.bv_rate[0], 0.0, 0.0);
    cf_tet4_forces(&s, &t, 1, CF_ELASTICITY_COROTATIONAL, NULL, dt, NULL);
    for (int k = 0; k < 12; k++)
        assert_near(s.tf[k], 0.0, 1e-6 * scale);
    assert_near(s.bv_work[0], 3 * w1, 3e-4 * w1);
    cf_solid_free(&s);
}

/* Drucker-Prager crushing (docs/physics.md §2.1): with an internal
 * friction angle phi the yield stress grows with the pressure p,
 * q = k + beta p, beta = 6 sin phi / (3 - sin phi), k = sigma_c (1 - beta/3).
 * In uniaxial strain to ten times von Mises' yield strain the pressure
 * stays K |e| (the return keeps the volume), so sigma_xx - sigma_yy =
 * -(k + beta K |e|), far above sigma_c, and the plastic work is the removed
 * deviator's; in pure shear (p = 0) the tet yields at k / sqrt(3) < sigma_c
 * / sqrt(3). */
static void test_crushing_grows_with_pressure(void **state)
{
    (void)state;
    cf_material mat = material(5e9, 0.2, 1200);
    mat.compressive_strength = 15e6;
    mat.internal_friction_angle = 30;
    cf_solid s;
    one_tet(&s, skew, &mat);
    double sc = mat.compressive_strength, beta = 6 * 0.5 / (3 - 0.5), k = sc * (1 - beta / 3);
    double K = s.lambda + 2 * s.mu / 3, V = s.vol[0], e = -10 * sc / (2 * s.mu);
    assert_near(s.crush_beta, beta, 1e-12);
    assert_near(s.crush_k, k, 1e-6);
    int t = 0;
    for (int i = 0; i < 4; i++)
        s.x[3 * i] = (1 + e) * s.X[3 * i];
    cf_tet4_forces(&s, &t, 1, CF_ELASTICITY_COROTATIONAL, NULL, 0, NULL);
    double sigma[9], q = k + beta * K * fabs(e);
    cf_tet4_stress(&s, 0, CF_ELASTICITY_COROTATIONAL, sigma);
    assert_near(sigma[0] - sigma[4], -q, 1e-9 * q);
    assert_near((sigma[0] + sigma[4] + sigma[8]) / 3, K * e, 1e-9 * sc);
    /* the trial deviator's equivalent stress is q_t = 2 mu |e|; the return
     * scales it to q, and the work (q / q_t)(1 - q / q_t) s:s / 2 mu with
     * s:s = 2/3 q_t^2 is q (q_t - q) / 3 mu */
    double q_trial = 2 * s.mu * fabs(e), w_closed = q * (q_trial - q) / (3 * s.mu) * V;
    assert_near(s.wp[0], w_closed, 1e-9 * w_closed);
    printf("FIGURE Drucker-Prager: phi 30 deg, uniaxial strain %.3g: q %.4g MPa (von Mises %.4g)\n",
           e, q / 1e6, sc / 1e6);
    cf_solid_free(&s);
    /* pure shear, no pressure: yields at k / sqrt(3) */
    one_tet(&s, skew, &mat);
    double g = 2 * (k / sqrt(3)) / s.mu; /* engineering shear strain, twice the yield */
    for (int i = 0; i < 4; i++)
        s.x[3 * i] = s.X[3 * i] + g * s.X[3 * i + 1];
    cf_tet4_forces(&s, &t, 1, CF_ELASTICITY_LINEAR, NULL, 0, NULL);
    cf_tet4_stress(&s, 0, CF_ELASTICITY_LINEAR, sigma);
    assert_near(sigma[1], k / sqrt(3), 1e-9 * k);
    assert_true(s.wp[0] > 0);
    cf_solid_free(&s);
}

/* Without compressive_strength the solid keeps no plastic state. */
static void test_no_crushing_no_plastic_state(void **state)
{
    (void)state;
    cf_material mat = material(5e9, 0.2, 1200);
    cf_solid s;
    one_tet(&s, skew, &mat);
    assert_null(s.ep);
    assert_null(s.wp);
    cf_solid_free(&s);
}

/* The strain energy of tet 0 at nodal positions x (m) with the plastic
 * strain ep (Voigt, tensor shear), J: V (mu e:e + lambda/2 (tr e)^2) with
 * e = U - I - ep, U the stretch of the exact polar decomposition, from the
 * eigenvectors of F^T F (not the kernel's iteration). */
static double plastic_energy(const cf_solid *s, const double x[12], const double ep[6])
{
    double Ds[9], F[9], C[9], w[3], V[9], e[9], E[9] = {ep[0], ep[3], ep[4], ep[3], ep[1],
                                                         ep[5], ep[4], ep[5], ep[2]};
    for (int j = 0; j < 3; j++)
        for (int r = 0; r < 3; r++)
            Ds[3 * r + j] = x[3 * (j + 1) + r] - x[r];
    m3_mul(Ds, s->Dm_inv, F);
    m3_mul_tn(F, F, C);
    sym3_eigen(C, w, V);
    double tr = 0, ee = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double u = 0;
            for (int k = 0; k < 3; k++)
                u += V[3 * i + k] * sqrt(w[k]) * V[3 * j + k];
            e[3 * i + j] = u - (i == j) - E[3 * i + j];
        }
    for (int k = 0; k < 9; k++)
        ee += e[k] * e[k];
    tr = e[0] + e[4] + e[8];
    return s->vol[0] * (s->mu * ee + 0.5 * s->lambda * tr * tr);
}

/* A tet with a plastic strain (crushing, docs/physics.md §2.1) in another
 * direction than its elastic strain, turned by 0.9 rad and inside its
 * yield surface (so nothing flows): its nodal forces are minus the
 * gradient of its strain energy (central differences of the energy with
 * an exact polar decomposition, plastic_energy) and carry no moment,
 * sum x_a x f_a = 0.  The forces of R sigma alone, without the spin, miss
 * the gradient by the figure printed and hold a moment. */
static void test_plastic_forces_are_the_energy_gradient(void **state)
{
    (void)state;
    cf_material mat = material(5e9, 0.2, 1200);
    mat.compressive_strength = 15e6;
    cf_solid s;
    one_tet(&s, skew, &mat);
    assert_non_null(s.ep);
    static const double ep[6] = {0.02, -0.012, -0.008, 0.015, 0.0, 0.009}; /* Voigt, tensor */
    memcpy(s.ep, ep, sizeof ep);
    double U[9] = {1 + ep[0] + 4e-4, ep[3] - 3e-4, ep[4] + 5e-4, ep[3] - 3e-4, 1 + ep[1] - 2e-4,
                   ep[5] + 1e-4, ep[4] + 5e-4, ep[5] + 1e-4, 1 + ep[2] + 6e-4};
    double q[4] = {cos(0.45), sin(0.45) * 0.36, sin(0.45) * 0.48, sin(0.45) * 0.8}, R[9], F[9];
    quat_to_mat(q, R);
    m3_mul(R, U, F); /* x = F X: the stretch U, turned */
    for (int i = 0; i < 4; i++)
        m3_mulv(F, &s.X[3 * i], &s.x[3 * i]);
    int t = 0;
    for (int pass = 0; pass < 8; pass++) /* the polar rotation's warm start converges */
        cf_tet4_forces(&s, &t, 1, CF_ELASTICITY_COROTATIONAL, NULL, 0, NULL);
    assert_true(s.wp[0] == 0); /* inside the yield surface */
    assert_near(s.tw[0], plastic_energy(&s, s.x, ep), 1e-5 * s.tw[0]);
    double f[12], fn[12], fbig = 0, err = 0, err_naive = 0, h = 1e-6;
    memcpy(f, s.tf, sizeof f);
    for (int k = 0; k < 12; k++)
        fbig = fbig > fabs(f[k]) ? fbig : fabs(f[k]);
    /* the forces of R sigma alone: -V sigma_world R grad N_a */
    double sw[9], Rq[9], qn[4], g[4][3];
    cf_tet4_stress(&s, 0, CF_ELASTICITY_COROTATIONAL, sw);
    memcpy(qn, &s.rq[0], sizeof qn);
    quat_normalize(qn);
    quat_to_mat(qn, Rq);
    cf_tet4_gradients(&s, 0, g);
    for (int a = 0; a < 4; a++) {
        double rg[3], fa[3];
        m3_mulv(Rq, g[a], rg);
        m3_mulv(sw, rg, fa);
        for (int c = 0; c < 3; c++)
            fn[3 * a + c] = -s.vol[0] * fa[c];
    }
    for (int k = 0; k < 12; k++) {
        double x[12], w[2];
        memcpy(x, s.x, sizeof x);
        for (int side = 0; side < 2; side++) {
            x[k] = s.x[k] + (side ? h : -h);
            w[side] = plastic_energy(&s, x, ep);
        }
        double grad = (w[1] - w[0]) / (2 * h);
        err = fmax(err, fabs(f[k] + grad));
        err_naive = fmax(err_naive, fabs(fn[k] + grad));
    }
    double M[3] = {0, 0, 0}, Mn[3] = {0, 0, 0}, scale = 0;
    for (int a = 0; a < 4; a++) {
        double m[3], mn[3];
        v3_cross(&s.x[3 * a], &f[3 * a], m);
        v3_cross(&s.x[3 * a], &fn[3 * a], mn);
        for (int c = 0; c < 3; c++)
            M[c] += m[c], Mn[c] += mn[c];
        scale = fmax(scale, v3_norm(&s.x[3 * a]) * fbig);
    }
    printf("FIGURE plastic tet: forces against the energy's gradient %.2e of the largest force "
           "(R sigma alone: %.2e); moment %.2e (%.2e) of |x| |f|\n",
           err / fbig, err_naive / fbig, v3_norm(M) / scale, v3_norm(Mn) / scale);
    assert_true(err <= 1e-5 * fbig); /* the rotation iteration's tolerance, 1e-7 */
    assert_true(err_naive >= 1e-3 * fbig); /* the test tells the two apart */
    assert_true(v3_norm(M) <= 1e-6 * scale);
    assert_true(v3_norm(Mn) >= 1e-3 * scale);
    cf_solid_free(&s);
}

/* A rigid rotation makes no corotational stress; small strain sees a spurious one. */
static void test_rigid_rotation_is_stress_free(void **state)
{
    (void)state;
    cf_material mat = material(1e6, 0.3, 1000);
    cf_solid s;
    one_tet(&s, skew, &mat);
    double q[4] = {cos(0.6), sin(0.6) / sqrt(3), sin(0.6) / sqrt(3), sin(0.6) / sqrt(3)}, R[9];
    quat_to_mat(q, R);
    for (int i = 0; i < 4; i++)
        m3_mulv(R, &s.X[3 * i], &s.x[3 * i]);
    int t = 0;
    cf_tet4_forces(&s, &t, 1, CF_ELASTICITY_COROTATIONAL, NULL, 0, NULL);
    for (int k = 0; k < 12; k++)
        assert_near(s.tf[k], 0.0, 1e-9 * s.mu * s.vol[0]);
    cf_tet4_forces(&s, &t, 1, CF_ELASTICITY_LINEAR, NULL, 0, NULL);
    double fmax = 0;
    for (int k = 0; k < 12; k++)
        fmax = fmax > fabs(s.tf[k]) ? fmax : fabs(s.tf[k]);
    assert_true(fmax > 1e-3 * s.mu * s.vol[0]);
    cf_solid_free(&s);
}

/* The reference for one tet at a time: the scalar formulas of linalg.h in
 * the order the kernel's comments give (F = Ds Dm^-1, the quaternion
 * polar iteration from the warm start q, Hooke on sym(R^T F) - I,
 * f_a = -V R sigma grad N_a, sigma_world = R sigma R^T); q is updated. */
static void one_tet_at_a_time(const cf_solid *s, int t, cf_elasticity kind, double q[4],
                              double f[12], double *w, double sigma[9])
{
    const int *T = &s->tet[4 * t];
    double Ds[9], F[9], R[9], S[9], eps[9], sig[9], P[9], g[4][3];
    for (int j = 0; j < 3; j++)
        for (int r = 0; r < 3; r++)
            Ds[3 * r + j] = s->x[3 * T[j + 1] + r] - s->x[3 * T[0] + r];
    m3_mul(Ds, &s->Dm_inv[9 * t], F);
    if (kind == CF_ELASTICITY_COROTATIONAL) {
        polar_rotation(F, q, 10, 1e-7, R);
        m3_mul_tn(R, F, S);
    } else {
        m3_identity(R);
        memcpy(S, F, sizeof S);
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            eps[3 * i + j] = 0.5 * (S[3 * i + j] + S[3 * j + i]) - (i == j);
    double tr = eps[0] + eps[4] + eps[8];
    *w = 0;
    for (int k = 0; k < 9; k++) {
        sig[k] = 2 * s->mu * eps[k] + ((k % 4) == 0 ? s->lambda * tr : 0);
        *w += 0.5 * sig[k] * eps[k];
    }
    m3_mul(R, sig, P);
    cf_tet4_gradients(s, t, g);
    for (int a = 0; a < 4; a++) {
        double fa[3];
        m3_mulv(P, g[a], fa);
        for (int c = 0; c < 3; c++)
            f[3 * a + c] = -s->vol[t] * fa[c];
    }
    m3_mul_nt(P, R, sigma);
}

/* The force kernel runs four tets side by side in vector lanes; every
 * lane must give the bits of the scalar formulas for its tet alone, with
 * the lanes' rotation iterations needing different numbers of steps (warm
 * starts from exact to 0.5 rad off, and one of zero length), for a list
 * whose last block is partial, both elasticity kinds. */
static void test_lanes_equal_one_tet_at_a_time(void **state)
{
    (void)state;
    cf_mesh m;
    cf_solid s;
    int *body;
    box_solid(&s, &m, &body, 3, 0.3, 1000);
    s.sigma = calloc((size_t)s.n_tets * 9, sizeof(double));
    s.hot = calloc((size_t)s.n_tets, 1);
    unsigned long long r = 12345;
    double qr[4] = {cos(0.4), sin(0.4) * 0.48, sin(0.4) * 0.6, sin(0.4) * 0.64}, R[9];
    quat_to_mat(qr, R);
    for (int i = 0; i < s.n_nodes; i++) { /* rotated 0.8 rad, strained by up to 5 % */
        double y[3];
        for (int k = 0; k < 3; k++) {
            r = r * 6364136223846793005ull + 1442695040888963407ull;
            y[k] = s.X[3 * i + k] * (1 + 0.05 * ((double)(r >> 11) / 9007199254740992.0 - 0.5));
        }
        m3_mulv(R, y, &s.x[3 * i]);
    }
    int nt = s.n_tets - 3, *list = malloc((size_t)nt * sizeof(int));
    for (int i = 0; i < nt; i++)
        list[i] = (7 * i) % s.n_tets; /* not in order, and tets of many blocks */
    assert_int_equal(nt % 4 != 0, 1);
    for (int kind = 0; kind < 2; kind++) {
        cf_elasticity el = kind ? CF_ELASTICITY_LINEAR : CF_ELASTICITY_COROTATIONAL;
        double *q0 = malloc((size_t)s.n_tets * 4 * sizeof(double));
        for (int t = 0; t < s.n_tets; t++) {
            double a = 0.4 - 0.5 * (t % 5) / 4.0; /* 0.4 exact ... -0.1: 0.5 rad off */
            double qt[4] = {cos(a), sin(a) * 0.48, sin(a) * 0.6, sin(a) * 0.64};
            if (t % 11 == 3)
                qt[0] = qt[1] = qt[2] = qt[3] = 0; /* zero length: the identity */
            memcpy(&s.rq[4 * t], qt, sizeof qt);
            memcpy(&q0[4 * t], qt, sizeof qt);
        }
        cf_stress_check check = {INFINITY, INFINITY, NULL};
        cf_tet4_forces(&s, list, nt, el, &check, 0, NULL);
        for (int i = 0; i < nt; i++) {
            int t = list[i];
            double f[12], w, sigma[9], sigma_one[9];
            one_tet_at_a_time(&s, t, el, &q0[4 * t], f, &w, sigma);
            assert_memory_equal(&s.tf[12 * t], f, sizeof f);
            double tw = w * s.vol[t];
            assert_memory_equal(&s.tw[t], &tw, sizeof tw);
            assert_memory_equal(&s.sigma[9 * t], sigma, sizeof sigma);
            if (el == CF_ELASTICITY_COROTATIONAL)
                assert_memory_equal(&s.rq[4 * t], &q0[4 * t], 4 * sizeof(double));
            cf_tet4_stress(&s, t, el, sigma_one); /* one tet, from the updated warm start */
            one_tet_at_a_time(&s, t, el, &q0[4 * t], f, &w, sigma);
            assert_memory_equal(sigma_one, sigma, sizeof sigma);
        }
        free(q0);
    }
    free(list), free(s.sigma), free(s.hot);
    s.sigma = NULL, s.hot = NULL;
    cf_solid_free(&s), cf_mesh_free(&m), free(body);
}

/* dt_cfl = 2 r_in / c_d: for a regular tet of edge a, 2 r_in = a / sqrt(6). */
static void test_cfl_of_regular_tet(void **state)
{
    (void)state;
    double a = 0.01;
    const double x[4][3] = {{0, 0, 0}, {a, 0, 0}, {a / 2, a * sqrt(3) / 2, 0},
                            {a / 2, a * sqrt(3) / 6, a * sqrt(2.0 / 3.0)}};
    cf_material mat = material(70e9, 0.22, 2500);
    cf_solid s;
    one_tet(&s, x, &mat);
    double cd = sqrt(70e9 * 0.78 / (2500 * 1.22 * 0.56));
    assert_near(s.dt_cfl, a / sqrt(6.0) / cd, 1e-9 * s.dt_cfl);
    cf_solid_free(&s);
}

/* Mass scaling (docs/physics.md §3.2): a box whose lowest layer
 * of cells is 200 times thinner than the rest has its step set by that
 * layer's tets.  With a floor of 0.5, every tet whose step h / c_d lies
 * below half the median's gets the density (floor dt_median / dt)^2 rho,
 * which puts its step exactly at the floor; the others keep rho; dt_cfl
 * becomes that floor; and the lumped masses add up to the scaled tets'
 * masses, the added mass reported to round-off. */
static void test_mass_scaling_lifts_the_thin_tets(void **state)
{
    (void)state;
    cf_mesh m;
    cf_solid s;
    int *body;
    fixture_box(&m, 3, 2, 4, 0.3, 0.2, 0.5);
    for (int i = 0; i < m.n_nodes; i++) /* the first layer of nodes above z = 0 */
        if (fabs(m.x[3 * i + 2] - 0.125) < 1e-9)
            m.x[3 * i + 2] = 0.125 / 200;
    body = calloc((size_t)m.n_tets, sizeof(int));
    cf_material mat = material(1e6, 0.3, 2400);
    assert_int_equal(cf_solid_init(&s, &m, &mat, body, NULL), CF_OK);
    int nt = s.n_tets;
    double cd = sqrt(1e6 * 0.7 / (2400 * 1.3 * 0.4)), *dt = malloc((size_t)nt * sizeof(double)),
           *sorted = malloc((size_t)nt * sizeof(double));
    for (int t = 0; t < nt; t++) { /* h = 6 V / total face area */
        const double *x[4];
        for (int j = 0; j < 4; j++)
            x[j] = &s.X[3 * s.tet[4 * t + j]];
        double area = 0;
        for (int k = 0; k < 4; k++) {
            double e1[3], e2[3], n[3];
            v3_sub(x[CF_TET_FACE[k][1]], x[CF_TET_FACE[k][0]], e1);
            v3_sub(x[CF_TET_FACE[k][2]], x[CF_TET_FACE[k][0]], e2);
            v3_cross(e1, e2, n);
            area += 0.5 * v3_norm(n);
        }
        dt[t] = sorted[t] = 6 * s.vol[t] / area / cd;
    }
    cf_doubles_sort(sorted, nt);
    double least = 0.5 * sorted[nt / 2];
    assert_true(s.dt_cfl < 0.1 * least); /* the thin layer sets the step */
    assert_int_equal(cf_solid_scale_mass(&s, 0.5, NULL), CF_OK);
    assert_near(s.dt_cfl, least, 1e-12 * least);
    int scaled = 0;
    double added = 0, M = 0;
    for (int t = 0; t < nt; t++) {
        double scale = s.mass_scale[t];
        if (dt[t] < least) {
            assert_near(dt[t] * sqrt(scale), least, 1e-12 * least);
            added += (scale - 1) * 2400 * s.vol[t], scaled++;
        } else {
            assert_true(scale == 1.0);
        }
    }
    for (int i = 0; i < s.n_nodes; i++)
        M += s.m[i];
    printf("FIGURE mass scaling: %d of %d tets scaled, %.4g kg added to %.4g kg\n", scaled, nt,
           added, M);
    assert_int_equal(scaled, s.n_mass_scaled);
    assert_true(scaled > 0 && scaled < nt / 2);
    assert_near(s.mass_added, added, 1e-12 * added);
    assert_near(M, 2400 * 0.3 * 0.2 * 0.5 + added, 1e-12 * M);
    free(dt), free(sorted), free(body);
    cf_solid_free(&s), cf_mesh_free(&m);
}

/* The strain energy of many tets is summed on the threads in chunks cut by
 * the count alone (chunks.h): the same bits for 1, 2 and 3 threads, with
 * terms whose sum depends on the order (magnitudes 2^-30 to 2^30: the halves'
 * sums added give other bits than the list order, checked here, so a sum
 * that followed the threads would fail), and the list-order sum itself
 * for a list of one chunk. */
static void test_strain_energy_same_bits_for_any_thread_count(void **state)
{
    (void)state;
    int n = 100003;
    double *tw = malloc((size_t)n * sizeof(double));
    int *tets = malloc((size_t)n * sizeof(int));
    assert_non_null(tw);
    assert_non_null(tets);
    for (int i = 0; i < n; i++) {
        tw[i] = ldexp(1.0 + (i % 1000) * 1e-3, (i * 37) % 60 - 30) * (i % 3 ? 1 : -1);
        tets[i] = n - 1 - i; /* the list order is not the tet order */
    }
    cf_solid s;
    memset(&s, 0, sizeof s);
    s.tw = tw;
    double e[3], halves[2] = {0, 0}, in_order = 0;
    for (int k = 0; k < 3; k++) {
        omp_set_num_threads(k + 1);
        e[k] = cf_tet4_strain_energy(&s, tets, n);
    }
    assert_memory_equal(&e[0], &e[1], sizeof(double));
    assert_memory_equal(&e[0], &e[2], sizeof(double));
    for (int i = 0; i < n; i++)
        halves[i >= n / 2] += tw[tets[i]];
    assert_true(halves[0] + halves[1] != e[0]);
    for (int i = 0; i < CF_CHUNK_MIN; i++)
        in_order += tw[tets[i]];
    double one_chunk = cf_tet4_strain_energy(&s, tets, CF_CHUNK_MIN);
    assert_memory_equal(&one_chunk, &in_order, sizeof(double));
    free(tw), free(tets);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gradients_reproduce_linear_fields),
        cmocka_unit_test(test_lumped_mass_of_box),
        cmocka_unit_test(test_uniaxial_stretch_corotational),
        cmocka_unit_test(test_uniaxial_stretch_linear),
        cmocka_unit_test(test_rigid_rotation_is_stress_free),
        cmocka_unit_test(test_plastic_forces_are_the_energy_gradient),
        cmocka_unit_test(test_crushing_uniaxial_strain),
        cmocka_unit_test(test_crushing_grows_with_pressure),
        cmocka_unit_test(test_bulk_viscosity_of_a_dilatation),
        cmocka_unit_test(test_no_crushing_no_plastic_state),
        cmocka_unit_test(test_lanes_equal_one_tet_at_a_time),
        cmocka_unit_test(test_cfl_of_regular_tet),
        cmocka_unit_test(test_mass_scaling_lifts_the_thin_tets),
        cmocka_unit_test(test_strain_energy_same_bits_for_any_thread_count),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
