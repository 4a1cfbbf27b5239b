/* The driver: builds what a scene asks for and runs the rigid-step loop
 * (DESIGN §1, §5).  Each rigid step: Bullet (or the pbd rigid backend)
 * moves the rigid fragments; a fragment hit harder than the impact threshold
 * is rolled back to the start of the step and re-done in fracture mode,
 * sub-cycled at dt_fracture; a fracture-mode fragment quiet for quiet_steps
 * steps is split into its components and handed back to rigid mode. */
#include "sim.h"
#include "hash.h"

#include "cohfrac/surface.h"
#include "linalg.h"
#include "renumber.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Place a body's mesh: x' = position + scale R (x - bbox centre). */
static void place_mesh(cf_mesh *m, const cf_body_def *b)
{
    double lo[3], hi[3];
    points_bbox(m->x, m->n_nodes, lo, hi);
    double c[3] = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])}, R[9];
    quat_to_mat(b->orientation, R);
    for (int i = 0; i < m->n_nodes; i++) {
        double r[3], y[3];
        v3_sub(&m->x[3 * i], c, r);
        m3_mulv(R, r, y);
        for (int k = 0; k < 3; k++)
            m->x[3 * i + k] = b->position[k] + b->scale * y[k];
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
static cf_status body_boundary(const cf_scene *sc, int b, const cf_mesh *m, int *bc, int *count,
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

static cf_status load_mesh(const cf_body_def *bd, const char *mesh_dir, cf_mesh *m, cf_error *err)
{
    cf_status st = bd->primitive.type != CF_PRIM_NONE
                       ? cf_mesh_primitive(&bd->primitive, mesh_dir ? mesh_dir : "build/meshes",
                                           m, err)
                       : cf_mesh_load(bd->mesh, m, err);
    /* bodies[i].hollow_layers: keep a shell of tets along the surface. */
    if (st == CF_OK && bd->hollow_layers > 0) {
        st = cf_mesh_hollow(m, bd->hollow_layers, err);
        if (st != CF_OK) {
            if (err) {
                char why[sizeof err->msg];
                memcpy(why, err->msg, sizeof why);
                cf_error_set(err, st, "hollow_layers = %d on %s: %s", bd->hollow_layers,
                             bd->mesh[0] ? bd->mesh : "the body's primitive mesh", why);
            }
            cf_mesh_free(m);
        }
    }
    return st;
}

/* All bodies' meshes, placed and concatenated; body[t] is each tet's body,
 * bc[n] each node's boundary condition (-1 none). */
static cf_status load_bodies(const cf_scene *sc, const char *mesh_dir, cf_mesh *all, int **body,
                             int **bc, cf_error *err)
{
    memset(all, 0, sizeof *all);
    *body = NULL, *bc = NULL;
    int *count = calloc((size_t)sc->n_boundaries + 1, sizeof(int));
    cf_status st = count ? CF_OK : cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    for (int b = 0; b < sc->n_bodies && st == CF_OK; b++) {
        cf_mesh m;
        st = load_mesh(&sc->bodies[b], mesh_dir, &m, err);
        if (st != CF_OK)
            break;
        place_mesh(&m, &sc->bodies[b]);
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
static cf_status select_crack_plane(cf_sim *sim, cf_error *err)
{
    const cf_solver_settings *set = &sim->scene->solver;
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
static cf_status make_initial_fragments(cf_sim *sim, const int *body, cf_error *err)
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
    for (int c = 0; c < k; c++)
        cf_fragment_new(sim, -1, 0.0);
    for (int t = 0; t < nt; t++) {
        cf_fragment *f = &sim->frag[comp[t]];
        if (!f->tets)
            f->tets = malloc((size_t)nt * sizeof(int)); /* trimmed below */
        f->tets[f->nt++] = t;
        s->tet_frag[t] = comp[t];
        for (int j = 0; j < 4; j++) {
            int a = s->tet[4 * t + j];
            if (!seen[a]) {
                seen[a] = 1;
                cf_int_list_push(&f->nodes, a);
            }
        }
    }
    free(all), free(comp), free(seen);

    /* Initial velocity field: v = v_b + w_b x (x - x_com) + rate (.) (x - x_e). */
    for (int b = 0; b < sim->scene->n_bodies; b++) {
        const cf_body_def *bd = &sim->scene->bodies[b];
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
    int fracture = sim->scene->solver.mode == CF_RUN_FRACTURE;
    for (int fi = 0; fi < sim->n_frag; fi++) {
        cf_fragment *f = &sim->frag[fi];
        int *tt = realloc(f->tets, (size_t)f->nt * sizeof(int));
        if (tt)
            f->tets = tt;
        cf_fragment_rest_props(sim, fi);
        cf_fragment_ledger_reset(sim, fi);
        if (fracture) {
            f->mode = CF_MODE_FRACTURE;
            f->t_enter = 0;
        }
        if (sim->bullet) {
            const cf_body_def *bd = &sim->scene->bodies[body[f->tets[0]]];
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

/* A mesh obstacle's surface placed in the world: x' = position + scale R x. */
static cf_status load_obstacle_mesh(const cf_obstacle *o, int j, cf_surface *srf, cf_error *err)
{
    cf_status st = cf_surface_load(o->file, srf, err);
    if (st != CF_OK)
        return st;
    double R[9];
    quat_to_mat(o->orientation, R);
    for (int i = 0; i < srf->n_verts; i++) {
        double y[3];
        m3_mulv(R, &srf->v[3 * i], y);
        for (int k = 0; k < 3; k++)
            srf->v[3 * i + k] = o->position[k] + o->scale * y[k];
    }
    if (srf->n_tris == 0) {
        cf_surface_free(srf);
        return cf_error_set(err, CF_ERR_SCENE_VALUE, "obstacles[%d].file %s has no triangle",
                            j + 1, o->file);
    }
    return CF_OK;
}

/* Mesh obstacles for the in-house solver (FCL), and every obstacle for
 * Bullet when there is a Bullet world.  Nodes count as inside a mesh down
 * to 5% of its size behind the surface. */
static cf_status add_obstacles(cf_sim *sim, cf_error *err)
{
    const cf_scene *sc = sim->scene;
    int n = sc->n_obstacles;
    sim->obs.n = n;
    sim->obs.o = sc->obstacles;
    if (n == 0)
        return CF_OK;
    sim->obs.mesh = calloc((size_t)n, sizeof *sim->obs.mesh);
    sim->obs.range = calloc((size_t)n, sizeof *sim->obs.range);
    sim->obstacle_body = malloc((size_t)n * sizeof(int));
    sim->obstacle_moving = calloc((size_t)n, 1);
    if (!sim->obs.mesh || !sim->obs.range || !sim->obstacle_body || !sim->obstacle_moving)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory for obstacles");
    for (int j = 0; j < n; j++) {
        const cf_obstacle *o = &sc->obstacles[j];
        int id = -1;
        sim->obstacle_body[j] = -1;
        sim->obstacle_moving[j] = o->type != CF_OBSTACLE_PLANE && o->type != CF_OBSTACLE_MESH &&
                                  v3_dot(o->velocity, o->velocity) > 0;
        if (o->type == CF_OBSTACLE_MESH) {
            cf_surface srf;
            cf_status st = load_obstacle_mesh(o, j, &srf, err);
            if (st != CF_OK)
                return st;
            double lo[3], hi[3], diag[3];
            points_bbox(srf.v, srf.n_verts, lo, hi);
            v3_sub(hi, lo, diag);
            sim->obs.range[j] = 0.05 * v3_norm(diag);
            sim->obs.mesh[j] = cff_mesh_create(srf.v, srf.n_verts, srf.tri, srf.n_tris);
            if (sim->obs.mesh[j] && sim->bullet)
                id = cfb_add_trimesh(sim->bullet, srf.v, srf.n_verts, srf.tri, srf.n_tris,
                                     o->friction, o->restitution);
            cf_surface_free(&srf);
            if (!sim->obs.mesh[j])
                return cf_error_set(err, CF_ERR_EXTERNAL, "FCL refused obstacle %d (%s): %s",
                                    j + 1, o->file, cff_last_error());
        } else if (!sim->bullet) {
            continue;
        } else if (o->type == CF_OBSTACLE_PLANE) {
            id = cfb_add_plane(sim->bullet, o->point, o->normal, o->friction, o->restitution);
        } else if (o->type == CF_OBSTACLE_SPHERE) {
            id = cfb_add_sphere(sim->bullet, o->center, o->radius, o->velocity, o->friction,
                                o->restitution);
        } else {
            id = cfb_add_box(sim->bullet, o->center, o->half_extents, o->velocity, o->friction,
                             o->restitution);
        }
        /* Bullet multiplies the two bodies' coefficients: material x obstacle factor. */
        if (sim->bullet && id < 0)
            return cf_error_set(err, CF_ERR_EXTERNAL, "Bullet refused obstacle %d: %s", j + 1,
                                cfb_last_error());
        sim->obstacle_body[j] = id;
    }
    return CF_OK;
}

static cf_status write_fragment_infos(cf_sim *sim, int first, cf_error *err)
{
    if (!sim->h5 || first >= sim->n_frag)
        return CF_OK;
    int n = sim->n_frag - first;
    cf_frag_info *info = calloc((size_t)n, sizeof *info);
    if (!info)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    for (int i = 0; i < n; i++) {
        const cf_fragment *f = &sim->frag[first + i];
        info[i].id = first + i;
        info[i].parent = f->parent;
        info[i].birth_time = f->birth_time;
        info[i].mass = f->mass;
        info[i].n_tets = f->nt;
        memcpy(info[i].inertia_principal, f->principal, sizeof f->principal);
        info[i].n_hulls = f->body >= 0 ? f->hulls.n_hulls : 0;
        info[i].hull_volume_error = cf_hulls_error(&f->hulls);
        info[i].decomposition_time = f->decompose_time;
    }
    cf_status st = cf_h5_add_fragments(sim->h5, info, n, err);
    free(info);
    return st;
}

/* What a reader needs to bound a run's outcome (tools/check_physics.py):
 * the box around the nodes, mass, energy and fastest node at t = 0, and the
 * fastest kinematic obstacle or prescribed node. */
static cf_status write_initial_bounds(cf_sim *sim, cf_error *err)
{
    const cf_solid *s = &sim->solid;
    const cf_scene *sc = sim->scene;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double mass = 0, v2 = 0, u = 0;
    for (int a = 0; a < s->n_nodes; a++) {
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], s->x[3 * a + k]);
            hi[k] = fmax(hi[k], s->x[3 * a + k]);
        }
        mass += s->m[a];
        v2 = fmax(v2, v3_dot(&s->v[3 * a], &s->v[3 * a]));
    }
    for (int j = 0; j < sc->n_obstacles; j++) {
        double uj[3];
        cf_obstacle_velocity(&sc->obstacles[j], uj);
        u = fmax(u, v3_norm(uj));
    }
    for (int j = 0; j < sc->n_boundaries; j++)
        u = fmax(u, v3_norm(sc->boundaries[j].velocity));
    double v0 = sqrt(v2);
    cf_status st = cf_h5_write_parameter(sim->h5, "initial_lower", lo, 3, "m", err);
    if (st == CF_OK)
        st = cf_h5_write_parameter(sim->h5, "initial_upper", hi, 3, "m", err);
    if (st == CF_OK)
        st = cf_h5_write_parameter(sim->h5, "total_mass", &mass, 1, "kg", err);
    if (st == CF_OK)
        st = cf_h5_write_parameter(sim->h5, "initial_energy", &sim->e0, 1, "J", err);
    if (st == CF_OK)
        st = cf_h5_write_parameter(sim->h5, "max_initial_speed", &v0, 1, "m/s", err);
    if (st == CF_OK)
        st = cf_h5_write_parameter(sim->h5, "max_obstacle_speed", &u, 1, "m/s", err);
    return st;
}

cf_status cf_sim_create(const cf_scene *scene, const cf_run_options *opt, cf_sim **out,
                        cf_error *err)
{
    *out = NULL;
    cf_sim *sim = calloc(1, sizeof *sim);
    if (!sim)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    sim->scene = scene;
    sim->opt = *opt;
    sim->wall_start = cf_wall_time();
    sim->bullet_base = cfb_allocated_bytes();
    int threads = opt->threads > 0 ? opt->threads : scene->solver.threads;
    if (threads > 0)
        omp_set_num_threads(threads);
    cf_ppr_init(&sim->ppr, &scene->material);

    cf_mesh all;
    int *body = NULL, *bc = NULL;
    cf_status st = load_bodies(scene, opt->mesh_dir, &all, &body, &bc, err);
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
            st = cf_error_set(err, CF_ERR_EXTERNAL, "Bullet world: %s", cfb_last_error());
        else
            cfb_set_sleeping(sim->bullet, scene->solver.sleep_linear, scene->solver.sleep_angular);
    }
    if (st == CF_OK)
        st = add_obstacles(sim, err);
    if (st == CF_OK)
        st = select_crack_plane(sim, err);
    if (st == CF_OK)
        st = make_initial_fragments(sim, body, err);
    free(body);
    if (st == CF_OK) { /* the ledger's reference state */
        cf_ledger l;
        cf_sim_ledger(sim, &l);
        sim->e0 = l.kinetic + l.strain;
        memcpy(sim->mx0, l.mass_moment, sizeof sim->mx0);
    }
    if (st == CF_OK && scene->output.file[0]) {
        st = cf_h5_open(scene->output.file, scene->name, scene->resolved, &sim->h5, err);
        if (st == CF_OK)
            st = write_initial_bounds(sim, err);
        if (st == CF_OK)
            st = write_fragment_infos(sim, 0, err);
    }
    if (st != CF_OK) {
        cf_sim_destroy(sim);
        return st;
    }
    *out = sim;
    return CF_OK;
}

void cf_sim_destroy(cf_sim *sim)
{
    if (!sim)
        return;
    if (sim->h5)
        cf_h5_close(sim->h5, NULL);
    for (int i = 0; i < sim->n_frag; i++) {
        cf_fragment *f = &sim->frag[i];
        free(f->tets), free(f->nodes.v), free(f->coh.v), free(f->contact), free(f->vn_pre);
        free(f->v_old), free(f->term);
        cf_bars_free(&f->bars);
        cf_hulls_free(&f->hulls);
        cf_node_impulses_free(&f->push);
        cf_hull_set_free(&f->near);
        cf_frag_surface_free(&f->surface);
    }
    free(sim->frag);
    for (int j = 0; sim->obs.mesh && j < sim->obs.n; j++)
        cff_mesh_destroy(sim->obs.mesh[j]);
    free(sim->obs.mesh), free(sim->obs.range), free(sim->obstacle_body), free(sim->obstacle_moving);
    free(sim->body_boxes), free(sim->cand.v), free(sim->tet_of_user);
    if (sim->bullet)
        cfb_world_destroy(sim->bullet);
    cf_solid_free(&sim->solid);
    free(sim);
}

/* Kinetic energy (J) of rigid fragment f in Bullet state st. */
static double state_kinetic_energy(const cf_fragment *f, const cfb_state *st)
{
    double Rb[9], wb[3];
    quat_to_mat(st->quat, Rb);
    m3_tmulv(Rb, st->w, wb); /* body-frame angular velocity */
    double e = 0.5 * f->mass * v3_dot(st->v, st->v);
    for (int k = 0; k < 3; k++)
        e += 0.5 * f->principal[k] * wb[k] * wb[k];
    return e;
}

double cf_body_kinetic_energy(const cf_sim *sim, int fi)
{
    cfb_state st;
    cfb_get_state(sim->bullet, sim->frag[fi].body, &st);
    return state_kinetic_energy(&sim->frag[fi], &st);
}

/* Kinetic energy minus gravity's potential work: what a Bullet body keeps
 * in free flight, J. */
static double body_energy(const cf_sim *sim, const cf_fragment *f, const cfb_state *st)
{
    return state_kinetic_energy(f, st) - f->mass * v3_dot(sim->scene->gravity, st->pos);
}

void cf_sim_ledger(const cf_sim *sim, cf_ledger *l)
{
    const cf_solid *s = &sim->solid;
    memset(l, 0, sizeof *l);
    for (int fi = 0; fi < sim->n_frag; fi++) {
        const cf_fragment *f = &sim->frag[fi];
        if (f->mode == CF_MODE_DEAD)
            continue;
        double P[3], L[3];
        if (f->body >= 0) {
            cfb_state st;
            cfb_get_state(sim->bullet, f->body, &st);
            l->kinetic += state_kinetic_energy(f, &st);
            v3_axpy(f->mass, st.pos, l->mass_moment);
            cf_body_momenta(f, &st, P, L);
        } else {
            l->kinetic += f->e_kin;
            l->strain += f->e_strain;
            v3_axpy(1.0, f->mx, l->mass_moment);
            cf_fragment_momenta(sim, fi, P, L);
        }
        v3_axpy(1.0, P, l->momentum);
        v3_axpy(1.0, L, l->angular_momentum);
    }
    cf_cohesive_energy(s, NULL, 0, &l->cohesive_stored, &l->cohesive_dissipated);
    double dmx[3];
    v3_sub(l->mass_moment, sim->mx0, dmx);
    l->work_gravity = v3_dot(sim->scene->gravity, dmx);
    l->work_boundary = sim->flow.boundary;
    l->work_obstacles = sim->flow.obstacles;
    l->contact = sim->flow.contact, l->pbd = sim->flow.pbd;
    l->damping = sim->flow.damping, l->handoff = sim->flow.handoff;
    l->integration = sim->flow.integration;
    l->initial = sim->e0;
    l->residual = l->kinetic + l->strain + l->cohesive_stored + l->cohesive_dissipated +
                  l->contact + l->pbd + l->damping + l->handoff + l->integration -
                  (l->initial + l->work_gravity + l->work_boundary + l->work_obstacles);
}

int cf_sim_fragments(cf_sim *sim, cf_fragment_state *out, int cap)
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
            cf_fragment_pose(sim, fi, o->com, R, o->v, o->w);
            mat_to_quat(R, o->quat);
            for (int k = 0; k < 3; k++)
                o->momentum[k] = f->mass * o->v[k];
            if (f->body >= 0) {
                cfb_state st;
                cfb_get_state(sim->bullet, f->body, &st);
                cf_body_spin(f, &st, o->angular_momentum);
                o->kinetic = state_kinetic_energy(f, &st);
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

double cf_sim_fragment_support(cf_sim *sim, int id, const double d[3])
{
    if (id < 0 || id >= sim->n_frag || sim->frag[id].mode == CF_MODE_DEAD)
        return 0;
    const cf_fragment *f = &sim->frag[id];
    double com[3], R[9], v[3], w[3], Rd[3], best = -INFINITY;
    cf_fragment_pose(sim, id, com, R, v, w);
    m3_tmulv(R, d, Rd); /* (R r).d = r.(R^T d), r from the rest centre of mass */
    for (int i = 0; i < f->nodes.n; i++) {
        double r[3];
        v3_sub(&sim->solid.X[3 * f->nodes.v[i]], f->com_rest, r);
        best = fmax(best, v3_dot(r, Rd));
    }
    return f->nodes.n ? best : 0;
}

int cf_sim_tet_count(const cf_sim *sim) { return sim->solid.n_tets; }

int cf_sim_tet_fragment(const cf_sim *sim, int t)
{
    return t >= 0 && t < sim->solid.n_tets ? sim->solid.tet_frag[sim->tet_of_user[t]] : -1;
}

/* Every cohesive element's place, opening and state now (output.cracks). */
static cf_status write_cracks(cf_sim *sim, cf_error *err)
{
    const cf_solid *s = &sim->solid;
    cf_crack_row *rows = malloc((size_t)(s->n_coh > 0 ? s->n_coh : 1) * sizeof *rows);
    if (!rows)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory writing %d crack rows", s->n_coh);
    for (int e = 0; e < s->n_coh; e++) {
        cf_crack_row *r = &rows[e];
        r->time = sim->t;
        r->element = e;
        cf_cohesive_state(s, e, r->centroid, r->normal, &r->area, &r->opening, &r->sliding,
                          &r->failed);
    }
    cf_status st = cf_h5_add_cracks(sim->h5, rows, s->n_coh, err);
    free(rows);
    return st;
}

static cf_status write_frame(cf_sim *sim, cf_error *err)
{
    if (!sim->h5)
        return CF_OK;
    double t0 = cf_wall_time();
    cf_frag_frame *fr = malloc((size_t)sim->n_frag * sizeof *fr);
    if (!fr)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    int n = 0, n_fracture = 0;
    for (int fi = 0; fi < sim->n_frag; fi++) {
        cf_fragment *f = &sim->frag[fi];
        if (f->mode == CF_MODE_DEAD)
            continue;
        double R[9];
        cf_frag_frame *o = &fr[n++];
        o->id = fi;
        o->mode = f->mode;
        cf_fragment_pose(sim, fi, o->com, R, o->v, o->w);
        mat_to_quat(R, o->quat);
        n_fracture += f->mode == CF_MODE_FRACTURE;
    }
    cf_status st = cf_h5_write_frame(sim->h5, sim->step, sim->t, fr, n, err);
    free(fr);
    unsigned long long mem = cf_h5_memory(sim->h5);
    sim->output_peak = mem > sim->output_peak ? mem : sim->output_peak;
    cf_ledger l;
    cf_sim_ledger(sim, &l);
    const struct {
        const char *name;
        double value;
    } obs[] = {
        {"energy_kinetic", l.kinetic},
        {"energy_strain", l.strain},
        {"energy_cohesive_stored", l.cohesive_stored},
        {"energy_cohesive_dissipated", l.cohesive_dissipated},
        {"work_gravity", l.work_gravity},
        {"work_boundary", l.work_boundary},
        {"work_obstacles", l.work_obstacles},
        {"energy_contact_removed", l.contact},
        {"energy_rigid_integration_removed", l.integration},
        {"energy_pbd_removed", l.pbd},
        {"energy_damping_removed", l.damping},
        {"energy_handoff_loss", l.handoff},
        {"energy_residual", l.residual},
        {"momentum_x", l.momentum[0]},
        {"momentum_y", l.momentum[1]},
        {"momentum_z", l.momentum[2]},
        {"angular_momentum_x", l.angular_momentum[0]},
        {"angular_momentum_y", l.angular_momentum[1]},
        {"angular_momentum_z", l.angular_momentum[2]},
        {"fragment_count", n},
        {"cohesive_elements", sim->solid.n_coh},
        {"crack_area", cf_solid_crack_area(&sim->solid)},
        {"fragments_in_fracture_mode", n_fracture},
        {"handoff_momentum_error_max", sim->max_momentum_error},
    };
    for (size_t i = 0; i < sizeof obs / sizeof obs[0] && st == CF_OK; i++)
        st = cf_h5_write_observable(sim->h5, obs[i].name, sim->step, sim->t, obs[i].value, err);
    if (st == CF_OK && sim->scene->output.cracks)
        st = write_cracks(sim, err);
    sim->prof.output += cf_wall_time() - t0;
    return st;
}

static int alive_fragments(const cf_sim *sim, int *in_fracture)
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

static void progress(cf_sim *sim, int final)
{
    if (!sim->opt.progress)
        return;
    double now = cf_wall_time(), el = now - sim->wall_start;
    int tty = isatty(STDERR_FILENO);
    if (!final && now - sim->last_progress < (tty ? 0.2 : 10.0))
        return;
    sim->last_progress = now;
    double frac = sim->t / sim->scene->duration;
    double eta = frac > 0 ? el * (1 - frac) / frac : 0;
    int nf, n = alive_fragments(sim, &nf);
    const char *mode = nf ? "fracture" : "rigid";
    if (tty) {
        char bar[31];
        int fill = (int)(30 * frac);
        for (int i = 0; i < 30; i++)
            bar[i] = i < fill ? '#' : '.';
        bar[30] = 0;
        fprintf(stderr, "\r[%s] t=%.4f/%.4g s  %-8s  fragments %d  cohesive %d  ETA %.0f s   ",
                bar, sim->t, sim->scene->duration, mode, n, sim->solid.n_coh, eta);
        if (final)
            fputc('\n', stderr);
    } else {
        fprintf(stderr, "t=%.4f/%.4g s (%3.0f%%)  %s  fragments %d  cohesive %d  ETA %.0f s\n",
                sim->t, sim->scene->duration, 100 * frac, mode, n, sim->solid.n_coh, eta);
    }
}

/* Divergence: a non-finite position or a node faster than 1e5 m/s. */
static int nodes_sane(const cf_solid *s, const cf_fragment *f)
{
    for (int i = 0; i < f->nodes.n; i++) {
        const double *x = &s->x[3 * f->nodes.v[i]], *v = &s->v[3 * f->nodes.v[i]];
        if (!isfinite(x[0] + x[1] + x[2]) || !(v3_dot(v, v) < 1e10))
            return 0;
    }
    return 1;
}

/* A fragment with no uncracked interior facet (a single tet, say) cannot
 * break further: an impact leaves it in rigid mode. */
static int can_break(const cf_sim *sim, const cf_fragment *f)
{
    const cf_solid *s = &sim->solid;
    if (sim->scene->solver.criterion == CF_CRITERION_NONE)
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
static int impact(const cf_sim *sim, const cf_fragment *f)
{
    double dv = (cfb_contact_impulse(sim->bullet, f->body) + f->pushed) / f->mass;
    return dv > sim->scene->solver.impact_threshold && can_break(sim, f);
}

/* One Bullet step.  Fragments hit harder than the impact threshold go to
 * fracture mode from their state at the start of the step; the step is
 * then re-run from that start for every other body, so that none keeps the
 * contact response of a fragment that is now sub-cycled instead (momentum is
 * exchanged with it through its nodes). */
static cf_status bullet_step(cf_sim *sim, double dt, cf_error *err)
{
    const cf_solver_settings *set = &sim->scene->solver;
    int n = sim->n_frag, no = sim->scene->n_obstacles;
    cfb_state *pre = malloc((size_t)(n + no) * sizeof *pre), *pre_obs = pre + n;
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
        double t0 = cf_wall_time();
        cfb_step(sim->bullet, dt, set->rigid_substeps);
        sim->prof.rigid += cf_wall_time() - t0;
        int hit = 0;
        for (int fi = 0; fi < n && st == CF_OK; fi++) {
            cf_fragment *f = &sim->frag[fi];
            if (f->mode != CF_MODE_RIGID || f->body < 0 || !impact(sim, f))
                continue;
            double th = cf_wall_time();
            st = cf_handoff_to_fracture(sim, fi, &pre[fi], err);
            sim->prof.handoff += cf_wall_time() - th;
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
    free(pre);
    sim->steps_rigid++;
    return st;
}

/* Advance the rigid fragments by one rigid step; detect impacts. */
static cf_status rigid_step(cf_sim *sim, double dt, cf_error *err)
{
    if (sim->bullet)
        return bullet_step(sim, dt, err);
    double t0 = cf_wall_time();
    for (int fi = 0; fi < sim->n_frag; fi++) {
        if (sim->frag[fi].mode != CF_MODE_RIGID)
            continue;
        if (cf_pbd_impact(sim, fi, dt) && can_break(sim, &sim->frag[fi])) {
            cf_status st = cf_handoff_to_fracture(sim, fi, NULL, err);
            if (st != CF_OK)
                return st;
            continue;
        }
        if (cf_solver_step(sim, fi, sim->t, dt, 0) != CF_OK)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory in the pbd rigid step");
    }
    sim->steps_rigid++;
    sim->prof.rigid += cf_wall_time() - t0;
    return CF_OK;
}

static cf_status diverged(const cf_sim *sim, cf_error *err, const char *what)
{
    const cf_solver_settings *set = &sim->scene->solver;
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
static double contact_pad(const cf_sim *sim, int fi, double dt)
{
    const cf_fragment *f = &sim->frag[fi];
    double v2 = 0;
    for (int i = 0; i < f->nodes.n; i++) {
        const double *v = &sim->solid.v[3 * f->nodes.v[i]];
        v2 = fmax(v2, v3_dot(v, v));
    }
    return dt * (sqrt(v2) + dt * v3_norm(sim->scene->gravity));
}

/* Sub-cycle every fracture-mode fragment through the rigid step, all of
 * them in step so that fragments of different bodies meet in contact after
 * each sub-step. */
static cf_status fracture_steps(cf_sim *sim, double dt, cf_error *err)
{
    const cf_solver_settings *set = &sim->scene->solver;
    long n_sub = lround(ceil(dt / sim->dt_fracture - 1e-9)); /* h <= dt_fracture */
    if (n_sub < 1)
        n_sub = 1;
    double h = dt / (double)n_sub;
    int n = sim->n_frag, boxed = 0; /* the rigid bodies' boxes are taken once */
    int bodies = cf_body_contact_needed(sim);
    for (int fi = 0; fi < n; fi++) {
        cf_fragment *f = &sim->frag[fi];
        if (f->mode == CF_MODE_FRACTURE &&
            ((!boxed++ && cf_body_boxes(sim, &sim->body_boxes)) ||
             cf_hull_set_gather(sim, fi, contact_pad(sim, fi, dt), sim->body_boxes, &f->near)))
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory gathering contact hulls");
    }
    for (long k = 0; k < n_sub; k++) {
        for (int fi = 0; fi < n; fi++) {
            if (sim->frag[fi].mode != CF_MODE_FRACTURE)
                continue;
            if (cf_solver_step(sim, fi, sim->t + (double)k * h, h, 1) != CF_OK)
                return cf_error_set(err, CF_ERR_NOMEM, "out of memory in fracture mode");
            sim->steps_fracture++;
        }
        if (bodies) {
            double removed, t0 = cf_wall_time();
            if (cf_body_contact(sim, h, &removed))
                return cf_error_set(err, CF_ERR_NOMEM, "contact between bodies failed: %s",
                                    cff_last_error());
            sim->flow.contact += removed;
            sim->prof.bodies += cf_wall_time() - t0;
        }
    }
    for (int fi = 0; fi < n; fi++) {
        cf_fragment *f = &sim->frag[fi];
        if (f->mode != CF_MODE_FRACTURE)
            continue;
        sim->flow.contact -= cf_node_impulses_flush(sim, &f->push, f->nodes.v);
        f->near.n = 0;
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
        int root = cf_fragment_root(sim, fi), inv = 0, nt = 0;
        for (int g = 0; f->n_inverted > 0 && g < n; g++)
            if (sim->frag[g].mode == CF_MODE_FRACTURE && cf_fragment_root(sim, g) == root)
                inv += sim->frag[g].n_inverted, nt += sim->frag[g].nt;
        if (inv > set->max_inverted_fraction * nt) {
            snprintf(what, sizeof what,
                     "fragment %d diverged: %d of the %d tets of its body in fracture mode are "
                     "inverted (more than solver.guard.max_inverted_fraction = %g)",
                     fi, inv, nt, set->max_inverted_fraction);
            return diverged(sim, err, what);
        }
    }
    return CF_OK;
}

/* Energy growth with no work input: kinetic + strain + cohesive energy
 * above (1 + max_energy_growth) times what was put in. */
static cf_status check_energy(cf_sim *sim, cf_error *err)
{
    cf_ledger l;
    cf_sim_ledger(sim, &l);
    double have = l.kinetic + l.strain + l.cohesive_stored + l.cohesive_dissipated;
    double input = l.initial + fmax(0.0, l.work_gravity) + fmax(0.0, l.work_boundary) +
                   fmax(0.0, l.work_obstacles);
    if (have <= (1 + sim->scene->solver.max_energy_growth) * input + 1e-12)
        return CF_OK;
    char what[200];
    snprintf(what, sizeof what,
             "energy grew with no work input: %.4g J against %.4g J put in (more than "
             "solver.guard.max_energy_growth = %g)",
             have, input, sim->scene->solver.max_energy_growth);
    return diverged(sim, err, what);
}

/* Fracture-mode fragments that have been quiet long enough go back to rigid mode. */
static cf_status return_to_rigid(cf_sim *sim, cf_error *err)
{
    const cf_solver_settings *set = &sim->scene->solver;
    int n = sim->n_frag;
    for (int fi = 0; fi < n; fi++) {
        cf_fragment *f = &sim->frag[fi];
        if (f->mode != CF_MODE_FRACTURE)
            continue;
        if (f->quiet < set->quiet_steps && sim->t - f->t_enter < set->max_fracture_time - 1e-12)
            continue;
        int first_new = sim->n_frag;
        double th = cf_wall_time();
        cf_status st = cf_handoff_to_rigid(sim, fi, err);
        sim->prof.handoff += cf_wall_time() - th;
        if (st == CF_OK)
            st = write_fragment_infos(sim, first_new, err);
        if (st != CF_OK)
            return st;
    }
    return CF_OK;
}

/* Fracture-only runs: fragments that cracked in this step and now fall
 * apart become one fragment per connected piece, labelled and written like
 * the pieces of a hybrid run's hand-off. */
static cf_status split_fragments(cf_sim *sim, cf_error *err)
{
    int n = sim->n_frag;
    for (int fi = 0; fi < n; fi++) {
        if (sim->frag[fi].mode != CF_MODE_FRACTURE || !sim->frag[fi].cracked)
            continue;
        int first = sim->n_frag;
        double th = cf_wall_time();
        int k = cf_fragment_split_fracture(sim, fi, &first);
        sim->prof.handoff += cf_wall_time() - th;
        if (k < 0)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory splitting fragment %d", fi);
        if (k > 0) {
            cf_status st = write_fragment_infos(sim, first, err);
            if (st != CF_OK)
                return st;
        }
    }
    return CF_OK;
}

int cf_sim_done(const cf_sim *sim) { return sim->step >= sim->n_steps; }

double cf_sim_time(const cf_sim *sim) { return sim->t; }

double cf_sim_dt_fracture(const cf_sim *sim) { return sim->dt_fracture; }

double cf_sim_dt_cfl(const cf_sim *sim) { return sim->solid.dt_cfl; }

cf_status cf_sim_advance(cf_sim *sim, cf_error *err)
{
    const cf_scene *sc = sim->scene;
    double dt = sim->dt_outer;
    cf_status st = rigid_step(sim, dt, err);
    if (st == CF_OK)
        st = fracture_steps(sim, dt, err);
    sim->step++;
    sim->t = (double)sim->step * dt;
    if (st == CF_OK && sc->solver.mode == CF_RUN_HYBRID)
        st = return_to_rigid(sim, err);
    if (st == CF_OK && sc->solver.mode == CF_RUN_FRACTURE)
        st = split_fragments(sim, err);
    if (st == CF_OK)
        st = check_energy(sim, err);
    if (st == CF_OK && (sim->t >= sim->next_frame - 1e-9 * dt || cf_sim_done(sim))) {
        st = write_frame(sim, err);
        while (sim->next_frame <= sim->t + 1e-9 * dt)
            sim->next_frame += sc->output.frame_interval;
    }
    progress(sim, 0);
    return st;
}

cf_status cf_sim_run(cf_sim *sim, cf_error *err)
{
    const cf_scene *sc = sim->scene;
    if (sim->opt.progress)
        fprintf(stderr, "cohfrac: %d nodes, %d tets, %d fragment(s); dt_cfl = %.4g s, "
                        "dt_fracture/dt_cfl = %.4g, dt_rigid/dt_cfl = %.4g\n",
                sim->solid.n_nodes, sim->solid.n_tets, sim->n_frag, sim->solid.dt_cfl,
                sim->dt_fracture / sim->solid.dt_cfl, sim->dt_outer / sim->solid.dt_cfl);
    cf_status st = write_frame(sim, err);
    sim->next_frame = sc->output.frame_interval;
    while (st == CF_OK && !cf_sim_done(sim))
        st = cf_sim_advance(sim, err);
    progress(sim, 1);
    cf_error cerr;
    if (sim->h5 && cf_h5_close(sim->h5, &cerr) != CF_OK && st == CF_OK) {
        *err = cerr;
        st = cerr.code;
    }
    sim->h5 = NULL;
    return st;
}

uint64_t cf_sim_state_hash(const cf_sim *sim)
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

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Convex decomposition of the rigid fragments alive now: hull-volume error
 * median and worst, and its share of the wall time. */
static void print_hull_summary(const cf_sim *sim, FILE *out, double wall)
{
    double *e = malloc((size_t)(sim->n_frag + 1) * sizeof(double));
    int n = 0, hulls = 0;
    for (int fi = 0; e && fi < sim->n_frag; fi++) {
        const cf_fragment *f = &sim->frag[fi];
        if (f->mode == CF_MODE_RIGID && f->body >= 0) {
            e[n++] = cf_hulls_error(&f->hulls);
            hulls += f->hulls.n_hulls;
        }
    }
    if (n > 0) {
        qsort(e, (size_t)n, sizeof *e, by_value);
        double median = n % 2 ? e[n / 2] : 0.5 * (e[n / 2 - 1] + e[n / 2]);
        fprintf(out, "convex hulls       %d over %d rigid fragments; hull volume / tet volume - 1: "
                     "median %.3g, worst %.3g; decomposition %.2f s (%.1f%% of wall time)\n",
                hulls, n, median, e[n - 1], sim->prof.decompose,
                100 * sim->prof.decompose / fmax(wall, 1e-300));
    }
    free(e);
}

void cf_sim_memory(const cf_sim *sim, cf_memory *m)
{
    const cf_solid *s = &sim->solid;
    const unsigned long long D = sizeof(double), I = sizeof(int);
    unsigned long long cn = (unsigned long long)s->cap_nodes, nt = (unsigned long long)s->n_tets;
    memset(m, 0, sizeof *m);
    m->solid = cn * (16 * D + 2 * I) + nt * (27 * D + 9 * I) +
               ((unsigned long long)s->n_verts0 + 1 + 4 * nt) * I;
    if (s->facet)
        m->fracture = nt * (9 * D + 1 + 20 * I) + cn * (1 + D) +
                      (unsigned long long)s->n_facets * (1 + (s->candidate != NULL));
    m->cohesive = (unsigned long long)s->cap_coh * sizeof(cf_cohesive);
    m->fragments = (unsigned long long)sim->cap_frag * sizeof(cf_fragment);
    for (int i = 0; i < sim->n_frag; i++) {
        const cf_fragment *f = &sim->frag[i];
        m->fragments += (unsigned long long)f->nt * I + (unsigned long long)f->nodes.cap * I +
                        (unsigned long long)f->coh.cap * I +
                        (unsigned long long)f->bars.n * (2 * I + 3 * D) +
                        (unsigned long long)f->scratch_cap * (I + 5 * D + I + 6 * D);
        if (f->hulls.n_hulls)
            m->fragments += (unsigned long long)f->hulls.start[f->hulls.n_hulls] * 3 * D +
                            ((unsigned long long)f->hulls.n_hulls + 1) * I;
    }
    unsigned long long b = cfb_allocated_bytes();
    m->bullet = b > sim->bullet_base ? b - sim->bullet_base : 0;
    for (int j = 0; sim->obs.mesh && j < sim->obs.n; j++)
        m->collision += cff_mesh_bytes(sim->obs.mesh[j]);
    for (int i = 0; i < sim->n_frag; i++) {
        const cf_frag_surface *fs = &sim->frag[i].surface;
        m->collision += cff_mesh_bytes(fs->mesh) +
                        (unsigned long long)fs->nv * (I + 3 * D) + 3ull * fs->ntri * I;
    }
    m->output = sim->output_peak;
}

void cf_sim_step_stats(const cf_sim *sim, cf_step_stats *o)
{
    const cf_solver_settings *set = &sim->scene->solver;
    memset(o, 0, sizeof *o);
    o->fracture_steps = sim->steps_fracture;
    o->stress = sim->prof.stress, o->insertion = sim->prof.insertion;
    o->forces = sim->prof.forces, o->pbd = sim->prof.pbd;
    for (int i = 0; i < sim->n_frag; i++) {
        const cf_fragment *f = &sim->frag[i];
        if (f->mode != CF_MODE_FRACTURE)
            continue;
        o->tets += f->nt, o->nodes += f->nodes.n, o->bars += f->bars.n, o->cohesive += f->coh.n;
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

static void print_memory(const cf_sim *sim, FILE *out)
{
    cf_memory m;
    cf_sim_memory(sim, &m);
    const struct {
        const char *name;
        unsigned long long bytes;
    } part[] = {{"solid", m.solid},       {"fracture state", m.fracture},
                {"cohesive", m.cohesive}, {"fragments", m.fragments},
                {"Bullet world", m.bullet}, {"FCL meshes", m.collision},
                {"HDF5 output", m.output}};
    fprintf(out, "memory (MiB)      ");
    for (size_t i = 0; i < sizeof part / sizeof part[0]; i++) {
        fprintf(out, "%s%s ", i ? " | " : "", part[i].name);
        if (part[i].bytes)
            fprintf(out, "%.3g", part[i].bytes / 1048576.0);
        else
            fputs("none", out);
    }
    fputc('\n', out);
}

void cf_sim_print_summary(const cf_sim *sim, FILE *out)
{
    const cf_scene *sc = sim->scene;
    const cf_profile *p = &sim->prof;
    int nf, n = alive_fragments(sim, &nf);
    double wall = cf_wall_time() - sim->wall_start;
    fprintf(out, "\n== cohfrac summary: %s ==\n", sc->name);
    static const char *constraints[] = {"pbd", "xpbd", "none"};
    fprintf(out, "simulated time     %.4g s in %ld rigid steps (dt_rigid %.3g s, backend %s)\n",
            sim->t, sim->step, sim->dt_outer,
            sc->solver.mode == CF_RUN_FRACTURE ? "none: fracture mode only"
            : sc->solver.rigid_backend == CF_RIGID_BULLET ? "bullet" : "pbd");
    fprintf(out, "constraints        %s\n", constraints[sc->solver.constraints]);
    fprintf(out, "mesh               %d tets, %d nodes (%d after duplication)\n",
            sim->solid.n_tets, sim->solid.n_verts0, sim->solid.n_nodes);
    fprintf(out, "time step          dt_fracture %.3g s = %.4g dt_cfl (dt_cfl %.4g s)\n",
            sim->dt_fracture, sim->dt_fracture / sim->solid.dt_cfl, sim->solid.dt_cfl);
    fprintf(out, "steps per mode     rigid %ld, fracture %ld (threads %d)\n", sim->steps_rigid,
            sim->steps_fracture, omp_get_max_threads());
    fprintf(out, "fragments          %d alive (%d in fracture mode), %d ever\n", n, nf,
            sim->n_frag);
    fprintf(out, "cohesive elements  %d\n", sim->solid.n_coh);
    fprintf(out, "hand-offs          %d, max linear momentum error %.3g (relative), "
                 "handoff_loss %.4g J\n",
            sim->n_handoffs, sim->max_momentum_error, sim->total_handoff_loss);
    print_hull_summary(sim, out, wall);
    print_memory(sim, out);
    double staged = p->rigid + p->stress + p->insertion + p->forces + p->pbd + p->bodies +
                    p->handoff + p->output;
    cf_ledger l;
    cf_sim_ledger(sim, &l);
    double scale = fmax(fabs(l.initial) + fabs(l.work_gravity) + fabs(l.work_boundary) +
                            fabs(l.work_obstacles), 1e-300);
    fprintf(out, "energy ledger (J)  kinetic %.6g | strain %.6g | cohesive stored %.6g | "
                 "cohesive dissipated %.6g\n",
            l.kinetic, l.strain, l.cohesive_stored, l.cohesive_dissipated);
    fprintf(out, "                   initial %.6g | work: gravity %.6g, boundary %.6g, "
                 "moving obstacles %.6g\n",
            l.initial, l.work_gravity, l.work_boundary, l.work_obstacles);
    fprintf(out, "                   removed: contact %.6g, PBD %.6g, damping %.6g, hand-off %.6g, "
                 "rigid integration %.6g\n",
            l.contact, l.pbd, l.damping, l.handoff, l.integration);
    fprintf(out, "                   residual %.4g J = %.3g of initial + work\n", l.residual,
            l.residual / scale);
    fprintf(out, "momentum           P = (%.6g, %.6g, %.6g) kg m/s, L = (%.6g, %.6g, %.6g) kg m^2/s\n",
            l.momentum[0], l.momentum[1], l.momentum[2], l.angular_momentum[0],
            l.angular_momentum[1], l.angular_momentum[2]);
    fprintf(out, "state hash         %016llx (FNV-1a of the final state)\n",
            (unsigned long long)cf_sim_state_hash(sim));
    fprintf(out, "wall time          %.2f s\n", wall);
    fprintf(out, "  rigid step %.2f s | stress %.2f s | insertion %.2f s | forces %.2f s | "
                 "PBD %.2f s | contact between bodies %.2f s | hand-off %.2f s | output %.2f s | "
                 "other %.2f s\n",
            p->rigid, p->stress, p->insertion, p->forces, p->pbd, p->bodies, p->handoff,
            p->output, wall - staged);
    if (sim->steps_fracture > 0)
        fprintf(out, "per fracture step  %.3f ms\n",
                1e3 * (p->stress + p->insertion + p->forces + p->pbd) / (double)sim->steps_fracture);
    if (sc->output.file[0])
        fprintf(out, "output             %s\n", sc->output.file);
}
