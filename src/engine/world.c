/* The driver: builds what a scene asks for and runs the rigid-step loop
 * (docs/architecture.md, docs/physics.md §9).  Each rigid step: Bullet (or the pbd rigid backend)
 * moves the rigid fragments; a fragment hit harder than the impact threshold
 * is rolled back to the start of the step and re-done in fracture mode,
 * sub-cycled at dt_fracture; a fracture-mode fragment that falls apart is
 * split into its pieces at the end of the rigid step, and one quiet for
 * quiet_steps steps is handed back to rigid mode. */
#include "fracture.h"
#include "handoff.h"

#include "hash.h"
#include "linalg.h"
#include "parallel.h"
#include "renumber.h"
#include "sort.h"

#include <math.h>
#include <omp.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A failed bridge call as an error: out of memory inside Bullet is
 * CF_ERR_NOMEM, anything else CF_ERR_EXTERNAL. */
static cf_status bullet_error(cf_error *err, const char *what)
{
    const char *why = cfb_last_error();
    return cf_error_set(err, strstr(why, "out of memory") ? CF_ERR_NOMEM : CF_ERR_EXTERNAL,
                        "Bullet, %s: %s", what, why);
}

void cf_body_place(const cf_body_def *b, const cf_mesh *mesh, const double *x, int n,
                   double *out)
{
    double lo[3], hi[3];
    points_bbox(mesh->x, mesh->n_nodes, lo, hi);
    double c[3] = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])}, R[9];
    quat_to_mat(b->orientation, R);
    for (int i = 0; i < n; i++) {
        double r[3], y[3];
        v3_sub(&x[3 * i], c, r);
        m3_mulv(R, r, y);
        for (int k = 0; k < 3; k++)
            out[3 * i + k] = b->position[k] + b->scale * y[k];
    }
}

/* Whether the placed node x of body b lies in the region of boundary c
 * (group regions are matched by the caller). */
static int in_region(const cf_boundary *c, const double x[3])
{
    if (c->type == CF_REGION_BOX) {
        for (int k = 0; k < 3; k++)
            if (x[k] < c->min[k] || x[k] > c->max[k])
                return 0;
        return 1;
    }
    double d[3];
    v3_sub(x, c->point, d);
    return fabs(v3_dot(d, c->normal)) <= c->tolerance;
}

/* The boundary condition of each node of body b (mesh m, placed): the last
 * matching entry of the scene's list wins.  Counts the nodes per entry. */
static cf_status body_boundary(const cf_world_def *sc, int b, const cf_mesh *m, int *bc, int *count,
                               cf_error *err)
{
    for (int c = 0; c < sc->n_boundaries; c++) {
        const cf_boundary *bd = &sc->boundaries[c];
        if (bd->body >= 0 && bd->body != b)
            continue;
        if (bd->type != CF_REGION_GROUP) {
            for (int i = 0; i < m->n_nodes; i++)
                if (in_region(bd, &m->x[3 * i]))
                    bc[i] = c, count[c]++;
            continue;
        }
        int g = 0;
        while (g < m->n_groups && strcmp(m->groups[g].name, bd->group) != 0)
            g++;
        if (g == m->n_groups) {
            if (bd->body < 0)
                continue; /* another body may have it */
            return cf_error_set(err, CF_ERR_SCENE_VALUE,
                                "boundary[%d].region.name: body %d's mesh has no physical group "
                                "'%s' (%d groups): name a Gmsh physical group of that mesh",
                                c + 1, b + 1, bd->group, m->n_groups);
        }
        for (int i = 0; i < m->groups[g].n_nodes; i++)
            bc[m->groups[g].nodes[i]] = c, count[c]++;
    }
    return CF_OK;
}

/* A copy of body b's mesh (the world places and renumbers its own). */
static cf_status copy_mesh(const cf_body_def *bd, int b, cf_mesh *m, cf_error *err)
{
    const cf_mesh *src = bd->tet_mesh;
    memset(m, 0, sizeof *m);
    m->n_nodes = src->n_nodes, m->n_tets = src->n_tets;
    m->x = malloc((size_t)src->n_nodes * 3 * sizeof(double));
    m->tets = malloc((size_t)src->n_tets * 4 * sizeof(int));
    m->groups = src->n_groups ? calloc((size_t)src->n_groups, sizeof *m->groups) : NULL;
    int ok = m->x && m->tets && (m->groups || !src->n_groups);
    for (int g = 0; ok && g < src->n_groups; g++) {
        m->groups[g] = src->groups[g];
        m->groups[g].nodes = malloc(((size_t)src->groups[g].n_nodes + 1) * sizeof(int));
        ok = m->groups[g].nodes != NULL;
        if (ok)
            memcpy(m->groups[g].nodes, src->groups[g].nodes,
                   (size_t)src->groups[g].n_nodes * sizeof(int));
        m->n_groups = g + 1;
    }
    if (!ok) {
        cf_mesh_free(m);
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory copying body %d's mesh", b + 1);
    }
    memcpy(m->x, src->x, (size_t)src->n_nodes * 3 * sizeof(double));
    memcpy(m->tets, src->tets, (size_t)src->n_tets * 4 * sizeof(int));
    return CF_OK;
}

/* All bodies' meshes, placed and concatenated; body[t] is each tet's body,
 * bc[n] each node's boundary condition (-1 none). */
static cf_status load_bodies(const cf_world_def *sc, cf_mesh *all, int **body, int **bc,
                             cf_error *err)
{
    memset(all, 0, sizeof *all);
    *body = NULL, *bc = NULL;
    int *count = calloc((size_t)sc->n_boundaries + 1, sizeof(int));
    cf_status st = count ? CF_OK : cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    for (int b = 0; b < sc->n_bodies && st == CF_OK; b++) {
        cf_mesh m;
        st = copy_mesh(&sc->bodies[b], b, &m, err);
        if (st != CF_OK)
            break;
        cf_body_place(&sc->bodies[b], &m, m.x, m.n_nodes, m.x);
        size_t nn = (size_t)(all->n_nodes + m.n_nodes), nt = (size_t)(all->n_tets + m.n_tets);
        double *x = realloc(all->x, nn * 3 * sizeof(double));
        if (x)
            all->x = x;
        int *t = realloc(all->tets, nt * 4 * sizeof(int));
        if (t)
            all->tets = t;
        int *bt = realloc(*body, nt * sizeof(int));
        if (bt)
            *body = bt;
        int *nb = realloc(*bc, nn * sizeof(int));
        if (nb)
            *bc = nb;
        if (!x || !t || !bt || !nb) {
            cf_mesh_free(&m);
            st = cf_error_set(err, CF_ERR_NOMEM, "out of memory loading body %d", b + 1);
            break;
        }
        for (int i = 0; i < m.n_nodes; i++)
            (*bc)[all->n_nodes + i] = -1;
        st = body_boundary(sc, b, &m, &(*bc)[all->n_nodes], count, err);
        memcpy(&all->x[3 * all->n_nodes], m.x, (size_t)m.n_nodes * 3 * sizeof(double));
        for (int i = 0; i < 4 * m.n_tets; i++)
            all->tets[4 * all->n_tets + i] = m.tets[i] + all->n_nodes;
        for (int i = 0; i < m.n_tets; i++)
            (*body)[all->n_tets + i] = b;
        all->n_nodes += m.n_nodes;
        all->n_tets += m.n_tets;
        cf_mesh_free(&m);
    }
    for (int c = 0; c < sc->n_boundaries && st == CF_OK; c++)
        if (count[c] == 0)
            st = cf_error_set(err, CF_ERR_SCENE_VALUE,
                              "boundary[%d] selects no node: check its region against the placed "
                              "mesh (positions are after scale, orientation and position)",
                              c + 1);
    free(count);
    if (st != CF_OK) {
        cf_mesh_free(all);
        free(*body), free(*bc);
        *body = *bc = NULL;
    }
    return st;
}

/* Body of an input node (-1 for a node no tet uses). */
static int node_body(const cf_solid *s, const int *body, int a)
{
    return s->vt_start[a] < s->vt_start[a + 1] ? body[s->vt_slot[s->vt_start[a]] / 4] : -1;
}

/* With a crack plane, only the interior facets on it may crack: mark the
 * others as not candidates. */
