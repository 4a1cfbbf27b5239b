/* The rigid-step loop (docs/architecture.md, docs/physics.md §9).  Each
 * rigid step: Bullet (or the pbd rigid backend) moves the rigid fragments;
 * a fragment hit harder than the impact threshold is rolled back to the
 * start of the step and re-done in fracture mode, sub-cycled at
 * dt_fracture; a fracture-mode fragment that falls apart is split into its
 * pieces at the end of the rigid step, and one quiet for quiet_steps steps
 * is handed back to rigid mode. */
#include "handoff.h"
#include "world_events.h"
#include "world_ledger.h"

#include "linalg.h"
#include "parallel.h"

#include <assert.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>

/* The event of a hand-off the step made. */
static cf_status handoff_event(cf_world *w, const cf_handoff_record *r, cf_error *err)
{
    cf_event e = {.type = CF_EVENT_HANDOFF, .time = w->t, .first = r->fragment, .count = 1,
                  .alive = cf_world_alive_fragments(w, NULL), .handoff = *r};
    return cf_world_push_event(w, &e, err);
}

/* Fragment fi to fracture mode (cf_handoff_to_fracture), and its event. */
static cf_status to_fracture(cf_world *w, int fi, const cfb_state *st, cf_error *err)
{
    cf_handoff_record r;
    cf_status rc = cf_handoff_to_fracture(w, fi, st, &r, err);
    return rc == CF_OK ? handoff_event(w, &r, err) : rc;
}

/* Divergence: a non-finite position or a node faster than 1e5 m/s. */
static int nodes_sane(const cf_solid *s, const cf_fragment *f)
{
    int insane = 0;
    CF_PARALLEL(f->nodes.n >= CF_NODES_PARALLEL_MIN,
                "omp parallel for schedule(static) reduction(+ : insane)",
        for (int i = 0; i < f->nodes.n; i++) {
            const double *x = &s->x[3 * f->nodes.v[i]], *v = &s->v[3 * f->nodes.v[i]];
            insane += !isfinite(x[0] + x[1] + x[2]) || !(v3_dot(v, v) < 1e10);
        });
    return insane == 0;
}

/* Rigid fragment f is hit: Bullet's contact impulse plus the pushes of
 * fracture-mode nodes, per unit mass (m/s), pass the impact threshold, and
 * the impact is new or stronger (docs/physics.md §9).  New: more than the
 * threshold comes from a moving obstacle, another body's fragment or the
 * pushes, which bring energy of their own.  Stronger: it exceeds the
 * strongest impact f has already taken in fracture mode and come back from
 * whole (f->dv_taken).  Fixed obstacles only give back what f brings, and
 * a contact that a spell took without breaking f, as when a piece rocking
 * on the floor strikes it again and again, breaks it no more the next
 * time.  Returns the impact, or 0. */
static double impact(const cf_world *w, const cf_fragment *f)
{
    double J = cfb_contact_impulse(w->bullet, f->body) + f->pushed;
    double dv = J / f->mass, dv_new = (J - cfb_contact_impulse_static(w->bullet, f->body)) / f->mass;
    double threshold = w->def.solver.impact_threshold;
    int hit = dv > threshold && (dv > f->dv_taken || dv_new > threshold);
    return hit && cf_fragment_can_break(f, &w->solid, &w->def.solver) ? dv : 0;
}

/* One Bullet step.  Fragments hit harder than the impact threshold go to
 * fracture mode from their state at the start of the step; the step is
 * then re-run from that start for every other body, so that none keeps the
 * contact response of a fragment that is now sub-cycled instead (momentum is
 * exchanged with it through its nodes). */
