/* cohfrac — the stability map (see src/cli/stability.h for the
 * cases, the criteria and the files). */
#define _GNU_SOURCE
#include "stability.h"
#include "cohfrac/mesh.h"
#include "cohfrac/scene.h"
#include "cohfrac/sim.h"
#include "clock.h"
#include "file_text.h"
#include "linalg.h"
#include "mpi_cases.h"
#include "report.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SIDE 0.1            /* m, the cube */
#define CELLS 3
#define SLIVER_SHIFT 0.45   /* of a cell, the largest move of an interior node */
#define SLIVER_NAME "sliver_cube" /* beside the scene files (scene paths are relative to them) */

static const double E_AXIS[] = {0.6, 1e3, 1e6, 1e9, 7e10, 2e11};
static const double DT_AXIS[] = {0.5, 1, 2, 10, 100, 1000};
static const double SPEED_AXIS[] = {1, 10, 100};
static const double MASS_AXIS[] = {0.01, 0.1, 1, 10, 100};
static const double E_QUICK[] = {0.6, 7e10};
static const double DT_QUICK[] = {0.5, 10, 100};
static const double MASS_QUICK[] = {0.01, 100};
#define LEN(a) ((int)(sizeof(a) / sizeof(a)[0]))

const char *cf_stability_mode_name(cf_stability_mode m)
{
    static const char *const names[] = {"none", "pbd_k0.9_it3", "pbd_k1_it10", "xpbd"};
    return m >= 0 && m < CF_STAB_N_MODES ? names[m] : "?";
}

/* The pieces both generated scenes share: no gravity, the material (E is
 * set per case), one cube of 3^3 cells, fracture mode without insertion
 * and the guard's criteria. */
#define SCENE_COMMON                                                                       \
    ", duration = 1, gravity = {0, 0, 0},\n"                                               \
    "  material = {E = 1e6, nu = 0.25, rho = 2400, G_I = 1, sigma_max = 1,\n"             \
    "              friction = 0.5, restitution = 0},\n"
#define SCENE_CUBE                                                                         \
    "{mesh = {type = 'box', size = {0.1, 0.1, 0.1}, cells = {3, 3, 3},\n"                 \
    "                     tets_per_cell = 6}"
#define SCENE_SOLVER                                                                       \
    "  solver = {mode = 'fracture', criterion = 'none', cfl_fraction = 1, threads = 1,\n"  \
    "            guard = {max_energy_growth = 0.1, max_inverted_fraction = 0.01}},\n"      \
    "  output = {file = ''},\n"                                                             \
    "}\n"

static const char *const scene_text =
    "-- Written by `cohfrac stability`: the base case (see cohfrac/stability.h).\n"
    "return {\n"
    "  name = 'stability'" SCENE_COMMON
    "  bodies = {" SCENE_CUBE ",\n"
    "             position = {0, 0, 0.05}, velocity = {0, 0, -10}}},\n"
    "  obstacles = {{type = 'plane', point = {0, 0, 0}, normal = {0, 0, 1}}},\n"
    SCENE_SOLVER;

/* The mass-ratio slice: the same cube at rest, hit on its top face by a
 * cube of the same material and mesh, side 0.1 (m_impactor/m_target)^(1/3)
 * m; no obstacle. */
static const char *const pair_scene_text =
    "-- Written by `cohfrac stability`: the mass-ratio case (see cohfrac/stability.h).\n"
    "return {\n"
    "  name = 'stability_pair'" SCENE_COMMON
    "  bodies = {" SCENE_CUBE ", position = {0, 0, 0}},\n"
    "            " SCENE_CUBE ",\n"
    "             position = {0, 0, 0.1}, velocity = {0, 0, -10}}},\n"
    SCENE_SOLVER;

/* 6 sqrt(2) V / l_max^3 of a tet: 1 for a regular tet, 0 for a flat one,
 * negative when inverted. */
