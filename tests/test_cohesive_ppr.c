/* The extrinsic PPR law: values at known openings, work of separation,
 * unloading to the origin, complete failure. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "check.h"

#include "cohesive_ppr.h"

#include <math.h>

static cf_ppr law(double GI, double GII, double smax, double tmax, double alpha, double beta)
{
    cf_material m = {1e6, 0.3, 2400, GI, GII, smax, tmax, alpha, beta, 0.5, 0, 0, 10, 1, 0, 0, 0, 0, 0, 0, 0};
    cf_ppr p;
    cf_ppr_init(&p, &m);
    return p;
}

static void test_traction_at_known_openings(void **state)
{
    (void)state;
    cf_ppr p = law(22, 22, 1e4, 1e4, 2, 2);
    double Tn, Tt;
    assert_near(p.delta_n, 2 * 22 / 1e4, 1e-15);
    cf_ppr_envelope(&p, 0, 0, &Tn, &Tt);
    assert_near(Tn, 1e4, 1e-9);
    assert_near(Tt, 1e4, 1e-9); /* magnitude tau_max; its direction comes from the opening */
    cf_ppr_envelope(&p, p.delta_n / 2, 0, &Tn, &Tt); /* alpha = 2: linear softening */
    assert_near(Tn, 0.5e4, 1e-9);
    cf_ppr p3 = law(22, 22, 1e4, 1e4, 3, 3);
    cf_ppr_envelope(&p3, p3.delta_n / 2, 0, &Tn, &Tt); /* (1 - 1/2)^2 */
    assert_near(Tn, 0.25e4, 1e-9);
    cf_ppr_envelope(&p, p.delta_n * 1.0001, 0, &Tn, &Tt);
    assert_near(Tn, 0.0, 0.0);
}

/* int_0^delta T dDelta = G: mode I with T_n, mode II with T_t (Simpson). */
static double work(const cf_ppr *p, int mode)
{
    int n = 20000;
    double L = mode == 1 ? p->delta_n : p->delta_t, h = L / n, acc = 0;
    for (int i = 0; i <= n; i++) {
        double Tn, Tt, d = i * h;
        cf_ppr_envelope(p, mode == 1 ? d : 0, mode == 1 ? 0 : d, &Tn, &Tt);
        double T = mode == 1 ? Tn : Tt;
        acc += T * ((i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2));
    }
    return acc * h / 3;
}

static void test_mode_I_work_equals_GI(void **state)
{
    (void)state;
    double alphas[] = {1.5, 2, 3, 5};
    for (int i = 0; i < 4; i++) {
        cf_ppr p = law(22, 30, 1e4, 2e4, alphas[i], 2);
        assert_near(work(&p, 1), 22.0, 22.0 * 1e-6);
    }
}

static void test_mode_II_work_equals_GII(void **state)
{
    (void)state;
    cf_ppr p = law(22, 40, 1e4, 2e4, 2, 3);
    assert_near(work(&p, 2), 40.0, 40.0 * 1e-6);
    cf_ppr q = law(50, 40, 1e4, 2e4, 2, 3); /* phi_n > phi_t branch */
    assert_near(work(&q, 2), 40.0, 40.0 * 1e-6);
    assert_near(work(&q, 1), 50.0, 50.0 * 1e-6);
}

/* A facet of strength w sigma_max (material.strength): traction w sigma_max
 * at zero opening, the same fracture energies in both modes and branches. */
static void test_scaled_law_keeps_fracture_energy(void **state)
{
    (void)state;
    double ws[] = {0.3, 0.8, 1.7};
    for (int i = 0; i < 3; i++) {
        cf_ppr base[2] = {law(22, 40, 1e4, 2e4, 2, 3), law(50, 40, 1e4, 2e4, 3, 2)}, p;
        for (int b = 0; b < 2; b++) {
            cf_ppr_scaled(&base[b], ws[i], &p);
            double Tn, Tt;
            cf_ppr_envelope(&p, 0, 0, &Tn, &Tt);
            assert_near(Tn, ws[i] * base[b].sigma_max, 1e-9 * base[b].sigma_max);
            assert_near(work(&p, 1), base[b].phi_n, base[b].phi_n * 1e-6);
            assert_near(work(&p, 2), base[b].phi_t, base[b].phi_t * 1e-6);
        }
    }
}

/* Unloading goes linearly to the origin; reloading retraces it; failure is final. */
static void test_unloading_and_failure(void **state)
{
    (void)state;
    cf_ppr p = law(22, 22, 1e4, 1e4, 2, 2);
    double dn_max = 0, dt_max = 0, Tn, Tt, Tpeak;
    unsigned char failed = 0;
    double d1 = 0.4 * p.delta_n;
    cf_ppr_traction(&p, d1, 0, &dn_max, &dt_max, &failed, &Tpeak, &Tt);
    assert_near(Tpeak, 1e4 * 0.6, 1e-9);
    cf_ppr_traction(&p, d1 / 2, 0, &dn_max, &dt_max, &failed, &Tn, &Tt);
    assert_near(Tn, Tpeak / 2, 1e-9);
    assert_near(dn_max, d1, 0);
    cf_ppr_traction(&p, 0.7 * p.delta_n, 0, &dn_max, &dt_max, &failed, &Tn, &Tt);
    assert_near(Tn, 1e4 * 0.3, 1e-9);
    assert_int_equal(failed, 0);
    cf_ppr_traction(&p, 1.01 * p.delta_n, 0, &dn_max, &dt_max, &failed, &Tn, &Tt);
    assert_int_equal(failed, 1);
    cf_ppr_traction(&p, 0.1 * p.delta_n, 0, &dn_max, &dt_max, &failed, &Tn, &Tt);
    assert_near(Tn, 0.0, 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_traction_at_known_openings),
        cmocka_unit_test(test_mode_I_work_equals_GI),
        cmocka_unit_test(test_mode_II_work_equals_GII),
        cmocka_unit_test(test_unloading_and_failure),
        cmocka_unit_test(test_scaled_law_keeps_fracture_energy),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