static cf_status bullet_step(cf_world *w, double dt, cf_error *err)
{
    const cf_solver_settings *set = &w->def.solver;
    int n = w->n_frag, no = w->def.n_obstacles;
    size_t mark = cf_arena_mark(&w->arena);
    cfb_state *pre = cf_arena_take(&w->arena, (size_t)(n + no) * sizeof *pre), *pre_obs = pre + n;
    if (!pre)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    for (int fi = 0; fi < n; fi++)
        if (w->frag[fi].body >= 0)
            cfb_get_state(w->bullet, w->frag[fi].body, &pre[fi]);
    for (int j = 0; j < no; j++)
        if (w->obstacle_moving[j])
            cfb_get_state(w->bullet, w->obstacle_body[j], &pre_obs[j]);
    int any_moving = 0;
    for (int j = 0; j < no; j++)
        any_moving |= w->obstacle_moving[j];
    cf_status st = CF_OK;
    for (int pass = 0; st == CF_OK; pass++) {
        /* Fails when Bullet ran out of memory, in this step or in an
         * earlier call that could not say so (the world is then unusable). */
        if (cfb_step(w->bullet, dt, set->rigid_substeps) < 0) {
            st = cf_world_bullet_error(err, "the rigid step");
            break;
        }
        int hit = 0;
        for (int fi = 0; fi < n && st == CF_OK; fi++) {
            cf_fragment *f = &w->frag[fi];
            double dv = f->mode == CF_MODE_RIGID && f->body >= 0 ? impact(w, f) : 0;
            if (dv == 0)
                continue;
            cf_profile_lap(&w->prof, CF_STAGE_RIGID_STEP);
            f->dv_enter = dv;
            f->dv_sustained = 0;
            st = to_fracture(w, fi, &pre[fi], err);
            cf_profile_lap(&w->prof, CF_STAGE_HANDOFF);
            hit++;
        }
        if (st != CF_OK || hit == 0 || pass == CF_MAX_RESTEPS)
            break;
        for (int fi = 0; fi < n; fi++)
            if (w->frag[fi].mode == CF_MODE_RIGID && w->frag[fi].body >= 0)
                cfb_set_state(w->bullet, w->frag[fi].body, &pre[fi]);
        for (int j = 0; j < no; j++)
            if (w->obstacle_moving[j])
                cfb_set_state(w->bullet, w->obstacle_body[j], &pre_obs[j]);
    }
    /* What contact did to the rigid bodies' energy beyond gravity's work. */
    for (int fi = 0; fi < n; fi++) {
        cf_fragment *f = &w->frag[fi];
        f->pushed = 0;
        if (f->mode != CF_MODE_RIGID || f->body < 0)
            continue;
        cfb_state now;
        cfb_get_state(w->bullet, f->body, &now);
        double removed = cf_world_body_energy(w, f, &pre[fi]) - cf_world_body_energy(w, f, &now);
        if (cfb_contact_impulse(w->bullet, f->body) == 0) { /* free flight */
            w->flow.integration += removed;
            continue;
        }
        if (removed < 0 && any_moving) { /* a moving obstacle did work on it */
            w->flow.obstacles -= removed;
            removed = 0;
        }
        w->flow.contact += removed;
    }
    cf_arena_release(&w->arena, mark);
    w->steps_rigid++;
    cf_profile_lap(&w->prof, CF_STAGE_RIGID_STEP);
    return st;
}

/* Advance the rigid fragments by one rigid step; detect impacts. */
static cf_status rigid_step(cf_world *w, double dt, cf_error *err)
{
    if (w->bullet)
        return bullet_step(w, dt, err);
    for (int fi = 0; fi < w->n_frag; fi++) {
        if (w->frag[fi].mode != CF_MODE_RIGID)
            continue;
        cf_step_ctx ctx = cf_world_step_ctx(w);
        int hit = cf_pbd_impact(&ctx, &w->frag[fi], w->t, dt) &&
                  cf_fragment_can_break(&w->frag[fi], &w->solid, &w->def.solver);
        cf_profile_lap(&w->prof, CF_STAGE_RIGID_STEP);
        if (hit) {
            cf_status st = to_fracture(w, fi, NULL, err);
            cf_profile_lap(&w->prof, CF_STAGE_HANDOFF);
            if (st != CF_OK)
                return st;
            continue;
        }
        /* The damped step's own stages are timed as the solver's. */
        if (cf_pbd_rigid_step(&ctx, &w->frag[fi], fi, w->t, dt) != CF_OK)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory in the pbd rigid step");
    }
    w->steps_rigid++;
    cf_profile_lap(&w->prof, CF_STAGE_RIGID_STEP);
    return CF_OK;
}