static double tet_quality(const double *x, const int *v)
{
    double e[3][3], c[3], lmax = 0;
    for (int j = 0; j < 3; j++)
        v3_sub(&x[3 * v[j + 1]], &x[3 * v[0]], e[j]);
    v3_cross(e[1], e[2], c);
    double vol = v3_dot(e[0], c) / 6;
    for (int i = 0; i < 4; i++)
        for (int j = i + 1; j < 4; j++) {
            double d[3];
            v3_sub(&x[3 * v[i]], &x[3 * v[j]], d);
            lmax = fmax(lmax, v3_norm(d));
        }
    return 6 * sqrt(2.0) * vol / (lmax * lmax * lmax);
}

/* The grid of the regular cube with its interior nodes moved at random (a
 * fixed seed) by up to SLIVER_SHIFT of a cell per axis; a draw that inverts
 * a tet is drawn again.  Writes DIR/SLIVER_NAME.{node,ele}; *quality gets
 * the smallest 6 sqrt(2) V / l_max^3 over the tets (1 for a regular tet). */
static cf_status write_sliver_mesh(const char *dir, double *quality, cf_error *err)
{
    const double size[3] = {SIDE, SIDE, SIDE};
    const int cells[3] = {CELLS, CELLS, CELLS};
    cf_mesh m = {0};
    cf_status st = cf_mesh_box(size, cells, 6, &m, err);
    if (st != CF_OK)
        return st;
    double *x0 = malloc((size_t)m.n_nodes * 3 * sizeof(double));
    if (!x0) {
        cf_mesh_free(&m);
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    }
    memcpy(x0, m.x, (size_t)m.n_nodes * 3 * sizeof(double));
    uint64_t seed = 0x9e3779b97f4a7c15ull;
    double h = SIDE / CELLS, q = 0;
    for (int draw = 0; draw < 1000 && q <= 0; draw++) {
        for (int a = 0; a < m.n_nodes; a++)
            for (int k = 0; k < 3; k++) {
                double *xa = &m.x[3 * a + k];
                *xa = x0[3 * a + k];
                int interior = 1;
                for (int c = 0; c < 3; c++)
                    interior &= fabs(fabs(x0[3 * a + c]) - 0.5 * SIDE) > 1e-9;
                seed = seed * 6364136223846793005ull + 1442695040888963407ull;
                double u = (double)(seed >> 11) / 9007199254740992.0; /* [0, 1) */
                if (interior)
                    *xa += SLIVER_SHIFT * h * (2 * u - 1);
            }
        q = INFINITY;
        for (int t = 0; t < m.n_tets; t++)
            q = fmin(q, tet_quality(m.x, &m.tets[4 * t]));
    }
    free(x0);
    *quality = q;
    char base[1100];
    snprintf(base, sizeof base, "%s/%s", dir, SLIVER_NAME);
    st = q > 0 ? cf_mesh_write_tetgen(&m, base, err)
               : cf_error_set(err, CF_ERR_MESH_INVERTED, "no valid sliver mesh drawn");
    cf_mesh_free(&m);
    return st;
}