static cf_status select_crack_plane(cf_world *sim, cf_error *err)
{
    const cf_solver_settings *set = &sim->def.solver;
    cf_solid *s = &sim->solid;
    if (!set->has_crack_plane || !s->facet)
        return CF_OK;
    s->candidate = malloc((size_t)s->n_facets);
    if (!s->candidate)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    int n = 0;
    for (int fc = 0; fc < s->n_facets; fc++) {
        const int *F = &s->facet[4 * fc];
        int on = F[2] >= 0;
        for (int i = 0; i < 3 && on; i++) {
            double d[3];
            v3_sub(&s->X[3 * s->tet0[4 * F[0] + CF_TET_FACE[F[1]][i]]], set->crack_plane_point, d);
            on = fabs(v3_dot(d, set->crack_plane_normal)) <= set->crack_plane_tolerance;
        }
        s->candidate[fc] = (unsigned char)on;
        n += on;
    }
    if (n == 0)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "solver.crack_plane: no interior facet lies within %g m of the plane: "
                            "move the plane onto a layer of mesh faces or raise its tolerance",
                            set->crack_plane_tolerance);
    return CF_OK;
}

/* Initial fragments: the connected components of each body. */
static cf_status make_initial_fragments(cf_world *sim, const cf_world_def *def, const int *body,
                                        cf_error *err)
{
    cf_solid *s = &sim->solid;
    int nt = s->n_tets;
    int *all = malloc((size_t)nt * sizeof(int)), *comp = malloc((size_t)nt * sizeof(int));
    unsigned char *seen = calloc((size_t)s->n_nodes, 1);
    if (!all || !comp || !seen) {
        free(all), free(comp), free(seen);
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    }
    for (int t = 0; t < nt; t++)
        all[t] = t;
    int k = cf_label_components(s, all, nt, comp);
    int ok = k >= 0;
    for (int c = 0; ok && c < k; c++)
        ok = cf_fragment_new(&sim->frag, &sim->n_frag, &sim->cap_frag, -1, 0.0) >= 0;
    for (int t = 0; ok && t < nt; t++) {
        cf_fragment *f = &sim->frag[comp[t]];
        if (!f->tets && !(f->tets = malloc((size_t)nt * sizeof(int)))) { /* trimmed below */
            ok = 0;
            break;
        }
        f->tets[f->nt++] = t;
        s->tet_frag[t] = comp[t];
        for (int j = 0; ok && j < 4; j++) {
            int a = s->tet[4 * t + j];
            if (!seen[a]) {
                seen[a] = 1;
                ok = cf_int_list_push(&f->nodes, a) == 0;
            }
        }
    }
    free(all), free(comp), free(seen);
    if (!ok) /* the fragments made so far are freed with the world */
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory finding the bodies' fragments");

    /* Initial velocity field: v = v_b + w_b x (x - x_com) + rate (.) (x - x_e). */
    for (int b = 0; b < def->n_bodies; b++) {
        const cf_body_def *bd = &def->bodies[b];
        double M = 0, com[3] = {0, 0, 0}, xe[3];
        for (int a = 0; a < s->n_nodes; a++)
            if (node_body(s, body, a) == b) {
                M += s->m[a];
                v3_axpy(s->m[a], &s->x[3 * a], com);
            }
        for (int k2 = 0; k2 < 3; k2++)
            com[k2] /= M;
        memcpy(xe, bd->has_expansion_center ? bd->expansion_center : com, sizeof xe);
        for (int a = 0; a < s->n_nodes; a++)
            if (node_body(s, body, a) == b) {
                double r[3], wr[3];
                v3_sub(&s->x[3 * a], com, r);
                v3_cross(bd->angular_velocity, r, wr);
                for (int k2 = 0; k2 < 3; k2++)
                    s->v[3 * a + k2] = bd->velocity[k2] + wr[k2] +
                                       bd->expansion_rate[k2] * (s->x[3 * a + k2] - xe[k2]);
            }
    }
    int fracture = sim->def.solver.mode == CF_RUN_FRACTURE;
    for (int fi = 0; fi < sim->n_frag; fi++) {
        cf_fragment *f = &sim->frag[fi];
        int *tt = realloc(f->tets, (size_t)f->nt * sizeof(int));
        if (tt)
            f->tets = tt;
        cf_fragment_rest_props(f, &sim->solid);
        cf_fragment_ledger_reset(f, &sim->solid, &sim->flow);
        if (fracture) {
            f->mode = CF_MODE_FRACTURE;
            f->t_enter = 0;
        }
        if (sim->bullet) {
            const cf_body_def *bd = &def->bodies[body[f->tets[0]]];
            cf_node_state ns;
            cf_nodes_momenta(s, f->nodes.v, f->nodes.n, &ns);
            double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
            cf_status st = cf_fragment_add_body(sim, fi, f->com_rest, I3, ns.v,
                                                bd->angular_velocity, err);
            if (st != CF_OK)
                return st;
        } else if (cf_bars_build(&f->bars, s, f->tets, f->nt)) {
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory building bars");
        }
    }
    return CF_OK;
}

/* Every obstacle for the in-house solver and, when there is a Bullet
 * world, as Bullet bodies; which of them move (kinematic). */
static cf_status add_obstacles(cf_world *sim, const cf_world_def *def, cf_error *err)
{
    int n = def->n_obstacles;
    sim->obs.o = sim->def.obstacles;
    sim->obstacle_body = malloc(((size_t)n + 1) * sizeof(int));
    sim->obstacle_moving = calloc((size_t)n + 1, 1);
    if (!sim->obstacle_body || !sim->obstacle_moving)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory for obstacles");
    for (int j = 0; j < n; j++) {
        double u[3];
        cf_obstacle_velocity(&def->obstacles[j], u);
        sim->obstacle_moving[j] = v3_dot(u, u) > 0;
    }
    return cf_obstacles_create(&sim->obs, def, sim->bullet, sim->obstacle_body, err);
}

/* Append an event (the array grows; out of memory drops it and says so). */
static cf_status push_event(cf_world *sim, const cf_event *e, cf_error *err)
{
    if (sim->n_ev == sim->cap_ev) {
        int cap = sim->cap_ev ? 2 * sim->cap_ev : 16;
        cf_event *ev = realloc(sim->ev, (size_t)cap * sizeof *ev);
        if (!ev)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory recording an event");
        sim->ev = ev, sim->cap_ev = cap;
    }
    sim->ev[sim->n_ev++] = *e;
    return CF_OK;
}

static int alive_fragments(const cf_world *sim, int *in_fracture)
{
    int n = 0, nf = 0;
    for (int i = 0; i < sim->n_frag; i++) {
        n += sim->frag[i].mode != CF_MODE_DEAD;
        nf += sim->frag[i].mode == CF_MODE_FRACTURE;
    }
    if (in_fracture)
        *in_fracture = nf;
    return n;
}

/* The event of a hand-off the step made. */
static cf_status handoff_event(cf_world *sim, const cf_handoff_record *r, cf_error *err)
{
    cf_event e = {.type = CF_EVENT_HANDOFF, .time = sim->t, .first = r->fragment, .count = 1,
                  .alive = alive_fragments(sim, NULL), .handoff = *r};
    return push_event(sim, &e, err);
}

/* Fragment fi to fracture mode (cf_handoff_to_fracture), and its event. */
static cf_status to_fracture(cf_world *sim, int fi, const cfb_state *st, cf_error *err)
{
    cf_handoff_record r;
    cf_status rc = cf_handoff_to_fracture(sim, fi, st, &r, err);
    return rc == CF_OK ? handoff_event(sim, &r, err) : rc;
}

/* Fragments first .. n_frag - 1 were born. */
static cf_status fragments_born(cf_world *sim, int first, cf_error *err)
{
    if (first >= sim->n_frag)
        return CF_OK;
    cf_event e = {.type = CF_EVENT_FRAGMENTS, .time = sim->t, .first = first,
                  .count = sim->n_frag - first, .alive = alive_fragments(sim, NULL)};
    return push_event(sim, &e, err);
}

const cf_event *cf_world_events(const cf_world *sim, int *n)
{
    *n = sim->n_ev;
    return sim->ev;
}

void cf_world_clear_events(cf_world *sim) { sim->n_ev = 0; }

int cf_world_fragments_ever(const cf_world *sim) { return sim->n_frag; }