static cf_status diverged(const cf_world *w, cf_error *err, const char *what)
{
    const cf_solver_settings *set = &w->def.solver;
    const char *fix = set->constraints == CF_CONSTRAINTS_NONE
                          ? "lower solver.dt_fracture (or solver.cfl_fraction) below dt_cfl, or use "
                            "solver.constraints = "
                            "\"pbd\""
                          : "lower solver.dt_fracture, or raise solver.pbd.iterations / "
                            "solver.pbd.k_stiffness";
    return cf_error_set(err, CF_ERR_DIVERGED,
                        "%s at t = %.6g s with dt_fracture/dt_cfl = %.3g (dt_cfl %.3g s): %s",
                        what, w->t, w->dt_fracture / w->solid.dt_cfl, w->solid.dt_cfl, fix);
}

/* How far beyond fragment fi's nodes a rigid body can be touched during a
 * rigid step of dt: the fastest node's travel, plus gravity's. */
static double contact_pad(const cf_world *w, int fi, double dt)
{
    const cf_fragment *f = &w->frag[fi];
    double v2 = 0; /* a maximum: the same for any thread count */
    CF_PARALLEL(f->nodes.n >= CF_NODES_PARALLEL_MIN,
                "omp parallel for schedule(static) reduction(max : v2)",
        for (int i = 0; i < f->nodes.n; i++) {
            const double *v = &w->solid.v[3 * f->nodes.v[i]];
            v2 = fmax(v2, v3_dot(v, v));
        });
    return dt * (sqrt(v2) + dt * v3_norm(w->def.gravity));
}

/* Sub-cycle every fracture-mode fragment through the rigid step, all of
 * them in step so that fragments of different bodies meet in contact after
 * each sub-step. */
/* Fracture sub-steps in a rigid step of dt: n_sub of h <= dt_fracture. */
static long sub_steps(const cf_world *w, double dt, double *h)
{
    long n_sub = lround(ceil(dt / w->dt_fracture - 1e-9));
    if (n_sub < 1)
        n_sub = 1;
    *h = dt / (double)n_sub;
    return n_sub;
}

/* The contact stages' view of the world (contact.h). */
static cf_contact_ctx contact_ctx(cf_world *w)
{
    return (cf_contact_ctx){w->frag, w->contact.v, w->n_frag, &w->solid, w->bullet,
                            &w->arena};
}

/* Stage collision, before the sub-steps: the hulls of the rigid bodies
 * near each fracture-mode fragment, from the bodies' boxes taken once.
 * Returns 0, or -1 out of memory. */
static int gather_hulls(cf_world *w, const cf_contact_ctx *cx, double dt)
{
    size_t mark = cf_arena_mark(&w->arena);
    double *boxes = NULL;
    int rc = 0;
    for (int fi = 0; fi < w->n_frag && !rc; fi++) {
        if (w->frag[fi].mode != CF_MODE_FRACTURE)
            continue;
        if (!boxes) {
            boxes = cf_arena_take(&w->arena, (size_t)w->n_frag * 6 * sizeof *boxes);
            if (!boxes) {
                rc = -1;
                break;
            }
            cf_body_boxes(cx, boxes);
        }
        rc = cf_hull_set_gather(cx, fi, contact_pad(w, fi, dt), boxes,
                                &w->contact.v[fi].near);
    }
    cf_arena_release(&w->arena, mark);
    return rc;
}

