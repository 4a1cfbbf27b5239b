/* cohfrac — the two rigid backends side by side (see src/cli/compare.h
 * for the metrics, the reference rules and the files). */
#include "compare.h"
#include "compare_metrics.h"
#include "cohfrac/surface.h"
#include "cohfrac/scene.h"
#include "cohfrac/sim.h"
#include "linalg.h"
#include "clock.h"
#include "file_text.h"
#include "report.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

static const char *const backend_name[2] = {"bullet", "pbd"};

static cf_status snap_take(cf_sim *sim, snap *s, cf_error *err)
{
    int n = cf_world_fragments(cf_sim_world(sim), NULL, 0);
    if (n > s->cap) {
        int cap = n + n / 2 + 4;
        cf_fragment_state *f = realloc(s->f, (size_t)cap * sizeof *f);
        if (!f)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory for %d fragment states", n);
        s->f = f, s->cap = cap;
    }
    s->n = cf_world_fragments(cf_sim_world(sim), s->f, s->cap);
    int max_id = -1;
    for (int i = 0; i < s->n; i++)
        if (s->f[i].id > max_id)
            max_id = s->f[i].id;
    if (max_id + 1 > s->index_cap) {
        int cap = max_id + 1 + (max_id + 1) / 2 + 4;
        int *ix = realloc(s->index, (size_t)cap * sizeof *ix);
        if (!ix)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory for a fragment index");
        s->index = ix, s->index_cap = cap;
    }
    for (int i = 0; i < s->index_cap; i++)
        s->index[i] = -1;
    for (int i = 0; i < s->n; i++)
        s->index[s->f[i].id] = i;
    return CF_OK;
}

static void snap_free(snap *s)
{
    free(s->f), free(s->index);
    memset(s, 0, sizeof *s);
}

/* ---- sampling ---- */

typedef struct state {
    cf_sim *sim[2];
    const cf_world_def *scene;
    snap s[2];
    uint64_t *keys;
    int *partner, *shared, match_cap;
    totals t0[2];
    double p_scale, T;
    reference ref;
    sample *smp;
    int n_smp, cap_smp;
} state;

static cf_status take_sample(state *st, cf_error *err)
{
    for (int b = 0; b < 2; b++) {
        cf_status rc = snap_take(st->sim[b], &st->s[b], err);
        if (rc != CF_OK)
            return rc;
    }
    if (st->n_smp == st->cap_smp) {
        int cap = 2 * st->cap_smp + 16;
        sample *p = realloc(st->smp, (size_t)cap * sizeof *p);
        if (!p)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory for samples");
        st->smp = p, st->cap_smp = cap;
    }
    if (st->s[0].n > st->match_cap) {
        int cap = st->s[0].n + st->s[0].n / 2 + 4;
        int *p = realloc(st->partner, (size_t)cap * sizeof *p);
        if (p)
            st->partner = p;
        int *q = p ? realloc(st->shared, (size_t)cap * sizeof *q) : NULL;
        if (!q)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory for fragment matching");
        st->shared = q, st->match_cap = cap;
    }
    const snap *sa = &st->s[0], *sb = &st->s[1];
    cf_cmp_match_fragments(st->sim[0], st->sim[1], sa, sb, st->keys, st->partner, st->shared);

    sample *o = &st->smp[st->n_smp];
    memset(o, 0, sizeof *o);
    o->t = cf_world_time(cf_sim_world(st->sim[0]));
    double wsum = 0, dsum = 0, asum = 0;
    for (int i = 0; i < sa->n; i++) {
        int j = st->partner[i];
        if (j < 0)
            continue;
        wsum += sa->f[i].mass;
        dsum += sa->f[i].mass * cf_cmp_dist(sa->f[i].com, sb->f[j].com);
        asum += sa->f[i].mass * cf_cmp_quat_angle(sa->f[i].quat, sb->f[j].quat);
    }
    o->com_dist = wsum > 0 ? dsum / wsum : NAN;
    o->orient = wsum > 0 ? asum / wsum : NAN;
    int has_ref = cf_cmp_reference_at(&st->ref, o->t, o->ref);
    const double *g = st->scene->gravity;
    for (int b = 0; b < 2; b++) {
        totals tt;
        cf_cmp_sum_totals(&st->s[b], g, &tt);
        if (st->n_smp == 0) {
            st->t0[b] = tt;
            if (b == 0)
                st->p_scale = fmax(v3_norm(tt.P), tt.M * v3_norm(g) * st->T);
        }
        const totals *z = &st->t0[b];
        o->nfrag[b] = st->s[b].n;
        memcpy(o->com[b], tt.com, sizeof tt.com);
        o->ref_err[b] = has_ref ? cf_cmp_dist(tt.com, o->ref) : NAN;
        o->ke[b] = (tt.E - z->E) / (z->E != 0 ? fabs(z->E) : 1.0);
        double dP[3], dL[3];
        for (int k = 0; k < 3; k++) {
            dP[k] = tt.P[k] - z->P[k] - z->M * g[k] * o->t;
            dL[k] = tt.L[k] - z->L[k];
        }
        o->p[b] = v3_norm(dP) / (st->p_scale > 0 ? st->p_scale : 1.0);
        double l0 = v3_norm(z->L);
        o->l[b] = v3_norm(dL) / (l0 > 0 ? l0 : 1.0);
        int h = cf_cmp_heaviest(&st->s[b]);
        o->axis_angle[b] = st->ref.top && h >= 0 ? cf_cmp_axis_angle(&st->ref, &st->s[b].f[h]) : NAN;
    }
    st->n_smp++;
    return CF_OK;
}