/* The case's --set overrides; `dt` > 0 also fixes dt_rigid and the duration. */
static int case_overrides(const cf_stability_case *c, double dt, char ov[][160])
{
    int n = 0;
    snprintf(ov[n++], 160, "material.E=%.17g", c->E);
    snprintf(ov[n++], 160, "solver.cfl_fraction=%.17g", c->dt_ratio);
    if (c->mass_ratio > 0) {
        double a = SIDE * cbrt(c->mass_ratio);
        snprintf(ov[n++], 160, "bodies[2].mesh.size={%.17g,%.17g,%.17g}", a, a, a);
        snprintf(ov[n++], 160, "bodies[2].position={0,0,%.17g}", 0.5 * (SIDE + a));
        snprintf(ov[n++], 160, "bodies[2].velocity={0,0,%.17g}", -c->speed);
    } else {
        snprintf(ov[n++], 160, "bodies[1].velocity={0,0,%.17g}", -c->speed);
    }
    if (c->sliver)
        snprintf(ov[n++], 160, "bodies[1].mesh=\"./%s\"", SLIVER_NAME);
    const char *cons = c->mode == CF_STAB_NONE ? "none" : c->mode == CF_STAB_XPBD ? "xpbd" : "pbd";
    snprintf(ov[n++], 160, "solver.constraints=\"%s\"", cons);
    if (c->mode == CF_STAB_PBD_STIFF) {
        snprintf(ov[n++], 160, "solver.pbd.k_stiffness=1");
        snprintf(ov[n++], 160, "solver.pbd.iterations=10");
    }
    if (dt > 0) {
        snprintf(ov[n++], 160, "solver.dt_rigid=%.17g", dt);
        snprintf(ov[n++], 160, "solver.dt_fracture=%.17g", dt);
        snprintf(ov[n++], 160, "duration=%.17g", CF_STABILITY_STEPS * dt);
    }
    return n;
}

static cf_status make_sim(const char *scene, const cf_stability_case *c, double dt, cf_scene *sc,
                          cf_sim **sim, cf_error *err)
{
    char ov[12][160];
    const char *ovp[12];
    int n = case_overrides(c, dt, ov);
    for (int i = 0; i < n; i++)
        ovp[i] = ov[i];
    cf_status st = cf_scene_load(scene, ovp, n, NULL, sc, err);
    if (st != CF_OK)
        return st;
    cf_run_options opt = {.progress = 0, .threads = 1};
    st = cf_sim_create(sc, &opt, sim, err);
    if (st != CF_OK)
        cf_scene_free(sc);
    return st;
}

/* Which criterion the engine's divergence guard reported. */
static const char *guard_reason(const char *msg)
{
    if (strstr(msg, "not finite"))
        return "nan";
    if (strstr(msg, "inverted"))
        return "inverted";
    if (strstr(msg, "energy grew"))
        return "energy";
    return "error";
}

/* Centre of mass of every fragment together, m; 0 when there is none. */
static int system_com(cf_sim *sim, double com[3])
{
    int n = cf_world_fragments(cf_sim_world(sim), NULL, 0);
    cf_fragment_state *f = n > 0 ? malloc((size_t)n * sizeof *f) : NULL;
    if (!f)
        return 0;
    n = cf_world_fragments(cf_sim_world(sim), f, n);
    double m = 0;
    com[0] = com[1] = com[2] = 0;
    for (int i = 0; i < n; i++) {
        v3_axpy(f[i].mass, f[i].com, com);
        m += f[i].mass;
    }
    for (int k = 0; k < 3; k++)
        com[k] /= m;
    free(f);
    return n;
}

/* One case: dt from the mesh's dt_cfl, then CF_STABILITY_STEPS steps. */
static cf_status run_case(const char *scene, cf_stability_case *c, cf_error *err)
{
    double t0 = cf_wall_time();
    cf_scene sc;
    cf_sim *sim = NULL;
    cf_status st = make_sim(scene, c, 0, &sc, &sim, err);
    if (st != CF_OK)
        return st;
    c->dt = cf_world_dt_fracture(cf_sim_world(sim));
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
    if ((st = make_sim(scene, c, c->dt, &sc, &sim, err)) != CF_OK)
        return st;
    double com0[3], com[3];
    system_com(sim, com0);
    double reach = 2 * c->speed * CF_STABILITY_STEPS * c->dt + 2 * SIDE;
    c->stable = 1, c->reason = "", c->fail_step = 0, c->energy_ratio = 1;
    for (long step = 1; !cf_sim_done(sim); step++) {
        cf_error e = {0};
        st = cf_sim_advance(sim, &e);
        cf_ledger l;
        cf_world_ledger(cf_sim_world(sim), &l);
        if (l.initial > 0 && isfinite(l.kinetic + l.strain))
            c->energy_ratio = fmax(c->energy_ratio, (l.kinetic + l.strain) / l.initial);
        const char *why = NULL;
        if (st == CF_ERR_DIVERGED)
            why = guard_reason(e.msg);
        else if (st != CF_OK)
            why = "error";
        else if (system_com(sim, com)) {
            double d[3];
            v3_sub(com, com0, d);
            if (!(v3_norm(d) <= reach) || (c->mass_ratio == 0 && com[2] < -SIDE))
                why = "escaped";
        }
        if (why) {
            c->stable = 0, c->reason = why, c->fail_step = step;
            break;
        }
    }
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
    c->wall = cf_wall_time() - t0;
    return CF_OK;
}

