/* The in-house solver step (source Table 6.2, docs/physics.md §4), per fragment. */
#include "fracture.h"

#include "chunks.h"
#include "linalg.h"
#include "parallel.h"
#include "tet4.h"

#include <stdlib.h>
#include <string.h>

/* Room for fragment f's scratch and its contact cache *cc. */
static int ensure_scratch(cf_fragment *f, cf_contact_cache *cc)
{
    if (cf_node_impulses_reserve(&cc->push, f->nodes.n))
        return -1;
    if (f->pairs_cap < f->coh.n) {
        int cap = f->coh.n + f->coh.n / 2 + 16;
        cf_pair_force *p = realloc(f->pairs, (size_t)cap * 3 * sizeof *p);
        if (!p)
            return -1;
        f->pairs = p, f->pairs_cap = cap;
    }
    if (f->scratch_cap >= f->nodes.n)
        return 0;
    int cap = f->nodes.n + f->nodes.n / 2 + 16;
    int *c = realloc(f->contact, (size_t)cap * sizeof(int));
    if (!c)
        return -1;
    f->contact = c;
    double *v = realloc(f->vn_pre, (size_t)cap * sizeof(double));
    if (!v)
        return -1;
    f->vn_pre = v;
    v = realloc(f->v_old, (size_t)cap * 3 * sizeof(double));
    if (!v)
        return -1;
    f->v_old = v;
    v = realloc(f->term, (size_t)cap * sizeof(double));
    if (!v)
        return -1;
    f->term = v;
    f->scratch_cap = cap;
    return 0;
}

/* Rayleigh wave speed, m/s: the fastest a crack runs in a brittle solid
 * (Freund 1990, the approximation c_R = c_s (0.862 + 1.14 nu) / (1 + nu)). */
static double rayleigh_speed(const cf_solid *s)
{
    double nu = s->mat.nu;
    return sqrt(s->mu / s->mat.rho) * (0.862 + 1.14 * nu) / (1.0 + nu);
}

/* An explicit step: fracture mode without the constraint projection (no
 * bars). */
static int explicit_step(const cf_solver_settings *set, int fracture)
{
    return fracture && set->constraints == CF_CONSTRAINTS_NONE;
}

/* Whether obstacles act on this step's nodes by a penalty force rather
 * than the projection (explicit fracture steps, docs/physics.md §7.1). */
static int penalty_step(const cf_solver_settings *set, int fracture)
{
    return explicit_step(set, fracture) && set->obstacle_contact == CF_OBSTACLE_CONTACT_PENALTY;
}

#define CF_PENALTY_SCALE 0.01 /* k = CF_PENALTY_SCALE m / dt^2 (penalty_chunk) */

/* Half k d^2 over the obstacles node a is under at time t (k from step dt). */
static double node_springs(const cf_step_ctx *ctx, int a, double t, double dt)
{
    const cf_solid *s = ctx->solid;
    const double *x = &s->x[3 * a];
    if (cf_obstacles_clear(ctx->obs, x))
        return 0;
    double k = CF_PENALTY_SCALE * s->m[a] / (dt * dt), e = 0;
    for (int o = 0; o < ctx->obs->n; o++) {
        double n[3], d = cf_obstacle_distance(ctx->obs, o, t, x, n);
        e += d < 0 ? 0.5 * k * d * d : 0;
    }
    return e;
}

double cf_fragment_spring_energy(const cf_step_ctx *ctx, const cf_fragment *f, double t, double h)
{
    if (!penalty_step(&ctx->def->solver, 1) || !(h > 0))
        return 0;
    double e = 0;
    for (int i = 0; i < f->nodes.n; i++)
        e += node_springs(ctx, f->nodes.v[i], t, h);
    return e;
}

/* Crushing at this check (time t, s; step dt; docs/physics.md §2.2):
 * the tets cf_crush_tets crushes come free as powder, without a cohesive
 * element, so the pieces are labelled again although no element failed.
 * Their strain energy, the cohesive elements on their faces (failed and
 * dropped from the fragment's list: their compression penalty would kick
 * the powder's light nodes) and, with the penalty contact, the springs of
 * their nodes under an obstacle (moved onto its surface: the spring held
 * the body's load, and would throw a node that now carries only its own
 * share at 0.1 d / dt) are booked as crushing work.  Returns how many tets
 * were crushed, or -1 out of memory. */
static int crush(const cf_step_ctx *ctx, cf_fragment *f, double t, double dt)
{
    cf_solid *s = ctx->solid;
    double released;
    ctx->crushed->n = 0;
    int crushed = cf_crush_tets(s, f->tets, f->nt, t, &f->nodes, ctx->touched, ctx->crushed,
                                &released);
    if (crushed <= 0)
        return crushed;
    int kept = 0;
    for (int i = 0; i < f->coh.n; i++) {
        int e = f->coh.v[i];
        if (s->crushed[s->coh[e].tet[0]] || s->crushed[s->coh[e].tet[1]])
            cf_cohesive_fail(s, e);
        else
            f->coh.v[kept++] = e;
    }
    f->coh.n = kept;
    f->separated = -1;
    f->e_strain -= released; /* the tets' part, in this step's sum already */
    if (!penalty_step(&ctx->def->solver, 1))
        return crushed;
    /* The springs' part was in the last step's sum: it goes to the tet's
     * crushing work. */
    for (int i = 0; i < ctx->crushed->n; i++)
        for (int j = 0; j < 4; j++) {
            int tt = ctx->crushed->v[i], a = s->tet[4 * tt + j];
            s->wp[tt] += node_springs(ctx, a, t, dt);
            cf_obstacles_push_out(ctx->obs, t, &s->x[3 * a]);
        }
    return crushed;
}

/* Stage insertion_check (source Table 6.2, docs/physics.md §5.1): the
 * facets that meet the criterion at this check (time t, s; n_hot tets
 * above the criterion's bound), then those the growth rule takes, in
 * ctx->cand.  Returns how many, or -1 out of memory. */