/* ---- files ---- */

/* A number for the report: "—" for NaN. */
static const char *num(char *buf, size_t n, double x)
{
    if (isnan(x))
        snprintf(buf, n, "—");
    else
        snprintf(buf, n, "%.4g", x);
    return buf;
}

static const char *ref_name(cf_compare_ref r)
{
    switch (r) {
    case CF_CMP_REF_FREE_FALL: return "free fall";
    case CF_CMP_REF_PROJECTILE: return "projectile";
    case CF_CMP_REF_BOUNCE: return "bounce";
    default: return "none";
    }
}

static void row(FILE *f, const char *metric, const char *unit, const double fin[2],
                const double mx[2])
{
    char a[32], b[32], c[32], d[32];
    const char *closer = "—";
    if (!isnan(mx[0]) && !isnan(mx[1]))
        closer = mx[0] < mx[1] ? "bullet" : mx[1] < mx[0] ? "pbd" : "tie";
    fprintf(f, "| %s | %s | %s | %s | %s | %s | %s |\n", metric, unit, num(a, 32, fin[0]),
            num(b, 32, mx[0]), num(c, 32, fin[1]), num(d, 32, mx[1]), closer);
}

static void write_headline(FILE *f, const cf_compare_options *opt, const cf_scene *sc,
                           const cf_compare_result *r, const reference *ref, cf_status run_st)
{
    char a[32], b[32], c[32];
    fprintf(f, "# Rigid backends compared: %s\n\n", r->scene_name);
    fprintf(f, "- scene: `%s`", opt->scene);
    for (int i = 0; i < opt->n_overrides; i++)
        fprintf(f, " `--set %s`", opt->overrides[i]);
    fprintf(f, "\n- simulated %.4g s of %.4g s, dt_rigid %.3g s, %d samples every %.3g s\n",
            r->duration, sc->duration, sc->world.solver.dt_rigid, r->n_samples,
            sc->output.frame_interval);
    fprintf(f, "- backends: **bullet** (Bullet, %d sub-steps per dt_rigid) and **pbd** "
               "(damped PBD rigid mode: k_damping = 1, k_stiffness %.3g, %d iterations)\n",
            sc->world.solver.rigid_substeps, sc->world.solver.k_stiffness,
            sc->world.solver.iterations);
    double ratio = r->wall[0] > 0 ? r->wall[1] / r->wall[0] : NAN;
    fprintf(f, "- wall time of the steps: bullet %.3f s, pbd %.3f s (pbd / bullet = %s)\n",
            r->wall[0], r->wall[1], num(a, 32, ratio));
    if (!isnan(r->t_split[0]) && !isnan(r->t_split[1])) {
        char b[32];
        fprintf(f, "- after the first split (bullet at %.4g s, pbd at %.4g s): bullet %.3f s, "
                   "pbd %.3f s (pbd / bullet = %s)\n",
                r->t_split[0], r->t_split[1], r->wall_split[0], r->wall_split[1],
                num(b, 32, r->wall_split[0] > 0 ? r->wall_split[1] / r->wall_split[0] : NAN));
    }
    fprintf(f, "- fragments at the end: bullet %d, pbd %d\n", r->n_fragments[0],
            r->n_fragments[1]);
    fprintf(f, "- analytic reference: %s", ref_name(r->reference));
    if (r->reference == CF_CMP_REF_BOUNCE)
        fprintf(f, " (restitution %.3g, contacts at %.4g s and %.4g s; compared until %.4g s)",
                ref->e, ref->t1, ref->t2, r->ref_until);
    if (r->top)
        fprintf(f, " + symmetric top");
    fputs("\n", f);
    if (sc->world.solver.mode == CF_RUN_FRACTURE)
        fprintf(f, "- solver.mode = \"fracture\": no rigid mode, so the backend makes no "
                   "difference\n");
    if (sc->world.n_obstacles > 0)
        fprintf(f, "- drifts include the obstacles' impulses and the energy contact removes "
                   "(they measure conservation in free flight only)\n");
    if (run_st != CF_OK)
        fprintf(f, "- **the runs stopped early: %s**\n", cf_status_name(run_st));

    fprintf(f, "\n| between the backends | unit | final | max |\n|---|---|---|---|\n");
    fprintf(f, "| COM distance (mass-weighted) | m | %s | %s |\n", num(a, 32, r->com_dist_final),
            num(b, 32, r->com_dist_max));
    fprintf(f, "| orientation difference (mass-weighted) | rad | %s | %s |\n",
            num(a, 32, r->orient_final), num(b, 32, r->orient_max));

    fprintf(f, "\n| metric | unit | bullet final | bullet max | pbd final | pbd max | "
               "closer |\n|---|---|---|---|---|---|---|\n");
    if (r->reference != CF_CMP_REF_NONE) {
        char m[64];
        snprintf(m, sizeof m, "COM error vs %s", ref_name(r->reference));
        row(f, m, "m", r->ref_err_final, r->ref_err_max);
    }
    row(f, "kinetic-energy drift", "rel.", r->ke_drift_final, r->ke_drift_max);
    row(f, "linear momentum drift", "rel.", r->p_drift_final, r->p_drift_max);
    row(f, "angular momentum drift", "rel.", r->l_drift_final, r->l_drift_max);
    if (r->top) {
        double fin[2] = {r->omega_measured[0], r->omega_measured[1]};
        /* one fit over the whole run: final and max are the same figure */
        row(f, "precession rate error", "rel.", r->omega_rel_err, r->omega_rel_err);
        fprintf(f, "\nSymmetric top: Ω_p = |L| / I_1\n\n| | precession rate (rad/s) | "
                   "relative error |\n|---|---|---|\n");
        fprintf(f, "| analytic | %s | |\n", num(a, 32, r->omega_p));
        for (int k = 0; k < 2; k++)
            fprintf(f, "| %s | %s | %s |\n", backend_name[k], num(b, 32, fin[k]),
                    num(c, 32, r->omega_rel_err[k]));
    }
    /* the verdict: closer to the analytic reference, and at what cost */
    const double *crit = r->top ? r->omega_rel_err
                         : r->reference != CF_CMP_REF_NONE ? r->ref_err_max
                                                           : r->ke_drift_max;
    const char *what = r->top ? "precession rate error"
                       : r->reference != CF_CMP_REF_NONE ? "max COM error"
                                                         : "max kinetic-energy drift";
    /* with obstacles and no reference the drifts mix contact losses in: no verdict */
    int judged = r->reference != CF_CMP_REF_NONE || sc->world.n_obstacles == 0;
    if (judged && !isnan(crit[0]) && !isnan(crit[1]) && r->wall[0] > 0 && r->wall[1] > 0) {
        int w = crit[1] < crit[0];
        fprintf(f, "\n**%s is closer%s** (%s %s vs %s) at %s× the wall time of %s.\n",
                backend_name[w], r->reference != CF_CMP_REF_NONE ? " to the analytic reference"
                                                                 : " to conservation",
                what, num(a, 32, crit[w]), num(b, 32, crit[!w]),
                num(c, 32, r->wall[w] / r->wall[!w]), backend_name[!w]);
    }
}