int cf_world_fragment_info(const cf_world *sim, int id, cf_frag_info *o)
{
    if (id < 0 || id >= sim->n_frag)
        return -1;
    const cf_fragment *f = &sim->frag[id];
    memset(o, 0, sizeof *o);
    o->id = id;
    o->parent = f->parent;
    o->birth_time = f->birth_time;
    o->mass = f->mass;
    o->n_tets = f->nt;
    memcpy(o->inertia_principal, f->principal, sizeof f->principal);
    o->n_hulls = f->body >= 0 ? f->hulls.n_hulls : 0;
    o->debris = cf_fragment_is_debris(f, &sim->def.solver);
    o->hull_volume_error = cf_hulls_error(&f->hulls);
    o->decomposition_time = f->decompose_time;
    memcpy(o->com_rest, f->com_rest, sizeof o->com_rest);
    return 0;
}

/* What a reader needs to bound a run's outcome (tools/check_physics.py):
 * the box around the nodes, mass, energy and fastest node at t = 0, and the
 * fastest kinematic obstacle or prescribed node; taken at create. */
static void initial_bounds(cf_world *sim)
{
    const cf_solid *s = &sim->solid;
    const cf_world_def *sc = &sim->def;
    cf_initial_bounds *b = &sim->bounds;
    double v2 = 0;
    for (int k = 0; k < 3; k++)
        b->lower[k] = INFINITY, b->upper[k] = -INFINITY;
    b->mass = 0, b->max_obstacle_speed = 0;
    for (int a = 0; a < s->n_nodes; a++) {
        for (int k = 0; k < 3; k++) {
            b->lower[k] = fmin(b->lower[k], s->x[3 * a + k]);
            b->upper[k] = fmax(b->upper[k], s->x[3 * a + k]);
        }
        b->mass += s->m[a];
        v2 = fmax(v2, v3_dot(&s->v[3 * a], &s->v[3 * a]));
    }
    for (int j = 0; j < sc->n_obstacles; j++) {
        double uj[3];
        cf_obstacle_velocity(&sc->obstacles[j], uj);
        b->max_obstacle_speed = fmax(b->max_obstacle_speed, v3_norm(uj));
    }
    for (int j = 0; j < sc->n_boundaries; j++)
        b->max_obstacle_speed = fmax(b->max_obstacle_speed, v3_norm(sc->boundaries[j].velocity));
    b->max_speed = sqrt(v2);
    b->energy = sim->e0;
    const cf_material *m = &s->mat;
    b->release_speed = 0;
    if (s->facet) /* an insertion criterion: facets can be held up to their strength */
        b->release_speed = s->strength_max * fmax(m->sigma_max / sqrt(m->rho * m->E),
                                                  m->tau_max / sqrt(m->rho * s->mu));
}

void cf_world_initial_bounds(const cf_world *sim, cf_initial_bounds *out) { *out = sim->bounds; }

/* A copy of n items of `size` bytes (NULL for none; *fail set when out
 * of memory). */
static void *copy_array(const void *src, int n, size_t size, int *fail)
{
    if (n <= 0 || !src)
        return NULL;
    void *d = malloc((size_t)n * size);
    if (d)
        memcpy(d, src, (size_t)n * size);
    else
        *fail = 1;
    return d;
}

/* The world's own copy of the definition: settings, obstacles and
 * boundary conditions (the bodies and meshes are used up at create; the
 * world never reads the caller's definition after create). */
static cf_status copy_def(cf_world *sim, const cf_world_def *def, cf_error *err)
{
    int fail = 0;
    sim->def = *def;
    sim->def.bodies = NULL, sim->def.n_bodies = 0;
    sim->def.resolved = NULL;
    sim->def.obstacles = copy_array(def->obstacles, def->n_obstacles, sizeof *def->obstacles, &fail);
    sim->def.boundaries = copy_array(def->boundaries, def->n_boundaries, sizeof *def->boundaries,
                                     &fail);
    for (int j = 0; sim->def.obstacles && j < def->n_obstacles; j++) /* FCL and Bullet copy them */
        sim->def.obstacles[j].vertices = NULL, sim->def.obstacles[j].triangles = NULL;
    return fail ? cf_error_set(err, CF_ERR_NOMEM, "out of memory copying the world definition")
                : CF_OK;
}

static void *probe_thread(void *arg) { return arg; }

/* How many of `n` threads can run at once (the caller's included): libgomp
 * ends the process with status 1 when it cannot start a thread, so the
 * threads are tried here first and a shortage becomes an error. */
static int threads_startable(int n)
{
    pthread_t t[256];
    int started = 0;
    n = n > 256 ? 256 : n;
    while (started < n - 1 && pthread_create(&t[started], NULL, probe_thread, NULL) == 0)
        started++;
    for (int i = 0; i < started; i++)
        pthread_join(t[i], NULL);
    return started + 1;
}

cf_status cf_world_create(const cf_world_def *def, cf_world **out, cf_error *err)
{
    *out = NULL;
    cf_status st = cf_world_def_check(def, err);
    if (st != CF_OK)
        return st;
    cf_world *sim = calloc(1, sizeof *sim);
    if (!sim)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    st = copy_def(sim, def, err);
    const cf_world_def *scene = &sim->def;
    sim->wall_start = cf_wall_time();
    sim->bullet_base = cfb_allocated_bytes();
    /* The world's own thread count: the process's OpenMP setting is the
     * caller's, and two worlds may run on different counts. */
    sim->threads = scene->solver.threads > 0 ? scene->solver.threads : omp_get_max_threads();
    int threads = sim->threads, startable = threads_startable(threads);
    if (st == CF_OK && startable < threads)
        st = cf_error_set(err, CF_ERR_NOMEM,
                          "cannot start %d threads for the element loops (only %d): the memory "
                          "or process limits (ulimit -v, ulimit -u) leave no room for their "
                          "stacks; run with fewer threads (-t %d, solver.threads)",
                          threads, startable, startable > 0 ? startable : 1);
    sim->law = &cf_law_ppr;
    sim->law->init(sim->law_params, &scene->material);

    cf_mesh all = {0};
    int *body = NULL, *bc = NULL;
    if (st == CF_OK)
        st = load_bodies(def, &all, &body, &bc, err);
    if (st == CF_OK) {
        int *user = malloc((size_t)all.n_tets * sizeof(int));
        sim->tet_of_user = malloc((size_t)all.n_tets * sizeof(int));
        if (!user || !sim->tet_of_user || cf_renumber_locality(&all, bc, body, user))
            st = cf_error_set(err, CF_ERR_NOMEM, "out of memory renumbering %d tets", all.n_tets);
        for (int t = 0; st == CF_OK && t < all.n_tets; t++)
            sim->tet_of_user[user[t]] = t;
        free(user);
    }
    if (st == CF_OK) {
        st = cf_solid_init(&sim->solid, &all, &scene->material, body, err);
        if (st == CF_OK)
            memcpy(sim->solid.bc, bc, (size_t)all.n_nodes * sizeof(int));
        if (st == CF_OK)
            st = cf_solid_scale_mass(&sim->solid, scene->solver.mass_scaling, err);
        if (st == CF_OK && scene->solver.criterion != CF_CRITERION_NONE)
            st = cf_solid_init_facets(&sim->solid, err);
        cf_mesh_free(&all);
    }
    free(bc);
    sim->dt_fracture = scene->solver.cfl_fraction > 0
                           ? scene->solver.cfl_fraction * sim->solid.dt_cfl
                           : scene->solver.dt_fracture;
    /* With no rigid mode the outer step only paces output and checks: a
     * whole number of fracture steps, so that every step is dt_fracture. */
    sim->dt_outer = scene->solver.dt_rigid;
    if (scene->solver.mode == CF_RUN_FRACTURE)
        sim->dt_outer = fmax(1.0, floor(scene->solver.dt_rigid / sim->dt_fracture + 1e-9)) *
                        sim->dt_fracture;
    sim->n_steps = lround(ceil(scene->duration / sim->dt_outer - 1e-9));
    if (st == CF_OK && scene->solver.rigid_backend == CF_RIGID_BULLET &&
        scene->solver.mode == CF_RUN_HYBRID) {
        sim->bullet = cfb_world_create(scene->gravity);
        if (!sim->bullet)
            st = bullet_error(err, "creating the world");
        else
            cfb_set_sleeping(sim->bullet, scene->solver.sleep_linear, scene->solver.sleep_angular);
    }
    if (st == CF_OK)
        st = add_obstacles(sim, def, err);
    if (st == CF_OK)
        st = select_crack_plane(sim, err);
    cf_profile_start(&sim->prof);
    if (st == CF_OK)
        st = make_initial_fragments(sim, def, body, err);
    free(body);
    /* The initial bodies' convex decompositions are the run's; the rest of
     * creation is no stage of a step. */
    double hulls = sim->prof.stage[CF_STAGE_CONVEX_DECOMPOSITION];
    memset(&sim->prof, 0, sizeof sim->prof);
    sim->prof.stage[CF_STAGE_CONVEX_DECOMPOSITION] = hulls;
    if (st == CF_OK) { /* the ledger's reference state */
        cf_ledger l;
        cf_world_ledger(sim, &l);
        sim->e0 = l.kinetic + l.strain;
        memcpy(sim->mx0, l.mass_moment, sizeof sim->mx0);
        initial_bounds(sim);
        st = fragments_born(sim, 0, err);
    }
    if (st != CF_OK) {
        cf_world_destroy(sim);
        return st;
    }
    *out = sim;
    return CF_OK;
}

