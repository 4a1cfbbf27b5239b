/* Extrinsic insertion and node duplication: topology, masses, momentum. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "check.h"
#include "chunks.h"
#include "cohesive.h"
#include "cohesive_law.h"
#include "cohesive_ppr.h"

#include "fixtures.h"
#include "pieces.h"
#include "insertion.h"
#include "linalg.h"
#include "pbd.h"
#include "tet4.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

static const cf_material mat = {1e6, 0.3, 2400, 22, 22, 1e3, 1e3, 2, 2, 0.5, 0, 0, 10, 1, 0, 0, 0, 0, 0, 0, 0};

/* K_cap of the cracked two-tet fixture's node pairs (cohesive.h), Pa/m:
 * facet A = 0.5 m^2, node copies of 100 kg, the step of `press`, 0.1 ms. */
static const double fixture_kcap = 3.0 / (4.0 * 0.5 * 1e-8 * (1.0 / 100 + 1.0 / 100));

/* The solid of mesh m in material ma. */
static void init_in(cf_solid *s, cf_mesh *m, const cf_material *ma)
{
    int *body = calloc((size_t)m->n_tets, sizeof(int));
    assert_int_equal(cf_solid_init(s, m, ma, body, NULL), CF_OK);
    assert_int_equal(cf_solid_init_facets(s, NULL), CF_OK);
    free(body);
    for (int i = 0; i < s->n_nodes; i++) /* a non-uniform velocity field */
        for (int k = 0; k < 3; k++)
            s->v[3 * i + k] = sin(1.0 + 3.7 * i + k) + 0.1 * k;
}

static void init(cf_solid *s, cf_mesh *m)
{
    init_in(s, m, &mat);
}

static void momentum(const cf_solid *s, double P[3], double *M)
{
    P[0] = P[1] = P[2] = 0, *M = 0;
    for (int i = 0; i < s->n_nodes; i++) {
        *M += s->m[i];
        v3_axpy(s->m[i], &s->v[3 * i], P);
    }
}

static int components(const cf_solid *s)
{
    int *all = malloc((size_t)s->n_tets * sizeof(int)), *comp = malloc((size_t)s->n_tets * sizeof(int));
    for (int t = 0; t < s->n_tets; t++)
        all[t] = t;
    int k = cf_label_components(s, all, s->n_tets, comp);
    free(all), free(comp);
    return k;
}

/* Cracking the one shared facet of two tets gives two fragments, three new
 * nodes, masses rho V/4 per tet, and conserves momentum. */
static void test_two_tets_split_into_two_fragments(void **state)
{
    (void)state;
    cf_mesh m;
    fixture_two_tets(&m);
    cf_solid s;
    init(&s, &m);
    assert_int_equal(components(&s), 1);
    double P0[3], M0, P1[3], M1;
    momentum(&s, P0, &M0);
    int f = -1;
    for (int i = 0; i < s.n_facets; i++)
        if (s.facet[4 * i + 2] >= 0)
            f = i;
    assert_true(f >= 0);
    cf_int_list nodes = {0}, touched = {0};
    assert_int_equal(cf_crack_facet(&s, f, &nodes, &touched), 0);
    assert_int_equal(s.n_nodes, 8);
    assert_int_equal(nodes.n, 3);
    assert_int_equal(s.n_coh, 1);
    assert_int_equal(components(&s), 2);
    momentum(&s, P1, &M1);
    assert_near(M1, M0, 1e-15 * M0);
    for (int k = 0; k < 3; k++)
        assert_near(P1[k], P0[k], 1e-15 * (fabs(P0[k]) + M0));
    for (int t = 0; t < 2; t++)
        for (int j = 0; j < 4; j++)
            assert_near(s.m[s.tet[4 * t + j]], 2400 * s.vol[t] / 4, 1e-12);
    /* The cohesive element joins copies of the same original vertex. */
    for (int i = 0; i < 3; i++) {
        int a = s.tet[4 * s.coh[0].tet[0] + s.coh[0].slot[0][i]];
        int b = s.tet[4 * s.coh[0].tet[1] + s.coh[0].slot[1][i]];
        assert_int_not_equal(a, b);
        assert_int_equal(s.origin[a], s.origin[b]);
    }
    free(nodes.v), free(touched.v);
    cf_solid_free(&s), cf_mesh_free(&m);
}

/* The two-tet fixture in material ma with its shared facet cracked: one
 * cohesive element. */
static void cracked_two_tets_in(cf_solid *s, cf_mesh *m, cf_int_list *nodes, cf_int_list *touched,
                                const cf_material *ma)
{
    fixture_two_tets(m);
    init_in(s, m, ma);
    int f = -1;
    for (int i = 0; i < s->n_facets; i++)
        if (s->facet[4 * i + 2] >= 0)
            f = i;
    assert_int_equal(cf_crack_facet(s, f, nodes, touched), 0);
}

static void cracked_two_tets(cf_solid *s, cf_mesh *m, cf_int_list *nodes, cf_int_list *touched)
{
    cracked_two_tets_in(s, m, nodes, touched, &mat);
}

/* Moves the lower tet's copies of the cracked facet's vertices to an overlap
 * `depth` (m) into the upper tet and a slide `slide` (m) along x, evaluates
 * the cohesive element once with faces that meet as fc says, and returns
 * the largest |f_z| (N) on them. */
static double press(cf_solid *s, const cf_ppr *law, double depth, double slide,
                    const cf_face_contact *fc)
{
    memset(s->f, 0, sizeof(double) * 3 * (size_t)s->n_nodes);
    for (int j = 0; j < 3; j++) { /* tet 1 = {0, 2, 1, 4}: slots 0-2 on the facet */
        int n = s->tet[4 + j];
        s->x[3 * n + 0] = s->X[3 * n + 0] + slide;
        s->x[3 * n + 2] = s->X[3 * n + 2] + depth;
    }
    cf_pair_force pairs[3];
    int elems[1] = {0};
    cf_cohesive_forces(s, &cf_law_ppr, law, elems, 1, 1e-4, fc, pairs);
    double fz = 0;
    for (int j = 0; j < 3; j++)
        fz = fmax(fz, fabs(s->f[3 * s->tet[4 + j] + 2]));
    return fz;
}

/* press with the penalty at the cap and the normal traction
 * rising from zero when `rises` (time_continuity "both"). */
static double squeeze(cf_solid *s, const cf_ppr *law, double depth, double slide, int rises)
{
    return press(s, law, depth, slide, &(cf_face_contact){0, rises});
}

/* The compression penalty of a cohesive element engages on a pair that
 * reaches the overlap facing its partner, and not on one that slid past it
 * and comes back into view already overlapped: that would kick the pair
 * apart with energy 1/2 K_p dn^2 that no load put in (a 6 mg crumb of a
 * plaster sphere left at 101 m/s).  docs/physics.md §6, regularisation 1. */
static void test_penalty_engages_only_on_approach(void **state)
{
    (void)state;
    cf_ppr law;
    cf_ppr_init(&law, &mat);
    for (int path = 0; path < 2; path++) {
        cf_mesh m;
        cf_solid s;
        cf_int_list nodes = {0}, touched = {0};
        cracked_two_tets(&s, &m, &nodes, &touched);
        assert_true(squeeze(&s, &law, -1e-5, 0, 0) > 0); /* open: the cohesive traction */
        double fz;
        if (path == 0) { /* closes while facing: the penalty pushes back */
            fz = squeeze(&s, &law, 1e-4, 0, 0);
            assert_true(fz > 0);
        } else {         /* slides past (|d|^2 > A/4), overlaps, comes back */
            assert_true(squeeze(&s, &law, 1e-4, 0.8, 0) == 0);
            fz = squeeze(&s, &law, 1e-4, 0.1, 0);
            assert_true(fz == 0);
            squeeze(&s, &law, -1e-5, 0.1, 0);                 /* reopens (failed by the slide) */
            assert_true(squeeze(&s, &law, 1e-4, 0.1, 0) > 0); /* and closes facing */
        }
        double stored, dissipated;
        cf_cohesive_energy(&s, NULL, 0, &stored, &dissipated);
        assert_true(stored >= 0 && dissipated >= 0);
        printf("FIGURE penalty: path %s, |f_z| %.4g N at 0.1 mm of overlap, stored %.3g J\n",
               path == 0 ? "closing while facing" : "back from a slide", fz, stored);
        free(nodes.v), free(touched.v);
        cf_solid_free(&s), cf_mesh_free(&m);
    }
}

/* solver.time_continuity "both": an extrinsic element's normal traction
 * rises from zero with the capped stiffness K_cap, as its tangential one
 * always does, where the PPR envelope would start at the strength: a pair
 * whose bulk pulls at less than that is otherwise pulled shut by the
 * difference at its first opening (time continuity, Papoulia, Sam and
 * Vavasis 2003; docs/physics.md §6, regularisation 2).  The fixture's
 * facet: A = 0.5 m^2, sigma_max = 1 kPa, copies of 100 kg, dt = 0.1 ms, so
 * K_cap = 7.5e9 Pa/m, and the branch meets the envelope at 133 nm of the
 * law's 44 mm. */
static void test_normal_traction_rises_from_zero(void **state)
{
    (void)state;
    cf_ppr law;
    cf_ppr_init(&law, &mat);
    const double k = fixture_kcap * 0.5 / 3.0; /* N/m */
    double f[2][3], env[3];
    const double open[3] = {1e-9, 2e-9, 1e-6}; /* m, rising */
    for (int i = 0; i < 3; i++) {
        double Tn, Tt;
        cf_ppr_envelope(&law, open[i], 0, &Tn, &Tt);
        env[i] = Tn * 0.5 / 3.0;
    }
    for (int rises = 0; rises < 2; rises++) {
        cf_mesh m;
        cf_solid s;
        cf_int_list nodes = {0}, touched = {0};
        cracked_two_tets(&s, &m, &nodes, &touched);
        for (int i = 0; i < 3; i++)
            f[rises][i] = squeeze(&s, &law, -open[i], 0, rises);
        free(nodes.v), free(touched.v);
        cf_solid_free(&s), cf_mesh_free(&m);
    }
    for (int i = 0; i < 3; i++) /* the source's law: the envelope from the start */
        assert_true(fabs(f[0][i] - env[i]) <= 1e-9 * env[i]);
    for (int i = 0; i < 2; i++) /* K_cap A/3 times the opening */
        assert_true(fabs(f[1][i] - k * open[i]) <= 1e-6 * k * open[i]);
    assert_true(fabs(f[1][2] - env[2]) <= 1e-9 * env[2]); /* past the branch: the envelope */
    printf("FIGURE normal continuity: at 1 nm, 2 nm and 1 um of opening %.4g, %.4g, %.4g N "
           "(tangential only: %.4g, %.4g, %.4g N, the envelope)\n",
           f[1][0], f[1][1], f[1][2], f[0][0], f[0][1], f[0][2]);
}

/* material.crack_friction: the faces of a cohesive element pressed
 * together resist sliding by Coulomb friction.  The fixture's crack face,
 * failed (so the law carries no shear) and pressed 10 um in, is slid along
 * x by 1 mm and back in 1 um steps.  The friction traction sticks with
 * half the capped stiffness, K_cap / 2 = 3.75e9 Pa/m (test above), to a
 * slip of mu |T_n| / (K_cap / 2) = 8 um, then slides at mu |T_n|: on each
 * node |f_x| = mu |f_z|, against the slide.  Out and back, the pair
 * dissipates mu |F_n| (2 S - 3 s0) (S the slide, s0 the stick's slip;
 * docs/physics.md §6, regularisation 3). */