static cf_status fracture_steps(cf_world *w, double dt, long n_sub, double h, cf_error *err)
{
    const cf_solver_settings *set = &w->def.solver;
    w->h_fracture = h;
    int n = w->n_frag;
    if (cf_contact_caches_reserve(&w->contact, n))
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory gathering contact hulls");
    /* No fragment is made before the splits after these steps, so neither
     * table moves while cx points into them. */
    const cf_contact_ctx cx = contact_ctx(w);
    int bodies = cf_body_contact_needed(&cx);
    if (gather_hulls(w, &cx, dt))
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory gathering contact hulls");
    cf_profile_lap(&w->prof, CF_STAGE_COLLISION);
    cf_step_ctx ctx = cf_world_step_ctx(w);
    /* The fracture-mode fragments, and the pass's scratch (3 ints each). */
    size_t mark = cf_arena_mark(&w->arena);
    int *list = cf_arena_take(&w->arena, (size_t)n * 3 * sizeof *list), m = 0;
    if (!list)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory in fracture mode");
    for (int fi = 0; fi < n; fi++)
        if (w->frag[fi].mode == CF_MODE_FRACTURE)
            list[m++] = fi;
    for (long k = 0; k < n_sub; k++) {
        int side;
        if (cf_fracture_pass(&ctx, w->frag, list, m, list + m, w->t + (double)k * h, h, &side) !=
            CF_OK) {
            cf_arena_release(&w->arena, mark);
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory in fracture mode");
        }
        for (int i = 0; i < m; i++)
            w->tet_steps_fracture += w->frag[list[i]].nt;
        w->steps_fracture += m;
        w->steps_side_by_side += side;
        if (bodies) {
            double removed;
            if (cf_body_contact(&cx, h, &removed)) {
                cf_arena_release(&w->arena, mark);
                return cf_error_set(err, CF_ERR_NOMEM, "contact between bodies failed: %s",
                                    cff_last_error());
            }
            w->flow.contact += removed;
            cf_profile_lap(&w->prof, CF_STAGE_COLLISION);
        }
        if (w->tick) {
            w->tick(w->tick_user, w->t + (double)(k + 1) * h);
            cf_profile_lap(&w->prof, CF_STAGE_BOOKKEEPING);
        }
    }
    cf_arena_release(&w->arena, mark);
    for (int fi = 0; fi < n; fi++) {
        cf_fragment *f = &w->frag[fi];
        if (f->mode != CF_MODE_FRACTURE)
            continue;
        double gained;
        cf_contact_cache *cc = &w->contact.v[fi];
        if (cf_node_impulses_flush(&cx, &cc->push, f->nodes.v, &gained))
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory pushing rigid fragments");
        w->flow.contact -= gained;
        cc->near.n = 0;
        cf_profile_lap(&w->prof, CF_STAGE_COLLISION);
        char what[160];
        if (!nodes_sane(&w->solid, f)) {
            snprintf(what, sizeof what,
                     "fragment %d diverged: a node position is not finite or a node is faster "
                     "than 1e5 m/s",
                     fi);
            return diverged(w, err, what);
        }
        /* Inverted tets counted over the fragment's whole initial body in
         * fracture mode (one inverted tet is all of a one-tet piece). */
        int root = cf_fragment_root(w->frag, fi), inv = 0, nt = 0;
        for (int g = 0; f->n_inverted > 0 && g < n; g++)
            if (w->frag[g].mode == CF_MODE_FRACTURE && cf_fragment_root(w->frag, g) == root)
                inv += w->frag[g].n_inverted, nt += w->frag[g].nt;
        if (inv > set->max_inverted_fraction * nt) {
            snprintf(what, sizeof what,
                     "fragment %d diverged: %d of the %d tets of its body in fracture mode are "
                     "inverted (more than solver.guard.max_inverted_fraction = %g)",
                     fi, inv, nt, set->max_inverted_fraction);
            return diverged(w, err, what);
        }
        cf_profile_lap(&w->prof, CF_STAGE_BOOKKEEPING);
    }
    return CF_OK;
}