static int insertion_check(const cf_step_ctx *ctx, const cf_fragment *f, double t, int n_hot)
{
    cf_solid *s = ctx->solid;
    const cf_solver_settings *set = &ctx->def->solver;
    double kink = set->front_max_kink < 180 ? set->front_max_kink * acos(-1.0) / 180 : 0;
    cf_growth growth = {set->crack_growth, rayleigh_speed(s), set->min_piece_tets,
                        cf_min_piece_volume(set), t,
                        set->front_direction == CF_FRONT_STRESS, kink,
                        set->front_split == CF_FRONT_SPLIT_PLANE, set->front_split_reach,
                        set->front_snap == CF_FRONT_SNAP_STRESS};
    int nc = cf_insertion_candidates(s, f->tets, f->nt, set->criterion, n_hot, &growth, ctx->cand);
    if (nc > 0)
        nc = cf_insertion_select(s, ctx->cand, set->criterion, &growth);
    return nc;
}

/* Stage node_duplication (docs/physics.md §5): extrinsic insertion of a
 * cohesive element on each of the nc facets insertion_check chose, with
 * the node duplication that opens them; crushing (crush); the bars of the
 * nodes whose star changed.  *inserted: elements plus crushed tets. */
static cf_status node_duplication(const cf_step_ctx *ctx, cf_fragment *f, double t, double dt,
                                  int nc, int *inserted)
{
    cf_solid *s = ctx->solid;
    ctx->touched->n = 0;
    for (int i = 0; i < nc; i++)
        if (cf_crack_facet(s, ctx->cand->v[i], &f->nodes, ctx->touched) ||
            cf_int_list_push(&f->coh, s->n_coh - 1))
            return CF_ERR_NOMEM;
    int crushed = crush(ctx, f, t, dt);
    if (crushed < 0)
        return CF_ERR_NOMEM;
    if (cf_bars_patch(&f->bars, s, ctx->touched->v, ctx->touched->n, ctx->bar_scratch))
        return CF_ERR_NOMEM;
    *inserted = nc + crushed;
    return CF_OK;
}

/* Energy a velocity change takes out of node i, J: from `from` to `to`.
 * The ledger's kinetic energy is the leapfrog product 1/2 m v_old . v
 * (update_velocities).  A change that also moves the node (`moves`: the
 * projection's, which sets x = p, and explicit friction) is the impulse
 * J = m (to - from) doing the work J . (v_old + to)/2, with which the product
 * telescopes from step to step (docs/physics.md §10): a node resting on an
 * obstacle while the body above presses it down takes J = -m dt f/m every
 * step but does no work (it does not move), where 1/2 m (|from|^2 - |to|^2)
 * would book 1/2 dt^2 |f|^2/m at each step, a loss of the order of the
 * impact's energy at dt ~ dt_cfl.  A change of the velocity alone (the speed
 * cap, PBD friction and restitution) changes the next product by
 * 1/2 m (|to|^2 - |from|^2). */
static double impulse_removes(const cf_solid *s, const cf_fragment *f, int i, const double from[3],
                              const double to[3], int moves)
{
    double m = s->m[f->nodes.v[i]];
    if (!moves)
        return 0.5 * m * (v3_dot(from, from) - v3_dot(to, to));
    double dv[3], mid[3];
    v3_sub(to, from, dv);
    for (int k = 0; k < 3; k++)
        mid[k] = 0.5 * (f->v_old[3 * i + k] + to[k]);
    return -m * v3_dot(dv, mid);
}

/* Node i's velocity shifted by dv; returns the energy that takes. */
static double shift_node(cf_solid *s, const cf_fragment *f, int i, const double dv[3])
{
    double *va = &s->v[3 * f->nodes.v[i]], to[3];
    for (int k = 0; k < 3; k++)
        to[k] = va[k] + dv[k];
    double removed = impulse_removes(s, f, i, va, to, 0);
    memcpy(va, to, sizeof to);
    return removed;
}

/* What the chunk sums of a step read (chunks.h). */
typedef struct {
    const cf_step_ctx *ctx;
    cf_fragment *f;
    cf_contact_cache *cc; /* f's */
    double t_next, dt, dv[3];
    int leapfrog; /* collision_friction: explicit friction moves the node */
    int penalty;  /* obstacles act by the penalty force (penalty_chunk) */
} step_sums;

/* Whether an obstacle is a triangle mesh: its FCL queries run on one thread. */
static int mesh_obstacles(const cf_step_ctx *ctx)
{
    for (int j = 0; ctx->obs->mesh && j < ctx->obs->n; j++)
        if (ctx->obs->mesh[j])
            return 1;
    return 0;
}

/* Friction and restitution of nodes in contact, relative to the obstacle.
 * In explicit runs (`leapfrog`) the position moves with friction's velocity
 * change, x += dt dv_t, so that x_n+1 = x_n + dt v_n+1/2 still holds: a node that
 * friction sticks then stays where it is, where moving it by the predicted
 * slip while its velocity reads zero let the tangential force do work that
 * no term counted (a corner pivoting on the ground lost 20 % of a box's
 * energy so).  With PBD or XPBD friction acts on the velocity alone, as in
 * position based dynamics.  Adds the energy this removes (J,
 * impulse_removes) into acc[0], and the moving obstacles' work in it into
 * acc[1]; each node changes only its own velocity and position. */