static void test_pressed_faces_slide_by_coulomb_friction(void **state)
{
    (void)state;
    const double mu = 0.4, depth = 1e-5, S = 1e-3, ds = 1e-6;
    const double kf = 0.5 * fixture_kcap; /* Pa/m */
    const cf_face_contact fc = {0, 0};
    cf_material rough = mat;
    rough.crack_friction = mu;
    cf_ppr law;
    cf_ppr_init(&law, &rough);
    cf_solid s;
    cf_mesh m;
    cf_int_list nodes = {0}, touched = {0};
    cracked_two_tets_in(&s, &m, &nodes, &touched, &rough);
    cf_cohesive_fail(&s, 0);
    int nstep = (int)lround(S / ds);
    double fx_stick = 0, fx_slide = 0, fz = 0, ratio_err = 0;
    for (int step = 0; step <= 2 * nstep; step++) {
        press(&s, &law, depth, ds * (step <= nstep ? step : 2 * nstep - step), &fc);
        for (int j = 0; j < 3; j++) {
            const double *f = &s.f[3 * s.tet[4 + j]];
            if (step == 2)
                fx_stick = fmax(fx_stick, fabs(f[0]));
            if (step > 20 && step < nstep) { /* sliding out: against the slide */
                assert_true(f[0] < 0);
                ratio_err = fmax(ratio_err, fabs(fabs(f[0]) - mu * fabs(f[2])) / fabs(f[2]));
                fx_slide = fabs(f[0]), fz = fabs(f[2]);
            }
            if (step > nstep + 20) /* and back */
                assert_true(f[0] > 0);
        }
    }
    double stored, dissipated;
    cf_cohesive_energy(&s, NULL, 0, &stored, &dissipated);
    double Fn = 3 * fz, s0 = mu * fz / (kf * 0.5 / 3.0);
    double expect = mu * Fn * (2 * S - 3 * s0);
    assert_true(fabs(fx_stick - kf * 0.5 / 3.0 * 2 * ds) <= 1e-6 * fx_stick); /* the stick */
    assert_true(ratio_err <= 1e-12);
    assert_true(fabs(dissipated - expect) <= 0.01 * expect);
    printf("FIGURE crack friction: stick %.4g N at 2 um, slide %.4g N = %.2f x %.4g N; "
           "out and back dissipated %.4g J (closed form %.4g J)\n",
           fx_stick, fx_slide, fx_slide / fz, fz, dissipated, expect);
    free(nodes.v), free(touched.v);
    cf_solid_free(&s), cf_mesh_free(&m);
}

/* Sets the six facet node copies of the cracked two-tet fixture at loop
 * angle th: the lower tet's copies pressed `depth` (m) into the upper one
 * and slid along y by 0.02 (1 - cos th), both sides turned about the x
 * axis by 0.3 sin th: a closed loop that turns the crack's normal while
 * the faces slide across the turn. */
static void loop_pose(cf_solid *s, double depth, double th)
{
    double ang = 0.3 * sin(th), c = cos(ang), sn = sin(ang);
    for (int t = 0; t < 2; t++)
        for (int j = 0; j < 3; j++) {
            int n = s->tet[4 * t + j];
            double y = s->X[3 * n + 1] - 0.3 + (t == 1 ? 0.02 * (1 - cos(th)) : 0);
            double z = s->X[3 * n + 2] + (t == 1 ? depth : 0);
            s->x[3 * n + 0] = s->X[3 * n + 0];
            s->x[3 * n + 1] = 0.3 + c * y - sn * z;
            s->x[3 * n + 2] = sn * y + c * z;
        }
}

/* A cohesive element's booked work (stored + dissipated) is the work its
 * forces do on its nodes, the trapezoid 1/2 (f' + f) . (x - x') summed
 * over the nodes as the leapfrog's kinetic energy product sees it: here
 * along a loop that presses a free crack face, slides it across the turn
 * of its normal and brings it back.  The tractions' trapezoid in the
 * scalar openings missed the turn: 1 % of a plaster drop's input went
 * unbooked (docs/physics.md §10, §14.20). */
static void test_cohesive_work_is_the_forces_work(void **state)
{
    (void)state;
    cf_ppr law;
    cf_ppr_init(&law, &mat);
    cf_mesh m;
    cf_solid s;
    cf_int_list nodes = {0}, touched = {0};
    cracked_two_tets(&s, &m, &nodes, &touched);
    cf_cohesive_fail(&s, 0); /* a free crack face: the penalty alone */
    const double dt = 1e-4, depth = 1e-4;
    int n = s.n_nodes, elems[1] = {0};
    cf_pair_force pairs[3];
    double *f_old = calloc((size_t)n * 3, sizeof(double)), *x_old = calloc((size_t)n * 3, sizeof(double));
    double w_nodes = 0, worst = 0, scale = 0, stored = 0, dissipated = 0;
    for (int step = 0; step <= 4000; step++) { /* press in, then the loop */
        double th = step <= 1000 ? 0 : 8.0 * atan(1.0) * (step - 1000) / 3000.0;
        loop_pose(&s, depth * fmin(1.0, step / 1000.0) - (step == 0) * 1e-6, th); /* from open */
        memset(s.f, 0, sizeof(double) * 3 * (size_t)n);
        cf_cohesive_forces(&s, &cf_law_ppr, &law, elems, 1, dt, &(cf_face_contact){0}, pairs);
        for (int q = 0; step > 0 && q < 3 * n; q++)
            w_nodes -= 0.5 * (f_old[q] + s.f[q]) * (s.x[q] - x_old[q]);
        memcpy(f_old, s.f, sizeof(double) * 3 * (size_t)n);
        memcpy(x_old, s.x, sizeof(double) * 3 * (size_t)n);
        cf_cohesive_energy(&s, NULL, 0, &stored, &dissipated);
        scale = fmax(scale, fabs(w_nodes));
        worst = fmax(worst, fabs(stored + dissipated - w_nodes));
    }
    assert_true(scale > 1);                 /* the penalty was pressed */
    assert_true(worst <= 1e-12 * scale);    /* the same sums, to round-off */
    printf("FIGURE cohesive work: largest %.4g J, booked minus the forces' work at most %.2g J; "
           "the loop ends at %.4g J (a potential would end where it began, 1/2 k g^2)\n",
           scale, worst, stored + dissipated);
    free(f_old), free(x_old), free(nodes.v), free(touched.v);
    cf_solid_free(&s), cf_mesh_free(&m);
}

/* 1 when interior facet f lies on the plane x = x0. */
static int facet_on_plane_x(const cf_solid *s, int f, double x0)
{
    const int *F = &s->facet[4 * f];
    int on = F[2] >= 0;
    for (int i = 0; i < 3; i++)
        on &= fabs(s->X[3 * s->tet[4 * F[0] + CF_TET_FACE[F[1]][i]]] - x0) < 1e-12;
    return on;
}

/* Crack every facet on the plane x = L/2 of a box: two fragments of equal
 * mass, momentum to round-off.  A single interior facet alone does not split. */
static void test_box_split_along_a_plane(void **state)
{
    (void)state;
    cf_mesh m;
    fixture_box(&m, 4, 2, 2, 0.4, 0.2, 0.2);
    cf_solid s;
    init(&s, &m);
    double P0[3], M0, P1[3], M1;
    momentum(&s, P0, &M0);
    cf_int_list nodes = {0}, touched = {0};
    int first = -1, cracked = 0;
    for (int f = 0; f < s.n_facets; f++) {
        if (!facet_on_plane_x(&s, f, 0.2))
            continue;
        assert_int_equal(cf_crack_facet(&s, f, &nodes, &touched), 0);
        if (first < 0) {
            first = f;
            assert_int_equal(components(&s), 1);
        }
        cracked++;
    }
    assert_int_equal(cracked, 2 * 2 * 2); /* 2 triangles per cell face, 2x2 faces */
    assert_int_equal(components(&s), 2);
    assert_int_equal(s.n_nodes, 45 + 9); /* the 3x3 plane nodes are duplicated */
    momentum(&s, P1, &M1);
    assert_near(M1, M0, 1e-14 * M0);
    for (int k = 0; k < 3; k++)
        assert_near(P1[k], P0[k], 1e-14 * (fabs(P0[k]) + M0));
    free(nodes.v), free(touched.v);
    cf_solid_free(&s), cf_mesh_free(&m);
}

/* Facet-traction criterion under uniaxial tension sigma_xx: facets normal to x
 * qualify, facets normal to y and z do not. */
static void test_criterion_selects_facets_normal_to_tension(void **state)
{
    (void)state;
    cf_mesh m;
    fixture_box(&m, 2, 2, 2, 1, 1, 1);
    cf_solid s;
    init(&s, &m);
    for (int t = 0; t < s.n_tets; t++) {
        memset(&s.sigma[9 * t], 0, 9 * sizeof(double));
        s.sigma[9 * t] = 1.5 * mat.sigma_max;
        s.hot[t] = 1;
    }
    int *all = malloc((size_t)s.n_tets * sizeof(int));
    cf_int_list cand = {0};
    for (int t = 0; t < s.n_tets; t++)
        all[t] = t;
    int n = cf_insertion_candidates(&s, all, s.n_tets, CF_CRITERION_TRACTION, s.n_tets, NULL, &cand);
    const int *out = cand.v;
    assert_true(n > 0);
    int normal_x = 0;
    for (int i = 0; i < n; i++) {
        const int *F = &s.facet[4 * out[i]];
        double xs[3];
        for (int j = 0; j < 3; j++)
            xs[j] = s.X[3 * s.tet[4 * F[0] + CF_TET_FACE[F[1]][j]]];
        normal_x += fabs(xs[0] - xs[1]) < 1e-12 && fabs(xs[1] - xs[2]) < 1e-12;
        /* any qualifying facet has sigma_n or tau >= sigma_max: never a facet normal to y or z */
        double ys[3], zs[3];
        for (int j = 0; j < 3; j++) {
            ys[j] = s.X[3 * s.tet[4 * F[0] + CF_TET_FACE[F[1]][j]] + 1];
            zs[j] = s.X[3 * s.tet[4 * F[0] + CF_TET_FACE[F[1]][j]] + 2];
        }
        assert_false(fabs(ys[0] - ys[1]) < 1e-12 && fabs(ys[1] - ys[2]) < 1e-12);
        assert_false(fabs(zs[0] - zs[1]) < 1e-12 && fabs(zs[1] - zs[2]) < 1e-12);
    }
    assert_int_equal(normal_x, 2 * 4); /* interior plane x = 0.5: 4 cell faces, 2 triangles each */
    free(all), free(cand.v);
    cf_solid_free(&s), cf_mesh_free(&m);
}

/* Every node of solid s moved by a fixed pseudo-random 2 % of a unit box,
 * then the stresses and hot flags of one check under `rule` (*n_hot of
 * them hot).  Returns the list of all tets, in order (the caller frees
 * it). */
static int *deform_and_check(cf_solid *s, cf_criterion rule, int *n_hot)
{
    for (int i = 0; i < s->n_nodes; i++)
        for (int k = 0; k < 3; k++)
            s->x[3 * i + k] += 0.02 * sin(12.9898 * i + 78.233 * k);
    int *all = malloc((size_t)s->n_tets * sizeof(int));
    for (int t = 0; t < s->n_tets; t++)
        all[t] = t;
    cf_stress_check bound = cf_insertion_bound(s, rule);
    *n_hot = 0;
    cf_tet4_forces(s, all, s->n_tets, CF_ELASTICITY_COROTATIONAL, &bound, 0, n_hot);
    return all;
}

/* The box of m as a solid with strengths sigma_max = tau_max = `strength`
 * (Pa), deformed and checked once under `rule` (deform_and_check). */
static int *deformed_box(cf_solid *s, cf_mesh *m, cf_criterion rule, double strength, int *n_hot)
{
    init(s, m);
    s->mat.sigma_max = s->mat.tau_max = strength;
    return deform_and_check(s, rule, n_hot);
}

/* The tet-level bound (Gershgorin, cf_insertion_bound) never drops a facet
 * that the full rule takes: under a random deformation, the candidates with
 * the hot flags of cf_tet4_forces equal those with every tet marked hot,
 * for both rules, at strengths where some but not all facets qualify. */
static void test_bound_never_misses_a_facet(void **state)
{
    (void)state;
    cf_mesh m;
    fixture_box(&m, 3, 3, 3, 1, 1, 1);
    static const cf_criterion rules[] = {CF_CRITERION_SOURCE, CF_CRITERION_TRACTION};
    int partial = 0, some = 0;
    for (int r = 0; r < 2; r++)
        for (int level = 0; level < 4; level++) {
            cf_solid s;
            int n_hot;
            /* strengths from a fifth to 1.6 times E times the displacement scale */
            int *all = deformed_box(&s, &m, rules[r], 0.2 * (1 << level) * 0.02 * mat.E, &n_hot);
            cf_int_list a = {0}, b = {0};
            int na = cf_insertion_candidates(&s, all, s.n_tets, rules[r], n_hot, NULL, &a);
            memset(s.hot, 1, (size_t)s.n_tets);
            int nb = cf_insertion_candidates(&s, all, s.n_tets, rules[r], s.n_tets, NULL, &b);
            printf("FIGURE bound: rule %d level %d: %d of %d tets hot, %d candidates\n", r, level,
                   n_hot, s.n_tets, na);
            assert_int_equal(na, nb);
            partial += n_hot > 0 && n_hot < s.n_tets;
            some += na > 0 && n_hot < s.n_tets;
            for (int i = 0; i < na; i++)
                assert_int_equal(a.v[i], b.v[i]);
            free(all), free(a.v), free(b.v);
            cf_solid_free(&s);
        }
    assert_true(partial >= 2 && some >= 1); /* the bound really skipped tets */
    cf_mesh_free(&m);
}