/* The cases of the map, in file order. */
static int build_cases(int quick, cf_stability_case *out)
{
    int n = 0;
    cf_stability_case base = {.slice = "E x dt", .speed = 10};
    for (int m = 0; m < CF_STAB_N_MODES; m++) {
        const double *ea = quick ? E_QUICK : E_AXIS, *da = quick ? DT_QUICK : DT_AXIS;
        int ne = quick ? LEN(E_QUICK) : LEN(E_AXIS), nd = quick ? LEN(DT_QUICK) : LEN(DT_AXIS);
        for (int i = 0; i < ne; i++)
            for (int j = 0; j < nd; j++) {
                cf_stability_case c = base;
                c.mode = (cf_stability_mode)m, c.E = ea[i], c.dt_ratio = da[j];
                if (out)
                    out[n] = c;
                n++;
            }
    }
    for (int m = 0; m < CF_STAB_N_MODES; m++) {
        const double *ma = quick ? MASS_QUICK : MASS_AXIS, *da = quick ? DT_QUICK : DT_AXIS;
        int nm = quick ? LEN(MASS_QUICK) : LEN(MASS_AXIS), nd = quick ? LEN(DT_QUICK) : LEN(DT_AXIS);
        for (int i = 0; i < nm; i++)
            for (int j = 0; j < nd; j++) {
                cf_stability_case c = {.slice = "mass x dt", .E = 7e10, .speed = 10,
                                       .mass_ratio = ma[i], .dt_ratio = da[j],
                                       .mode = (cf_stability_mode)m};
                if (out)
                    out[n] = c;
                n++;
            }
    }
    if (quick)
        return n;
    for (int m = 0; m < CF_STAB_N_MODES; m++)
        for (int i = 0; i < LEN(SPEED_AXIS); i++)
            for (int j = 0; j < LEN(DT_AXIS); j++) {
                cf_stability_case c = {.slice = "speed x dt", .E = 7e10, .speed = SPEED_AXIS[i],
                                       .dt_ratio = DT_AXIS[j], .mode = (cf_stability_mode)m};
                if (out)
                    out[n] = c;
                n++;
            }
    for (int m = 0; m < CF_STAB_N_MODES; m++)
        for (int s = 0; s < 2; s++)
            for (int j = 0; j < LEN(DT_AXIS); j++) {
                cf_stability_case c = {.slice = "mesh x dt", .E = 7e10, .speed = 10,
                                       .sliver = s, .dt_ratio = DT_AXIS[j],
                                       .mode = (cf_stability_mode)m};
                if (out)
                    out[n] = c;
                n++;
            }
    return n;
}