static cf_status write_md(const char *dir, const char *headline, const state *st,
                          cf_error *err)
{
    cf_outfile o;
    cf_status rc = cf_out_open(&o, dir, "compare.md", err);
    if (rc != CF_OK)
        return rc;
    fputs(headline, o.f);
    const snap *sa = &st->s[0], *sb = &st->s[1];
    int *order = malloc((size_t)(sa->n + 1) * sizeof *order);
    if (!order) {
        fclose(o.f), remove(o.tmp);
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    }
    for (int i = 0; i < sa->n; i++)
        order[i] = i;
    int shown = sa->n < 20 ? sa->n : 20;
    for (int i = 0; i < shown; i++) /* partial selection sort: the 20 heaviest */
        for (int j = i + 1; j < sa->n; j++)
            if (sa->f[order[j]].mass > sa->f[order[i]].mass) {
                int t = order[i];
                order[i] = order[j], order[j] = t;
            }
    fprintf(o.f, "\n## The %d heaviest fragments at the end (of %d in the Bullet run)\n\n",
            shown, sa->n);
    fprintf(o.f, "| bullet id | pbd partner | mass (kg) | shared tets | COM distance (m) | "
                 "orientation difference (rad) |\n|---|---|---|---|---|---|\n");
    for (int i = 0; i < shown; i++) {
        const cf_fragment_state *f = &sa->f[order[i]];
        int j = st->partner[order[i]];
        if (j < 0) {
            fprintf(o.f, "| %d | — | %.4g | 0 | — | — |\n", f->id, f->mass);
            continue;
        }
        fprintf(o.f, "| %d | %d | %.4g | %d of %d | %.4g | %.4g |\n", f->id, sb->f[j].id,
                f->mass, st->shared[order[i]], f->n_tets, cf_cmp_dist(f->com, sb->f[j].com),
                cf_cmp_quat_angle(f->quat, sb->f[j].quat));
    }
    fprintf(o.f, "\nFiles: `compare.csv` (time series), `fragments.csv` (every fragment at "
                 "the end), `compare.png` (plots by python/cohfrac/compare_plot.py, when "
                 "python3-matplotlib is installed).\n");
    free(order);
    return cf_out_close(&o, err);
}