/* Largest eigenvalue of a symmetric 3x3 matrix by Jacobi rotations: a
 * method of its own, not insertion.c's closed form. */
static double jacobi_max_eigenvalue(const double S[9])
{
    double A[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            A[i][j] = S[3 * i + j];
    for (int sweep = 0; sweep < 50; sweep++)
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                if (A[p][q] == 0)
                    continue;
                double th = 0.5 * atan2(2 * A[p][q], A[q][q] - A[p][p]);
                double c = cos(th), sn = sin(th);
                for (int k = 0; k < 3; k++) { /* A <- J^T A J */
                    double akp = A[k][p], akq = A[k][q];
                    A[k][p] = c * akp - sn * akq, A[k][q] = sn * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) {
                    double apk = A[p][k], aqk = A[q][k];
                    A[p][k] = c * apk - sn * aqk, A[q][k] = sn * apk + c * aqk;
                }
            }
    return fmax(A[0][0], fmax(A[1][1], A[2][2]));
}

/* The source's rule found by brute force: every node's volume-averaged
 * world stress over all its tets, its largest eigenvalue (Jacobi), and each
 * interior facet whose three nodes all reach 0.9 sigma_max.  The insertion
 * check, which computes the eigenvalue only where a bound does not already
 * put it below the threshold and drops the other nodes, takes exactly those
 * facets, in tet order.  Facets with a node within 1e-9 of the threshold
 * (relative) would depend on rounding: none occur here (counted). */
static void test_source_rule_equals_brute_force(void **state)
{
    (void)state;
    /* 162 tets, and 4,374: a fragment of CF_TET4_PARALLEL_MIN tets or more
     * lists its marked nodes and qualifying tets on the threads. */
    static const int cells[2] = {3, 9};
    for (int box = 0; box < 2; box++) {
        cf_mesh m;
        fixture_box(&m, cells[box], cells[box], cells[box], 1, 1, 1);
        int checked = 0;
        for (int level = 0; level < 5; level++) {
            cf_solid s;
            int n_hot;
            /* the strains grow as the cells shrink: the strengths with them */
            double strength = 0.15 * (1 << level) * 0.02 * mat.E * cells[box] / 3;
            int *all = deformed_box(&s, &m, CF_CRITERION_SOURCE, strength, &n_hot);
            double *avg = calloc((size_t)s.n_nodes * 10, sizeof(double)), *value =
                malloc((size_t)s.n_nodes * sizeof(double));
            for (int t = 0; t < s.n_tets; t++)
                for (int j = 0; j < 4; j++) {
                    double *a = &avg[10 * s.tet[4 * t + j]];
                    for (int k = 0; k < 9; k++)
                        a[k] += s.vol[t] * s.sigma[9 * t + k];
                    a[9] += s.vol[t];
                }
            double thr = 0.9 * s.mat.sigma_max;
            int near = 0;
            for (int n = 0; n < s.n_nodes; n++) {
                double S[9];
                for (int k = 0; k < 9; k++)
                    S[k] = avg[10 * n + k] / avg[10 * n + 9];
                value[n] = jacobi_max_eigenvalue(S);
                near += fabs(value[n] - thr) <= 1e-9 * thr;
            }
            assert_int_equal(near, 0);
            cf_int_list want = {0}, got = {0};
            for (int t = 0; t < s.n_tets; t++)
                for (int k = 0; k < 4; k++) {
                    int f = s.tet_facet[4 * t + k], ok = 1;
                    if (s.facet[4 * f] != t || s.facet[4 * f + 2] < 0)
                        continue; /* a boundary facet, or seen from its other tet */
                    for (int j = 0; j < 3; j++)
                        ok &= value[s.tet[4 * t + CF_TET_FACE[k][j]]] >= thr;
                    if (ok)
                        assert_int_equal(cf_int_list_push(&want, f), 0);
                }
            memset(s.hot, 1, (size_t)s.n_tets);
            int n = cf_insertion_candidates(&s, all, s.n_tets, CF_CRITERION_SOURCE, s.n_tets,
                                            NULL, &got);
            printf("FIGURE source rule: %d tets, level %d: %d facets by brute force, %d by the "
                   "check\n", s.n_tets, level, want.n, n);
            assert_int_equal(n, want.n);
            for (int i = 0; i < n; i++)
                assert_int_equal(got.v[i], want.v[i]);
            checked += n > 0;
            free(all), free(avg), free(value), free(want.v), free(got.v);
            cf_solid_free(&s);
        }
        assert_true(checked >= 2); /* some levels really insert */
        cf_mesh_free(&m);
    }
}

/* cf_flagged_chunks keeps exactly the flagged items, in order, the same
 * list on one thread and on two: items of a shuffled list, and a range. */
static void test_flagged_chunks_keep_order(void **state)
{
    (void)state;
    enum { N = 200003, LO = 17 };
    unsigned char *flag = malloc(N + LO);
    int *v = malloc(N * sizeof(int)), *want = malloc(N * sizeof(int)),
        *got = malloc(N * sizeof(int));
    unsigned r = 12345;
    for (int i = 0; i < N + LO; i++) {
        r = r * 1103515245u + 12345u;
        flag[i] = (r >> 16) % 7 == 0; /* about one in seven */
    }
    for (int i = 0; i < N; i++)
        v[i] = N - 1 - i;
    for (int i = N - 1; i > 0; i--) { /* Fisher-Yates */
        r = r * 1103515245u + 12345u;
        int j = (int)((r >> 8) % (unsigned)(i + 1)), t = v[i];
        v[i] = v[j], v[j] = t;
    }
    int threads = omp_get_max_threads();
    for (int list = 0; list < 2; list++) {
        int nw = 0;
        for (int i = 0; i < N; i++) {
            int item = list ? v[i] : LO + i;
            if (flag[item])
                want[nw++] = item;
        }
        for (int t = 1; t <= 2; t++) {
            omp_set_num_threads(t);
            memset(got, 0xff, N * sizeof(int));
            int n = cf_flagged_chunks(list ? v : NULL, LO, N, flag, 1, got);
            assert_int_equal(n, nw);
            assert_memory_equal(got, want, (size_t)nw * sizeof(int));
        }
        assert_true(nw > N / 10 && nw < N / 5);
    }
    omp_set_num_threads(threads);
    assert_int_equal(cf_flagged_chunks(NULL, 0, 0, flag, 1, got), 0);
    free(flag), free(v), free(want), free(got);
}

/* Bars sorted by their ends, for comparing bar sets. */
typedef struct {
    int a, b;
    double rest, compliance;
} bar_row;

static int by_ends(const void *x, const void *y)
{
    const bar_row *p = x, *q = y;
    return p->a != q->a ? (p->a > q->a) - (p->a < q->a) : (p->b > q->b) - (p->b < q->b);
}

static bar_row *rows(const cf_bars *b)
{
    bar_row *r = malloc((size_t)(b->n ? b->n : 1) * sizeof *r);
    for (int i = 0; i < b->n; i++)
        r[i] = (bar_row){b->ends[2 * i], b->ends[2 * i + 1], b->rest[i], b->compliance[i]};
    qsort(r, (size_t)b->n, sizeof *r, by_ends);
    return r;
}

/* Same bars (ends, rest length, compliance to the bit) and every colour
 * group a matching: no node twice in one colour. */
static void assert_same_bars_validly_coloured(const cf_bars *got, const cf_bars *want, int nodes)
{
    assert_int_equal(got->n, want->n);
    assert_int_equal(got->color_start[CF_BARS_COLORS + 1], got->n);
    bar_row *g = rows(got), *w = rows(want);
    for (int i = 0; i < got->n; i++) {
        assert_int_equal(g[i].a, w[i].a);
        assert_int_equal(g[i].b, w[i].b);
        assert_true(g[i].rest == w[i].rest && g[i].compliance == w[i].compliance);
    }
    free(g), free(w);
    int *seen = malloc((size_t)nodes * sizeof(int));
    for (int i = 0; i < nodes; i++)
        seen[i] = -1;
    for (int c = 0; c < CF_BARS_COLORS; c++)
        for (int i = got->color_start[c]; i < got->color_start[c + 1]; i++)
            for (int e = 0; e < 2; e++) {
                int a = got->ends[2 * i + e];
                assert_int_not_equal(seen[a], c);
                seen[a] = c;
            }
    for (int c = 0; c <= CF_BARS_COLORS; c++)
        assert_true(c < got->n_colors || got->color_start[c + 1] == got->color_start[c]);
    free(seen);
}

/* Bars patched at the duplicated nodes after each round of insertions
 * equal the bars built anew from all tets; when the box falls apart, the
 * pieces' split bars equal the bars built on each piece's tets. */
static void test_bars_patched_after_insertion_equal_a_rebuild(void **state)
{
    (void)state;
    cf_mesh m;
    fixture_box(&m, 4, 3, 3, 0.4, 0.3, 0.3);
    cf_solid s;
    init(&s, &m);
    int *all = malloc((size_t)s.n_tets * sizeof(int));
    for (int t = 0; t < s.n_tets; t++)
        all[t] = t;
    cf_bars bars = {0}, fresh = {0};
    cf_bars_scratch w = {0};
    assert_int_equal(cf_bars_build(&bars, &s, all, s.n_tets), 0);
    cf_int_list nodes = {0}, touched = {0};
    /* Rounds: scattered facets, then the whole plane x = 0.2. */
    for (int round = 0; round < 4; round++) {
        touched.n = 0;
        for (int f = 0; f < s.n_facets; f++) {
            if (s.facet[4 * f + 2] < 0 || s.cracked[f])
                continue;
            int pick = round < 3 ? (f * 7 + round) % 11 == 0 : facet_on_plane_x(&s, f, 0.2);
            if (pick)
                assert_int_equal(cf_crack_facet(&s, f, &nodes, &touched), 0);
        }
        assert_int_equal(cf_bars_patch(&bars, &s, touched.v, touched.n, &w), 0);
        assert_int_equal(cf_bars_build(&fresh, &s, all, s.n_tets), 0);
        assert_same_bars_validly_coloured(&bars, &fresh, s.n_nodes);
    }
    for (int i = 0; i < s.n_nodes; i++)
        assert_int_equal(w.flag[i], 0); /* the scratch is left clean */
    /* Split by pieces. */
    int *comp = malloc((size_t)s.n_tets * sizeof(int));
    int k = cf_label_components(&s, all, s.n_tets, comp);
    assert_true(k >= 2);
    int *piece = malloc((size_t)s.n_nodes * sizeof(int));
    for (int t = 0; t < s.n_tets; t++)
        for (int j = 0; j < 4; j++)
            piece[s.tet[4 * t + j]] = comp[t];
    cf_bars *parts = calloc((size_t)k, sizeof *parts), **dst = malloc((size_t)k * sizeof *dst);
    for (int p = 0; p < k; p++)
        dst[p] = &parts[p];
    assert_int_equal(cf_bars_split(&bars, piece, k, dst), 0);
    for (int p = 0; p < k; p++) {
        int nt = 0;
        for (int t = 0; t < s.n_tets; t++)
            if (comp[t] == p)
                all[nt++] = t;
        assert_int_equal(cf_bars_build(&fresh, &s, all, nt), 0);
        assert_same_bars_validly_coloured(&parts[p], &fresh, s.n_nodes);
        cf_bars_free(&parts[p]);
    }
    free(parts), free(dst), free(piece), free(comp), free(all);
    free(nodes.v), free(touched.v);
    cf_bars_free(&bars), cf_bars_free(&fresh), cf_bars_scratch_free(&w);
    cf_solid_free(&s), cf_mesh_free(&m);
}

/* The box of m as a solid under a uniform uniaxial stress `sy` (Pa) along
 * y, every tet hot, the traction rule at strength sigma_max = tau_max =
 * `strength`: the facets normal to y qualify with ratio sy / strength, the
 * others (traction below the strength) do not.  The nucleation radius is
 * set to `radius` (m).  Returns the list of all tets. */
