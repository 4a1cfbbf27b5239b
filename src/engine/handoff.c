/* Hand-off between rigid mode (Bullet, or the pbd rigid backend) and
 * fracture mode (docs/physics.md §9). */
#include "handoff.h"

#include "fracture.h"

#include "chunks.h"
#include "linalg.h"
#include "tet4.h"

#include <math.h>

#include <stdlib.h>
#include <string.h>

static const double PI = 3.14159265358979323846;

/* The world's heartbeat between the cuts of a decomposition (the hulls of
 * a 10^5-tet piece take more than a second). */
static void decompose_tick(void *user)
{
    const cf_world *sim = user;
    sim->tick(sim->tick_user, sim->t);
}

/* Convex decomposition of fragment fi (docs/physics.md §9), kept in the principal
 * frame for Bullet and for fracture-mode contact.  A fragment's tets never
 * change (a split makes new fragments) and the decomposition reads their
 * rest shape only, so a fragment that comes back from fracture mode in one
 * piece keeps the hulls it had: the same bits, without the work (most of
 * a drop's wall time went to decomposing pieces again after each touch). */
static int decompose_fragment(cf_world *sim, cf_fragment *f)
{
    if (f->hulls.n_hulls > 0)
        return 0;
    cf_profile_lap(&sim->prof, CF_STAGE_HANDOFF);
    cf_hulls_free(&f->hulls);
    int most = f->nt / CF_HULL_TETS_PER_HULL;
    most = most < 1 ? 1 : most > CF_HULL_MAX_COUNT ? CF_HULL_MAX_COUNT : most;
    int fail = cf_decompose(&sim->solid, f->tets, f->nt, CF_HULL_MAX_ERROR, most,
                            CF_HULL_MIN_TETS, &f->hulls, sim->tick ? decompose_tick : NULL, sim);
    for (int i = 0; !fail && i < f->hulls.start[f->hulls.n_hulls]; i++) {
        double r[3];
        v3_sub(&f->hulls.pts[3 * i], f->com_rest, r);
        m3_tmulv(f->Q, r, &f->hulls.pts[3 * i]);
    }
    f->decompose_time = cf_profile_lap(&sim->prof, CF_STAGE_CONVEX_DECOMPOSITION);
    if (fail)
        return -1;
    if (sim->tick) {
        sim->tick(sim->tick_user, sim->t);
        cf_profile_lap(&sim->prof, CF_STAGE_BOOKKEEPING);
    }
    return 0;
}

/* Debris's sphere: of the piece's volume, shrunk where an obstacle is
 * nearer its centre of mass (a piece lying flat on the floor), so that
 * Bullet finds no overlap to push apart. */
static double debris_radius(const cf_world *sim, const cf_fragment *f, const double com[3])
{
    double n[3], r = cbrt(3 * f->volume / (4 * PI));
    for (int j = 0; j < sim->obs.n; j++) {
        double d = cf_obstacle_distance(&sim->obs, j, sim->t, com, n);
        if (d > 0)
            r = fmin(r, d);
    }
    return r;
}

/* Rotation of the Bullet body frame: rest->current R times principal axes Q. */
cf_status cf_fragment_add_body(cf_world *sim, int fi, const double pos[3], const double R[9],
                               const double v[3], const double w[3], cf_error *err)
{
    cf_fragment *f = &sim->frag[fi];
    const cf_solid *s = &sim->solid;
    cfb_state st;
    double RQ[9];
    m3_mul(R, f->Q, RQ);
    mat_to_quat(RQ, st.quat);
    memcpy(st.pos, pos, sizeof st.pos);
    memcpy(st.v, v, sizeof st.v);
    memcpy(st.w, w, sizeof st.w);
    if (cf_fragment_is_debris(f, &sim->def.solver))
        f->body = cfb_add_sphere_body(sim->bullet, f->mass, f->principal, debris_radius(sim, f, pos),
                                      &st, s->mat.friction, s->mat.restitution);
    else if (decompose_fragment(sim, f))
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory decomposing fragment %d", fi);
    else
        f->body = cfb_add_compound_body(sim->bullet, f->mass, f->principal, f->hulls.pts,
                                        f->hulls.start, f->hulls.n_hulls,
                                        cf_fragment_margin(f, &s->mat), &st, s->mat.friction,
                                        s->mat.restitution);
    if (f->body < 0)
        return cf_error_set(err, CF_ERR_EXTERNAL, "Bullet refused fragment %d: %s", fi,
                            cfb_last_error());
    /* Continuous collision detection for fragments that move more than their
     * smallest radius of gyration in a sub-step; the swept sphere stays
     * inside the fragment. */
    if (sim->def.solver.ccd) {
        double rg = sqrt(fmin(f->principal[0], fmin(f->principal[1], f->principal[2])) / f->mass);
        cfb_set_ccd(sim->bullet, f->body, rg, 0.5 * rg);
    }
    return CF_OK;
}