static void csv_num(FILE *f, double x) { fprintf(f, isnan(x) ? ",nan" : ",%.10g", x); }

static cf_status write_csv(const char *dir, const state *st, cf_error *err)
{
    cf_outfile o;
    cf_status rc = cf_out_open(&o, dir, "compare.csv", err);
    if (rc != CF_OK)
        return rc;
    fprintf(o.f, "time,com_dist,orient_diff,n_frag_bullet,n_frag_pbd,"
                 "com_x_bullet,com_y_bullet,com_z_bullet,com_x_pbd,com_y_pbd,com_z_pbd,"
                 "ref_x,ref_y,ref_z,ref_err_bullet,ref_err_pbd,ke_drift_bullet,ke_drift_pbd,"
                 "p_drift_bullet,p_drift_pbd,l_drift_bullet,l_drift_pbd,"
                 "axis_angle_bullet,axis_angle_pbd,axis_angle_ref\n");
    for (int i = 0; i < st->n_smp; i++) {
        const sample *s = &st->smp[i];
        fprintf(o.f, "%.10g", s->t);
        csv_num(o.f, s->com_dist), csv_num(o.f, s->orient);
        fprintf(o.f, ",%d,%d", s->nfrag[0], s->nfrag[1]);
        for (int b = 0; b < 2; b++)
            for (int k = 0; k < 3; k++)
                csv_num(o.f, s->com[b][k]);
        for (int k = 0; k < 3; k++)
            csv_num(o.f, s->ref[k]);
        csv_num(o.f, s->ref_err[0]), csv_num(o.f, s->ref_err[1]);
        csv_num(o.f, s->ke[0]), csv_num(o.f, s->ke[1]);
        csv_num(o.f, s->p[0]), csv_num(o.f, s->p[1]);
        csv_num(o.f, s->l[0]), csv_num(o.f, s->l[1]);
        csv_num(o.f, s->axis_angle[0]), csv_num(o.f, s->axis_angle[1]);
        /* analytic: starts where the Bullet run's axis starts */
        csv_num(o.f, st->ref.top ? st->smp[0].axis_angle[0] + st->ref.omega_p * s->t : NAN);
        fputc('\n', o.f);
    }
    return cf_out_close(&o, err);
}