static void contact_chunk(void *ctx, int i0, int i1, double *acc)
{
    const step_sums *c = ctx;
    cf_solid *s = c->ctx->solid;
    cf_fragment *f = c->f;
    int shift = c->dv[0] != 0 || c->dv[1] != 0 || c->dv[2] != 0;
    for (int i = i0; i < i1; i++) {
        if (shift) /* the momentum the speed cap took, given back (velocity_update) */
            acc[2] += shift_node(s, f, i, c->dv);
        int j = f->contact[i];
        if (j < 0)
            continue;
        const cf_obstacle *o = &c->ctx->obs->o[j];
        double mu = s->mat.friction * o->friction, e = s->mat.restitution * o->restitution;
        int a = f->nodes.v[i];
        double n[3], u[3], vr[3], *va = &s->v[3 * a];
        cf_obstacle_distance(c->ctx->obs, j, c->t_next, &s->x[3 * a], n);
        cf_obstacle_velocity(o, u);
        v3_sub(va, u, vr);
        double vn = v3_dot(vr, n), vt[3];
        for (int k = 0; k < 3; k++)
            vt[k] = vr[k] - vn * n[k];
        double vn_new = vn, dvn;
        if (c->penalty) { /* the penalty force's normal velocity change (penalty_chunk) */
            dvn = f->vn_pre[i];
        } else {
            if (f->vn_pre[i] < 0 && vn < -e * f->vn_pre[i])
                vn_new = -e * f->vn_pre[i];
            dvn = fabs(vn_new - (f->vn_pre[i] < 0 ? f->vn_pre[i] : 0));
        }
        /* Coulomb: the tangential change is bounded by mu times the normal one. */
        double vtl = v3_norm(vt);
        double scale = vtl > 0 ? fmax(0.0, 1.0 - mu * dvn / vtl) : 0;
        double dv[3], vnew[3];
        for (int k = 0; k < 3; k++) {
            vnew[k] = u[k] + vn_new * n[k] + scale * vt[k];
            dv[k] = vnew[k] - va[k];
        }
        acc[0] += impulse_removes(s, f, i, va, vnew, c->leapfrog);
        memcpy(va, vnew, sizeof vnew);
        if (c->leapfrog) /* friction's part; the projection already placed it normally */
            v3_axpy(-c->dt * (1.0 - scale), vt, &s->x[3 * a]);
        /* A moving obstacle's work: the impulse it gives times its velocity. */
        double w = s->m[a] * v3_dot(dv, u);
        acc[0] += w;
        acc[1] += w;
    }
}

/* Stage collision, after the velocity update: friction and restitution
 * (contact_chunk), after each node's velocity is shifted by dv (the speed
 * cap's momentum, from velocity_update; zero: none); the shift's energy is
 * booked with the projection's. */
static double collision_friction(const cf_step_ctx *ctx, cf_fragment *f, cf_contact_cache *cc,
                                 double t, double dt, int leapfrog, int penalty,
                                 const double dv[3])
{
    step_sums c = {.ctx = ctx, .f = f, .cc = cc, .t_next = t, .dt = dt,
                   .dv = {dv[0], dv[1], dv[2]}, .leapfrog = leapfrog, .penalty = penalty};
    double sums[3]; /* removed, of which the obstacles' work; the shift's */
    cf_sum_chunks(f->nodes.n, 3, !mesh_obstacles(ctx), contact_chunk, &c, sums);
    f->pending.obstacles += sums[1];
    f->pending.pbd += sums[2];
    return sums[0];
}

/* The prescribed velocity components of boundary node a: into v (m/s), or
 * into the prediction p = x + dt v when `on_p` is set.  Returns the work of
 * the reaction that restores p (J): the impulse m dp/dt times the node's
 * prescribed velocity. */
static double impose_boundary(const cf_step_ctx *ctx, int a, double dt, int on_p)
{
    cf_solid *s = ctx->solid;
    const cf_boundary *bc = &ctx->def->boundaries[s->bc[a]];
    double work = 0;
    for (int k = 0; k < 3; k++)
        if (bc->axes & (1 << k)) {
            if (on_p) {
                double target = s->x[3 * a + k] + dt * bc->velocity[k];
                work += s->m[a] * (target - s->p[4 * a + k]) / dt * bc->velocity[k];
                s->p[4 * a + k] = target;
            } else {
                s->v[3 * a + k] = bc->velocity[k];
            }
        }
    return work;
}

/* The penalty contact on nodes i0..i1-1 at x_n: a node at signed distance
 * d < 0 from an obstacle gets the force k (-d) n along its outward normal,
 * k = CF_PENALTY_SCALE m / dt^2 from the node's lumped mass and the step
 * (the soft-constraint stiffness of explicit codes, e.g. LS-DYNA's
 * SOFT = 1).  (k/m) dt^2 = 0.01 adds a hundredth to the squared frequency
 * whose leapfrog limit is 4, so the contact never sets the step even beside
 * the cohesive elements' own penalties; LS-DYNA's default 0.1 did, once a
 * plaster bunny landing at 7.6 m/s cracked at the floor.  A 6 kg body's
 * landing still sinks its contact nodes by micrometres.  The spring is
 * conservative: its energy 1/2 k d^2 goes to acc[0] (booked with the
 * strain energy), a moving obstacle's work F . u dt to acc[1].  contact[i]
 * records the obstacle and vn_pre[i] the normal velocity the force gives
 * in the step, dt |F|/m, the bound of Coulomb friction in contact_chunk. */
static void penalty_chunk(void *ctx, int i0, int i1, double *acc)
{
    const step_sums *c = ctx;
    cf_solid *s = c->ctx->solid;
    cf_fragment *f = c->f;
    const cf_obstacles *obs = c->ctx->obs;
    for (int i = i0; i < i1; i++) {
        int a = f->nodes.v[i];
        const double *x = &s->x[3 * a];
        f->contact[i] = -1;
        f->vn_pre[i] = 0;
        if (cf_obstacles_clear(obs, x))
            continue;
        double k = CF_PENALTY_SCALE * s->m[a] / (c->dt * c->dt);
        for (int j = 0; j < obs->n; j++) {
            double n[3], u[3];
            double d = cf_obstacle_distance(obs, j, c->t_next, x, n);
            if (d >= 0)
                continue;
            v3_axpy(-k * d, n, &s->f[3 * a]);
            cf_obstacle_velocity(&obs->o[j], u);
            acc[0] += 0.5 * k * d * d;
            acc[1] += -k * d * c->dt * v3_dot(n, u);
            f->contact[i] = j;
            f->vn_pre[i] += -k * d * c->dt / s->m[a];
        }
    }
}