/* The record of a hand-off of fragment fi: momenta before (P0, L0) and
 * after (P1, L1); the run's totals too. */
static void record_handoff(cf_world *sim, int fi, int direction, const double P0[3],
                           const double L0[3], const double P1[3], const double L1[3], double loss,
                           cf_handoff_record *r)
{
    *r = (cf_handoff_record){sim->t, fi, direction, 0, {0}, {0}, loss};
    v3_sub(P1, P0, r->momentum_change);
    v3_sub(L1, L0, r->angular_momentum_change);
    double pn = v3_norm(P0), dp = v3_norm(r->momentum_change);
    r->momentum_error = pn > 0 ? dp / pn : dp;
    sim->n_handoffs++;
    if (r->momentum_error > sim->max_momentum_error)
        sim->max_momentum_error = r->momentum_error;
    sim->total_handoff_loss += loss;
}

/* Fragment f's cohesive elements, those whose two tets both belong to it,
 * in ascending order: from the ascending list from[0..n) (a split piece's
 * are among its parent's), or from NULL, the whole solid's (a body that
 * enters fracture mode; scanning them all for each piece of a split made
 * a shattering bar's splits cost pieces times elements). */
static int collect_cohesive(cf_world *sim, cf_fragment *f, const int *from, int n)
{
    const cf_solid *s = &sim->solid;
    int id = (int)(f - sim->frag);
    f->coh.n = 0;
    for (int i = 0, count = from ? n : s->n_coh; i < count; i++) {
        int c = from ? from[i] : i;
        if (s->tet_frag[s->coh[c].tet[0]] == id && s->tet_frag[s->coh[c].tet[1]] == id &&
            cf_int_list_push(&f->coh, c))
            return -1;
    }
    return 0;
}

/* Momentum-preserving rigid velocities: v = P/M, w = (R I_rest R^T)^-1 L. */
static void rigid_velocity(const cf_fragment *f, const cf_node_state *ns, double w[3])
{
    double RQ[9], D[9] = {0}, I[9], tmp[9], Iinv[9];
    m3_mul(ns->R, f->Q, RQ);
    D[0] = f->principal[0], D[4] = f->principal[1], D[8] = f->principal[2];
    m3_mul(RQ, D, tmp);
    m3_mul_nt(tmp, RQ, I);
    w[0] = w[1] = w[2] = 0;
    if (m3_inv(I, Iinv) != 0)
        m3_mulv(Iinv, ns->L, w);
}

/* Put fragment f's nodes on the rigid motion (com, R rest -> current, v, w):
 * x = R (X - X_cm) + com, v = v + w x (x - com). */
static void place_rigid(cf_solid *s, const cf_fragment *f, const double com[3], const double R[9],
                        const double v[3], const double w[3])
{
    for (int i = 0; i < f->nodes.n; i++) {
        int a = f->nodes.v[i];
        double r[3], x[3], wr[3];
        v3_sub(&s->X[3 * a], f->com_rest, r);
        m3_mulv(R, r, x);
        v3_cross(w, x, wr);
        for (int k = 0; k < 3; k++) {
            s->x[3 * a + k] = com[k] + x[k];
            s->v[3 * a + k] = v[k] + wr[k];
        }
    }
    /* Every tet's corotational rotation is now R exactly: its warm start.
     * The one it kept is the pose it left fracture mode in, and the body
     * may have turned by anything since; from far off, the polar
     * iteration's ten turns stop short of R, and the tets start with a
     * strain no motion made (a tumbling 14-tet piece re-entering fracture
     * mode booked 4.7 J of plastic work, docs/physics.md §14.22). */
    double q[4];
    mat_to_quat(R, q);
    for (int i = 0; i < f->nt; i++)
        memcpy(&s->rq[4 * f->tets[i]], q, sizeof q);
}