static cf_status write_fragments_csv(const char *dir, const state *st, cf_error *err)
{
    cf_outfile o;
    cf_status rc = cf_out_open(&o, dir, "fragments.csv", err);
    if (rc != CF_OK)
        return rc;
    const snap *sa = &st->s[0], *sb = &st->s[1];
    fprintf(o.f, "id_bullet,id_pbd,mass_bullet,mass_pbd,n_tets_bullet,shared_tets,"
                 "com_dist,orient_diff,speed_bullet,speed_pbd,kinetic_bullet,kinetic_pbd,"
                 "qw_bullet,qx_bullet,qy_bullet,qz_bullet,qw_pbd,qx_pbd,qy_pbd,qz_pbd,"
                 "wx_bullet,wy_bullet,wz_bullet,wx_pbd,wy_pbd,wz_pbd\n");
    for (int i = 0; i < sa->n; i++) {
        const cf_fragment_state *f = &sa->f[i];
        int j = st->partner[i];
        const cf_fragment_state *g = j >= 0 ? &sb->f[j] : NULL;
        fprintf(o.f, "%d,%d,%.10g", f->id, g ? g->id : -1, f->mass);
        csv_num(o.f, g ? g->mass : NAN);
        fprintf(o.f, ",%d,%d", f->n_tets, st->shared[i]);
        csv_num(o.f, g ? cf_cmp_dist(f->com, g->com) : NAN);
        csv_num(o.f, g ? cf_cmp_quat_angle(f->quat, g->quat) : NAN);
        csv_num(o.f, v3_norm(f->v));
        csv_num(o.f, g ? v3_norm(g->v) : NAN);
        csv_num(o.f, f->kinetic);
        csv_num(o.f, g ? g->kinetic : NAN);
        for (int k = 0; k < 4; k++)
            csv_num(o.f, f->quat[k]);
        for (int k = 0; k < 4; k++)
            csv_num(o.f, g ? g->quat[k] : NAN);
        for (int k = 0; k < 3; k++)
            csv_num(o.f, f->w[k]);
        for (int k = 0; k < 3; k++)
            csv_num(o.f, g ? g->w[k] : NAN);
        fputc('\n', o.f);
    }
    return cf_out_close(&o, err);
}

/* Make compare.png; returns 1 when it was written (warnings on stderr otherwise). */
static int run_plot(const cf_compare_options *opt, const char *dir, const cf_compare_result *r)
{
    char csv[1100], png[1100], title[300];
    snprintf(csv, sizeof csv, "%s/compare.csv", dir);
    snprintf(png, sizeof png, "%s/compare.png", dir);
    snprintf(title, sizeof title, "%s (reference: %s%s)", r->scene_name, ref_name(r->reference),
             r->top ? ", symmetric top" : "");
    const char *args[] = {csv, png, title, NULL};
    return cf_report_plot("compare_plot.py", opt->plot_script, args, "compare.md and compare.csv");
}

/* ---- the run ---- */