/* Stage elasticity, its first part: the Tet4 kernel on every tet of f at
 * x_n (corotational or Neo-Hookean forces per tet, rotation, inverted
 * tets; the stress too when `check`), and the strain energy.  Returns how
 * many tets are above the criterion's bound (cf_tet4_forces). */
static int elasticity(const cf_step_ctx *ctx, cf_fragment *f, int check, double dt)
{
    cf_solid *s = ctx->solid;
    const cf_solver_settings *set = &ctx->def->solver;
    cf_stress_check bound = cf_insertion_bound(s, set->criterion);
    int n_hot = 0;
    f->n_inverted = cf_tet4_forces(s, f->tets, f->nt, set->elasticity, check ? &bound : NULL,
                                   dt, &n_hot);
    f->e_strain = cf_tet4_strain_energy(s, f->tets, f->nt);
    return n_hot;
}

/* Stage elasticity, its second part: the tets' forces gathered at the
 * nodes, with gravity: f = m g - f_int. */
static void elasticity_scatter(const cf_step_ctx *ctx, cf_fragment *f)
{
    cf_tet4_scatter(ctx->solid, f->tets, f->nt, f->nodes.v, f->nodes.n, ctx->def->gravity);
}

/* Stage cohesive_forces (docs/physics.md §6): the PPR tractions of f's
 * cohesive elements and, in explicit runs, the crack faces' compression
 * penalty, added to the node forces (with PBD the faces are kept apart by
 * a constraint in pbd_projection instead). */
static void cohesive_forces(const cf_step_ctx *ctx, cf_fragment *f, double dt)
{
    const cf_solver_settings *set = &ctx->def->solver;
    cf_face_contact fc = {
        .kp = set->constraints == CF_CONSTRAINTS_NONE ? set->contact_stiffness : -1.0,
        .normal_rises = set->time_continuity == CF_CONTINUITY_BOTH,
    };
    cf_cohesive_forces(ctx->solid, ctx->law, ctx->law_params, f->coh.v, f->coh.n, dt, &fc,
                       f->pairs);
}

/* Stage collision, as a force (explicit runs with the penalty contact,
 * docs/physics.md §7.1): penalty_chunk on every node; the springs' energy
 * goes with the strain energy. */
static void collision_forces(const cf_step_ctx *ctx, cf_fragment *f, double t, double dt)
{
    step_sums c = {.ctx = ctx, .f = f, .t_next = t, .dt = dt, .leapfrog = 1, .penalty = 1};
    double e[2]; /* the springs' energy; moving obstacles' work */
    cf_sum_chunks(f->nodes.n, 2, !mesh_obstacles(ctx), penalty_chunk, &c, e);
    f->e_strain += e[0];
    f->pending.obstacles += e[1];
}

/* The ledger's kinetic energy, the leapfrog product 1/2 m v_old . v, and
 * the mass moment m x (3 terms). */
static void kinetic_chunk(void *ctx, int i0, int i1, double *acc)
{
    const step_sums *c = ctx;
    const cf_solid *s = c->ctx->solid;
    const cf_fragment *f = c->f;
    for (int i = i0; i < i1; i++) {
        int a = f->nodes.v[i];
        acc[0] += 0.5 * s->m[a] * v3_dot(&f->v_old[3 * i], &s->v[3 * a]);
    }
    cf_nodes_mass_moment_add(s, f->nodes.v, i0, i1, &acc[1]);
}

/* The kick v <- v + dt M^-1 f on nodes i0..i1-1 (v_old keeps v), then
 * kinetic_chunk's sums of the new velocities, and the count of prescribed
 * nodes in acc[4]: one pass over the nodes where no prescribed node or
 * damping changes v after the kick. */
static void kick_chunk(void *ctx, int i0, int i1, double *acc)
{
    const step_sums *c = ctx;
    cf_solid *s = c->ctx->solid;
    const cf_fragment *f = c->f;
    for (int i = i0; i < i1; i++) {
        int a = f->nodes.v[i];
        memcpy(&f->v_old[3 * i], &s->v[3 * a], 3 * sizeof(double));
        v3_axpy(c->dt / s->m[a], &s->f[3 * a], &s->v[3 * a]);
        acc[4] += s->bc[a] >= 0;
    }
    kinetic_chunk(ctx, i0, i1, acc);
}

/* v <- v + dt M^-1 f, prescribed velocities, global damping (pbd rigid
 * mode); the ledger's kinetic energy and the boundary and damping work.
 * Returns the number of prescribed nodes. */