static int *stressed_box(cf_solid *s, cf_mesh *m, double sy, double strength, double radius)
{
    init(s, m);
    s->mat.sigma_max = s->mat.tau_max = strength;
    for (int t = 0; t < s->n_tets; t++) {
        memset(&s->sigma[9 * t], 0, 9 * sizeof(double));
        s->sigma[9 * t + 4] = sy;
    }
    memset(s->hot, 1, (size_t)s->n_tets);
    s->nucleation_radius = radius;
    cf_crack_grid_free(&s->cracks);
    cf_crack_grid_init(&s->cracks, radius);
    int *all = malloc((size_t)s->n_tets * sizeof(int));
    for (int t = 0; t < s->n_tets; t++)
        all[t] = t;
    return all;
}

/* Checks at times 0, dt, 2 dt, ... under growth rule g, each inserting
 * what cf_insertion_select takes, until a check takes nothing (at most
 * `checks`).  Returns the facets inserted. */
static int grow_memo(cf_solid *s, const int *all, cf_growth g, double dt, int checks, int forget)
{
    cf_int_list cand = {0}, nodes = {0}, touched = {0};
    int total = 0;
    for (int c = 0; c < checks; c++) {
        g.t = c * dt;
        if (forget) /* the growth rule's memo of how facets meet the cracks */
            memset(s->contact_key, 0, (size_t)s->n_facets * sizeof *s->contact_key);
        int n = cf_insertion_candidates(s, all, s->n_tets, CF_CRITERION_TRACTION, s->n_tets, NULL, &cand);
        assert_true(n >= 0);
        n = cf_insertion_select(s, &cand, CF_CRITERION_TRACTION, &g);
        assert_true(n >= 0);
        for (int i = 0; i < n; i++)
            assert_int_equal(cf_crack_facet(s, cand.v[i], &nodes, &touched), 0);
        total += n;
        if (n == 0 && g.rule == CF_GROWTH_ALL)
            break;
    }
    free(cand.v), free(nodes.v), free(touched.v);
    return total;
}

static int grow(cf_solid *s, const int *all, cf_growth g, double dt, int checks)
{
    return grow_memo(s, all, g, dt, checks, 0);
}

/* Tets in the smallest piece that the crack faces and the boundary close
 * (tets joined through uncracked interior facets); the least volume of
 * such a piece (m^3) in *volume when not NULL. */
static int smallest_closed_piece(const cf_solid *s, double *volume)
{
    int *parent = malloc((size_t)s->n_tets * sizeof(int)), *size = calloc((size_t)s->n_tets, sizeof(int));
    double *vol = calloc((size_t)s->n_tets, sizeof(double));
    for (int t = 0; t < s->n_tets; t++)
        parent[t] = t;
    for (int f = 0; f < s->n_facets; f++) {
        const int *F = &s->facet[4 * f];
        if (F[2] < 0 || s->cracked[f])
            continue;
        int a = F[0], b = F[2];
        while (parent[a] != a)
            a = parent[a];
        while (parent[b] != b)
            b = parent[b];
        parent[a > b ? a : b] = a < b ? a : b;
    }
    for (int t = 0; t < s->n_tets; t++) {
        int r = t;
        while (parent[r] != r)
            r = parent[r];
        size[r]++, vol[r] += s->vol[t];
    }
    int least = s->n_tets;
    double least_vol = INFINITY;
    for (int t = 0; t < s->n_tets; t++)
        if (size[t] > 0) {
            least = size[t] < least ? size[t] : least;
            least_vol = fmin(least_vol, vol[t]);
        }
    if (volume)
        *volume = least_vol;
    free(parent), free(size), free(vol);
    return least;
}

/* Every facet of a box overloaded in every direction qualifies at every
 * check.  The source's rule (all) then cracks every one at once and cuts
 * the box into single tets; the front rule, given all the time it wants,
 * cracks many facets but never closes a piece of 4 tets or fewer, and
 * with a least piece volume (min_piece_size) of two cells, 12 tets, none
 * of less volume. */
static void test_fronts_close_no_small_piece(void **state)
{
    (void)state;
    cf_mesh m;
    fixture_box(&m, 4, 4, 4, 1, 1, 1);
    const double two_cells = 2.0 / 64.0;
    int least[3], cracked[3];
    double least_vol[3];
    for (int rule = 0; rule < 3; rule++) {
        cf_solid s;
        int *all = stressed_box(&s, &m, 0, 1.0, 1e-9);
        for (int t = 0; t < s.n_tets; t++) /* hydrostatic tension: every normal */
            s.sigma[9 * t] = s.sigma[9 * t + 4] = s.sigma[9 * t + 8] = 10.0;
        cf_growth g = {rule == 0 ? CF_GROWTH_ALL : CF_GROWTH_FRONTS, INFINITY, 4,
                       rule == 2 ? two_cells : 0, 0, 0, 0, 0, 0, 0};
        cracked[rule] = grow(&s, all, g, 1.0, 200);
        least[rule] = smallest_closed_piece(&s, &least_vol[rule]);
        free(all);
        cf_solid_free(&s);
    }
    printf("FIGURE fronts: all: %d facets, smallest piece %d tets; fronts: %d facets, smallest "
           "piece %d tets; with a least volume of %g m^3: %d facets, smallest piece %g m^3 "
           "(%d tets)\n", cracked[0], least[0], cracked[1], least[1], two_cells, cracked[2],
           least_vol[2], least[2]);
    assert_int_equal(least[0], 1);
    assert_true(least[1] > 4);
    assert_true(cracked[1] > cracked[0] / 4); /* the front rule does crack */
    assert_true(least_vol[2] >= two_cells * (1 - 1e-12));
    assert_true(least[2] < 96);               /* it does close pieces */
    assert_true(cracked[2] > cracked[0] / 8); /* and crack */
    cf_mesh_free(&m);
}

/* The growth rule remembers how each facet meets the cracks (front,
 * touching, clear) until a facet on its vertices cracks or a crack on its
 * edges comes of age.  Forgetting it before every check gives the same
 * cracks at the same times: in the box overloaded in every direction (no
 * waiting) and in the bar whose single crack grows at a finite speed (a
 * memo that lives until a crack is old enough). */
static void test_contact_memo_changes_nothing(void **state)
{
    (void)state;
    for (int scene = 0; scene < 2; scene++) {
        cf_mesh m;
        if (scene == 0)
            fixture_box(&m, 4, 4, 4, 1, 1, 1);
        else
            fixture_box(&m, 8, 2, 2, 8, 2, 2);
        unsigned char *cracked[2];
        double *when[2];
        int n[2], nf = 0;
        for (int forget = 0; forget < 2; forget++) {
            cf_solid s;
            int *all = scene == 0 ? stressed_box(&s, &m, 0, 1.0, 1e-9) : stressed_box(&s, &m, 1.4, 1.0, 100.0);
            if (scene == 0)
                for (int t = 0; t < s.n_tets; t++)
                    s.sigma[9 * t] = s.sigma[9 * t + 4] = s.sigma[9 * t + 8] = 10.0;
            cf_growth g = {CF_GROWTH_FRONTS, scene == 0 ? INFINITY : 10.0, 4, 0, 0, 0, 0, 0, 0, 0};
            n[forget] = grow_memo(&s, all, g, scene == 0 ? 1.0 : 0.01, 200, forget);
            nf = s.n_facets;
            cracked[forget] = malloc((size_t)nf), when[forget] = malloc((size_t)nf * sizeof(double));
            memcpy(cracked[forget], s.cracked, (size_t)nf);
            memcpy(when[forget], s.crack_time, (size_t)nf * sizeof(double));
            free(all);
            cf_solid_free(&s);
        }
        printf("FIGURE contact memo: %s, %d facets cracked with it, %d without\n",
               scene == 0 ? "box overloaded in every direction" : "bar, one crack at 10 m/s",
               n[0], n[1]);
        assert_true(n[0] > 0);
        assert_int_equal(n[0], n[1]);
        assert_memory_equal(cracked[0], cracked[1], (size_t)nf);
        assert_memory_equal(when[0], when[1], (size_t)nf * sizeof(double));
        for (int i = 0; i < 2; i++)
            free(cracked[i]), free(when[i]);
        cf_mesh_free(&m);
    }
}

/* A bar 8 m long under tension across one plane: the facets of the plane
 * y = 1 qualify (ratio 1.4), every other facet is below its strength.  A
 * nucleation radius longer than the bar lets one crack start; it grows
 * along the plane from facet to facet, and no cracked facet ever lies
 * farther from the first than the front speed times the time since, plus
 * one cell's diagonal (the step from a facet to the next).  The whole plane
 * cracks in the end. */
static void test_front_moves_no_faster_than_its_speed(void **state)
{
    (void)state;
    cf_mesh m;
    fixture_box(&m, 8, 2, 2, 8, 2, 2); /* cubic cells: no diagonal facet qualifies */
    cf_solid s;
    int *all = stressed_box(&s, &m, 1.4, 1.0, 100.0);
    double speed = 10.0, dt = 0.01, cell = sqrt(3.0);
    cf_growth g = {CF_GROWTH_FRONTS, speed, 0, 0, 0, 0, 0, 0, 0, 0};
    cf_int_list cand = {0}, nodes = {0}, touched = {0};
    double first[3] = {0, 0, 0}, worst = -INFINITY;
    int nuclei = 0, total = 0;
    for (int c = 0; c < 200; c++) {
        g.t = c * dt;
        int n = cf_insertion_candidates(&s, all, s.n_tets, CF_CRITERION_TRACTION, s.n_tets, NULL, &cand);
        n = cf_insertion_select(&s, &cand, CF_CRITERION_TRACTION, &g);
        for (int i = 0; i < n; i++) {
            const int *F = &s.facet[4 * cand.v[i]];
            double ctr[3] = {0, 0, 0};
            for (int j = 0; j < 3; j++)
                v3_axpy(1.0 / 3, &s.X[3 * s.tet0[4 * F[0] + CF_TET_FACE[F[1]][j]]], ctr);
            if (total == 0)
                memcpy(first, ctr, sizeof first), nuclei++;
            double d[3];
            v3_sub(ctr, first, d);
            worst = fmax(worst, v3_norm(d) - (speed * g.t + cell));
            assert_int_equal(cf_crack_facet(&s, cand.v[i], &nodes, &touched), 0);
            total++;
        }
    }
    printf("FIGURE front speed: %d facets cracked from %d nucleus, farthest beyond speed x time "
           "+ one cell: %g m\n", total, nuclei, worst);
    assert_int_equal(total, 2 * 8 * 2); /* the plane: 8 x 2 cells, 2 triangles each */
    assert_true(worst <= 0);
    free(cand.v), free(nodes.v), free(touched.v), free(all);
    cf_solid_free(&s), cf_mesh_free(&m);
}

/* Original vertices of facet f. */
static void facet_vertices(const cf_solid *s, int f, int o[3])
{
    const int *F = &s->facet[4 * f];
    for (int j = 0; j < 3; j++)
        o[j] = s->tet0[4 * F[0] + CF_TET_FACE[F[1]][j]];
}

/* An interior facet on the plane y = 0.5 (the middle of fixture_box's
 * unit box), or -1. */
static int middle_facet(const cf_solid *s)
{
    for (int f = 0; f < s->n_facets; f++) {
        int o[3];
        facet_vertices(s, f, o);
        if (s->facet[4 * f + 2] >= 0 && s->X[3 * o[0] + 1] == 0.5 && s->X[3 * o[1] + 1] == 0.5 &&
            s->X[3 * o[2] + 1] == 0.5)
            return f;
    }
    return -1;
}

/* The source's rule at a crack front reads the stress ahead of it
 * (docs/physics.md §5.1): beside a cracked facet whose neighbourhood has
 * unloaded (every tet at one of its vertices at zero stress, the rest under
 * a tension ten times the threshold), the facets that share an edge with it
 * qualify when their vertex off that edge reaches the threshold, although
 * their two vertices on the edge read zero; a facet that touches the crack
 * at one vertex only does not (that vertex fails the plain rule, and it is
 * no front). */