static cf_status write_csv(const cf_stability_result *r, cf_error *err)
{
    cf_outfile o;
    cf_status st = cf_out_open(&o, r->out_dir, "stability.csv", err);
    if (st != CF_OK)
        return st;
    fprintf(o.f, "slice,constraints,E_Pa,dt_over_dt_cfl,speed_m_s,mesh,mass_ratio,dt_s,stable,"
                 "reason,first_failing_step,max_energy_ratio,wall_s\n");
    for (int i = 0; i < r->n; i++) {
        const cf_stability_case *c = &r->cases[i];
        fprintf(o.f, "%s,%s,%.6g,%g,%g,%s,%g,%.6g,%d,%s,%ld,%.6g,%.4f\n", c->slice,
                cf_stability_mode_name(c->mode), c->E, c->dt_ratio, c->speed,
                c->sliver ? "sliver" : "regular", c->mass_ratio, c->dt, c->stable, c->reason,
                c->fail_step, c->energy_ratio, c->wall);
    }
    return cf_out_close(&o, err);
}

/* The stiffest E of the E x dt slice at which `mode` is stable at dt_ratio
 * (NaN when none). */
static double stiffest_stable(const cf_stability_result *r, cf_stability_mode mode,
                              double dt_ratio)
{
    double best = NAN;
    for (int i = 0; i < r->n; i++) {
        const cf_stability_case *c = &r->cases[i];
        if (!strcmp(c->slice, "E x dt") && c->mode == mode && c->dt_ratio == dt_ratio &&
            c->stable && !(c->E <= best))
            best = c->E;
    }
    return best;
}

static cf_status write_md(const cf_stability_result *r, int quick, const char *command,
                          double quality, cf_error *err)
{
    cf_outfile o;
    cf_status st = cf_out_open(&o, r->out_dir, "stability.md", err);
    if (st != CF_OK)
        return st;
    FILE *f = o.f;
    char mach[512], date[32];
    cf_report_stamp(mach, sizeof mach, date);
    fprintf(f, "<!-- cohfrac stability, %s, %s; regenerate with: %s -->\n", date, mach,
            command ? command : "cohfrac stability");
    fprintf(f, "# Stability map%s\n\n", quick ? " (--quick)" : "");
    fprintf(f, "Each case: a %.1f m cube (rho 2400 kg/m^3, nu 0.25, %d^3 cells of 6 Tet4) "
               "touching a rigid plane moves into it at the impact speed; fracture mode only, "
               "no gravity, no cohesive insertion, friction 0.5, restitution 0; %d steps of "
               "dt = (dt/dt_cfl) dt_cfl.\n\n", SIDE, CELLS, CF_STABILITY_STEPS);
    fprintf(f, "Unstable at the first step where: **nan** a node is not finite or faster "
               "than 1e5 m/s; **energy** kinetic + strain > 1.1 x the initial kinetic energy "
               "(no work input); **inverted** more than 1%% of the tets have det F <= 0; "
               "**escaped** the centre of mass is farther than 2 v T + 0.2 m from its start "
               "or 0.1 m below the plane.  Cells give `stable`, or the criterion and the first "
               "failing step.\n\n");
    fprintf(f, "Mass ratio (slice \"mass x dt\"): the cube at rest, no plane, is hit on its "
               "top face at the impact speed by a cube of the same material and mesh (%d^3 "
               "cells) whose side is %.1f (m_impactor / m_target)^(1/3) m; both deform, and "
               "they meet through the contact between fracture-mode bodies; the escape "
               "criterion follows the centre of mass of both.\n\n", CELLS, SIDE);
    if (!quick)
        fprintf(f, "Sliver mesh: interior nodes moved at random by up to %.0f%% of a cell; "
                   "smallest tet quality 6 sqrt(2) V / l_max^3 = %.3f (1 for a regular tet, "
                   "0.5 in the regular cube mesh).\n\n", 100 * SLIVER_SHIFT, quality);
    fprintf(f, "Stiffest E stable at 100 dt_cfl (E x dt slice, 10 m/s):");
    for (int m = 0; m < CF_STAB_N_MODES; m++) {
        double e = stiffest_stable(r, (cf_stability_mode)m, 100);
        if (isnan(e))
            fprintf(f, "%s %s: none", m ? ";" : "", cf_stability_mode_name((cf_stability_mode)m));
        else
            fprintf(f, "%s %s: %.3g Pa", m ? ";" : "", cf_stability_mode_name((cf_stability_mode)m), e);
    }
    fprintf(f, ".\n");
    const char *slice = "";
    for (int i = 0; i < r->n; i++) {
        const cf_stability_case *c = &r->cases[i];
        if (strcmp(c->slice, slice)) {
            slice = c->slice;
            fprintf(f, "\n## %s\n\n| constraints | E (Pa) | speed (m/s) | mesh | mass ratio | "
                       "dt/dt_cfl | dt (s) | result | max energy ratio |\n"
                       "|---|---|---|---|---|---|---|---|---|\n",
                    slice);
        }
        char res[64];
        if (c->stable)
            snprintf(res, sizeof res, "stable");
        else
            snprintf(res, sizeof res, "**%s** at step %ld", c->reason, c->fail_step);
        char mass[32] = "-";
        if (c->mass_ratio > 0)
            snprintf(mass, sizeof mass, "%g", c->mass_ratio);
        fprintf(f, "| %s | %.3g | %g | %s | %s | %g | %.3g | %s | %.3g |\n",
                cf_stability_mode_name(c->mode), c->E, c->speed, c->sliver ? "sliver" : "regular",
                mass, c->dt_ratio, c->dt, res, c->energy_ratio);
    }
    fprintf(f, "\nFiles: `stability.csv` (every case), `stability.png` (heatmaps by "
               "python/cohfrac/stability_plot.py).\n");
    return cf_out_close(&o, err);
}