/* How deep fragment f's nodes reach into obstacle j grown by gap (m,
 * <= 0), and the obstacle's normal at the deepest: at their current
 * positions, or (R not NULL) at those of its rest shape placed with
 * rotation R and centre of mass com; either moved by shift. */
static double deepest_overlap(const cf_world *sim, int j, const cf_fragment *f,
                              const double com[3], const double R[9], const double shift[3],
                              double gap, double n[3])
{
    const cf_solid *s = &sim->solid;
    double deepest = 0;
    n[0] = n[1] = n[2] = 0;
    for (int i = 0; i < f->nodes.n; i++) {
        double x[3], nj[3];
        if (R) {
            double r[3];
            v3_sub(&s->X[3 * f->nodes.v[i]], f->com_rest, r);
            m3_mulv(R, r, x);
            v3_axpy(1.0, com, x);
        } else {
            memcpy(x, &s->x[3 * f->nodes.v[i]], sizeof x);
        }
        v3_axpy(1.0, shift, x);
        double d = cf_obstacle_distance(&sim->obs, j, sim->t, x, nj) - gap;
        if (d < deepest)
            deepest = d, memcpy(n, nj, sizeof nj);
    }
    return deepest;
}

#define CLEAR_PASSES 8
#define CLEAR_TOL 1e-12 /* m: overlaps left by rounding after the first pass */

/* The translation (m) that takes fragment f (placed as deepest_overlap
 * says) out of every obstacle grown by gap.  One obstacle's push can send
 * the piece into another (a sphere's normal below its equator points into
 * the floor), so the obstacles are visited again until none overlaps, at
 * most CLEAR_PASSES times; returns whether it is clear. */
static int clearing_shift(const cf_world *sim, const cf_fragment *f, const double com[3],
                          const double R[9], double gap, double shift[3])
{
    shift[0] = shift[1] = shift[2] = 0;
    for (int pass = 0; pass < CLEAR_PASSES; pass++) {
        int moved = 0;
        for (int j = 0; j < sim->obs.n; j++) {
            double n[3], deepest = deepest_overlap(sim, j, f, com, R, shift, gap, n);
            if (deepest < (pass ? -CLEAR_TOL : 0))
                v3_axpy(-deepest, n, shift), moved = 1;
        }
        if (!moved)
            return 1;
    }
    return 0;
}

/* Energy a hand-off puts in (J), booked as a gain of the hand-off flow and
 * counted as input by the energy guard. */
static void put_in(cf_world *sim, double e)
{
    sim->flow.handoff -= e;
    sim->flow.put_in += e;
}

/* Gravity's potential that moving a piece of `mass` (kg) by `shift` (m)
 * puts in, J: a plastically flattened 487 kg hollow sphere lifted 15 mm
 * clear of the floor at its return to rigid mode gained 70 J, 1.1 % of
 * its drop's input, that the ledger missed. */
static double lift_energy(const cf_world *sim, double mass, const double shift[3])
{
    return -mass * v3_dot(sim->def.gravity, shift);
}

/* Translate fragment f out of every obstacle its placed nodes overlap (a
 * rigid pose from Bullet rests within the contact margin, and a kinematic
 * obstacle's push in one rigid step can reach centimetres into a body; a
 * best rigid fit of deformed nodes can reach below the ground).  In
 * fracture mode the PBD projection would otherwise push the overlap out
 * at dt_fracture, and the bars would carry that push to the whole
 * fragment as velocity: 2 mm over a 5 us step is a rebound at metres per
 * second; the penalty contact's spring, k = 0.01 m / dt^2, would throw it
 * harder still.  A piece no translation clears (wedged between obstacles:
 * a moving sphere over a piece on the floor) has the nodes still inside
 * put on the surface they are under.  That strains it: the energy, what
 * the obstacles' push did to the piece, is booked as a hand-off gain
 * (a negative hand-off loss), as is gravity's potential of the shift. */