static int update_velocities(const cf_step_ctx *ctx, cf_fragment *f, double dt, int fracture)
{
    cf_solid *s = ctx->solid;
    const int *nodes = f->nodes.v;
    int nn = f->nodes.n;
    step_sums c = {.ctx = ctx, .f = f, .dt = dt};
    double sums[5];
    cf_sum_chunks(nn, 5, 1, kick_chunk, &c, sums);
    int n_bc = (int)sums[4]; /* prescribed nodes: most fragments have none */
    /* Work of the boundary: the reaction R = m (v_bc - v_free)/dt over
     * dt (v_old + v_new)/2, the leapfrog work of a force. */
    double w_bc = 0;
    for (int i = 0; n_bc > 0 && i < nn; i++) {
        int a = nodes[i];
        if (s->bc[a] < 0)
            continue;
        double vfree[3], *vo = &f->v_old[3 * i];
        memcpy(vfree, &s->v[3 * a], sizeof vfree);
        impose_boundary(ctx, a, dt, 0);
        for (int k = 0; k < 3; k++)
            w_bc += s->m[a] * (s->v[3 * a + k] - vfree[k]) * 0.5 * (vo[k] + s->v[3 * a + k]);
    }
    if (n_bc > 0) /* the world's flows: fragments with prescribed nodes step alone */
        ctx->flow->boundary += w_bc;
    if (!fracture) {
        /* Global damping D is linear, keeps momentum, and leaves the uniform
         * kick dt g as it is, so D(v_old + dt g) = D(v_old) + dt g: it acts
         * as a change of the velocity at the step's start, v_old <- D(v_old),
         * which takes 1/2 m (|v|^2 - |D v|^2) and which the leapfrog product
         * below then starts from.  (The velocities before damping wait in p,
         * free until the prediction.) */
        for (int i = 0; i < nn; i++)
            memcpy(&s->p[4 * nodes[i]], &s->v[3 * nodes[i]], 3 * sizeof(double));
        cf_global_damping(s, nodes, nn, ctx->def->solver.k_damping);
        for (int i = 0; i < nn; i++) {
            int a = nodes[i];
            ctx->flow->damping += impulse_removes(s, f, i, &s->p[4 * a], &s->v[3 * a], 0);
            for (int k = 0; k < 3; k++)
                f->v_old[3 * i + k] = s->v[3 * a + k] - dt * s->f[3 * a + k] / s->m[a];
        }
    }
    if (n_bc > 0 || !fracture) /* v changed after the kick: the sums anew */
        cf_sum_chunks(nn, 4, 1, kinetic_chunk, &c, sums);
    f->e_kin = sums[0];
    memcpy(f->mx, &sums[1], sizeof f->mx);
    return n_bc;
}

/* The obstacles and rigid neighbours' hulls on node i's prediction at
 * t_next; records its contact and approach speed.  Returns the work of
 * moving obstacles on it in this pass, J. */
static double obstacle_node(const cf_step_ctx *ctx, cf_fragment *f, cf_contact_cache *cc, int i,
                            double t_next, double dt, int penalty)
{
    cf_solid *s = ctx->solid;
    int a = f->nodes.v[i];
    double n[3], before[3], w = 0;
    memcpy(before, &s->p[4 * a], sizeof before);
    int hit = penalty ? -1
                      : cf_obstacles_project(ctx->obs, t_next - dt, &s->x[3 * a], t_next,
                                             &s->p[4 * a], n);
    if (hit >= 0 && f->contact[i] < 0) {
        double u[3], vr[3];
        cf_obstacle_velocity(&ctx->obs->o[hit], u);
        v3_sub(&s->v[3 * a], u, vr);
        f->vn_pre[i] = v3_dot(vr, n);
    }
    if (hit >= 0) {
        double u[3], dp[3];
        f->contact[i] = hit;
        cf_obstacle_velocity(&ctx->obs->o[hit], u);
        v3_sub(&s->p[4 * a], before, dp);
        w = s->m[a] * v3_dot(dp, u) / dt;
    }
    if (cc->near.n > 0) { /* rigid fragments: the push is an impulse on the body */
        double *pa = &s->p[4 * a], dJ[3];
        memcpy(before, pa, sizeof before);
        int h = cf_hull_set_project(&cc->near, &s->x[3 * a], pa);
        if (h >= 0) {
            v3_sub(pa, before, dJ);
            for (int c = 0; c < 3; c++)
                dJ[c] *= s->m[a] / dt;
            cf_node_impulses_add(&cc->push, i, cc->near.frag[h], dJ, pa);
        }
    }
    return w;
}

/* The obstacles on nodes i0..i1-1 (obstacle_node), and their work. */
static void obstacle_chunk(void *ctx, int i0, int i1, double *acc)
{
    const step_sums *c = ctx;
    const cf_solid *s = c->ctx->solid;
    int alone = c->cc->near.n == 0; /* no rigid neighbour's hull to test */
    if (alone && c->penalty)
        return; /* the obstacles acted as forces (penalty_chunk) */
    for (int i = i0; i < i1; i++) {
        if (alone && cf_obstacles_clear(c->ctx->obs, &s->p[4 * c->f->nodes.v[i]]))
            continue; /* nothing to move, record or add */
        acc[0] += obstacle_node(c->ctx, c->f, c->cc, i, c->t_next, c->dt, c->penalty);
    }
}

/* The energy terms a node loop left in f->term. */
static void term_chunk(void *ctx, int i0, int i1, double *acc)
{
    const step_sums *c = ctx;
    for (int i = i0; i < i1; i++)
        acc[0] += c->f->term[i];
}

/* Stage integration: v <- v + dt M^-1 f with the prescribed velocities
 * and global damping (update_velocities), then the prediction
 * p = x + dt v that the projection moves.  Clears the contact records
 * (unless the penalty force made them) and, with bars, notes each node's
 * predicted speed for the cap in velocity_update.  Returns the number of
 * prescribed nodes. */
static int integration(const cf_step_ctx *ctx, cf_fragment *f, double dt, int fracture)
{
    cf_solid *s = ctx->solid;
    const cf_solver_settings *set = &ctx->def->solver;
    int n_bc = update_velocities(ctx, f, dt, fracture);
    const int *nodes = f->nodes.v;
    int nn = f->nodes.n, par = nn >= CF_NODES_PARALLEL_MIN;
    int bars = !explicit_step(set, fracture), penalty = penalty_step(set, fracture);
    CF_PARALLEL(par, "omp parallel for schedule(static)",
        for (int i = 0; i < nn; i++) {
            int a = nodes[i];
            for (int k = 0; k < 3; k++)
                s->p[4 * a + k] = s->x[3 * a + k] + dt * s->v[3 * a + k];
            s->p[4 * a + 3] = 1.0 / s->m[a];
            if (!penalty) { /* the penalty force recorded its contacts (penalty_chunk) */
                f->contact[i] = -1;
                f->vn_pre[i] = 0;
            }
            if (bars) /* the predicted speed, for the cap (v stays until then) */
                s->vcap[a] = s->speed[a] = v3_norm(&s->v[3 * a]);
        });
    return n_bc;
}

