/* Creating a world: the bodies placed, renumbered for locality and
 * joined into one solid, boundary conditions, the crack plane, obstacles,
 * the initial fragments and their Bullet bodies; and destroying it. */
#include "handoff.h"
#include "insertion.h"
#include "world_events.h"

#include "linalg.h"
#include "renumber.h"

#include <math.h>
#include <omp.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

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
static cf_status select_crack_plane(cf_world *w, cf_error *err)
{
    const cf_solver_settings *set = &w->def.solver;
    cf_solid *s = &w->solid;
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
        cf_solid_update_open(s, fc);
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
static cf_status make_initial_fragments(cf_world *w, const cf_world_def *def, const int *body,
                                        cf_error *err)
{
    cf_solid *s = &w->solid;
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
        ok = cf_fragment_new(&w->frag, &w->n_frag, &w->cap_frag, -1, 0.0) >= 0;
    for (int t = 0; ok && t < nt; t++) {
        cf_fragment *f = &w->frag[comp[t]];
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
    int fracture = w->def.solver.mode == CF_RUN_FRACTURE;
    for (int fi = 0; fi < w->n_frag; fi++) {
        cf_fragment *f = &w->frag[fi];
        int *tt = realloc(f->tets, (size_t)f->nt * sizeof(int));
        if (tt)
            f->tets = tt;
        cf_fragment_rest_props(f, &w->solid);
        cf_fragment_ledger_reset(f, &w->solid, &w->flow);
        if (fracture) {
            f->mode = CF_MODE_FRACTURE;
            f->t_enter = 0;
        }
        if (w->bullet) {
            const cf_body_def *bd = &def->bodies[body[f->tets[0]]];
            cf_node_state ns;
            cf_nodes_momenta(s, f->nodes.v, f->nodes.n, &ns);
            double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
            cf_status st = cf_fragment_add_body(w, fi, f->com_rest, I3, ns.v,
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
static cf_status add_obstacles(cf_world *w, const cf_world_def *def, cf_error *err)
{
    int n = def->n_obstacles;
    w->obs.o = w->def.obstacles;
    w->obstacle_body = malloc(((size_t)n + 1) * sizeof(int));
    w->obstacle_moving = calloc((size_t)n + 1, 1);
    if (!w->obstacle_body || !w->obstacle_moving)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory for obstacles");
    for (int j = 0; j < n; j++) {
        double u[3];
        cf_obstacle_velocity(&def->obstacles[j], u);
        w->obstacle_moving[j] = v3_dot(u, u) > 0;
    }
    return cf_obstacles_create(&w->obs, def, w->bullet, w->obstacle_body, err);
}

/* What a reader needs to bound a run's outcome (tests/checks/check_physics.py):
 * the box around the nodes, mass, energy and fastest node at t = 0, and the
 * fastest kinematic obstacle or prescribed node; taken at create. */
static void initial_bounds(cf_world *w)
{
    const cf_solid *s = &w->solid;
    const cf_world_def *sc = &w->def;
    cf_initial_bounds *b = &w->bounds;
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
    b->energy = w->e0;
    const cf_material *m = &s->mat;
    b->release_speed = 0;
    if (s->facet) { /* an insertion criterion: facets can be held up to their strength, */
        double bar = sqrt(m->rho * m->E); /* and crushed material at sigma_c */
        b->release_speed = fmax(s->strength_max * fmax(m->sigma_max / bar,
                                                       m->tau_max / sqrt(m->rho * s->mu)),
                                m->compressive_strength / bar);
    }
}

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
static cf_status copy_def(cf_world *w, const cf_world_def *def, cf_error *err)
{
    int fail = 0;
    w->def = *def;
    w->def.bodies = NULL, w->def.n_bodies = 0;
    w->def.obstacles = copy_array(def->obstacles, def->n_obstacles, sizeof *def->obstacles, &fail);
    w->def.boundaries = copy_array(def->boundaries, def->n_boundaries, sizeof *def->boundaries,
                                     &fail);
    for (int j = 0; w->def.obstacles && j < def->n_obstacles; j++) /* FCL and Bullet copy them */
        w->def.obstacles[j].vertices = NULL, w->def.obstacles[j].triangles = NULL;
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
    cf_world *w = calloc(1, sizeof *w);
    if (!w)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    st = copy_def(w, def, err);
    const cf_world_def *scene = &w->def;
    w->wall_start = cf_wall_time();
    w->bullet_base = cfb_allocated_bytes();
    /* The world's own thread count: the process's OpenMP setting is the
     * caller's, and two worlds may run on different counts. */
    w->threads = scene->solver.threads > 0 ? scene->solver.threads : omp_get_max_threads();
    int threads = w->threads, startable = threads_startable(threads);
    if (st == CF_OK && startable < threads)
        st = cf_error_set(err, CF_ERR_NOMEM,
                          "cannot start %d threads for the element loops (only %d): the memory "
                          "or process limits (ulimit -v, ulimit -u) leave no room for their "
                          "stacks; run with fewer threads (-t %d, solver.threads)",
                          threads, startable, startable > 0 ? startable : 1);
    w->law = cf_cohesive_law_of(scene->material.cohesive_law);
    w->law->init(w->law_params, &scene->material);

    cf_mesh all = {0};
    int *body = NULL, *bc = NULL;
    if (st == CF_OK)
        st = load_bodies(def, &all, &body, &bc, err);
    if (st == CF_OK) {
        w->user_of_tet = malloc((size_t)all.n_tets * sizeof(int));
        w->tet_of_user = malloc((size_t)all.n_tets * sizeof(int));
        if (!w->user_of_tet || !w->tet_of_user ||
            cf_renumber_locality(&all, bc, body, w->user_of_tet))
            st = cf_error_set(err, CF_ERR_NOMEM, "out of memory renumbering %d tets", all.n_tets);
        for (int t = 0; st == CF_OK && t < all.n_tets; t++)
            w->tet_of_user[w->user_of_tet[t]] = t;
    }
    if (st == CF_OK) {
        st = cf_solid_init(&w->solid, &all, &scene->material, body, err);
        if (st == CF_OK)
            memcpy(w->solid.bc, bc, (size_t)all.n_nodes * sizeof(int));
        if (st == CF_OK)
            st = cf_solid_scale_mass(&w->solid, scene->solver.mass_scaling, err);
        if (st == CF_OK && scene->solver.bulk_viscosity > 0)
            st = cf_solid_init_bulk_viscosity(&w->solid, scene->solver.bulk_viscosity, err);
        if (st == CF_OK && scene->solver.criterion != CF_CRITERION_NONE)
            st = cf_solid_init_facets(&w->solid, err);
        if (st == CF_OK && scene->solver.criterion == CF_CRITERION_SOURCE &&
            scene->solver.crack_growth == CF_GROWTH_FRONTS &&
            scene->solver.front_threshold != CF_FRONT_STRENGTH)
            st = cf_solid_init_front_toughness(
                &w->solid, scene->solver.front_threshold == CF_FRONT_CRACK, err);
        if (st == CF_OK)
            cf_insertion_init_front_floors(&w->solid);
        cf_mesh_free(&all);
    }
    free(bc);
    w->dt_fracture = scene->solver.cfl_fraction > 0
                           ? scene->solver.cfl_fraction * w->solid.dt_cfl
                           : scene->solver.dt_fracture;
    /* With no rigid mode the outer step only paces output and checks: a
     * whole number of fracture steps, so that every step is dt_fracture. */
    w->dt_outer = scene->solver.dt_rigid;
    if (scene->solver.mode == CF_RUN_FRACTURE)
        w->dt_outer = fmax(1.0, floor(scene->solver.dt_rigid / w->dt_fracture + 1e-9)) *
                        w->dt_fracture;
    if (st == CF_OK && scene->solver.rigid_backend == CF_RIGID_BULLET &&
        scene->solver.mode == CF_RUN_HYBRID) {
        w->bullet = cfb_world_create(scene->gravity);
        if (!w->bullet)
            st = cf_world_bullet_error(err, "creating the world");
        else
            cfb_set_sleeping(w->bullet, scene->solver.sleep_linear, scene->solver.sleep_angular);
    }
    if (st == CF_OK)
        st = add_obstacles(w, def, err);
    if (st == CF_OK)
        st = select_crack_plane(w, err);
    cf_profile_start(&w->prof);
    if (st == CF_OK)
        st = make_initial_fragments(w, def, body, err);
    free(body);
    /* The initial bodies' convex decompositions are the run's; the rest of
     * creation is no stage of a step. */
    double hulls = w->prof.stage[CF_STAGE_CONVEX_DECOMPOSITION];
    memset(&w->prof, 0, sizeof w->prof);
    w->prof.stage[CF_STAGE_CONVEX_DECOMPOSITION] = hulls;
    if (st == CF_OK) { /* the ledger's reference state */
        cf_ledger l;
        cf_world_ledger(w, &l);
        w->e0 = l.kinetic + l.strain;
        memcpy(w->mx0, l.mass_moment, sizeof w->mx0);
        initial_bounds(w);
        st = cf_world_fragments_born(w, 0, err);
    }
    if (st != CF_OK) {
        cf_world_destroy(w);
        return st;
    }
    *out = w;
    return CF_OK;
}

void cf_world_destroy(cf_world *w)
{
    if (!w)
        return;
    for (int i = 0; i < w->n_frag; i++) {
        cf_fragment *f = &w->frag[i];
        free(f->tets), free(f->nodes.v), free(f->coh.v), free(f->contact), free(f->vn_pre);
        free(f->v_old), free(f->term), free(f->pairs);
        cf_bars_free(&f->bars);
        cf_hulls_free(&f->hulls);
    }
    free(w->frag);
    cf_contact_caches_free(&w->contact);
    cf_arena_free(&w->arena);
    cf_obstacles_free(&w->obs);
    free(w->obstacle_body), free(w->obstacle_moving);
    free(w->cand.v), free(w->tet_of_user), free(w->user_of_tet), free(w->ev);
    free(w->touched.v), free(w->crushed.v);
    cf_bars_scratch_free(&w->bar_scratch);
    free(w->def.obstacles), free(w->def.boundaries);
    if (w->bullet)
        cfb_world_destroy(w->bullet);
    cf_solid_free(&w->solid);
    free(w);
}