static void summarise(const state *st, cf_compare_result *r)
{
    const sample *s = st->smp;
    int n = st->n_smp;
    r->n_samples = n;
    r->duration = n ? s[n - 1].t : 0;
    r->com_dist_max = r->orient_max = 0;
    for (int b = 0; b < 2; b++) {
        r->n_fragments[b] = st->s[b].n;
        r->ke_drift_max[b] = r->p_drift_max[b] = r->l_drift_max[b] = 0;
        r->ref_err_max[b] = r->ref_err_final[b] = NAN;
    }
    r->ref_until = NAN;
    for (int i = 0; i < n; i++) {
        r->com_dist_max = fmax(r->com_dist_max, s[i].com_dist);
        r->orient_max = fmax(r->orient_max, s[i].orient);
        for (int b = 0; b < 2; b++) {
            r->ke_drift_max[b] = fmax(r->ke_drift_max[b], fabs(s[i].ke[b]));
            r->p_drift_max[b] = fmax(r->p_drift_max[b], s[i].p[b]);
            r->l_drift_max[b] = fmax(r->l_drift_max[b], s[i].l[b]);
            if (!isnan(s[i].ref_err[b])) {
                r->ref_err_final[b] = s[i].ref_err[b];
                r->ref_err_max[b] = isnan(r->ref_err_max[b])
                                        ? s[i].ref_err[b]
                                        : fmax(r->ref_err_max[b], s[i].ref_err[b]);
                r->ref_until = s[i].t;
            }
        }
    }
    if (n) {
        r->com_dist_final = s[n - 1].com_dist;
        r->orient_final = s[n - 1].orient;
        for (int b = 0; b < 2; b++) {
            r->ke_drift_final[b] = s[n - 1].ke[b];
            r->p_drift_final[b] = s[n - 1].p[b];
            r->l_drift_final[b] = s[n - 1].l[b];
        }
    }
    r->reference = st->ref.kind;
    r->top = st->ref.top;
    r->omega_p = st->ref.top ? st->ref.omega_p : NAN;
    for (int b = 0; b < 2; b++)
        r->omega_measured[b] = r->omega_rel_err[b] = NAN;
    if (st->ref.top && n >= 3) {
        double *a = malloc((size_t)n * sizeof *a);
        for (int b = 0; a && b < 2; b++) {
            for (int i = 0; i < n; i++)
                a[i] = s[i].axis_angle[b];
            r->omega_measured[b] = cf_cmp_unwrap_slope(s, n, a);
            r->omega_rel_err[b] = fabs(r->omega_measured[b] - r->omega_p) / r->omega_p;
        }
        free(a);
    }
}