static void test_front_rule_reads_the_stress_ahead(void **state)
{
    (void)state;
    cf_mesh m;
    fixture_box(&m, 4, 4, 4, 1, 1, 1);
    cf_solid s;
    double strength = 1.0, thr = 0.9 * strength;
    int *all = stressed_box(&s, &m, 10.0 * thr, strength, 1e-9);
    int f0 = middle_facet(&s), o0[3]; /* an interior facet normal to y near the middle */
    assert_true(f0 >= 0);
    facet_vertices(&s, f0, o0);
    cf_mark_cracked(&s, f0, 1);
    for (int t = 0; t < s.n_tets; t++)
        for (int j = 0; j < 4; j++)
            if (s.tet0[4 * t + j] == o0[0] || s.tet0[4 * t + j] == o0[1] ||
                s.tet0[4 * t + j] == o0[2])
                memset(&s.sigma[9 * t], 0, 9 * sizeof(double));
    cf_int_list cand = {0};
    int n = cf_insertion_candidates(&s, all, s.n_tets, CF_CRITERION_SOURCE, s.n_tets, NULL, &cand);
    int fronts = 0;
    for (int i = 0; i < n; i++) {
        const int *F = &s.facet[4 * cand.v[i]];
        int shared = 0;
        for (int j = 0; j < 3; j++) {
            int o = s.tet0[4 * F[0] + CF_TET_FACE[F[1]][j]];
            shared += o == o0[0] || o == o0[1] || o == o0[2];
        }
        assert_true(shared != 1 && shared != 3);
        fronts += shared == 2;
    }
    printf("FIGURE front rule: %d facets qualify, %d of them fronts of the crack\n", n, fronts);
    assert_true(fronts >= 2);
    free(cand.v), free(all);
    cf_solid_free(&s), cf_mesh_free(&m);
}

/* Facet f cracked long ago (a front at once, whatever the front speed),
 * its rest centroid in the crack grid. */
static void old_crack(cf_solid *s, int f)
{
    int o[3];
    double c[3];
    facet_vertices(s, f, o);
    cf_mark_cracked(s, f, 1);
    s->crack_time[f] = -1e9;
    for (int k = 0; k < 3; k++)
        c[k] = (s->X[3 * o[0] + k] + s->X[3 * o[1] + k] + s->X[3 * o[2] + k]) / 3;
    assert_int_equal(cf_crack_grid_add(&s->cracks, c), 0);
}

/* Cracked facets holding the edge of original vertices a and b. */
static int cracked_on_edge(const cf_solid *s, int a, int b)
{
    int n = 0;
    for (int f = 0; f < s->n_facets; f++) {
        int o[3];
        facet_vertices(s, f, o);
        int has_a = o[0] == a || o[1] == a || o[2] == a, has_b = o[0] == b || o[1] == b || o[2] == b;
        n += s->cracked[f] && has_a && has_b;
    }
    return n;
}

/* A crack grows from its front, the edges where its surface ends, and does
 * not branch (docs/physics.md §5.1): in a box overloaded in every
 * direction, a crack of two facets f0 and f1 that share an edge e, checked
 * once, takes facets across its four outer edges, at most one across each
 * (so no edge of the crack holds three cracked facets), and none across e,
 * which two cracked facets already share.  The nucleation radius is longer
 * than the box, and a front takes far longer than one check to cross a
 * cell: every facet taken is a front of f0 and f1. */
static void test_fronts_do_not_branch(void **state)
{
    (void)state;
    cf_mesh m;
    fixture_box(&m, 4, 4, 4, 1, 1, 1);
    cf_solid s;
    int *all = stressed_box(&s, &m, 0, 1.0, 1e9);
    for (int t = 0; t < s.n_tets; t++)
        s.sigma[9 * t] = s.sigma[9 * t + 4] = s.sigma[9 * t + 8] = 10.0;
    int f0 = middle_facet(&s), f1 = -1, o0[3], o1[3], e[2] = {-1, -1};
    assert_true(f0 >= 0);
    facet_vertices(&s, f0, o0);
    for (int f = 0; f < s.n_facets && f1 < 0; f++) { /* an interior neighbour across an edge */
        int shared = 0;
        facet_vertices(&s, f, o1);
        for (int j = 0; j < 3; j++)
            shared += o1[j] == o0[0] || o1[j] == o0[1] || o1[j] == o0[2];
        if (f != f0 && s.facet[4 * f + 2] >= 0 && shared == 2)
            f1 = f;
    }
    assert_true(f1 >= 0);
    facet_vertices(&s, f1, o1);
    for (int j = 0, k = 0; j < 3; j++)
        if (o0[j] == o1[0] || o0[j] == o1[1] || o0[j] == o1[2])
            e[k++] = o0[j];
    old_crack(&s, f0);
    cf_mark_cracked(&s, f1, 1);
    s.crack_time[f1] = -1e9;
    assert_int_equal(cracked_on_edge(&s, e[0], e[1]), 2);
    cf_growth g = {CF_GROWTH_FRONTS, 1e-6, 0, 0, 0.0, 0, 0, 0, 0, 0};
    cf_int_list cand = {0};
    int n = cf_insertion_candidates(&s, all, s.n_tets, CF_CRITERION_TRACTION, s.n_tets, NULL, &cand);
    assert_true(n > 0);
    n = cf_insertion_select(&s, &cand, CF_CRITERION_TRACTION, &g);
    int outer = 0, most = 0;
    for (int a = 0; a < 2; a++) /* the four outer edges: each corner with each end of e */
        for (int j = 0; j < 3; j++) {
            const int *o = a ? o1 : o0;
            if (o[j] == e[0] || o[j] == e[1])
                continue;
            for (int q = 0; q < 2; q++) {
                int k = cracked_on_edge(&s, o[j], e[q]);
                outer += k - 1, most = k > most ? k : most;
            }
        }
    printf("FIGURE branching: %d facets taken, %d across the outer edges, at most %d cracked "
           "facets on an edge of the crack, %d on the shared edge\n",
           n, outer, most, cracked_on_edge(&s, e[0], e[1]));
    assert_true(outer >= 1);
    assert_true(most <= 2);
    assert_int_equal(cracked_on_edge(&s, e[0], e[1]), 2);
    free(cand.v), free(all);
    cf_solid_free(&s), cf_mesh_free(&m);
}

/* The 4-cell unit box under a uniaxial tension sy (Pa) along y, of unit
 * strength, with an old crack at its middle facet (every facet taken
 * beside it is a front: the nucleation radius is longer than the box).
 * Returns the list of its tets. */
static int *box_with_crack(cf_mesh *m, cf_solid *s, double sy)
{
    fixture_box(m, 4, 4, 4, 1, 1, 1);
    int *all = stressed_box(s, m, sy, 1.0, 1e9), f0 = middle_facet(s);
    assert_true(f0 >= 0);
    old_crack(s, f0);
    return all;
}

/* One check of the source's criterion with fronts (across the tension
 * when `along`); the facets taken, in cand. */
static int check_fronts(cf_solid *s, const int *all, int along, cf_int_list *cand)
{
    cf_growth g = {CF_GROWTH_FRONTS, 1e-6, 0, 0, 0.0, along, 0, 0, 0, 0};
    int n = cf_insertion_candidates(s, all, s->n_tets, CF_CRITERION_SOURCE, s->n_tets, &g, cand);
    return n > 0 ? cf_insertion_select(s, cand, CF_CRITERION_SOURCE, &g) : n;
}

/* The y component of facet f's unit rest normal. */
static double facet_normal_y(const cf_solid *s, int f)
{
    int o[3];
    double e1[3], e2[3], nrm[3];
    facet_vertices(s, f, o);
    v3_sub(&s->X[3 * o[1]], &s->X[3 * o[0]], e1), v3_sub(&s->X[3 * o[2]], &s->X[3 * o[0]], e2);
    v3_cross(e1, e2, nrm);
    return nrm[1] / v3_norm(nrm);
}

/* The maximum tangential stress criterion at a front (docs/physics.md §5.1
 * rule 3, solver.front_direction "stress"): in a box under a uniaxial
 * tension sy along y of 1.5 times the threshold, a crack of one facet
 * normal to y, checked once, takes across its edges only facets whose
 * normal stress sy n_y^2 reaches the threshold, and some; the source's
 * front rule ("any"), which reads the principal stress at the vertex
 * ahead (sy everywhere), also takes facets whose normal stress does not.
 * The nucleation radius is longer than the box: every facet taken is a
 * front. */
static void test_fronts_run_across_the_tension(void **state)
{
    (void)state;
    double thr = 0.9, sy = 1.5 * thr; /* threshold of a facet of strength 1 */
    int taken[2], below[2];
    for (int along = 0; along < 2; along++) {
        cf_mesh m;
        cf_solid s;
        int *all = box_with_crack(&m, &s, sy);
        cf_int_list cand = {0};
        int n = check_fronts(&s, all, along, &cand);
        taken[along] = n, below[along] = 0;
        for (int i = 0; i < n; i++) {
            double ny = facet_normal_y(&s, cand.v[i]);
            below[along] += sy * ny * ny < thr;
        }
        free(cand.v), free(all);
        cf_solid_free(&s), cf_mesh_free(&m);
    }
    printf("FIGURE fronts along the stress: %d facets taken, %d of them with a normal stress "
           "below the threshold (any facet: %d, %d)\n",
           taken[1], below[1], taken[0], below[0]);
    assert_true(taken[1] >= 1);
    assert_int_equal(below[1], 0);
    assert_true(below[0] >= 1);
}

/* The rest angle, in degrees, by which facet f turns from facet g across
 * the edge they share: 0 straight ahead of g, 180 folded back onto it. */
static double kink_degrees(const cf_solid *s, int f, int g)
{
    int of[3], og[3], e[2], n = 0, pf = -1, pg = -1;
    facet_vertices(s, f, of), facet_vertices(s, g, og);
    for (int j = 0; j < 3; j++) {
        if (of[j] != og[0] && of[j] != og[1] && of[j] != og[2])
            pf = of[j];
        else if (n < 2)
            e[n++] = of[j];
        else
            n++;
        if (og[j] != of[0] && og[j] != of[1] && og[j] != of[2])
            pg = og[j];
    }
    assert_int_equal(n, 2);
    double edge[3], a[3], b[3];
    v3_sub(&s->X[3 * e[1]], &s->X[3 * e[0]], edge);
    v3_sub(&s->X[3 * pf], &s->X[3 * e[0]], a), v3_sub(&s->X[3 * pg], &s->X[3 * e[0]], b);
    double ee = v3_dot(edge, edge), ka = v3_dot(a, edge) / ee, kb = v3_dot(b, edge) / ee;
    v3_axpy(-ka, edge, a), v3_axpy(-kb, edge, b); /* each facet's direction away from the edge */
    double phi = acos(v3_dot(a, b) / (v3_norm(a) * v3_norm(b))) * 180 / acos(-1.0);
    return 180 - phi;
}

/* A front turns from its crack by at most solver.front_max_kink
 * (docs/physics.md §5.1 rule 3).  In the box under a uniaxial tension of
 * 1.5 thresholds with a crack of one facet normal to it, one check of the
 * source's front rule ("any": every facet across a front edge whose vertex
 * ahead is loaded) takes facets that turn from the crack by more than 45
 * degrees; with a limit of 45 degrees the crack still grows, and no facet
 * it takes turns by more.  Every facet taken is a front of the crack (the
 * nucleation radius is longer than the box). */
static void test_fronts_kink_no_further_than_the_limit(void **state)
{
    (void)state;
    int taken[2], sharp[2];
    double most[2];
    for (int limit = 0; limit < 2; limit++) {
        cf_mesh m;
        cf_solid s;
        int *all = box_with_crack(&m, &s, 1.35), f0 = middle_facet(&s);
        cf_growth g = {CF_GROWTH_FRONTS, 1e-6, 0, 0, 0.0, 0, limit ? acos(-1.0) / 4 : 0, 0, 0, 0};
        cf_int_list cand = {0};
        int n = cf_insertion_candidates(&s, all, s.n_tets, CF_CRITERION_SOURCE, s.n_tets, &g,
                                        &cand);
        n = n > 0 ? cf_insertion_select(&s, &cand, CF_CRITERION_SOURCE, &g) : n;
        taken[limit] = n, sharp[limit] = 0, most[limit] = 0;
        for (int i = 0; i < n; i++) {
            double k = kink_degrees(&s, cand.v[i], f0);
            sharp[limit] += k > 45 + 1e-9;
            most[limit] = fmax(most[limit], k);
        }
        free(cand.v), free(all);
        cf_solid_free(&s), cf_mesh_free(&m);
    }
    printf("FIGURE front kink: no limit %d facets taken, %d turning by more than 45 deg (at "
           "most %.1f); limit 45 deg %d taken, %d (at most %.1f)\n",
           taken[0], sharp[0], most[0], taken[1], sharp[1], most[1]);
    assert_true(sharp[0] >= 1);
    assert_true(taken[1] >= 1);
    assert_int_equal(sharp[1], 0);
}