void cf_world_destroy(cf_world *sim)
{
    if (!sim)
        return;
    for (int i = 0; i < sim->n_frag; i++) {
        cf_fragment *f = &sim->frag[i];
        free(f->tets), free(f->nodes.v), free(f->coh.v), free(f->contact), free(f->vn_pre);
        free(f->v_old), free(f->term), free(f->pairs);
        cf_bars_free(&f->bars);
        cf_hulls_free(&f->hulls);
    }
    free(sim->frag);
    cf_contact_caches_free(&sim->contact);
    cf_arena_free(&sim->arena);
    cf_obstacles_free(&sim->obs);
    free(sim->obstacle_body), free(sim->obstacle_moving);
    free(sim->cand.v), free(sim->tet_of_user), free(sim->ev);
    free(sim->touched.v), free(sim->crushed.v);
    cf_bars_scratch_free(&sim->bar_scratch);
    free(sim->def.obstacles), free(sim->def.boundaries);
    if (sim->bullet)
        cfb_world_destroy(sim->bullet);
    cf_solid_free(&sim->solid);
    free(sim);
}

/* Kinetic energy minus gravity's potential work: what a Bullet body keeps
 * in free flight, J. */
static double body_energy(const cf_world *sim, const cf_fragment *f, const cfb_state *st)
{
    return cf_body_kinetic_energy(f, st) - f->mass * v3_dot(sim->def.gravity, st->pos);
}

/* The ledger; the momenta too with `momenta` (for fragments in fracture
 * mode a pass over their nodes, which the energy guard does not need). */
static void ledger(const cf_world *sim, cf_ledger *l, int momenta)
{
    const cf_solid *s = &sim->solid;
    memset(l, 0, sizeof *l);
    for (int fi = 0; fi < sim->n_frag; fi++) {
        const cf_fragment *f = &sim->frag[fi];
        if (f->mode == CF_MODE_DEAD)
            continue;
        double P[3] = {0, 0, 0}, L[3] = {0, 0, 0};
        if (f->body >= 0) {
            cfb_state st;
            cfb_get_state(sim->bullet, f->body, &st);
            l->kinetic += cf_body_kinetic_energy(f, &st);
            v3_axpy(f->mass, st.pos, l->mass_moment);
            if (momenta)
                cf_body_momenta(f, &st, P, L);
        } else {
            l->kinetic += f->e_kin;
            l->strain += f->e_strain;
            v3_axpy(1.0, f->mx, l->mass_moment);
            if (momenta)
                cf_fragment_momenta(f, &sim->solid, sim->bullet, P, L);
        }
        v3_axpy(1.0, P, l->momentum);
        v3_axpy(1.0, L, l->angular_momentum);
    }
    cf_cohesive_energy(s, NULL, 0, &l->cohesive_stored, &l->cohesive_dissipated);
    l->plastic_dissipated = 0;
    if (s->wp)
        for (int t = 0; t < s->n_tets; t++) /* tet order: the same sum on any thread count */
            l->plastic_dissipated += s->wp[t];
    double dmx[3];
    v3_sub(l->mass_moment, sim->mx0, dmx);
    l->work_gravity = v3_dot(sim->def.gravity, dmx);
    l->work_boundary = sim->flow.boundary;
    l->work_obstacles = sim->flow.obstacles;
    l->contact = sim->flow.contact, l->pbd = sim->flow.pbd;
    l->damping = sim->flow.damping, l->handoff = sim->flow.handoff;
    l->integration = sim->flow.integration;
    l->initial = sim->e0;
    l->residual = l->kinetic + l->strain + l->cohesive_stored + l->cohesive_dissipated +
                  l->plastic_dissipated + l->contact + l->pbd + l->damping + l->handoff + l->integration -
                  (l->initial + l->work_gravity + l->work_boundary + l->work_obstacles);
}

void cf_world_ledger(const cf_world *sim, cf_ledger *l) { ledger(sim, l, 1); }

int cf_world_fragments(cf_world *sim, cf_fragment_state *out, int cap)
{
    int n = 0;
    for (int fi = 0; fi < sim->n_frag; fi++) {
        cf_fragment *f = &sim->frag[fi];
        if (f->mode == CF_MODE_DEAD)
            continue;
        if (n < cap) {
            cf_fragment_state *o = &out[n];
            double R[9];
            memset(o, 0, sizeof *o);
            o->id = fi, o->parent = f->parent, o->birth_time = f->birth_time;
            o->mode = f->mode, o->n_tets = f->nt, o->mass = f->mass;
            memcpy(o->principal, f->principal, sizeof o->principal);
            memcpy(o->axes, f->Q, sizeof o->axes);
            cf_fragment_pose_peek(f, &sim->solid, sim->bullet, o->com, R, o->v, o->w);
            mat_to_quat(R, o->quat);
            for (int k = 0; k < 3; k++)
                o->momentum[k] = f->mass * o->v[k];
            if (f->body >= 0) {
                cfb_state st;
                cfb_get_state(sim->bullet, f->body, &st);
                cf_body_spin(f, &st, o->angular_momentum);
                o->kinetic = cf_body_kinetic_energy(f, &st);
            } else {
                cf_node_state ns;
                cf_nodes_momenta(&sim->solid, f->nodes.v, f->nodes.n, &ns);
                memcpy(o->angular_momentum, ns.L, sizeof ns.L);
                for (int k = 0; k < 3; k++)
                    o->momentum[k] = ns.M * ns.v[k];
                o->kinetic = ns.ke;
            }
        }
        n++;
    }
    return n;
}

double cf_world_fragment_support(cf_world *sim, int id, const double d[3])
{
    if (id < 0 || id >= sim->n_frag || sim->frag[id].mode == CF_MODE_DEAD)
        return 0;
    const cf_fragment *f = &sim->frag[id];
    double com[3], R[9], v[3], w[3], Rd[3], best = -INFINITY;
    cf_fragment_pose_peek(f, &sim->solid, sim->bullet, com, R, v, w);
    m3_tmulv(R, d, Rd); /* (R r).d = r.(R^T d), r from the rest centre of mass */
    for (int i = 0; i < f->nodes.n; i++) {
        double r[3];
        v3_sub(&sim->solid.X[3 * f->nodes.v[i]], f->com_rest, r);
        best = fmax(best, v3_dot(r, Rd));
    }
    return f->nodes.n ? best : 0;
}

int cf_world_tet_count(const cf_world *sim) { return sim->solid.n_tets; }

int cf_world_rest_node_count(const cf_world *sim) { return sim->solid.n_verts0; }

void cf_world_rest_nodes(const cf_world *sim, double *X)
{
    memcpy(X, sim->solid.X, (size_t)sim->solid.n_verts0 * 3 * sizeof(double));
}

int cf_world_rest_tet(const cf_world *sim, int t, int nodes[4])
{
    if (t < 0 || t >= sim->solid.n_tets)
        return -1;
    memcpy(nodes, &sim->solid.tet0[4 * sim->tet_of_user[t]], 4 * sizeof(int));
    return 0;
}