/* Energy growth with no work input: kinetic + strain + cohesive energy
 * above (1 + max_energy_growth) times what was put in (the work of
 * gravity, prescribed nodes and moving obstacles, and what hand-offs put
 * in: the squeeze of wedged pieces, gravity's potential of pieces moved
 * clear of obstacles). */
static cf_status check_energy(cf_world *w, cf_error *err)
{
    cf_ledger l;
    cf_world_ledger_terms(w, &l, 0);
    double have = l.kinetic + l.strain + l.cohesive_stored + l.cohesive_dissipated +
                  l.plastic_dissipated;
    double input = l.initial + fmax(0.0, l.work_gravity) + fmax(0.0, l.work_boundary) +
                   fmax(0.0, l.work_obstacles) + w->flow.put_in;
    if (have <= (1 + w->def.solver.max_energy_growth) * input + 1e-12)
        return CF_OK;
    char what[200];
    snprintf(what, sizeof what,
             "energy grew with no work input: %.4g J against %.4g J put in (more than "
             "solver.guard.max_energy_growth = %g)",
             have, input, w->def.solver.max_energy_growth);
    return diverged(w, err, what);
}

#define CF_CONTACT_SLOP 1e-9 /* m: a node projected onto an obstacle, up to round-off */
#define CF_IMPACT_OVER 0.01  /* of the kinetic energy at entry: see impact_unfinished */

/* Whether fracture-mode fragment fi is still in the middle of an impact:
 * a node lies on an obstacle (or would reach it within a rigid step at the
 * fragment's rigid-body velocity, or lies within the collision margin of
 * its hulls, where Bullet's contact begins), and either its rigid-body
 * velocity there approaches the obstacle faster than the impact threshold
 * (rigid mode would see an impact at once), or the energy a hand-off would drop,
 * the strain energy and the kinetic energy beyond the rigid-body motion,
 * is more than CF_IMPACT_OVER of the kinetic energy it entered with.
 * Handed back in the middle of its impact, a fragment hits again at once:
 * it chattered between the modes (63 round trips on the 3,858-tet plaster
 * bunny), every hand-off kept only the rigid part of the motion and gave
 * the rest of the impact to Bullet's inelastic contact, and the stress
 * wave that breaks a body never built up.  A body that rests on the ground
 * holds next to no strain energy, so it still goes back
 * (docs/physics.md §9).  A fixed obstacle holds it no longer than its
 * landing time (cf_fragment_landing_time): a 52,859-tet piece of the
 * 202,231-tet plaster drop that landed pivoting on an edge was held more than 7 ms,
 * 33,000 steps, by nodes of its rigid motion still driving into the floor.
 * A moving one holds it as long as it drives in: it loads the fragment,
 * and rigid mode would hand it back at once as a new impact.  The fixed
 * contacts a landing time no longer holds are sustained, and rigid mode
 * takes them on: f->dv_sustained is the impact they give at most in a
 * rigid step, (1 + e) times the fastest approach there and the weight
 * they hold over the step, which f has then taken (the sink cube of
 * test_sustained_contact_stays_rigid, crushing into the floor, went back
 * to fracture mode at the next rigid step, Bullet's first response to the
 * same contact reading as a stronger impact).  A landing slower than the
 * margin over a rigid step enters fracture mode with its nodes that far
 * off the floor: counted as clear, it went back after its quiet period
 * and Bullet's contact sent it in again, a 0.3 m cube landing on its
 * corner at 1 m/s 926 times in 0.3 s (docs/physics.md §9). */