static void clear_obstacles(cf_world *sim, const cf_fragment *f)
{
    cf_solid *s = &sim->solid;
    double shift[3];
    int clear = clearing_shift(sim, f, NULL, NULL, 0, shift);
    for (int i = 0; i < f->nodes.n; i++) {
        double *x = &s->x[3 * f->nodes.v[i]];
        v3_axpy(1.0, shift, x);
        if (!clear)
            cf_obstacles_push_out(&sim->obs, sim->t, x);
    }
    put_in(sim, lift_energy(sim, f->mass, shift));
    if (!clear)
        put_in(sim, cf_tet4_energy_now(s, f->tets, f->nt, sim->def.solver.elasticity));
}

/* A piece going back to rigid mode is its rest shape at the pose fitted
 * to its deformed nodes, and where a body still pressed the ground that
 * shape reaches into it by about the compression.  Bullet's push-out of
 * such an overlap reads as a fresh impact, and the piece went straight
 * back to fracture mode; the pose is lifted clear of every obstacle
 * instead (the translation alone: momenta stay as they are; gravity's
 * potential of the lift is booked as a hand-off gain).  Clear by the
 * hulls' collision margin, as Bullet's shape is the hull grown by it: a
 * margin inside the floor is a penetration that Bullet's solver removes
 * as velocity, erp x depth / dt_rigid (0.2 x 0.17 mm / 50 us = 0.7 m/s
 * on the 6.1 kg bunny), and a 15,040-tet bunny landing whole at
 * 0.35 m/s left the floor at 0.63 m/s, 1.3 J from nothing (docs/physics.md
 * §9).  A debris sphere's radius already stops at the floor. */
static void lift_clear(cf_world *sim, const cf_fragment *g, double com[3], const double R[9])
{
    int sphere = cf_fragment_is_debris(g, &sim->def.solver);
    double shift[3], gap = sphere ? 0 : cf_fragment_margin(g, &sim->solid.mat);
    clearing_shift(sim, g, com, R, gap, shift);
    v3_axpy(1.0, shift, com);
    put_in(sim, lift_energy(sim, g->mass, shift));
}

cf_status cf_handoff_to_fracture(cf_world *sim, int fi, const cfb_state *st, cf_handoff_record *rec,
                                 cf_error *err)
{
    cf_fragment *f = &sim->frag[fi];
    cf_solid *s = &sim->solid;
    cf_fragment_book_pending(f, &sim->flow);
    double P0[3], L0[3], P1[3], L1[3];
    if (st)
        cf_body_momenta(f, st, P0, L0);
    else
        cf_fragment_momenta(f, &sim->solid, sim->bullet, P0, L0);
    /* Fracture mode starts from the rigid motion: from the Bullet body, or,
     * with the pbd backend, from its nodes' best rigid fit (shape matching)
     * and momenta, so that the bars start at rest length instead of
     * releasing the residual strain of the long rigid step at dt_fracture. */
    double loss = 0;
    if (st) {
        double Rb[9], R[9];
        quat_to_mat(st->quat, Rb);
        m3_mul_nt(Rb, f->Q, R);
        place_rigid(s, f, st->pos, R, st->v, st->w);
        cfb_remove_body(sim->bullet, f->body);
        f->body = -1;
    } else {
        cf_node_state ns;
        double w[3];
        cf_nodes_state(s, f->nodes.v, f->nodes.n, f->q_match, &ns);
        rigid_velocity(f, &ns, w);
        place_rigid(s, f, ns.com, ns.R, ns.v, w);
        loss = ns.ke - (0.5 * ns.M * v3_dot(ns.v, ns.v) + 0.5 * v3_dot(w, ns.L));
        sim->flow.handoff += loss;
    }
    clear_obstacles(sim, f);
    f->mode = CF_MODE_FRACTURE;
    f->separated = -1;
    f->steps = f->quiet = f->grown = 0;
    f->t_enter = sim->t;
    cf_fragment_ledger_reset(f, &sim->solid, &sim->flow);
    f->e_enter = f->e_kin;
    if (collect_cohesive(sim, f, NULL, 0) ||
        (cf_world_reads_bars(sim) && cf_bars_build(&f->bars, s, f->tets, f->nt)))
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory entering fracture mode");
    cf_fragment_momenta(f, &sim->solid, sim->bullet, P1, L1);
    record_handoff(sim, fi, 0, P0, L0, P1, L1, loss, rec);
    return CF_OK;
}