/* ---- Cases over MPI ranks (mpi_cases.h), or on this process alone ---- */

static const char *const REASONS[] = {"", "nan", "energy", "inverted", "escaped", "error"};
enum { N_REASONS = sizeof REASONS / sizeof REASONS[0] };

/* A case's results as the ranks send them: stable, reason (index in
 * REASONS), failing step, energy ratio, dt, wall time. */
enum { CASE_FIGURES = 6 };

typedef struct spread {
    cf_stability_result *r;
    const cf_stability_options *opt;
    const char *scene, *pair;
    int finished;
} spread;

static void run_spread(int i, double *out, void *user)
{
    spread *sp = user;
    cf_stability_case c = sp->r->cases[i];
    cf_error e = {0};
    if (run_case(c.mass_ratio > 0 ? sp->pair : sp->scene, &c, &e) != CF_OK) {
        fprintf(stderr, "cohfrac stability: case %d: %s\n", i + 1, e.msg);
        c.stable = 0, c.reason = "error", c.fail_step = 0;
    }
    int reason = 0;
    while (reason < N_REASONS - 1 && strcmp(REASONS[reason], c.reason))
        reason++;
    double fig[CASE_FIGURES] = {c.stable, reason, (double)c.fail_step, c.energy_ratio, c.dt,
                                c.wall};
    memcpy(out, fig, sizeof fig);
}

static void spread_done(int i, const double *fig, int rank, void *user)
{
    spread *sp = user;
    cf_stability_case *c = &sp->r->cases[i];
    c->stable = (int)fig[0], c->reason = REASONS[(int)fig[1]], c->fail_step = (long)fig[2];
    c->energy_ratio = fig[3], c->dt = fig[4], c->wall = fig[5];
    sp->finished++;
    if (!sp->opt->progress)
        return;
    fprintf(stderr, "stability %3d/%d  %-12s E %-8.3g dt/dt_cfl %-6g v %-4g %-7s mass ratio "
                    "%-5g %s%s",
            sp->finished, sp->r->n, cf_stability_mode_name(c->mode), c->E, c->dt_ratio,
            c->speed, c->sliver ? "sliver" : "regular", c->mass_ratio,
            c->stable ? "stable" : "unstable: ", c->reason);
    if (cf_mpi_size() > 1)
        fprintf(stderr, " (case %d, rank %d)", i + 1, rank);
    fputc('\n', stderr);
}