int cf_world_tet_positions(const cf_world *sim, int t, double x[12])
{
    if (t < 0 || t >= sim->solid.n_tets)
        return -1;
    const cf_solid *s = &sim->solid;
    int st = sim->tet_of_user[t], fi = s->tet_frag[st];
    const cf_fragment *f = &sim->frag[fi];
    double com[3], R[9], v[3], w[3];
    if (f->body >= 0) /* rigid in Bullet: the nodes are not moved, the pose is */
        cf_fragment_pose_peek(f, &sim->solid, sim->bullet, com, R, v, w);
    for (int j = 0; j < 4; j++) {
        int a = s->tet[4 * st + j];
        if (f->body < 0) {
            memcpy(&x[3 * j], &s->x[3 * a], 3 * sizeof(double));
            continue;
        }
        double r[3], y[3];
        v3_sub(&s->X[3 * a], f->com_rest, r);
        m3_mulv(R, r, y);
        for (int k = 0; k < 3; k++)
            x[3 * j + k] = com[k] + y[k];
    }
    return 0;
}

int cf_world_fracture_tets(const cf_world *sim, int *tets, double *stress, double *damage)
{
    const cf_solid *s = &sim->solid;
    int nt = s->n_tets, n = 0;
    /* damage by the solid's tets: each element's to both its sides */
    double *d = calloc((size_t)(nt > 0 ? nt : 1), sizeof *d);
    if (!d)
        return -1;
    for (int e = 0; e < s->n_coh; e++) {
        double de = cf_cohesive_damage(s, e);
        for (int side = 0; side < 2; side++)
            d[s->coh[e].tet[side]] = fmax(d[s->coh[e].tet[side]], de);
    }
    static const int voigt[6] = {0, 4, 8, 5, 2, 1}; /* xx yy zz yz xz xy of [3][3] */
    for (int t = 0; t < nt; t++) {
        int st = sim->tet_of_user[t];
        if (sim->frag[s->tet_frag[st]].mode != CF_MODE_FRACTURE)
            continue;
        tets[n] = t;
        damage[n] = d[st];
        for (int k = 0; k < 6; k++)
            stress[6 * n + k] = s->sigma ? s->sigma[9 * st + voigt[k]] : 0.0;
        n++;
    }
    free(d);
    return n;
}

int cf_world_tet_fragment(const cf_world *sim, int t)
{
    return t >= 0 && t < sim->solid.n_tets ? sim->solid.tet_frag[sim->tet_of_user[t]] : -1;
}

int cf_world_cohesive_count(const cf_world *sim) { return sim->solid.n_coh; }

int cf_world_crack(const cf_world *sim, int e, cf_crack_row *r)
{
    memset(r, 0, sizeof *r);
    if (e < 0 || e >= sim->solid.n_coh)
        return -1;
    r->time = sim->t;
    r->element = e;
    cf_cohesive_state(&sim->solid, e, r->centroid, r->normal, &r->area, &r->opening, &r->sliding,
                      &r->failed);
    return 0;
}

double cf_world_crack_area(const cf_world *sim) { return cf_solid_crack_area(&sim->solid); }

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

/* Debris, and a fragment with no uncracked interior facet (a single tet,
 * say), cannot break further: an impact leaves it in rigid mode. */
static int can_break(const cf_world *sim, const cf_fragment *f)
{
    const cf_solid *s = &sim->solid;
    const cf_solver_settings *set = &sim->def.solver;
    if (set->criterion == CF_CRITERION_NONE || cf_fragment_is_debris(f, set))
        return 0;
    for (int i = 0; i < f->nt; i++)
        for (int k = 0; k < 4; k++) {
            int fc = s->tet_facet[4 * f->tets[i] + k];
            if (s->facet[4 * fc + 2] >= 0 && !s->cracked[fc])
                return 1;
        }
    return 0;
}

/* Rigid fragment fi is hit: Bullet's contact impulse plus the pushes of
 * fracture-mode nodes, per unit mass, pass the impact threshold. */
static int impact(const cf_world *sim, const cf_fragment *f)
{
    double dv = (cfb_contact_impulse(sim->bullet, f->body) + f->pushed) / f->mass;
    return dv > sim->def.solver.impact_threshold && can_break(sim, f);
}

/* One Bullet step.  Fragments hit harder than the impact threshold go to
 * fracture mode from their state at the start of the step; the step is
 * then re-run from that start for every other body, so that none keeps the
 * contact response of a fragment that is now sub-cycled instead (momentum is
 * exchanged with it through its nodes). */
static cf_status bullet_step(cf_world *sim, double dt, cf_error *err)
{
    const cf_solver_settings *set = &sim->def.solver;
    int n = sim->n_frag, no = sim->def.n_obstacles;
    size_t mark = cf_arena_mark(&sim->arena);
    cfb_state *pre = cf_arena_take(&sim->arena, (size_t)(n + no) * sizeof *pre), *pre_obs = pre + n;
    if (!pre)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    for (int fi = 0; fi < n; fi++)
        if (sim->frag[fi].body >= 0)
            cfb_get_state(sim->bullet, sim->frag[fi].body, &pre[fi]);
    for (int j = 0; j < no; j++)
        if (sim->obstacle_moving[j])
            cfb_get_state(sim->bullet, sim->obstacle_body[j], &pre_obs[j]);
    int any_moving = 0;
    for (int j = 0; j < no; j++)
        any_moving |= sim->obstacle_moving[j];
    cf_status st = CF_OK;
    for (int pass = 0; st == CF_OK; pass++) {
        /* Fails when Bullet ran out of memory, in this step or in an
         * earlier call that could not say so (the world is then unusable). */
        if (cfb_step(sim->bullet, dt, set->rigid_substeps) < 0) {
            st = bullet_error(err, "the rigid step");
            break;
        }
        int hit = 0;
        for (int fi = 0; fi < n && st == CF_OK; fi++) {
            cf_fragment *f = &sim->frag[fi];
            if (f->mode != CF_MODE_RIGID || f->body < 0 || !impact(sim, f))
                continue;
            cf_profile_lap(&sim->prof, CF_STAGE_RIGID_STEP);
            st = to_fracture(sim, fi, &pre[fi], err);
            cf_profile_lap(&sim->prof, CF_STAGE_HANDOFF);
            hit++;
        }
        if (st != CF_OK || hit == 0 || pass == CF_MAX_RESTEPS)
            break;
        for (int fi = 0; fi < n; fi++)
            if (sim->frag[fi].mode == CF_MODE_RIGID && sim->frag[fi].body >= 0)
                cfb_set_state(sim->bullet, sim->frag[fi].body, &pre[fi]);
        for (int j = 0; j < no; j++)
            if (sim->obstacle_moving[j])
                cfb_set_state(sim->bullet, sim->obstacle_body[j], &pre_obs[j]);
    }
    /* What contact did to the rigid bodies' energy beyond gravity's work. */
    for (int fi = 0; fi < n; fi++) {
        cf_fragment *f = &sim->frag[fi];
        f->pushed = 0;
        if (f->mode != CF_MODE_RIGID || f->body < 0)
            continue;
        cfb_state now;
        cfb_get_state(sim->bullet, f->body, &now);
        double removed = body_energy(sim, f, &pre[fi]) - body_energy(sim, f, &now);
        if (cfb_contact_impulse(sim->bullet, f->body) == 0) { /* free flight */
            sim->flow.integration += removed;
            continue;
        }
        if (removed < 0 && any_moving) { /* a moving obstacle did work on it */
            sim->flow.obstacles -= removed;
            removed = 0;
        }
        sim->flow.contact += removed;
    }
    cf_arena_release(&sim->arena, mark);
    sim->steps_rigid++;
    cf_profile_lap(&sim->prof, CF_STAGE_RIGID_STEP);
    return st;
}

/* Advance the rigid fragments by one rigid step; detect impacts. */
static cf_status rigid_step(cf_world *sim, double dt, cf_error *err)
{
    if (sim->bullet)
        return bullet_step(sim, dt, err);
    for (int fi = 0; fi < sim->n_frag; fi++) {
        if (sim->frag[fi].mode != CF_MODE_RIGID)
            continue;
        cf_step_ctx ctx = cf_world_step_ctx(sim);
        int hit = cf_pbd_impact(&ctx, &sim->frag[fi], sim->t, dt) && can_break(sim, &sim->frag[fi]);
        cf_profile_lap(&sim->prof, CF_STAGE_RIGID_STEP);
        if (hit) {
            cf_status st = to_fracture(sim, fi, NULL, err);
            cf_profile_lap(&sim->prof, CF_STAGE_HANDOFF);
            if (st != CF_OK)
                return st;
            continue;
        }
        /* The damped step's own stages are timed as the solver's. */
        if (cf_solver_step(&ctx, &sim->frag[fi], fi, sim->t, dt, 0) != CF_OK)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory in the pbd rigid step");
    }
    sim->steps_rigid++;
    cf_profile_lap(&sim->prof, CF_STAGE_RIGID_STEP);
    return CF_OK;
}