/* The tets grouped by component, in list order within each: component c
 * is out[start[c]] .. out[start[c + 1] - 1] (one pass: a split into many
 * pieces does not scan the whole list once per piece).  NULL when out of
 * memory; free both. */
static int *group_by_component(const int *tets, const int *comp, int nt, int k, int **start)
{
    int *out = malloc((size_t)(nt ? nt : 1) * sizeof(int));
    int *at = calloc((size_t)k + 2, sizeof(int));
    if (!out || !at) {
        free(out), free(at);
        return NULL;
    }
    /* Counts shifted by two, summed: at[c + 1] is where component c starts.
     * Filling moves it to where c ends, which is where c + 1 starts, so at
     * ends as the start of each component. */
    for (int i = 0; i < nt; i++)
        at[comp[i] + 2]++;
    for (int c = 0; c < k; c++)
        at[c + 2] += at[c + 1];
    for (int i = 0; i < nt; i++)
        out[at[comp[i] + 1]++] = tets[i];
    *start = at;
    return out;
}

/* Give the new fragment `ci` the `count` tets at `tets` and their nodes. */
static int take_component(cf_world *sim, int ci, const int *tets, int count, unsigned char *seen)
{
    cf_fragment *f = &sim->frag[ci];
    cf_solid *s = &sim->solid;
    f->tets = malloc((size_t)(count ? count : 1) * sizeof(int));
    if (!f->tets)
        return -1;
    f->nt = 0;
    for (int i = 0; i < count; i++) {
        int t = tets[i];
        f->tets[f->nt++] = t;
        s->tet_frag[t] = ci;
        for (int j = 0; j < 4; j++) {
            int a = s->tet[4 * t + j];
            if (!seen[a]) {
                if (cf_int_list_push(&f->nodes, a))
                    return -1;
                seen[a] = 1; /* only the listed nodes: the split clears them by the list */
            }
        }
    }
    return 0;
}