static int impact_unfinished(cf_world *w, int fi)
{
    cf_fragment *f = &w->frag[fi];
    const cf_solid *s = &w->solid;
    /* fixed obstacles no longer hold it */
    int landed = w->t - f->t_enter >=
                 cf_fragment_landing_time(f, &w->solid.mat, w->def.solver.impact_threshold);
    double com[3], R[9], v[3], omega[3], P[3], L[3], r[3], wr[3], vr[3];
    double reach = w->def.solver.dt_rigid, held = v3_norm(w->def.gravity) * reach;
    double margin = (w->bullet ? cf_fragment_margin(f, &s->mat) : 0) + CF_CONTACT_SLOP;
    cf_fragment_pose(&w->frag[fi], &w->solid, w->bullet, com, R, v, omega);
    int touching = 0;
    f->dv_sustained = 0;
    for (int i = 0; i < f->nodes.n; i++) {
        const double *x = &s->x[3 * f->nodes.v[i]];
        v3_sub(x, com, r);
        v3_cross(omega, r, wr);
        for (int j = 0; j < w->obs.n; j++) {
            double n[3], u[3];
            double d = cf_obstacle_distance(&w->obs, j, w->t, x, n);
            cf_obstacle_velocity(&w->obs.o[j], u);
            for (int k = 0; k < 3; k++)
                vr[k] = v[k] + wr[k] - u[k];
            double approach = -v3_dot(vr, n);
            if (d > fmax(0.0, approach) * reach + margin)
                continue;
            if (landed && v3_dot(u, u) == 0) { /* sustained: rigid mode takes it */
                double e = s->mat.restitution * w->obs.o[j].restitution;
                f->dv_sustained = fmax(f->dv_sustained, (1 + e) * approach + held);
                continue;
            }
            if (approach > w->def.solver.impact_threshold)
                return 1; /* rigid mode would see an impact at once */
            touching = 1;
        }
    }
    if (!touching)
        return 0;
    double Lo[3]; /* the spin's angular momentum, about the centre of mass */
    cf_fragment_momenta(f, &w->solid, w->bullet, P, L);
    v3_cross(com, P, r);
    v3_sub(L, r, Lo);
    double rigid = 0.5 * f->mass * v3_dot(v, v) + 0.5 * v3_dot(omega, Lo);
    double deformation = f->e_strain + fmax(0.0, f->e_kin - rigid);
    return deformation > CF_IMPACT_OVER * f->e_enter;
}

/* Fracture-mode fragments that have been quiet long enough, and no longer
 * drive into an obstacle, go back to rigid mode; those that cannot split
 * any further at once (a split's pieces of a few tets stepped in fracture
 * mode until they were quiet, with nothing left to break). */
static cf_status return_to_rigid(cf_world *w, cf_error *err)
{
    const cf_solver_settings *set = &w->def.solver;
    int n = w->n_frag;
    for (int fi = 0; fi < n; fi++) {
        cf_fragment *f = &w->frag[fi];
        if (f->mode != CF_MODE_FRACTURE)
            continue;
        int timed_out = w->t - f->t_enter >= set->max_fracture_time - 1e-12;
        if (!timed_out && !cf_fragment_cannot_split(f, set, &w->solid.mat) &&
            (f->quiet < set->quiet_steps || impact_unfinished(w, fi)))
            continue;
        int first_new = w->n_frag;
        cf_handoff_record r;
        cf_status st = cf_handoff_to_rigid(w, fi, &r, err);
        cf_profile_lap(&w->prof, CF_STAGE_HANDOFF);
        if (st == CF_OK)
            st = handoff_event(w, &r, err);
        if (st == CF_OK)
            st = cf_world_fragments_born(w, first_new, err);
        if (st != CF_OK)
            return st;
    }
    cf_profile_lap(&w->prof, CF_STAGE_HANDOFF); /* the checks of those that stay */
    return CF_OK;
}