static cf_status diverged(const cf_world *sim, cf_error *err, const char *what)
{
    const cf_solver_settings *set = &sim->def.solver;
    const char *fix = set->constraints == CF_CONSTRAINTS_NONE
                          ? "lower solver.dt_fracture (or solver.cfl_fraction) below dt_cfl, or use "
                            "solver.constraints = "
                            "\"pbd\""
                          : "lower solver.dt_fracture, or raise solver.pbd.iterations / "
                            "solver.pbd.k_stiffness";
    return cf_error_set(err, CF_ERR_DIVERGED,
                        "%s at t = %.6g s with dt_fracture/dt_cfl = %.3g (dt_cfl %.3g s): %s",
                        what, sim->t, sim->dt_fracture / sim->solid.dt_cfl, sim->solid.dt_cfl, fix);
}

/* How far beyond fragment fi's nodes a rigid body can be touched during a
 * rigid step of dt: the fastest node's travel, plus gravity's. */
static double contact_pad(const cf_world *sim, int fi, double dt)
{
    const cf_fragment *f = &sim->frag[fi];
    double v2 = 0; /* a maximum: the same for any thread count */
    CF_PARALLEL(f->nodes.n >= CF_NODES_PARALLEL_MIN,
                "omp parallel for schedule(static) reduction(max : v2)",
        for (int i = 0; i < f->nodes.n; i++) {
            const double *v = &sim->solid.v[3 * f->nodes.v[i]];
            v2 = fmax(v2, v3_dot(v, v));
        });
    return dt * (sqrt(v2) + dt * v3_norm(sim->def.gravity));
}

/* Sub-cycle every fracture-mode fragment through the rigid step, all of
 * them in step so that fragments of different bodies meet in contact after
 * each sub-step. */
/* Fracture sub-steps in a rigid step of dt: n_sub of h <= dt_fracture. */
static long sub_steps(const cf_world *sim, double dt, double *h)
{
    long n_sub = lround(ceil(dt / sim->dt_fracture - 1e-9));
    if (n_sub < 1)
        n_sub = 1;
    *h = dt / (double)n_sub;
    return n_sub;
}

/* The contact stages' view of the world (contact.h). */
static cf_contact_ctx contact_ctx(cf_world *sim)
{
    return (cf_contact_ctx){sim->frag, sim->contact.v, sim->n_frag, &sim->solid, sim->bullet,
                            &sim->arena};
}

/* Stage collision, before the sub-steps: the hulls of the rigid bodies
 * near each fracture-mode fragment, from the bodies' boxes taken once.
 * Returns 0, or -1 out of memory. */
static int gather_hulls(cf_world *sim, const cf_contact_ctx *cx, double dt)
{
    size_t mark = cf_arena_mark(&sim->arena);
    double *boxes = NULL;
    int rc = 0;
    for (int fi = 0; fi < sim->n_frag && !rc; fi++) {
        if (sim->frag[fi].mode != CF_MODE_FRACTURE)
            continue;
        if (!boxes) {
            boxes = cf_arena_take(&sim->arena, (size_t)sim->n_frag * 6 * sizeof *boxes);
            if (!boxes) {
                rc = -1;
                break;
            }
            cf_body_boxes(cx, boxes);
        }
        rc = cf_hull_set_gather(cx, fi, contact_pad(sim, fi, dt), boxes,
                                &sim->contact.v[fi].near);
    }
    cf_arena_release(&sim->arena, mark);
    return rc;
}

static cf_status fracture_steps(cf_world *sim, double dt, long n_sub, double h, cf_error *err)
{
    const cf_solver_settings *set = &sim->def.solver;
    sim->h_fracture = h;
    int n = sim->n_frag;
    if (cf_contact_caches_reserve(&sim->contact, n))
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory gathering contact hulls");
    /* No fragment is made before the splits after these steps, so neither
     * table moves while cx points into them. */
    const cf_contact_ctx cx = contact_ctx(sim);
    int bodies = cf_body_contact_needed(&cx);
    if (gather_hulls(sim, &cx, dt))
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory gathering contact hulls");
    cf_profile_lap(&sim->prof, CF_STAGE_COLLISION);
    cf_step_ctx ctx = cf_world_step_ctx(sim);
    for (long k = 0; k < n_sub; k++) {
        for (int fi = 0; fi < n; fi++) {
            if (sim->frag[fi].mode != CF_MODE_FRACTURE)
                continue;
            if (cf_solver_step(&ctx, &sim->frag[fi], fi, sim->t + (double)k * h, h, 1) != CF_OK)
                return cf_error_set(err, CF_ERR_NOMEM, "out of memory in fracture mode");
            sim->steps_fracture++;
            sim->tet_steps_fracture += sim->frag[fi].nt;
        }
        if (bodies) {
            double removed;
            if (cf_body_contact(&cx, h, &removed))
                return cf_error_set(err, CF_ERR_NOMEM, "contact between bodies failed: %s",
                                    cff_last_error());
            sim->flow.contact += removed;
            cf_profile_lap(&sim->prof, CF_STAGE_COLLISION);
        }
        if (sim->tick) {
            sim->tick(sim->tick_user, sim->t + (double)(k + 1) * h);
            cf_profile_lap(&sim->prof, CF_STAGE_BOOKKEEPING);
        }
    }
    for (int fi = 0; fi < n; fi++) {
        cf_fragment *f = &sim->frag[fi];
        if (f->mode != CF_MODE_FRACTURE)
            continue;
        double gained;
        cf_contact_cache *cc = &sim->contact.v[fi];
        if (cf_node_impulses_flush(&cx, &cc->push, f->nodes.v, &gained))
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory pushing rigid fragments");
        sim->flow.contact -= gained;
        cc->near.n = 0;
        cf_profile_lap(&sim->prof, CF_STAGE_COLLISION);
        char what[160];
        if (!nodes_sane(&sim->solid, f)) {
            snprintf(what, sizeof what,
                     "fragment %d diverged: a node position is not finite or a node is faster "
                     "than 1e5 m/s",
                     fi);
            return diverged(sim, err, what);
        }
        /* Inverted tets counted over the fragment's whole initial body in
         * fracture mode (one inverted tet is all of a one-tet piece). */
        int root = cf_fragment_root(sim->frag, fi), inv = 0, nt = 0;
        for (int g = 0; f->n_inverted > 0 && g < n; g++)
            if (sim->frag[g].mode == CF_MODE_FRACTURE && cf_fragment_root(sim->frag, g) == root)
                inv += sim->frag[g].n_inverted, nt += sim->frag[g].nt;
        if (inv > set->max_inverted_fraction * nt) {
            snprintf(what, sizeof what,
                     "fragment %d diverged: %d of the %d tets of its body in fracture mode are "
                     "inverted (more than solver.guard.max_inverted_fraction = %g)",
                     fi, inv, nt, set->max_inverted_fraction);
            return diverged(sim, err, what);
        }
        cf_profile_lap(&sim->prof, CF_STAGE_BOOKKEEPING);
    }
    return CF_OK;
}

/* Energy growth with no work input: kinetic + strain + cohesive energy
 * above (1 + max_energy_growth) times what was put in (the work of
 * gravity, prescribed nodes and moving obstacles, and what hand-offs put
 * in: the squeeze of wedged pieces, gravity's potential of pieces moved
 * clear of obstacles). */
static cf_status check_energy(cf_world *sim, cf_error *err)
{
    cf_ledger l;
    ledger(sim, &l, 0);
    double have = l.kinetic + l.strain + l.cohesive_stored + l.cohesive_dissipated +
                  l.plastic_dissipated;
    double input = l.initial + fmax(0.0, l.work_gravity) + fmax(0.0, l.work_boundary) +
                   fmax(0.0, l.work_obstacles) + sim->flow.put_in;
    if (have <= (1 + sim->def.solver.max_energy_growth) * input + 1e-12)
        return CF_OK;
    char what[200];
    snprintf(what, sizeof what,
             "energy grew with no work input: %.4g J against %.4g J put in (more than "
             "solver.guard.max_energy_growth = %g)",
             have, input, sim->def.solver.max_energy_growth);
    return diverged(sim, err, what);
}