/* Copies of original vertex o among the solid's tets' nodes. */
static int copies_of(const cf_solid *s, int o)
{
    int seen[64], n = 0;
    for (int i = s->vt_start[o]; i < s->vt_start[o + 1]; i++) {
        int c = s->tet[s->vt_slot[i]], dup = 0;
        for (int j = 0; j < n; j++)
            dup |= seen[j] == c;
        if (!dup && n < 64)
            seen[n++] = c;
    }
    return n;
}

/* The facet on the plane y = 0.5 nearest the centre of fixture_box's unit
 * box. */
static int central_facet(const cf_solid *s)
{
    int f0 = -1;
    double best = INFINITY;
    for (int f = 0; f < s->n_facets; f++) {
        int o[3];
        facet_vertices(s, f, o);
        double d = 0;
        for (int k = 0; k < 3; k++) {
            double c = (s->X[3 * o[0] + k] + s->X[3 * o[1] + k] + s->X[3 * o[2] + k]) / 3 - 0.5;
            d += c * c;
        }
        if (fabs(facet_normal_y(s, f)) == 1 && d < best)
            best = d, f0 = f;
    }
    assert_true(f0 >= 0);
    return f0;
}

/* A front splits the vertices behind it along its plane
 * (solver.front_split "plane", docs/physics.md §5.1 rule 3).  In the box
 * under a uniaxial tension along y of 1.5 thresholds, a crack of one
 * facet on the plane y = 0.5 at the box's centre grows in one check by
 * fronts across the tension, and each facet taken is inserted with node
 * duplication.  Without the split, no vertex of the crack gets a second
 * copy: the facets round each of them do not yet cut its star, so the
 * crack cannot open anywhere.  With it, the two vertices on the cracked
 * edge of the first front taken have two copies each (the third may wait
 * for a front of its own: the first split took the facets across its
 * edges), more facets are taken, and every one lies on the plane y = 0.5:
 * the split cuts each star along the crack's plane, and the crack stays
 * one surface.  With a reach (solver.front_split_reach) shorter than any
 * star facet's distance from its vertex, the split takes nothing: as
 * without it. */
static void test_front_split_opens_the_crack_to_its_front(void **state)
{
    (void)state;
    int taken[3], off_plane[3], parted[3];
    for (int split = 0; split < 3; split++) { /* none, plane, plane within 0.05 m */
        cf_mesh m;
        cf_solid s;
        fixture_box(&m, 4, 4, 4, 1, 1, 1);
        int *all = stressed_box(&s, &m, 1.35, 1.0, 1e9), f0 = central_facet(&s), o0[3];
        old_crack(&s, f0);
        facet_vertices(&s, f0, o0);
        cf_growth g = {CF_GROWTH_FRONTS, 1e-6, 0, 0, 0.0, 1, 0, split > 0, split == 2 ? 0.05 : 0, 0};
        cf_int_list cand = {0}, nodes = {0}, touched = {0};
        int n = cf_insertion_candidates(&s, all, s.n_tets, CF_CRITERION_SOURCE, s.n_tets, &g,
                                        &cand);
        n = n > 0 ? cf_insertion_select(&s, &cand, CF_CRITERION_SOURCE, &g) : n;
        taken[split] = n, off_plane[split] = 0, parted[split] = 0;
        assert_int_equal(cf_crack_facet(&s, f0, &nodes, &touched), 0);
        for (int i = 0; i < n; i++) {
            off_plane[split] += fabs(facet_normal_y(&s, cand.v[i])) != 1;
            assert_int_equal(cf_crack_facet(&s, cand.v[i], &nodes, &touched), 0);
        }
        for (int j = 0; j < 3; j++)
            parted[split] += copies_of(&s, o0[j]) == 2;
        free(cand.v), free(nodes.v), free(touched.v), free(all);
        cf_solid_free(&s), cf_mesh_free(&m);
    }
    printf("FIGURE front split: without, %d facets taken, %d of the crack's 3 first vertices "
           "parted; with, %d taken (%d off its plane), %d parted; within 0.05 m, %d taken, "
           "%d parted\n",
           taken[0], parted[0], taken[1], off_plane[1], parted[1], taken[2], parted[2]);
    assert_true(taken[0] >= 1);
    assert_int_equal(parted[0], 0);
    assert_true(taken[1] > taken[0]);
    assert_int_equal(off_plane[1], 0);
    assert_true(parted[1] >= 2);
    /* every facet of a vertex's star has its centroid at least 0.08 m from
     * it on cells of 0.25 m: a reach of 0.05 m takes none of them */
    assert_int_equal(taken[2], taken[0]);
    assert_int_equal(parted[2], 0);
}

/* A front's vertex ahead moves onto the plane across the tension
 * (solver.front_snap "stress", docs/physics.md §5.1 rule 3).  In a box of
 * 6^3 cells under a uniaxial tension along d = (0, cos 0.3, sin 0.3), 1.8
 * times the strength, stretched uniformly by A (x = A X) and moving with a
 * non-uniform velocity, a crack of one facet on y = 0.5 at the centre
 * grows in one check by fronts across the tension.  Each vertex that
 * moves is the vertex ahead of a facet taken, and its distance from the
 * plane through that facet's front edge with rest normal A^T d (the
 * tension's normal pulled back) falls to 0, a half or three quarters of
 * what it was (the whole move, or half or a quarter of it); every tet
 * keeps the gradient A to round-off (the current position moves by A
 * times the rest shift), and the mass, the volume and the momentum are
 * unchanged to round-off.  The step's least height is halved, as on a
 * mesh whose worst tet lies elsewhere: on this box every tet sets it. */