int cf_fragment_split_fracture(cf_world *sim, int fi, int *first)
{
    cf_solid *s = &sim->solid;
    cf_fragment *f = &sim->frag[fi];
    /* Insertion alone never splits a fragment: a new cohesive element joins
     * the two tets whose nodes it duplicated until all three of its node
     * pairs have failed (cf_label_pieces).  Unless more elements have failed
     * completely since the last check, the pieces are those it found. */
    int separated = 0;
    for (int e = 0; e < f->coh.n; e++)
        separated += cf_cohesive_all_failed(&s->coh[f->coh.v[e]]);
    if (separated == f->separated)
        return 0;
    f->separated = separated;
    int nt = f->nt, *tets = f->tets;
    int *comp = malloc((size_t)nt * sizeof(int));
    if (!comp)
        return -1;
    int k = cf_label_pieces(s, tets, nt, f->coh.v, f->coh.n, comp);
    if (k <= 1) {
        free(comp);
        return k < 0 ? -1 : 0;
    }
    cf_fragment_book_pending(f, &sim->flow);
    /* The parent's per-node leapfrog kinetic energy terms, by node id. */
    int *index = malloc((size_t)s->n_nodes * sizeof(int));
    /* The nodes taken, marked in the insertion check's scratch (all 0 here,
     * and cleared again below; a run without a criterion has none): a
     * split paid a clear array of all the solid's nodes, thousands of
     * times over for a shattering body. */
    unsigned char *own = s->node_mark ? NULL : calloc((size_t)s->n_nodes, 1);
    unsigned char *seen = s->node_mark ? s->node_mark : own;
    int *cstart = NULL, *grouped = group_by_component(tets, comp, nt, k, &cstart);
    int rc = -(!index || !seen || !grouped);
    for (int i = 0; rc == 0 && i < f->nodes.n; i++)
        index[f->nodes.v[i]] = i;
    *first = sim->n_frag;
    for (int c = 0; rc == 0 && c < k; c++)
        if (cf_fragment_new(&sim->frag, &sim->n_frag, &sim->cap_frag, fi, sim->t) < 0)
            rc = -1;
    for (int c = 0; rc == 0 && c < k; c++) {
        int ci = *first + c;
        if (take_component(sim, ci, grouped + cstart[c], cstart[c + 1] - cstart[c], seen)) {
            rc = -1;
            break;
        }
        cf_fragment *g = &sim->frag[ci], *p = &sim->frag[fi]; /* the array may have moved */
        cf_fragment_rest_props(g, &sim->solid);
        g->mode = CF_MODE_FRACTURE;
        g->steps = p->steps, g->quiet = p->quiet, g->grown = p->grown, g->t_enter = p->t_enter;
        g->e_enter = p->e_enter;
        memcpy(g->q_match, p->q_match, sizeof g->q_match);
        cf_step_ctx ctx = cf_world_step_ctx(sim);
        g->e_strain = cf_tet4_strain_energy(s, g->tets, g->nt) +
                      cf_fragment_spring_energy(&ctx, g, sim->t, sim->h_fracture);
        for (int i = 0; i < g->nodes.n; i++) {
            int a = g->nodes.v[i];
            g->e_kin += 0.5 * s->m[a] * v3_dot(&p->v_old[3 * index[a]], &s->v[3 * a]);
            v3_axpy(s->m[a], &s->x[3 * a], g->mx);
        }
        if (collect_cohesive(sim, g, p->coh.v, p->coh.n))
            rc = -1;
    }
    for (int c = 0; s->node_mark && c < k && *first + c < sim->n_frag; c++) {
        const cf_fragment *g = &sim->frag[*first + c];
        for (int i = 0; i < g->nodes.n; i++)
            seen[g->nodes.v[i]] = 0;
    }
    /* The parent's bars go to the pieces (index now gives a node's piece). */
    cf_bars **dst = rc ? NULL : malloc((size_t)k * sizeof *dst);
    rc |= -(!dst);
    for (int c = 0; rc == 0 && c < k; c++) {
        cf_fragment *g = &sim->frag[*first + c];
        dst[c] = &g->bars;
        for (int i = 0; i < g->nodes.n; i++)
            index[g->nodes.v[i]] = c;
    }
    if (rc == 0 && cf_bars_split(&sim->frag[fi].bars, index, k, dst))
        rc = -1;
    free(dst);
    if (rc == 0) {
        f = &sim->frag[fi];
        f->mode = CF_MODE_DEAD;
        f->tets = NULL, f->nt = 0;
        cf_fragment_release(f, 1);
        cf_bars_free(&f->bars);
        free(tets);
    }
    free(comp), free(index), free(own), free(grouped), free(cstart);
    return rc ? -1 : k;
}