#define CF_CONTACT_SLOP 1e-9 /* m: a node projected onto an obstacle, up to round-off */
#define CF_IMPACT_OVER 0.01  /* of the kinetic energy at entry: see impact_unfinished */

/* Whether fracture-mode fragment fi is still in the middle of an impact:
 * a node lies on an obstacle (or would reach it within a rigid step at the
 * fragment's rigid-body velocity), and either its rigid-body velocity there
 * approaches the obstacle faster than the impact threshold (rigid mode would
 * see an impact at once), or the energy a hand-off would drop,
 * the strain energy and the kinetic energy beyond the rigid-body motion,
 * is more than CF_IMPACT_OVER of the kinetic energy it entered with.
 * Handed back in the middle of its impact, a fragment hits again at once:
 * it chattered between the modes (63 round trips on the 3,858-tet plaster
 * bunny), every hand-off kept only the rigid part of the motion and gave
 * the rest of the impact to Bullet's inelastic contact, and the stress
 * wave that breaks a body never built up.  A body that rests on the ground
 * holds next to no strain energy, so it still goes back
 * (docs/physics.md §9). */
static int impact_unfinished(cf_world *sim, int fi)
{
    const cf_fragment *f = &sim->frag[fi];
    const cf_solid *s = &sim->solid;
    double com[3], R[9], v[3], w[3], P[3], L[3], r[3], wr[3], vr[3];
    double reach = sim->def.solver.dt_rigid;
    cf_fragment_pose(&sim->frag[fi], &sim->solid, sim->bullet, com, R, v, w);
    int touching = 0;
    for (int i = 0; i < f->nodes.n; i++) {
        const double *x = &s->x[3 * f->nodes.v[i]];
        v3_sub(x, com, r);
        v3_cross(w, r, wr);
        for (int j = 0; j < sim->obs.n; j++) {
            double n[3], u[3];
            double d = cf_obstacle_distance(&sim->obs, j, sim->t, x, n);
            cf_obstacle_velocity(&sim->obs.o[j], u);
            for (int k = 0; k < 3; k++)
                vr[k] = v[k] + wr[k] - u[k];
            double approach = -v3_dot(vr, n);
            if (d > fmax(0.0, approach) * reach + CF_CONTACT_SLOP)
                continue;
            if (approach > sim->def.solver.impact_threshold)
                return 1; /* rigid mode would see an impact at once */
            touching = 1;
        }
    }
    if (!touching)
        return 0;
    double Lo[3]; /* the spin's angular momentum, about the centre of mass */
    cf_fragment_momenta(f, &sim->solid, sim->bullet, P, L);
    v3_cross(com, P, r);
    v3_sub(L, r, Lo);
    double rigid = 0.5 * f->mass * v3_dot(v, v) + 0.5 * v3_dot(w, Lo);
    double deformation = f->e_strain + fmax(0.0, f->e_kin - rigid);
    return deformation > CF_IMPACT_OVER * f->e_enter;
}

/* Fracture-mode fragments that have been quiet long enough, and no longer
 * drive into an obstacle, go back to rigid mode; debris at once, as it
 * cannot break further. */