/* Largest first: two-body cases have twice the tets, and the constraint
 * modes differ in iterations per step; all run CF_STABILITY_STEPS steps. */
static double case_cost(const cf_stability_case *c)
{
    int iterations[CF_STAB_N_MODES] = {[CF_STAB_NONE] = 0, [CF_STAB_PBD_SRC] = 3,
                                       [CF_STAB_PBD_STIFF] = 10, [CF_STAB_XPBD] = 3};
    return (c->mass_ratio > 0 ? 2 : 1) * (1 + iterations[c->mode]);
}

static int by_cost(const void *a, const void *b, void *cases)
{
    const cf_stability_case *c = cases;
    int x = *(const int *)a, y = *(const int *)b;
    double cx = case_cost(&c[x]), cy = case_cost(&c[y]);
    return cx < cy ? 1 : cx > cy ? -1 : x - y;
}

/* Write `text` to DIR/NAME (whole or not at all); path gets DIR/NAME. */
static cf_status write_scene(const char *dir, const char *name, const char *text, char path[1100],
                             cf_error *err)
{
    snprintf(path, 1100, "%s/%s", dir, name);
    cf_outfile o;
    cf_status st = cf_out_open(&o, dir, name, err);
    if (st != CF_OK)
        return st;
    fputs(text, o.f);
    return cf_out_close(&o, err);
}

cf_status cf_stability_run(const cf_stability_options *opt, cf_stability_result *r,
                           cf_error *err)
{
    memset(r, 0, sizeof *r);
    snprintf(r->out_dir, sizeof r->out_dir, "%s", opt->out_dir ? opt->out_dir : "build/stability");
    cf_status st = cf_mkdirs(r->out_dir, "report directory", err);
    if (st != CF_OK)
        return st;
    char scene[1100], pair[1100];
    if ((st = write_scene(r->out_dir, "stability_scene.lua", scene_text, scene, err)) != CF_OK ||
        (st = write_scene(r->out_dir, "stability_pair_scene.lua", pair_scene_text, pair, err)))
        return st;
    double quality = NAN;
    if (!opt->quick && (st = write_sliver_mesh(r->out_dir, &quality, err)))
        return st;
    r->n = build_cases(opt->quick, NULL);
    r->cases = calloc((size_t)r->n, sizeof *r->cases);
    if (!r->cases)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    build_cases(opt->quick, r->cases);
    spread sp = {r, opt, scene, pair, 0};
    int *order = malloc((size_t)r->n * sizeof *order);
    double *fig = malloc((size_t)r->n * CASE_FIGURES * sizeof *fig);
    if (!order || !fig)
        st = cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    for (int i = 0; st == CF_OK && i < r->n; i++)
        order[i] = i;
    if (st == CF_OK) {
        qsort_r(order, (size_t)r->n, sizeof *order, by_cost, r->cases);
        st = cf_mpi_cases(r->n, order, CASE_FIGURES, fig, run_spread, spread_done, &sp, err);
    }
    free(order), free(fig);
    if (st != CF_OK || cf_mpi_rank() > 0)
        return st; /* the other ranks only run cases */
    if ((st = write_csv(r, err)) != CF_OK ||
        (st = write_md(r, opt->quick, opt->command, quality, err)) != CF_OK)
        return st;
    if (opt->plot) {
        char csv[1100], png[1100];
        snprintf(csv, sizeof csv, "%s/stability.csv", r->out_dir);
        snprintf(png, sizeof png, "%s/stability.png", r->out_dir);
        const char *args[] = {csv, png, NULL};
        r->plot_made = cf_report_plot("stability_plot.py", opt->plot_script, args,
                                      "stability.md and stability.csv");
    }
    return CF_OK;
}

void cf_stability_free(cf_stability_result *r)
{
    free(r->cases);
    r->cases = NULL;
    r->n = 0;
}