cf_status cf_handoff_to_rigid(cf_world *sim, int fi, cf_handoff_record *rec, cf_error *err)
{
    cf_solid *s = &sim->solid;
    cf_fragment *f = &sim->frag[fi];
    cf_fragment_book_pending(f, &sim->flow);
    int nt = f->nt;
    int *tets = f->tets;
    int *comp = malloc((size_t)nt * sizeof(int));
    unsigned char *seen = calloc((size_t)s->n_nodes, 1);
    if (!comp || !seen) {
        free(comp), free(seen);
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory at hand-off");
    }
    /* Pieces still joined by a cohesive element with an unfailed node pair
     * go back as one body, and the element keeps its state for the next
     * impact (its stored energy is dropped below, as a rigid body stores
     * none): only what has come apart leaves on its own. */
    int k = cf_label_pieces(s, tets, nt, f->coh.v, f->coh.n, comp);
    int *cstart = NULL, *grouped = k < 1 ? NULL : group_by_component(tets, comp, nt, k, &cstart);
    free(comp);
    if (!grouped) { /* k -1: out of memory; 0 components would empty the fragment */
        free(seen);
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory at hand-off");
    }
    /* A rigid fragment keeps no strain or cohesive energy. */
    sim->flow.handoff += f->e_strain + cf_cohesive_release(s, f->coh.v, f->coh.n);
    f->e_strain = 0;
    cf_tet4_to_rigid(s, tets, nt);
    cf_node_state before;
    cf_nodes_momenta(s, f->nodes.v, f->nodes.n, &before);
    double P0[3], L0[3], P1[3] = {0, 0, 0}, L1[3] = {0, 0, 0}, ke_after = 0;
    cf_fragment_momenta(f, &sim->solid, sim->bullet, P0, L0);

    /* One component: the fragment stays itself, and has taken the impact
     * it entered with and the sustained contacts rigid mode takes on (a
     * weaker one leaves it rigid); several: children, new bodies whose
     * next impact is their own. */
    int first = fi;
    if (k == 1)
        f->dv_taken = fmax(f->dv_taken, fmax(f->dv_enter, f->dv_sustained));
    if (k > 1) {
        f->mode = CF_MODE_DEAD;
        first = sim->n_frag;
        for (int c = 0; c < k; c++)
            if (cf_fragment_new(&sim->frag, &sim->n_frag, &sim->cap_frag, fi, sim->t) < 0) {
                free(grouped), free(cstart), free(seen);
                return cf_error_set(err, CF_ERR_NOMEM, "out of memory at hand-off");
            }
        f = &sim->frag[fi]; /* the array may have moved */
    }
    f->tets = NULL; /* the old lists are handed out to the components below */
    f->nt = 0;
    f->nodes.n = 0;
    for (int c = 0; c < k; c++) {
        int ci = first + c;
        if (take_component(sim, ci, grouped + cstart[c], cstart[c + 1] - cstart[c], seen)) {
            free(grouped), free(cstart), free(seen);
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory at hand-off");
        }
        cf_fragment *g = &sim->frag[ci];
        /* A fragment that stays itself keeps its tets, so its mass, centre
         * and principal frame: its hulls, kept from its last hand-off, are
         * in that frame.  Computed again, a body of equal principal
         * moments (a cube) got other axes from the round-off of the node
         * order, and its hulls were posed turned, deep in the ground. */
        if (k > 1)
            cf_fragment_rest_props(g, &sim->solid);
        g->mode = CF_MODE_RIGID;
        memcpy(g->q_match, sim->frag[fi].q_match, sizeof g->q_match);
        cf_node_state ns;
        cf_nodes_state(s, g->nodes.v, g->nodes.n, g->q_match, &ns);
        double w[3];
        rigid_velocity(g, &ns, w);
        ke_after += 0.5 * ns.M * v3_dot(ns.v, ns.v) + 0.5 * v3_dot(w, ns.L);
        if (sim->bullet) {
            lift_clear(sim, g, ns.com, ns.R);
            cf_status st = cf_fragment_add_body(sim, ci, ns.com, ns.R, ns.v, w, err);
            if (st != CF_OK) {
                free(grouped), free(cstart), free(seen);
                return st;
            }
        } else {
            if (cf_bars_build(&g->bars, s, g->tets, g->nt)) {
                free(grouped), free(cstart), free(seen);
                return cf_error_set(err, CF_ERR_NOMEM, "out of memory at hand-off");
            }
            g->steps = 0;
            cf_fragment_ledger_reset(g, &sim->solid, &sim->flow);
        }
    }
    /* Fragments of one initial body do not collide with each other in
     * Bullet: their hulls may overlap where a crack face is not convex, and
     * thousands of touching pieces would dominate Bullet's narrow phase
     * (about 14 times the rigid-step cost on a shattering sphere). */
    if (sim->bullet) {
        int root = cf_fragment_root(sim->frag, fi);
        for (int a = 0; a < k; a++)
            cfb_set_family(sim->bullet, sim->frag[first + a].body, root);
    }
    if (sim->bullet || k > 1)
        cf_bars_free(&sim->frag[fi].bars);
    cf_contact_cache_clear(&sim->contact, fi);
    free(tets), free(grouped), free(cstart), free(seen);
    for (int c = 0; c < k; c++) {
        double P[3], L[3];
        cf_fragment_momenta(&sim->frag[first + c], &sim->solid, sim->bullet, P, L);
        v3_axpy(1.0, P, P1);
        v3_axpy(1.0, L, L1);
    }
    cf_fragment_release(&sim->frag[fi], k > 1);
    double loss = before.ke - ke_after;
    if (sim->bullet) /* the pbd rigid backend keeps the nodes' velocities: damping removes it */
        sim->flow.handoff += loss;
    record_handoff(sim, fi, 1, P0, L0, P1, L1, loss, rec);
    return CF_OK;
}