cf_status cf_compare_run(const cf_compare_options *opt, cf_compare_result *res, cf_error *err)
{
    static const char *const extra[2][3] = {
        {"solver.rigid_backend=\"bullet\"", "output.file=\"\"", NULL},
        {"solver.rigid_backend=\"pbd\"", "solver.pbd.k_damping=1", "output.file=\"\""}};
    const char *mesh_dir = opt->mesh_dir ? opt->mesh_dir : cf_default_mesh_dir();
    cf_compare_result local, *r = res ? res : &local;
    memset(r, 0, sizeof *r);
    cf_scene sc[2];
    memset(sc, 0, sizeof sc);
    state st;
    memset(&st, 0, sizeof st);
    cf_status rc = CF_OK, run_st = CF_OK;
    const char **sets = malloc((size_t)(opt->n_overrides + 3) * sizeof *sets);
    if (!sets)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");

    for (int b = 0; b < 2 && rc == CF_OK; b++) {
        int n = 0;
        for (int i = 0; i < opt->n_overrides; i++)
            sets[n++] = opt->overrides[i];
        for (int i = 0; i < 3 && extra[b][i]; i++)
            sets[n++] = extra[b][i];
        rc = cf_scene_load(opt->scene, sets, n, mesh_dir, &sc[b], err);
    }
    free(sets);
    cf_run_options ro = {.progress = 0, .threads = opt->threads, .mesh_dir = mesh_dir};
    for (int b = 0; b < 2 && rc == CF_OK; b++)
        rc = cf_sim_create(&sc[b], &ro, &st.sim[b], err);
    if (rc == CF_OK && cf_world_tet_count(cf_sim_world(st.sim[0])) != cf_world_tet_count(cf_sim_world(st.sim[1])))
        rc = cf_error_set(err, CF_ERR_SCENE_VALUE, "the two runs of %s have different meshes",
                          opt->scene);
    if (rc == CF_OK) {
        st.keys = malloc(((size_t)cf_world_tet_count(cf_sim_world(st.sim[0])) + 1) * sizeof *st.keys);
        if (!st.keys)
            rc = cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    }
    if (rc != CF_OK)
        goto done;
    st.scene = &sc[0].world;
    st.T = sc[0].duration;
    snprintf(r->scene_name, sizeof r->scene_name, "%s", sc[0].name);
    if (opt->out_dir)
        snprintf(r->out_dir, sizeof r->out_dir, "%s", opt->out_dir);
    else
        snprintf(r->out_dir, sizeof r->out_dir, "build/compare/%s", sc[0].name);
    /* fail on an unwritable directory before spending the run's time */
    if ((rc = cf_mkdirs(r->out_dir, "report directory", err)) != CF_OK)
        goto done;

    if ((rc = snap_take(st.sim[0], &st.s[0], err)) != CF_OK)
        goto done;
    cf_cmp_reference_setup(&sc[0].world, st.sim[0], &st.s[0], &st.ref);
    if ((rc = take_sample(&st, err)) != CF_OK)
        goto done;
    double dt = sc[0].world.solver.dt_rigid, every = sc[0].output.frame_interval;
    double next = every, next_report = 0.1 * st.T;
    cf_error run_err = {0};
    int n_bodies = cf_world_fragments(cf_sim_world(st.sim[0]), NULL, 0);
    r->t_split[0] = r->t_split[1] = NAN;
    while (!cf_sim_done(st.sim[0]) || !cf_sim_done(st.sim[1])) {
        for (int b = 0; b < 2 && run_st == CF_OK; b++) {
            if (cf_sim_done(st.sim[b]))
                continue;
            double t0 = cf_wall_time();
            run_st = cf_sim_advance(st.sim[b], &run_err);
            double w = cf_wall_time() - t0;
            r->wall[b] += w;
            /* after the split: from the step whose fragments outnumber the bodies */
            if (isnan(r->t_split[b]) && cf_world_fragments(cf_sim_world(st.sim[b]), NULL, 0) > n_bodies)
                r->t_split[b] = cf_world_time(cf_sim_world(st.sim[b]));
            if (!isnan(r->t_split[b]))
                r->wall_split[b] += w;
            if (run_st != CF_OK)
                fprintf(stderr, "cohfrac: %s run: error [%s]: %s\n", backend_name[b],
                        cf_status_name(run_st), run_err.msg);
        }
        if (run_st != CF_OK)
            break;
        double t = cf_world_time(cf_sim_world(st.sim[0]));
        int done = cf_sim_done(st.sim[0]) && cf_sim_done(st.sim[1]);
        if (t >= next - 1e-9 * dt || done) {
            if ((rc = take_sample(&st, err)) != CF_OK)
                goto done;
            while (next <= t + 1e-9 * dt)
                next += every;
        }
        if (opt->progress && t >= next_report) {
            fprintf(stderr, "compare: t = %.4g of %.4g s, wall bullet %.2f s, pbd %.2f s\n", t,
                    st.T, r->wall[0], r->wall[1]);
            next_report += 0.1 * st.T;
        }
    }
    summarise(&st, r);

    /* the files: the headline in memory first (it also goes to opt->headline) */
    char *head = NULL;
    size_t head_len = 0;
    FILE *hf = open_memstream(&head, &head_len);
    if (!hf) {
        rc = cf_error_set(err, CF_ERR_NOMEM, "out of memory for the report");
        goto done;
    }
    write_headline(hf, opt, &sc[0], r, &st.ref, run_st);
    fclose(hf);
    rc = write_md(r->out_dir, head, &st, err);
    if (rc == CF_OK)
        rc = write_csv(r->out_dir, &st, err);
    if (rc == CF_OK)
        rc = write_fragments_csv(r->out_dir, &st, err);
    if (rc == CF_OK && opt->headline)
        fputs(head, opt->headline);
    free(head);
    if (rc == CF_OK && opt->plot)
        r->plot_made = run_plot(opt, r->out_dir, r);
    if (rc == CF_OK && run_st != CF_OK) {
        if (err)
            *err = run_err;
        rc = run_st;
    }

done:
    for (int b = 0; b < 2; b++) {
        cf_sim_destroy(st.sim[b]);
        cf_scene_free(&sc[b]);
        snap_free(&st.s[b]);
    }
    free(st.keys), free(st.partner), free(st.shared), free(st.smp);
    return rc;
}