/* Stage pbd_projection, one sweep: the bars (PBD, or XPBD in fracture
 * mode) and the crack faces' contact constraint.  *caps: whether the
 * neighbours' speeds for the cap were taken (in the first PBD sweep). */
static void pbd_projection(const cf_step_ctx *ctx, cf_fragment *f, double dt, int fracture,
                           int *caps)
{
    cf_solid *s = ctx->solid;
    const cf_solver_settings *set = &ctx->def->solver;
    if (set->constraints == CF_CONSTRAINTS_XPBD && fracture) {
        cf_bars_project_xpbd(&f->bars, s, dt, set->compliance_scale);
    } else {
        double k = cf_pbd_effective_stiffness(set->k_stiffness, set->iterations,
                                              set->iteration_independent);
        cf_bars_project(&f->bars, s, k, *caps ? NULL : s->speed, *caps ? NULL : s->vcap);
        *caps = 1;
    }
    if (fracture)
        cf_cohesive_project_contact(s, f->coh.v, f->coh.n);
}

/* Stage collision, one sweep of the projection: obstacles and rigid
 * neighbours' hulls node by node, each writing its own p (obstacle_chunk).
 * Returns the moving obstacles' work, J. */
static double collision_sweep(const cf_step_ctx *ctx, cf_fragment *f, cf_contact_cache *cc,
                              double t_next, double dt, int penalty)
{
    int nn = f->nodes.n, par = nn >= CF_NODES_PARALLEL_MIN;
    /* On the threads unless hull pushes of rigid neighbours (one list) or
     * FCL queries need one thread. */
    int obstacles_par = par && cc->near.n == 0 && !mesh_obstacles(ctx);
    step_sums sums = {.ctx = ctx, .f = f, .cc = cc, .t_next = t_next, .dt = dt, .penalty = penalty};
    double w;
    cf_sum_chunks(nn, 1, obstacles_par, obstacle_chunk, &sums, &w);
    return w;
}

/* The prescribed nodes' predictions restored (a constraint of the
 * projection); returns the work of their reactions, J. */
static double prescribed_nodes(const cf_step_ctx *ctx, const cf_fragment *f, double dt)
{
    double w = 0;
    for (int i = 0; i < f->nodes.n; i++)
        if (ctx->solid->bc[f->nodes.v[i]] >= 0)
            w += impose_boundary(ctx, f->nodes.v[i], dt, 1);
    return w;
}

/* Stage velocity_update: v <- (p - x)/dt ; x <- p, with a node's new speed
 * bounded by the fastest predicted speed among itself and its bar
 * neighbours, or, on a moving obstacle, by |u| + |v_pred - u| (a discrete
 * maximum principle).  The constraints exchange momentum between
 * neighbours and stop nodes at obstacles; a speed above every speed around
 * it can only come from a violation left in the bars by the unconverged
 * sweep, released within one step (violation/dt: measured 100-450 m/s on a
 * node where a crack has just split a compressed impact zone, in a 4.4 m/s
 * drop), energy that no load put in.  Nodes pushed by rigid neighbours'
 * hulls are left as they are (their push is booked as an impulse on the
 * body).  The projection's energy is the work of its impulses m (v - v_pred)
 * (impulse_removes), booked when the next step starts, with the moving
 * obstacles' and prescribed nodes' work w_obs and w_bc in it.  dv receives
 * the velocity every node must gain to give back the momentum the speed
 * cap took (zero when it took none): collision_friction adds it in its
 * pass over the nodes. */
static void velocity_update(const cf_step_ctx *ctx, cf_fragment *f, const cf_contact_cache *cc,
                            double dt, int fracture, int caps, double w_obs, double w_bc,
                            double dv[3])
{
    cf_solid *s = ctx->solid;
    const cf_solver_settings *set = &ctx->def->solver;
    const int *nodes = f->nodes.v;
    int nn = f->nodes.n, par = nn >= CF_NODES_PARALLEL_MIN;
    int bars = !explicit_step(set, fracture);
    if (bars && !caps)
        cf_bars_neighbour_speed(&f->bars, s->speed, s->vcap);
    int n_capped = 0;
    CF_PARALLEL(par, "omp parallel for schedule(static) reduction(+ : n_capped)",
        for (int i = 0; i < nn; i++) {
            int a = nodes[i];
            double *va = &s->v[3 * a], vnew[3];
            for (int c = 0; c < 3; c++)
                vnew[c] = (s->p[4 * a + c] - s->x[3 * a + c]) / dt;
            double cap = s->vcap[a];
            if (f->contact[i] >= 0) { /* a moving wall: |v' - u| <= |v - u| */
                double u[3], vr[3];
                cf_obstacle_velocity(&ctx->obs->o[f->contact[i]], u);
                v3_sub(va, u, vr);
                cap = fmax(cap, v3_norm(vr) + v3_norm(u));
            }
            double speed = v3_norm(vnew), scale = 1.0;
            if (bars && speed > cap && (cc->near.n == 0 || cc->push.frag[i] < 0))
                scale = cap / speed, n_capped++;
            double vout[3] = {scale * vnew[0], scale * vnew[1], scale * vnew[2]};
            f->term[i] =
                impulse_removes(s, f, i, va, vnew, 1) + impulse_removes(s, f, i, vnew, vout, 0);
            for (int c = 0; c < 3; c++) {
                va[c] = vout[c];
                s->x[3 * a + c] = s->p[4 * a + c];
                s->p[4 * a + c] = s->m[a] * (1.0 - scale) * vnew[c]; /* momentum the cap took */
            }
        });
    /* The momentum the cap took goes back to the whole fragment, so that the
     * projection keeps linear momentum (bars act in equal and opposite pairs;
     * the cap does not). */
    step_sums sums = {.ctx = ctx, .f = f, .dt = dt};
    double removed;
    cf_sum_chunks(nn, 1, par, term_chunk, &sums, &removed);
    double dP[3] = {0, 0, 0}; /* zero unless the cap took some (then in node order) */
    for (int i = 0; n_capped > 0 && i < nn; i++)
        v3_axpy(1.0, &s->p[4 * nodes[i]], dP);
    dv[0] = dv[1] = dv[2] = 0;
    if (v3_dot(dP, dP) > 0) {
        double mass = 0;
        for (int i = 0; i < nn; i++)
            mass += s->m[nodes[i]];
        for (int c = 0; c < 3; c++)
            dv[c] = dP[c] / mass;
    }
    /* The kinetic change includes what moving obstacles and prescribed nodes
     * put in (a prescribed node that the bars push back and the projection
     * restores passes the bars' impulse on at its velocity): book that as
     * their work, and the rest as the projection's own removal. */
    f->pending.obstacles += w_obs;
    f->pending.boundary += w_bc;
    if (bars)
        f->pending.pbd += removed + w_obs + w_bc;
    else
        f->pending.contact += removed + w_obs + w_bc;
}