static void test_front_snap_moves_the_vertex_onto_the_plane(void **state)
{
    (void)state;
    cf_mesh m;
    cf_solid s;
    fixture_box(&m, 6, 6, 6, 1, 1, 1);
    int *all = stressed_box(&s, &m, 0, 1.0, 1e9), f0 = -1;
    double d[3] = {0, cos(0.3), sin(0.3)}, sig = 1.8;
    double A[9] = {1.0005, 0.0002, 0, 0, 1.001, 0.0007, 0.0001, 0, 0.9995};
    for (int t = 0; t < s.n_tets; t++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                s.sigma[9 * t + 3 * i + j] = sig * d[i] * d[j];
    for (int i = 0; i < s.n_nodes; i++)
        m3_mulv(A, &s.X[3 * i], &s.x[3 * i]);
    s.dt_cfl *= 0.5;
    double P0[3], M0, V0 = 0, u0[3];
    f0 = central_facet(&s);
    old_crack(&s, f0);
    momentum(&s, P0, &M0);
    for (int t = 0; t < s.n_tets; t++)
        V0 += s.vol[t];
    double *X0 = malloc((size_t)s.n_nodes * 3 * sizeof(double));
    memcpy(X0, s.X, (size_t)s.n_nodes * 3 * sizeof(double));
    for (int k = 0; k < 3; k++) /* the rest normal of the tension's planes */
        u0[k] = A[k] * d[0] + A[3 + k] * d[1] + A[6 + k] * d[2];
    cf_growth g = {CF_GROWTH_FRONTS, 1e-6, 0, 0, 0.0, 1, 0, 0, 0, 1};
    cf_int_list cand = {0};
    int n = cf_insertion_candidates(&s, all, s.n_tets, CF_CRITERION_SOURCE, s.n_tets, &g, &cand);
    n = n > 0 ? cf_insertion_select(&s, &cand, CF_CRITERION_SOURCE, &g) : n;
    assert_true(n >= 1);
    int moved = 0, whole = 0, onto = 0;
    for (int c = 0; c < s.n_verts0; c++) {
        double sh[3];
        v3_sub(&s.X[3 * c], &X0[3 * c], sh);
        if (v3_norm(sh) == 0)
            continue;
        moved++;
        for (int i = 0, found = 0; i < n && !found; i++) { /* the facet it is ahead of */
            int o[3], a = 0;
            facet_vertices(&s, cand.v[i], o);
            while (a < 3 && o[a] != c)
                a++;
            if (a == 3)
                continue;
            int e0 = o[(a + 1) % 3], e1 = o[(a + 2) % 3];
            double e[3], u[3], r0[3], r1[3];
            v3_sub(&s.X[3 * e1], &s.X[3 * e0], e);
            memcpy(u, u0, sizeof u);
            v3_axpy(-v3_dot(u, e) / v3_dot(e, e), e, u);
            v3_sub(&X0[3 * c], &s.X[3 * e0], r0), v3_sub(&s.X[3 * c], &s.X[3 * e0], r1);
            double q = v3_dot(r1, u) / v3_dot(r0, u);
            found = fabs(q) < 1e-9 || fabs(q - 0.5) < 1e-9 || fabs(q - 0.75) < 1e-9;
            onto += found, whole += found && fabs(q) < 1e-9;
        }
    }
    double worst = 0, P[3], M, V = 0;
    for (int t = 0; t < s.n_tets; t++) {
        const int *C = &s.tet[4 * t];
        double Ds[9], F[9];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                Ds[3 * r + c] = s.x[3 * C[c + 1] + r] - s.x[3 * C[0] + r];
        m3_mul(Ds, &s.Dm_inv[9 * t], F);
        for (int k = 0; k < 9; k++)
            worst = fmax(worst, fabs(F[k] - A[k]));
        V += s.vol[t];
    }
    momentum(&s, P, &M);
    printf("FIGURE front snap: %d facets taken, %d vertices moved, %d towards their plane "
           "(%d the whole way); largest |F - A| %.2e; mass %.2e, volume %.2e, momentum %.2e "
           "apart\n",
           n, moved, onto, whole, worst, fabs(M - M0) / M0, fabs(V - V0) / V0,
           fabs(P[0] - P0[0]) + fabs(P[1] - P0[1]) + fabs(P[2] - P0[2]));
    assert_true(moved >= 1);
    assert_int_equal(onto, moved);
    assert_true(worst < 1e-12);
    assert_true(fabs(M - M0) < 1e-12 * M0 && fabs(V - V0) < 1e-12 * V0);
    for (int k = 0; k < 3; k++)
        assert_true(fabs(P[k] - P0[k]) < 1e-12 * (fabs(P0[0]) + fabs(P0[1]) + fabs(P0[2])));
    free(X0), free(cand.v), free(all);
    cf_solid_free(&s), cf_mesh_free(&m);
}

/* A front's rank reads only this check's nodal values (facet_ratio): a
 * node on its cracked edge that no hot tet holds is not valued, and reads
 * as 0, not as whatever the array kept from another check.  A box under a
 * uniaxial tension of 3.3 thresholds with one old crack, the tets at the
 * crack's vertices cold and unloaded: one check takes the same fronts
 * whether the array held zeros or other values (the ranking decides which
 * front wins a tet two of them share). */
static void test_front_rank_reads_this_check_only(void **state)
{
    (void)state;
    int n[2];
    unsigned char *taken[2];
    for (int stale = 0; stale < 2; stale++) {
        cf_mesh m;
        cf_solid s;
        int *all = box_with_crack(&m, &s, 3.0), f0 = middle_facet(&s), o0[3];
        facet_vertices(&s, f0, o0);
        for (int t = 0; t < s.n_tets; t++)
            for (int j = 0; j < 4; j++)
                if (s.tet0[4 * t + j] == o0[0] || s.tet0[4 * t + j] == o0[1] ||
                    s.tet0[4 * t + j] == o0[2]) {
                    s.hot[t] = 0;
                    memset(&s.sigma[9 * t], 0, 9 * sizeof(double));
                }
        unsigned r = 12345;
        for (int a = 0; a < s.n_nodes; a++, r = r * 1103515245u + 12345u)
            s.nodal[a] = stale ? (double)(r >> 16 & 1023) : 0.0;
        cf_int_list cand = {0};
        n[stale] = check_fronts(&s, all, 0, &cand);
        taken[stale] = calloc((size_t)s.n_facets, 1);
        for (int i = 0; i < n[stale]; i++)
            taken[stale][cand.v[i]] = 1;
        if (stale)
            assert_memory_equal(taken[0], taken[1], (size_t)s.n_facets);
        free(cand.v), free(all);
        cf_solid_free(&s), cf_mesh_free(&m);
    }
    printf("FIGURE front rank: %d facets taken with a clean array, %d with stale values\n", n[0],
           n[1]);
    assert_true(n[0] >= 1);
    assert_int_equal(n[0], n[1]);
    free(taken[0]), free(taken[1]);
}

/* A front's threshold from the toughness (solver.front_threshold
 * "toughness", docs/physics.md §5.1).  A box of 0.25 m cells under a
 * uniaxial tension sy of 0.6 of a facet's threshold, with one crack normal
 * to it: no facet reaches its strength, so with the strength's threshold
 * the crack takes nothing.  With K_IC = 0.4 Pa m^1/2 the field of a tip at
 * the toughness a facet's height ahead (r <= 0.25 sqrt(2) m) is
 * K_IC / sqrt(2 pi r) >= 0.27 Pa, and the crack grows: every facet it takes
 * is a front whose normal stress reaches at least that, and none is
 * enclosed by nuclei (sy passes no facet's strength). */
static void test_front_threshold_from_the_toughness(void **state)
{
    (void)state;
    double thr = 0.9, sy = 0.6 * thr, K = 0.4, r_max = 0.25 * sqrt(2.0);
    int taken[2], below = 0;
    for (int tough = 0; tough < 2; tough++) {
        cf_mesh m;
        cf_solid s;
        int *all = box_with_crack(&m, &s, sy);
        if (tough) {
            s.mat.G_I = K * K / s.mat.E;
            assert_int_equal(cf_solid_init_front_toughness(&s, 0, NULL), CF_OK);
            assert_float_equal(s.front_K, K, 1e-12);
            assert_true(s.front_floor_min <= K / sqrt(2 * acos(-1.0) * r_max));
        }
        cf_int_list cand = {0};
        int n = check_fronts(&s, all, 1, &cand);
        taken[tough] = n;
        for (int i = 0; i < n; i++) {
            double ny = facet_normal_y(&s, cand.v[i]);
            below += sy * ny * ny < K / sqrt(2 * acos(-1.0) * r_max);
        }
        free(cand.v), free(all);
        cf_solid_free(&s), cf_mesh_free(&m);
    }
    printf("FIGURE front threshold from the toughness: %d facets taken at 0.6 of the "
           "strength's threshold (%d with the strength's)\n", taken[1], taken[0]);
    assert_int_equal(taken[0], 0);
    assert_true(taken[1] >= 1);
    assert_int_equal(below, 0);
}

/* A front's threshold from a penny crack (solver.front_threshold "crack",
 * docs/physics.md §5.1).  The box of test_front_threshold_from_the_toughness
 * under sy = 0.6 of a facet's threshold, its crack of one facet f0, K_IC
 * such that a penny crack is critical under sy at radius a_c = pi K^2 /
 * (4 sy^2) = 0.03 m, and three checks, each later than the last: the crack
 * grows from its fronts (with the strength's threshold it takes nothing,
 * as that test shows), every facet taken belongs to f0's crack, and each
 * extends an edge that a facet cracked in an earlier check holds, at a
 * radius a (f0's rest centroid to the edge's midpoint) whose penny-crack
 * threshold K_IC sqrt(pi) / (2 sqrt(a)) its normal stress sy n_y^2
 * reaches: the closed form, from the test's own geometry.  A facet at 45
 * degrees to the tension (sy / 2) is below the first fronts' threshold
 * (a about 0.06-0.09 m) and above a wider crack's. */
static void test_front_threshold_from_a_penny_crack(void **state)
{
    (void)state;
    double thr = 0.9, sy = 0.6 * thr, a_c = 0.03, K = 2 * sy * sqrt(a_c / acos(-1.0));
    cf_mesh m;
    cf_solid s;
    int *all = box_with_crack(&m, &s, sy), f0 = middle_facet(&s), taken = 0, tilted[3] = {0};
    s.mat.G_I = K * K / s.mat.E;
    assert_int_equal(cf_solid_init_front_toughness(&s, 1, NULL), CF_OK);
    cf_insertion_init_front_floors(&s);
    double c0[3] = {0, 0, 0}, a_min = INFINITY;
    int o0[3];
    facet_vertices(&s, f0, o0);
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++)
            c0[k] += s.X[3 * o0[i] + k] / 3;
    for (int round = 0; round < 3; round++) {
        unsigned char *before = malloc((size_t)s.n_facets);
        memcpy(before, s.cracked, (size_t)s.n_facets);
        cf_growth g = {CF_GROWTH_FRONTS, 1e-6, 0, 0, 1e9 * (round + 1), 1, 0, 0, 0, 0};
        cf_int_list cand = {0};
        memset(s.hot, 1, (size_t)s.n_tets);
        int n = cf_insertion_candidates(&s, all, s.n_tets, CF_CRITERION_SOURCE, s.n_tets, &g,
                                        &cand);
        n = n > 0 ? cf_insertion_select(&s, &cand, CF_CRITERION_SOURCE, &g) : n;
        for (int i = 0; i < n; i++) {
            int h = cand.v[i], o[3], fronts = 0;
            double ny = facet_normal_y(&s, h), lowest = INFINITY;
            assert_int_equal(s.nucleus[h], f0);
            facet_vertices(&s, h, o);
            for (int e = 0; e < 3; e++) {
                int a = o[(e + 1) % 3], b = o[(e + 2) % 3], old = 0;
                for (int g2 = 0; g2 < s.n_facets; g2++) {
                    int og[3], on = 0;
                    facet_vertices(&s, g2, og);
                    for (int q = 0; q < 3; q++)
                        on += og[q] == a || og[q] == b;
                    old |= g2 != h && before[g2] && on == 2;
                }
                if (!old)
                    continue;
                double d[3];
                for (int k = 0; k < 3; k++)
                    d[k] = c0[k] - 0.5 * (s.X[3 * a + k] + s.X[3 * b + k]);
                lowest = fmin(lowest, K * sqrt(acos(-1.0)) / (2 * sqrt(v3_norm(d))));
                a_min = fmin(a_min, v3_norm(d));
                fronts++;
            }
            assert_true(fronts >= 1);
            assert_true(sy * ny * ny >= lowest * (1 - 1e-9));
            tilted[round] += ny * ny < 0.9;
        }
        taken += n;
        free(cand.v), free(before);
    }
    printf("FIGURE front threshold from a penny crack: %d facets taken in 3 checks at 0.6 of "
           "the strength's threshold, fronts from a = %.3f m (a_c = %.2f m); facets at 45 "
           "degrees to the tension %d, %d, %d\n",
           taken, a_min, a_c, tilted[0], tilted[1], tilted[2]);
    /* the first fronts are too short for a facet at 45 degrees (sy / 2 below their
     * threshold), the wider crack's are not */
    assert_true(taken >= 1 && tilted[0] == 0 && tilted[1] + tilted[2] >= 1);
    free(all);
    cf_solid_free(&s), cf_mesh_free(&m);
}

/* The 4-cell box of m with a Weibull strength field (modulus 6, reference
 * area 0.01, seed 3) of mean strength near `strength` (Pa), deformed and
 * checked once under the source's rule (deform_and_check), with an old
 * crack at its middle facet.  Returns all its tets. */
static int *weibull_box_with_crack(cf_solid *s, cf_mesh *m, double strength)
{
    fixture_box(m, 4, 4, 4, 1, 1, 1);
    cf_material mt = mat;
    mt.weibull = 1, mt.weibull_modulus = 6, mt.strength_seed = 3, mt.strength_area = 0.01;
    mt.sigma_max = mt.tau_max = strength;
    int *body = calloc((size_t)m->n_tets, sizeof(int));
    assert_int_equal(cf_solid_init(s, m, &mt, body, NULL), CF_OK);
    assert_int_equal(cf_solid_init_facets(s, NULL), CF_OK);
    free(body);
    int n_hot, *all = deform_and_check(s, CF_CRITERION_SOURCE, &n_hot), f0 = middle_facet(s);
    assert_true(f0 >= 0);
    old_crack(s, f0);
    return all;
}

/* With fronts that run across the tension, no rank reads a nodal value
 * below its vertex's floor (the weakest facet on it), so the values are
 * exact only from there up (cf_insertion_candidates with the growth rule)
 * and the eigenvalue is skipped where a bound shows a node below it: on a
 * deformed box with a strength field and a crack, at strengths where some
 * facets qualify, the check takes the same facets as with the values exact
 * from the solid's weakest facet up (no growth rule given), and at some
 * nodes the two values differ, each below its vertex's floor. */
static void test_values_exact_from_the_floor_take_the_same_facets(void **state)
{
    (void)state;
    int skipped = 0, taken = 0;
    for (int level = 0; level < 4; level++) {
        double strength = 0.2 * (1 << level) * 0.02 * mat.E;
        int n[2], *picks[2], nn = 0;
        double *nodal[2];
        for (int exact_from_floor = 0; exact_from_floor < 2; exact_from_floor++) {
            cf_mesh m;
            cf_solid s;
            int *all = weibull_box_with_crack(&s, &m, strength);
            cf_growth g = {CF_GROWTH_FRONTS, 1e-6, 0, 0, 0.0, 1, 0, 0, 0, 0};
            cf_int_list cand = {0};
            int nc = cf_insertion_candidates(&s, all, s.n_tets, CF_CRITERION_SOURCE, s.n_tets,
                                             exact_from_floor ? &g : NULL, &cand);
            nodal[exact_from_floor] = malloc((size_t)s.n_nodes * sizeof(double));
            memcpy(nodal[exact_from_floor], s.nodal, (size_t)s.n_nodes * sizeof(double));
            nn = s.n_nodes;
            n[exact_from_floor] = nc > 0 ? cf_insertion_select(&s, &cand, CF_CRITERION_SOURCE, &g) : nc;
            picks[exact_from_floor] = cand.v;
            if (exact_from_floor) /* the floors of the nodes whose values differ */
                for (int i = 0; i < nn; i++)
                    if (nodal[0][i] != nodal[1][i]) {
                        double floor = 0.9 * strength * s.vert_wmin[s.origin[i]];
                        assert_true(nodal[0][i] < floor && nodal[1][i] < floor);
                        skipped++;
                    }
            free(all);
            cf_solid_free(&s), cf_mesh_free(&m);
        }
        assert_int_equal(n[0], n[1]);
        for (int i = 0; i < n[0]; i++)
            assert_int_equal(picks[0][i], picks[1][i]);
        taken += n[0];
        free(picks[0]), free(picks[1]), free(nodal[0]), free(nodal[1]);
    }
    printf("FIGURE values exact from the floor: %d facets taken alike, %d node values skipped\n",
           taken, skipped);
    assert_true(taken >= 1 && skipped >= 1);
}

/* Three checks of growing cracks on the box of `weibull` (0: box_with_crack
 * under sy = 0.6 of the threshold, uniform strength; 1: the deformed
 * Weibull box with a crack at `strength`) with K_IC = K: with the floors
 * of the cracks there are (`floors`, hot flags from the tet bound and its
 * s1_tet), or with every tet hot and each vertex's lowest front floor
 * wherever it lies.  The facets taken go to picks[round]; returns the
 * checks with fewer tets hot than all.  Each tet's count of the cracked
 * facets on its edges must equal a count of the facets. */