static cf_status return_to_rigid(cf_world *sim, cf_error *err)
{
    const cf_solver_settings *set = &sim->def.solver;
    int n = sim->n_frag;
    for (int fi = 0; fi < n; fi++) {
        cf_fragment *f = &sim->frag[fi];
        if (f->mode != CF_MODE_FRACTURE)
            continue;
        int timed_out = sim->t - f->t_enter >= set->max_fracture_time - 1e-12;
        if (!timed_out && !cf_fragment_is_debris(f, &sim->def.solver) &&
            (f->quiet < set->quiet_steps || impact_unfinished(sim, fi)))
            continue;
        int first_new = sim->n_frag;
        cf_handoff_record r;
        cf_status st = cf_handoff_to_rigid(sim, fi, &r, err);
        cf_profile_lap(&sim->prof, CF_STAGE_HANDOFF);
        if (st == CF_OK)
            st = handoff_event(sim, &r, err);
        if (st == CF_OK)
            st = fragments_born(sim, first_new, err);
        if (st != CF_OK)
            return st;
    }
    cf_profile_lap(&sim->prof, CF_STAGE_HANDOFF); /* the checks of those that stay */
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
static cf_status split_fragments(cf_world *sim, cf_error *err)
{
    int n = sim->n_frag;
    for (int fi = 0; fi < n; fi++) {
        if (sim->frag[fi].mode != CF_MODE_FRACTURE)
            continue;
        int first = sim->n_frag;
        int k = cf_fragment_split_fracture(sim, fi, &first);
        cf_profile_lap(&sim->prof, CF_STAGE_SPLIT);
        if (k < 0)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory splitting fragment %d", fi);
        if (k > 0) {
            cf_status st = fragments_born(sim, first, err);
            if (st != CF_OK)
                return st;
        }
    }
    return CF_OK;
}

const char *cf_stage_name(cf_stage s)
{
#define CF_STAGE_NAME(id, name) #name,
    static const char *const names[] = {CF_STAGES(CF_STAGE_NAME)};
#undef CF_STAGE_NAME
    return s >= 0 && s < CF_STAGE_COUNT ? names[s] : "?";
}

const cf_world_def *cf_world_definition(const cf_world *sim) { return &sim->def; }

int cf_world_done(const cf_world *sim) { return sim->step >= sim->n_steps; }

void cf_world_set_tick(cf_world *sim, cf_world_tick_fn fn, void *user)
{
    sim->tick = fn, sim->tick_user = user;
}

void cf_world_set_threads(cf_world *sim, int n)
{
    if (n >= 1)
        sim->threads = n;
}

long cf_world_step_count(const cf_world *sim) { return sim->step; }

long cf_world_steps_total(const cf_world *sim) { return sim->n_steps; }

double cf_world_dt_outer(const cf_world *sim) { return sim->dt_outer; }

double cf_world_time(const cf_world *sim) { return sim->t; }

double cf_world_dt_fracture(const cf_world *sim) { return sim->dt_fracture; }

double cf_world_dt_cfl(const cf_world *sim) { return sim->solid.dt_cfl; }

static cf_status world_step(cf_world *sim, cf_error *err)
{
    cf_profile_start(&sim->prof);
    const cf_world_def *sc = &sim->def;
    double dt = sim->dt_outer, h, t0 = sim->t;
    long n_sub = sub_steps(sim, dt, &h);
    /* The last step is cut short so that the run ends at the duration: in
     * rigid mode exactly; a fracture-only run in whole fracture steps of the
     * same h (the leapfrog energy estimate needs a constant step), so it
     * ends less than one fracture step past it. */
    double rest = sc->duration - (double)sim->step * sim->dt_outer;
    int cut = sim->step == sim->n_steps - 1 && rest < (1 - 1e-9) * dt;
    if (cut && sc->solver.mode == CF_RUN_FRACTURE) {
        n_sub = lround(fmax(1.0, ceil(rest / h - 1e-9)));
        dt = (double)n_sub * h;
    } else if (cut) {
        dt = rest;
        n_sub = sub_steps(sim, dt, &h);
    }
    int n_coh = sim->solid.n_coh;
    long stepped = sim->steps_fracture;
    cf_status st = rigid_step(sim, dt, err);
    if (st == CF_OK)
        st = fracture_steps(sim, dt, n_sub, h, err);
    if (sim->steps_fracture > stepped)
        sim->t_fracture += dt;
    sim->step++;
    sim->t = !cut ? (double)sim->step * sim->dt_outer
                  : sc->solver.mode == CF_RUN_FRACTURE ? t0 + dt : sc->duration;
    if (st == CF_OK && sim->solid.n_coh > n_coh) {
        cf_event e = {.type = CF_EVENT_INSERTIONS, .time = sim->t, .first = n_coh,
                      .count = sim->solid.n_coh - n_coh, .alive = alive_fragments(sim, NULL)};
        st = push_event(sim, &e, err);
    }
    if (st == CF_OK)
        st = split_fragments(sim, err);
    if (st == CF_OK && sc->solver.mode == CF_RUN_HYBRID)
        st = return_to_rigid(sim, err);
    if (st == CF_OK)
        st = check_energy(sim, err);
    if (cf_arena_end_step(&sim->arena) && st == CF_OK)
        st = cf_error_set(err, CF_ERR_NOMEM, "out of memory growing the step's scratch");
    cf_profile_lap(&sim->prof, CF_STAGE_BOOKKEEPING);
    return st;
}

cf_status cf_world_step(cf_world *sim, cf_error *err)
{
    /* OpenMP's thread count is the calling thread's setting: the step runs
     * on the world's and gives the caller back its own. */
    int caller = omp_get_max_threads();
    omp_set_num_threads(sim->threads);
    cf_status st = world_step(sim, err);
    omp_set_num_threads(caller);
    return st;
}

uint64_t cf_world_state_hash(const cf_world *sim)
{
    const cf_solid *s = &sim->solid;
    uint64_t h = CF_FNV1A_SEED;
    h = cf_fnv1a(h, s->x, (size_t)s->n_nodes * 3 * sizeof(double));
    h = cf_fnv1a(h, s->v, (size_t)s->n_nodes * 3 * sizeof(double));
    h = cf_fnv1a(h, s->tet_frag, (size_t)s->n_tets * sizeof(int));
    for (int fi = 0; fi < sim->n_frag; fi++) {
        const cf_fragment *f = &sim->frag[fi];
        int mode = f->mode;
        h = cf_fnv1a(h, &mode, sizeof mode);
        if (f->body >= 0) {
            cfb_state st;
            cfb_get_state(sim->bullet, f->body, &st);
            h = cf_fnv1a(h, &st, sizeof st);
        }
    }
    return h;
}

void cf_world_stats_get(const cf_world *sim, cf_world_stats *o)
{
    const cf_profile *p = &sim->prof;
    memset(o, 0, sizeof *o);
    o->tets = sim->solid.n_tets, o->nodes_input = sim->solid.n_verts0;
    o->nodes = sim->solid.n_nodes;
    o->dt_fracture = sim->dt_fracture, o->dt_cfl = sim->solid.dt_cfl, o->dt_outer = sim->dt_outer;
    o->mass_scaled = sim->solid.n_mass_scaled, o->mass_added = sim->solid.mass_added;
    o->mass_total = sim->solid.mass_total;
    o->wave_speed_least = o->mass_scaled ? 1.0 / sqrt(sim->solid.mass_scale_max) : 1.0;
    o->steps_rigid = sim->steps_rigid, o->steps_fracture = sim->steps_fracture;
    o->threads = sim->threads;
    o->alive = alive_fragments(sim, &o->in_fracture);
    o->ever = sim->n_frag;
    o->cohesive = sim->solid.n_coh;
    o->handoffs = sim->n_handoffs;
    o->max_momentum_error = sim->max_momentum_error, o->handoff_loss = sim->total_handoff_loss;
    memcpy(o->stage, p->stage, sizeof o->stage);
    /* Convex decomposition of the rigid fragments alive now: median and worst
     * error (NaN when there is no memory to sort them: unknown, not 0). */
    double *e = malloc((size_t)(sim->n_frag + 1) * sizeof(double));
    int n = 0;
    for (int fi = 0; fi < sim->n_frag; fi++) {
        const cf_fragment *f = &sim->frag[fi];
        if (f->mode != CF_MODE_DEAD)
            o->mass_alive += f->mass;
        if (f->mode != CF_MODE_DEAD && cf_fragment_is_debris(f, &sim->def.solver)) {
            o->debris++;
            o->debris_mass += f->mass;
            continue;
        }
        if (f->mode == CF_MODE_RIGID && f->body >= 0) {
            if (e)
                e[n] = cf_hulls_error(&f->hulls);
            n++;
            o->hulls += f->hulls.n_hulls;
        }
    }
    if (n > 0 && !e) {
        o->hull_error_median = o->hull_error_worst = NAN;
    } else if (n > 0) {
        cf_doubles_sort(e, n);
        o->hull_error_median = n % 2 ? e[n / 2] : 0.5 * (e[n / 2 - 1] + e[n / 2]);
        o->hull_error_worst = e[n - 1];
    }
    o->rigid_with_hulls = n;
    free(e);
}

void cf_world_memory(const cf_world *sim, cf_memory *m)
{
    const cf_solid *s = &sim->solid;
    const unsigned long long D = sizeof(double), I = sizeof(int);
    unsigned long long cn = (unsigned long long)s->cap_nodes, nt = (unsigned long long)s->n_tets;
    memset(m, 0, sizeof *m);
    /* per node: X x v f, the row p, m vcap speed; origin bc */
    m->solid = cn * (19 * D + 2 * I) + nt * (27 * D + 9 * I) +
               ((unsigned long long)s->n_verts0 + 1 + 4 * nt) * I + (s->ep ? nt * 7 * D : 0);
    if (s->facet)
        m->fracture = nt * (9 * D + 2 + 20 * I) + cn * (1 + D) +
                      (unsigned long long)s->n_facets * (1 + (s->candidate != NULL));
    m->cohesive = (unsigned long long)s->cap_coh * sizeof(cf_cohesive);
    m->fragments = (unsigned long long)sim->cap_frag * sizeof(cf_fragment);
    for (int i = 0; i < sim->n_frag; i++) {
        const cf_fragment *f = &sim->frag[i];
        m->fragments += (unsigned long long)f->nt * I + (unsigned long long)f->nodes.cap * I +
                        (unsigned long long)f->coh.cap * I +
                        (unsigned long long)f->bars.n * (2 * I + 3 * D) +
                        (unsigned long long)f->scratch_cap * (I + 5 * D + I + 6 * D) +
                        (unsigned long long)f->pairs_cap * 3 * sizeof(cf_pair_force);
        if (f->hulls.n_hulls)
            m->fragments += (unsigned long long)f->hulls.start[f->hulls.n_hulls] * 3 * D +
                            ((unsigned long long)f->hulls.n_hulls + 1) * I;
    }
    unsigned long long b = cfb_allocated_bytes();
    m->bullet = b > sim->bullet_base ? b - sim->bullet_base : 0;
    for (int j = 0; sim->obs.mesh && j < sim->obs.n; j++)
        m->collision += cff_mesh_bytes(sim->obs.mesh[j]);
    for (int i = 0; i < sim->contact.cap; i++) {
        const cf_frag_surface *fs = &sim->contact.v[i].surface;
        m->collision += cff_mesh_bytes(fs->mesh) +
                        (unsigned long long)fs->nv * (I + 3 * D) + 3ull * fs->ntri * I;
    }
}

void cf_world_step_stats(const cf_world *sim, cf_step_stats *o)
{
    const cf_solver_settings *set = &sim->def.solver;
    memset(o, 0, sizeof *o);
    o->fracture_steps = sim->steps_fracture;
    o->tet_steps = sim->tet_steps_fracture, o->fracture_time = sim->t_fracture;
    memcpy(o->stage, sim->prof.stage, sizeof o->stage);
    for (int i = 0; i < sim->n_frag; i++) {
        const cf_fragment *f = &sim->frag[i];
        if (f->mode != CF_MODE_FRACTURE)
            continue;
        o->tets += f->nt, o->nodes += f->nodes.n, o->bars += f->bars.n, o->cohesive += f->coh.n;
        if (f->bars.color_start) {
            o->colours = f->bars.n_colors > o->colours ? f->bars.n_colors : o->colours;
            o->serial_bars += f->bars.n - f->bars.color_start[CF_BARS_COLORS];
        }
    }
    o->iterations = set->constraints == CF_CONSTRAINTS_NONE ? 0 : set->iterations;
    o->check = set->criterion != CF_CRITERION_NONE;
    o->xpbd = set->constraints == CF_CONSTRAINTS_XPBD;
}

double cf_step_traffic(const cf_step_stats *st)
{
    double tet = 168 + (st->check ? 144 : 0);
    double node = 104 + 48.0 * st->iterations;
    double bar = (st->xpbd ? 40.0 : 16.0) * st->iterations;
    return tet * st->tets + node * st->nodes + bar * st->bars +
           2.0 * sizeof(cf_cohesive) * st->cohesive;
}