/* Stages elasticity (part one) of a fracture step: e_strain restarts from
 * the tets' strain energy.  *check: whether the criterion is checked at
 * this step (every check_interval steps).  Returns the hot tets' count. */
static int fracture_stress(const cf_step_ctx *ctx, cf_fragment *f, int *check, double dt)
{
    const cf_solver_settings *set = &ctx->def->solver;
    *check = set->criterion != CF_CRITERION_NONE && (f->steps % set->check_interval) == 0;
    f->e_strain = 0;
    int n_hot = elasticity(ctx, f, *check, dt);
    cf_profile_lap(ctx->prof, CF_STAGE_ELASTICITY);
    return n_hot;
}

/* Stages insertion_check and node_duplication of a fracture step, with the
 * energy the last step left pending booked into the world's flows.  They
 * grow the solid's shared tables (node copies, cohesive elements, the
 * crack grid), so fragments take them one at a time, in their order. */
static cf_status fracture_insert(const cf_step_ctx *ctx, cf_fragment *f, double t, double dt,
                                 int check, int n_hot)
{
    cf_fragment_book_pending(f, ctx->flow);
    int inserted = 0;
    if (check) {
        int nc = insertion_check(ctx, f, t, n_hot);
        cf_profile_lap(ctx->prof, CF_STAGE_INSERTION_CHECK);
        cf_status st = nc < 0 ? CF_ERR_NOMEM : node_duplication(ctx, f, t, dt, nc, &inserted);
        cf_profile_lap(ctx->prof, CF_STAGE_NODE_DUPLICATION);
        if (st != CF_OK)
            return st;
    }
    cf_fragment_count_quiet(f, inserted, ctx->def->solver.quiet_growth);
    return CF_OK;
}

/* The rest of a step, from the forces at the nodes on: it reads and writes
 * fragment f's own nodes, cohesive elements and contact cache (number fi,
 * reserved by the caller) only, and the world's flows only through
 * prescribed nodes. */
static cf_status solver_advance(const cf_step_ctx *ctx, cf_fragment *f, int fi, double t,
                                double dt, int fracture)
{
    cf_profile *prof = ctx->prof;
    const cf_solver_settings *set = &ctx->def->solver;
    int penalty = penalty_step(set, fracture), bars = !explicit_step(set, fracture);
    cf_contact_cache *cc = &ctx->contact->v[fi];
    if (ensure_scratch(f, cc))
        return CF_ERR_NOMEM;
    if (fracture) {
        elasticity_scatter(ctx, f);
        cf_profile_lap(prof, CF_STAGE_ELASTICITY);
        cohesive_forces(ctx, f, dt);
        cf_profile_lap(prof, CF_STAGE_COHESIVE_FORCES);
        if (penalty) {
            collision_forces(ctx, f, t, dt);
            cf_profile_lap(prof, CF_STAGE_COLLISION);
        }
    } else {
        cf_solid *s = ctx->solid;
        for (int i = 0; i < f->nodes.n; i++) { /* pbd rigid mode: gravity alone */
            int a = f->nodes.v[i];
            for (int k = 0; k < 3; k++)
                s->f[3 * a + k] = s->m[a] * ctx->def->gravity[k];
        }
    }
    int n_bc = integration(ctx, f, dt, fracture);
    cf_profile_lap(prof, CF_STAGE_INTEGRATION);
    if (set->constraints == CF_CONSTRAINTS_XPBD)
        cf_bars_reset_lambda(&f->bars);
    double w_obs = 0, w_bc = 0; /* work of moving obstacles and prescribed nodes */
    int caps = 0, iterations = bars ? set->iterations : 1;
    for (int it = 0; it < iterations; it++) {
        if (bars) {
            pbd_projection(ctx, f, dt, fracture, &caps);
            cf_profile_lap(prof, CF_STAGE_PBD_PROJECTION);
        }
        w_obs += collision_sweep(ctx, f, cc, t + dt, dt, penalty);
        cf_profile_lap(prof, CF_STAGE_COLLISION);
        if (n_bc > 0) {
            w_bc += prescribed_nodes(ctx, f, dt);
            cf_profile_lap(prof, CF_STAGE_PBD_PROJECTION);
        }
    }
    double dv[3];
    velocity_update(ctx, f, cc, dt, fracture, caps, w_obs, w_bc, dv);
    cf_profile_lap(prof, CF_STAGE_VELOCITY_UPDATE);
    f->pending.contact += collision_friction(ctx, f, cc, t + dt, dt, !bars, penalty, dv);
    cf_profile_lap(prof, CF_STAGE_COLLISION);
    f->steps++;
    return CF_OK;
}

/* One step of the pbd rigid backend on fragment fi (fracture.h), stage by
 * stage, each stage's time charged to its timer as it ends. */
cf_status cf_pbd_rigid_step(const cf_step_ctx *ctx, cf_fragment *f, int fi, double t, double dt)
{
    if (cf_contact_caches_reserve(ctx->contact, ctx->n_frag))
        return CF_ERR_NOMEM;
    cf_fragment_book_pending(f, ctx->flow);
    f->e_strain = 0;
    return solver_advance(ctx, f, fi, t, dt, 0);
}