static int checks_with_floors(int weibull, double strength, double K, int floors, int crack,
                              cf_int_list picks[3])
{
    cf_mesh m;
    cf_solid s;
    int *all = weibull ? weibull_box_with_crack(&s, &m, strength)
                       : box_with_crack(&m, &s, 0.6 * 0.9 * strength);
    s.mat.G_I = K * K / s.mat.E;
    assert_int_equal(cf_solid_init_front_toughness(&s, crack, NULL), CF_OK);
    if (floors) /* without: every vertex's lowest front floor, the solid's hot bound */
        cf_insertion_init_front_floors(&s);
    int cooler = 0;
    for (int round = 0; round < 3; round++) {
        cf_growth g = {CF_GROWTH_FRONTS, 1e-6, 0, 0, 1e9 * (round + 1), 1, 0, 0, 0, 0};
        cf_stress_check bound = cf_insertion_bound(&s, CF_CRITERION_SOURCE);
        int n_hot = s.n_tets;
        if (floors && weibull) /* the kernel's flags */
            cf_tet4_forces(&s, all, s.n_tets, CF_ELASTICITY_COROTATIONAL, &bound, 0, &n_hot);
        else if (floors) /* the same test on the box's given stress */
            for (int t = n_hot = 0; t < s.n_tets; t++)
                n_hot += s.hot[t] = cf_tet4_max_principal_bound(&s.sigma[9 * t]) >=
                                    fmax(bound.s1, bound.s1_tet[t]);
        else
            memset(s.hot, 1, (size_t)s.n_tets);
        cooler += n_hot < s.n_tets;
        int n = cf_insertion_candidates(&s, all, s.n_tets, CF_CRITERION_SOURCE, n_hot, &g,
                                        &picks[round]);
        picks[round].n = n > 0 ? cf_insertion_select(&s, &picks[round], CF_CRITERION_SOURCE, &g) : n;
    }
    if (floors) { /* near a crack: sharing a tet with a vertex a facet ever cracked on */
        unsigned char *near = calloc((size_t)s.n_verts0, 1);
        for (int t = 0; t < s.n_tets; t++)
            for (int i = 0; i < 4; i++)
                for (int j = 0; j < 4; j++)
                    near[s.tet0[4 * t + i]] |= s.vert_cracks[s.tet0[4 * t + j]] > 0;
        for (int o = 0; o < s.n_verts0; o++)
            assert_int_equal(s.vert_front_near[o], near[o]);
        for (int t = 0; t < s.n_tets; t++) {
            const int *T = &s.tet0[4 * t];
            assert_true((s.tet_floor[t] == 0) == (near[T[0]] || near[T[1]] || near[T[2]] || near[T[3]]));
        }
        free(near);
    }
    static const int edge[4][4] = {{0, 0, 1, 2}, {0, 0, 3, 4}, {1, 3, 0, 5}, {2, 4, 5, 0}};
    for (int t = 0; t < s.n_tets; t++)
        for (int i = 0; i < 4; i++)
            for (int j = i + 1; j < 4; j++)
                assert_int_equal(s.edge_cracks[6 * t + edge[i][j]],
                                 cracked_on_edge(&s, s.tet0[4 * t + i], s.tet0[4 * t + j]));
    /* and the faces the criterion asks: interior, owned, not cracked */
    for (int t = 0; t < s.n_tets; t++)
        for (int k = 0; k < 4; k++) {
            const int f = s.tet_facet[4 * t + k], *F = &s.facet[4 * f];
            assert_int_equal(s.tet_open[t] >> k & 1, F[2] >= 0 && F[0] == t && !s.cracked[f]);
        }
    free(all);
    cf_solid_free(&s), cf_mesh_free(&m);
    return cooler;
}

/* With a front threshold from the toughness, a vertex that no cracked edge
 * faces keeps its strength's floor and a tet away from the cracks its own
 * hot bound (cf_insertion_init_front_floors): three checks of growing
 * cracks take the same facets as with every tet hot and each vertex's
 * lowest front floor wherever it lies, while fewer tets are hot.  On the
 * box under uniform tension below every strength only fronts grow (K_IC
 * as in test_front_threshold_from_the_toughness); on the deformed Weibull
 * box, with K_IC such that a tip's field a cell ahead is half the
 * threshold, fronts and nuclei.  The same with the penny crack's threshold
 * ("crack") at a quarter of that K_IC, about the tip's field at the first
 * fronts (a near a quarter of a cell, r near one). */
static void test_toughness_floors_take_the_same_facets(void **state)
{
    (void)state;
    int taken[2][2] = {{0, 0}, {0, 0}}, cooler = 0;
    for (int level = 0; level < 10; level++) {
        int crack = level >= 5;
        int weibull = level % 5 > 0;
        double strength = weibull ? 0.2 * (1 << (level % 5 - 1)) * 0.02 * mat.E : 1.0;
        double K = (weibull ? 0.45 * strength * sqrt(2 * acos(-1.0) * 0.25) : 0.4) /
                   (crack ? 4 : 1);
        cf_int_list picks[2][3] = {{{0}}};
        for (int floors = 0; floors < 2; floors++)
            cooler += checks_with_floors(weibull, strength, K, floors, crack, picks[floors]);
        for (int round = 0; round < 3; round++) {
            assert_int_equal(picks[0][round].n, picks[1][round].n);
            for (int i = 0; i < picks[0][round].n; i++)
                assert_int_equal(picks[0][round].v[i], picks[1][round].v[i]);
            taken[crack][weibull] += picks[0][round].n;
            free(picks[0][round].v), free(picks[1][round].v);
        }
    }
    printf("FIGURE toughness floors: %d facets taken alike under tension, %d on the Weibull "
           "box; penny crack's %d and %d; %d checks with fewer tets hot\n",
           taken[0][0], taken[0][1], taken[1][0], taken[1][1], cooler);
    for (int crack = 0; crack < 2; crack++)
        assert_true(taken[crack][0] >= 3 && taken[crack][1] >= 3);
    assert_true(cooler >= 6);
}

/* The size-free strength factor of facet f of area A_f on the box of
 * `cells` per edge (seed `seed`, reference area A0, modulus m), its rest
 * centroid and (A_f / A0) w_f^m (for a facet larger than A0).  Returns the
 * number of interior facets written. */
static int box_strengths(int cells, int seed, double A0, double modulus, double *w, double *cen,
                         double *area)
{
    cf_mesh m;
    fixture_box(&m, cells, cells, cells, 1, 1, 1);
    cf_material mt = mat;
    mt.weibull = 1, mt.weibull_modulus = modulus, mt.strength_seed = seed, mt.strength_area = A0;
    int *body = calloc((size_t)m.n_tets, sizeof(int));
    cf_solid s;
    assert_int_equal(cf_solid_init(&s, &m, &mt, body, NULL), CF_OK);
    assert_int_equal(cf_solid_init_facets(&s, NULL), CF_OK);
    int n = 0;
    for (int f = 0; f < s.n_facets; f++) {
        const int *F = &s.facet[4 * f];
        if (F[2] < 0)
            continue;
        const double *p[3];
        for (int i = 0; i < 3; i++)
            p[i] = &s.X[3 * s.tet0[4 * F[0] + CF_TET_FACE[F[1]][i]]];
        double e1[3], e2[3], nrm[3];
        v3_sub(p[1], p[0], e1), v3_sub(p[2], p[0], e2), v3_cross(e1, e2, nrm);
        area[n] = 0.5 * v3_norm(nrm);
        for (int k = 0; k < 3; k++)
            cen[3 * n + k] = (p[0][k] + p[1][k] + p[2][k]) / 3.0;
        w[n] = s.strength[f] * pow(fmax(area[n] / A0, 1.0), 1.0 / modulus);
        n++;
    }
    free(body);
    cf_solid_free(&s), cf_mesh_free(&m);
    return n;
}

/* The strength is a field of the material (docs/physics.md §5.1, rule 2).
 * With A0 = 0.02 m^2 (L = 0.14 m) the coarse box's facets (4 cells per
 * edge) are all larger than A0 and the fine box's (8 per edge) all
 * smaller:
 * - the fine facets' factors are Weibull of scale 1 (w^m exponential,
 *   mean 1) and the coarse ones are weakest links, (A/A0) w^m of mean 1,
 *   over 16 seeds within four standard errors of the independent regions;
 * - the two meshes see the same material: the factors of a fine and a
 *   coarse facet whose (distinct) centroids are less than L/2 apart
 *   correlate (log-strength correlation above 0.7), those 2 L apart do
 *   not (below 0.25 in magnitude).  A per-facet draw gives 0 for both. */
static void test_strength_is_a_field_of_the_material(void **state)
{
    (void)state;
    const double modulus = 6, A0 = 0.02, L = sqrt(A0);
    enum { MAX = 20000, SEEDS = 16 };
    double *w[2], *cen[2], *area[2];
    int n[2];
    for (int i = 0; i < 2; i++)
        w[i] = malloc(MAX * sizeof(double)), cen[i] = malloc(3 * MAX * sizeof(double)),
        area[i] = malloc(MAX * sizeof(double));
    double zsum[2] = {0, 0}, cnum[2] = {0, 0};
    double pair[2][6] = {{0}}; /* near, far: count and sums of a, b, ab, a^2, b^2 (log w) */
    for (int seed = 1; seed <= SEEDS; seed++) {
        for (int i = 0; i < 2; i++) {
            n[i] = box_strengths(4 << i, seed, A0, modulus, w[i], cen[i], area[i]);
            for (int f = 0; f < n[i]; f++) {
                assert_true(i == 0 ? area[i][f] > A0 : area[i][f] < A0);
                zsum[i] += pow(w[i][f], modulus), cnum[i]++;
            }
        }
        for (int f = 0; f < n[1]; f++)
            for (int g = 0; g < n[0]; g++) {
                double d[3];
                v3_sub(&cen[1][3 * f], &cen[0][3 * g], d);
                double r = v3_norm(d);
                int k = r > 1e-9 && r < 0.5 * L ? 0 : fabs(r - 2 * L) < 0.05 * L ? 1 : -1;
                if (k < 0)
                    continue;
                double a = log(w[1][f]), b = log(w[0][g]);
                double add[6] = {1, a, b, a * b, a * a, b * b};
                for (int j = 0; j < 6; j++)
                    pair[k][j] += add[j];
            }
    }
    /* independent regions: the box's volume over L^3, per seed */
    double regions = SEEDS / (L * L * L);
    for (int i = 0; i < 2; i++) {
        double z = zsum[i] / cnum[i];
        printf("FIGURE strength field: %s mesh, mean %s %.4f (1 +- %.4f)\n", i ? "fine" : "coarse",
               i ? "w^m" : "(A/A0) w^m", z, 4 / sqrt(regions));
        assert_true(fabs(z - 1) <= 4 / sqrt(regions));
    }
    double corr[2];
    for (int k = 0; k < 2; k++) {
        const double *p = pair[k];
        double ma = p[1] / p[0], mb = p[2] / p[0];
        corr[k] = (p[3] / p[0] - ma * mb) /
                  sqrt((p[4] / p[0] - ma * ma) * (p[5] / p[0] - mb * mb));
        printf("FIGURE strength field: facets of the two meshes %s, %.0f pairs, log-strength "
               "correlation %.3f\n", k ? "2 L apart" : "apart by less than L/2", p[0], corr[k]);
    }
    assert_true(corr[0] > 0.7);
    assert_true(fabs(corr[1]) < 0.25);
    for (int i = 0; i < 2; i++)
        free(w[i]), free(cen[i]), free(area[i]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_tets_split_into_two_fragments),
        cmocka_unit_test(test_penalty_engages_only_on_approach),
        cmocka_unit_test(test_normal_traction_rises_from_zero),
        cmocka_unit_test(test_pressed_faces_slide_by_coulomb_friction),
        cmocka_unit_test(test_cohesive_work_is_the_forces_work),
        cmocka_unit_test(test_box_split_along_a_plane),
        cmocka_unit_test(test_bars_patched_after_insertion_equal_a_rebuild),
        cmocka_unit_test(test_criterion_selects_facets_normal_to_tension),
        cmocka_unit_test(test_bound_never_misses_a_facet),
        cmocka_unit_test(test_source_rule_equals_brute_force),
        cmocka_unit_test(test_flagged_chunks_keep_order),
        cmocka_unit_test(test_fronts_close_no_small_piece),
        cmocka_unit_test(test_front_moves_no_faster_than_its_speed),
        cmocka_unit_test(test_front_rule_reads_the_stress_ahead),
        cmocka_unit_test(test_fronts_do_not_branch),
        cmocka_unit_test(test_fronts_run_across_the_tension),
        cmocka_unit_test(test_fronts_kink_no_further_than_the_limit),
        cmocka_unit_test(test_front_split_opens_the_crack_to_its_front),
        cmocka_unit_test(test_front_snap_moves_the_vertex_onto_the_plane),
        cmocka_unit_test(test_values_exact_from_the_floor_take_the_same_facets),
        cmocka_unit_test(test_front_rank_reads_this_check_only),
        cmocka_unit_test(test_front_threshold_from_the_toughness),
        cmocka_unit_test(test_front_threshold_from_a_penny_crack),
        cmocka_unit_test(test_toughness_floors_take_the_same_facets),
        cmocka_unit_test(test_contact_memo_changes_nothing),
        cmocka_unit_test(test_strength_is_a_field_of_the_material),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