/* Fracture-mode fragments that now fall apart (more of their cohesive
 * elements have failed at all three node pairs since the last check, with or
 * without a new insertion: a piece comes free when its last node pair fails)
 * become one fracture-mode fragment per connected piece, labelled and
 * written like the pieces of a hand-off.  The failed cohesive elements
 * between two pieces go with the split: their compression penalty, kept
 * between pieces that tumble apart, acted along a mid-surface that no
 * longer means anything and pumped energy in (an explicit drop's cohesive
 * stored energy fell to -280 J within 50 us, docs/physics.md §14.6). */
static cf_status split_fragments(cf_world *w, cf_error *err)
{
    int n = w->n_frag;
    for (int fi = 0; fi < n; fi++) {
        if (w->frag[fi].mode != CF_MODE_FRACTURE)
            continue;
        int first = w->n_frag;
        int k = cf_fragment_split_fracture(w, fi, &first);
        cf_profile_lap(&w->prof, CF_STAGE_SPLIT);
        if (k < 0)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory splitting fragment %d", fi);
        if (k > 0) {
            cf_status st = cf_world_fragments_born(w, first, err);
            if (st != CF_OK)
                return st;
        }
    }
    return CF_OK;
}

static cf_status world_step(cf_world *w, double want, cf_error *err)
{
    cf_profile_start(&w->prof);
    const cf_world_def *sc = &w->def;
    double dt = w->dt_outer, h, t0 = w->t;
    long n_sub = sub_steps(w, dt, &h);
    /* A step shorter than the regular one (a run that ends between two):
     * in rigid mode exactly `want`; a fracture-only run in whole fracture
     * steps of the same h (the leapfrog energy estimate needs a constant
     * step), so it ends less than one fracture step past t0 + want. */
    int cut = want < (1 - 1e-9) * dt;
    if (cut && sc->solver.mode == CF_RUN_FRACTURE) {
        n_sub = lround(fmax(1.0, ceil(want / h - 1e-9)));
        dt = (double)n_sub * h;
    } else if (cut) {
        dt = want;
        n_sub = sub_steps(w, dt, &h);
    }
    int n_coh = w->solid.n_coh;
    long stepped = w->steps_fracture;
    cf_status st = rigid_step(w, dt, err);
    if (st == CF_OK)
        st = fracture_steps(w, dt, n_sub, h, err);
    if (w->steps_fracture > stepped)
        w->t_fracture += dt;
    w->step++;
    /* Regular steps count from zero, so that no rounding builds up. */
    w->t = !cut ? (double)w->step * w->dt_outer : t0 + dt;
    if (st == CF_OK && w->solid.n_coh > n_coh) {
        cf_event e = {.type = CF_EVENT_INSERTIONS, .time = w->t, .first = n_coh,
                      .count = w->solid.n_coh - n_coh, .alive = cf_world_alive_fragments(w, NULL)};
        st = cf_world_push_event(w, &e, err);
    }
    if (st == CF_OK)
        st = split_fragments(w, err);
    if (st == CF_OK && sc->solver.mode == CF_RUN_HYBRID)
        st = return_to_rigid(w, err);
    if (st == CF_OK)
        st = check_energy(w, err);
    if (cf_arena_end_step(&w->arena) && st == CF_OK)
        st = cf_error_set(err, CF_ERR_NOMEM, "out of memory growing the step's scratch");
    cf_profile_lap(&w->prof, CF_STAGE_BOOKKEEPING);
    return st;
}

cf_status cf_world_step(cf_world *w, double dt, cf_error *err)
{
    assert(dt > 0 && dt <= w->dt_outer * (1 + 1e-9)); /* the caller's step (world.h) */
    /* OpenMP's thread count is the calling thread's setting: the step runs
     * on the world's and gives the caller back its own. */
    int caller = omp_get_max_threads();
    omp_set_num_threads(w->threads);
    cf_status st = world_step(w, dt, err);
    omp_set_num_threads(caller);
    return st;
}