/* One stage of a pass (cf_fracture_pass) over the fracture-mode fragments
 * list[0..n): their stresses (PASS_STRESS, into check[] and n_hot[] by
 * list entry) or the rest of their step (PASS_ADVANCE). */
typedef struct {
    cf_fragment *frag;
    const int *list;
    int *check, *n_hot;
    double t, dt;
} pass;

enum { PASS_STRESS, PASS_ADVANCE };

static cf_status pass_one(const cf_step_ctx *ctx, const pass *p, int stage, int i)
{
    int fi = p->list[i];
    if (stage == PASS_STRESS) {
        p->n_hot[i] = fracture_stress(ctx, &p->frag[fi], &p->check[i], p->dt);
        return CF_OK;
    }
    return solver_advance(ctx, &p->frag[fi], fi, p->t, p->dt, 1);
}

/* Small fragments step side by side from this many tets in all: on fewer
 * (a few crumbs of tens of tets) the team's fork and join cost more than
 * they save (make run's drop ran 3 % slower on two threads). */
#define CF_SIDE_BY_SIDE_MIN 1024

/* Whether fragment f steps beside others, one per thread: its Tet4 kernel
 * would run on one thread anyway (tet4.h). */
static int steps_alone(const cf_fragment *f) { return f->nt < CF_TET4_PARALLEL_MIN; }

/* Stage `stage` of the pass on every listed fragment.  The large ones go
 * one after another, each loop on all threads; with `side_by_side` the
 * small ones then go one per thread, each on its own, so that a split body
 * of hundreds of pieces keeps every thread busy instead of stepping them
 * in turn on one.  Each thread times its stages on its own clock; the
 * section's wall time is charged to the stages in proportion. */
static cf_status pass_stage(const cf_step_ctx *ctx, const pass *p, int n, int stage,
                            int side_by_side)
{
    cf_status st = CF_OK;
    for (int i = 0; i < n && st == CF_OK; i++)
        if (!side_by_side || !steps_alone(&p->frag[p->list[i]]))
            st = pass_one(ctx, p, stage, i);
    if (st != CF_OK || !side_by_side)
        return st;
    double busy[CF_STAGE_COUNT] = {0};
    int failed = 0;
#pragma omp parallel
    {
        cf_profile mine = {{0}, 0};
        cf_step_ctx own = *ctx;
        own.prof = &mine;
        omp_set_num_threads(1); /* this thread's fragments run their loops on it alone */
        cf_profile_start(&mine);
#pragma omp for schedule(dynamic, 1)
        for (int i = 0; i < n; i++) {
            int stop;
#pragma omp atomic read
            stop = failed;
            if (stop || !steps_alone(&p->frag[p->list[i]]) || pass_one(&own, p, stage, i) == CF_OK)
                continue;
#pragma omp atomic write
            failed = 1;
        }
#pragma omp critical(cf_pass_profile)
        for (int k = 0; k < CF_STAGE_COUNT; k++)
            busy[k] += mine.stage[k];
    }
    double total = 0, wall = cf_wall_time() - ctx->prof->mark;
    for (int k = 0; k < CF_STAGE_COUNT; k++)
        total += busy[k];
    for (int k = 0; total > 0 && k < CF_STAGE_COUNT; k++)
        ctx->prof->stage[k] += wall * busy[k] / total;
    ctx->prof->mark += wall;
    return failed ? CF_ERR_NOMEM : CF_OK;
}

cf_status cf_fracture_pass(const cf_step_ctx *ctx, cf_fragment *frag, const int *list, int n,
                           int *work, double t, double dt, int *side_by_side)
{
    if (cf_contact_caches_reserve(ctx->contact, ctx->n_frag))
        return CF_ERR_NOMEM;
    int small = 0, small_tets = 0;
    for (int i = 0; i < n; i++)
        if (steps_alone(&frag[list[i]]))
            small++, small_tets += frag[list[i]].nt;
    /* Explicit steps only: the bars' sweep keeps a team's barriers
     * (pbd.c).  FCL's queries (mesh obstacles) take one thread; prescribed
     * nodes book their work straight into the world's flows
     * (update_velocities). */
    int side = small > 1 && small_tets >= CF_SIDE_BY_SIDE_MIN && omp_get_max_threads() > 1 &&
               explicit_step(&ctx->def->solver, 1) &&
               !mesh_obstacles(ctx) && ctx->def->n_boundaries == 0;
    *side_by_side = side ? small : 0;
    pass p = {frag, list, work, work + n, t, dt};
    cf_status st = pass_stage(ctx, &p, n, PASS_STRESS, side);
    for (int i = 0; st == CF_OK && i < n; i++)
        st = fracture_insert(ctx, &frag[list[i]], t, dt, p.check[i], p.n_hot[i]);
    return st != CF_OK ? st : pass_stage(ctx, &p, n, PASS_ADVANCE, side);
}

int cf_pbd_impact(const cf_step_ctx *ctx, const cf_fragment *f, double t, double dt)
{
    const cf_solid *s = ctx->solid;
    const double *g = ctx->def->gravity;
    for (int i = 0; i < f->nodes.n; i++) {
        int a = f->nodes.v[i];
        double v[3], p[3];
        for (int k = 0; k < 3; k++) {
            v[k] = s->v[3 * a + k] + dt * g[k];
            p[k] = s->x[3 * a + k] + dt * v[k];
        }
        for (int j = 0; j < ctx->obs->n; j++) {
            double n[3];
            if (cf_obstacle_distance(ctx->obs, j, t + dt, p, n) >= 0)
                continue;
            double u[3], vr[3];
            cf_obstacle_velocity(&ctx->obs->o[j], u);
            v3_sub(v, u, vr);
            if (-v3_dot(vr, n) > ctx->def->solver.impact_threshold)
                return 1;
        }
    }
    return 0;
}
