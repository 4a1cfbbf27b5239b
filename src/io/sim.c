/* The run loop: a world stepped to its duration, its events turned into
 * HDF5 rows and progress lines, a frame every output.frame_interval. */
#include "cohfrac/sim.h"

#include "clock.h"
#include "eta.h"
#include "cohfrac/h5_output.h"
#include "cohfrac/scene.h"
#include "cohfrac/surface.h"
#include "visual.h"

#include <dirent.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* A triangle's three node indices, ascending (a face seen from either side). */
typedef struct face_key {
    int v[3];
} face_key;

static int face_cmp(const void *a, const void *b)
{
    const int *x = ((const face_key *)a)->v, *y = ((const face_key *)b)->v;
    for (int k = 0; k < 3; k++)
        if (x[k] != y[k])
            return (x[k] > y[k]) - (x[k] < y[k]);
    return 0;
}

static face_key key_of(const int *tri)
{
    face_key k = {{tri[0], tri[1], tri[2]}};
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2 - i; j++)
            if (k.v[j] > k.v[j + 1]) {
                int t = k.v[j];
                k.v[j] = k.v[j + 1], k.v[j + 1] = t;
            }
    return k;
}

struct cf_sim {
    cf_world *world;
    cf_world_meshes meshes;
    cf_run_options opt;
    char name[128];
    double duration;            /* s */
    long n_steps;               /* rigid steps the duration needs (the last may be cut) */
    cf_output_settings output;
    cf_h5 *h5;                  /* NULL when no output is asked for */
    double next_frame;          /* s */
    double wall_start;          /* s, wall clock at create */
    double loop_start;          /* s, wall clock at the first step */
    double last_progress;       /* s, wall clock of the last progress display */
    double t_inner;             /* s, simulated time reached inside the current step */
    int bar_shown;              /* a progress bar is on the terminal's last line */
    double output_time;         /* s of wall time writing the file */
    double frame_time;          /* s of it writing frames (write_frame), for the ETA */
    cf_eta eta;                 /* the run sampled for the ETA (eta.h) */
    double last_sample;         /* s, wall clock of its last sample */
    unsigned long long output_peak; /* largest HDF5 metadata cache seen at a frame, bytes */
    /* Geometry output (docs/output.md): the rest tets (input order), the
     * rest mesh's own boundary faces (sorted keys: a fragment face not
     * among them is a crack face), the tet -> fragment map, and whether it
     * changed since the last frame. */
    int n_tets;
    int *rest_tets;             /* [n_tets][4] */
    face_key *outer;            /* [n_outer] sorted */
    int n_outer;
    int *tet_frag;              /* [n_tets] */
    int topology_changed;
    long frames_written;
    /* Threads on a shared host (docs/performance.md): with the default
     * count, the element loops use the cores other processes leave free. */
    int threads_max;            /* the count at create; 0: the user chose it, fixed */
    int threads_now, threads_least;
    double busy;                /* other processes' runnable tasks, smoothed */
    double last_balance;        /* s, wall clock of the last look at the host */
};

cf_world *cf_sim_world(const cf_sim *sim) { return sim->world; }

int cf_sim_done(const cf_sim *sim) { return cf_world_step_count(sim->world) >= sim->n_steps; }

static int tty(void) { return isatty(STDERR_FILENO); }

/* A line above the progress bar (the bar is redrawn at the next update). */
static void event_line(cf_sim *sim, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void event_line(cf_sim *sim, const char *fmt, ...)
{
    if (!sim->opt.progress)
        return;
    if (sim->bar_shown)
        fputs("\r\033[K", stderr);
    sim->bar_shown = 0;
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    sim->last_progress = 0; /* redraw the bar at once */
}

/* The boundary triangles of fragments first .. first + n - 1 (their rest
 * shapes, outward), crack faces marked, appended to /surfaces; each
 * fragment's rows into its record. */
static cf_status write_surfaces(cf_sim *sim, cf_frag_info *info, int first, int n, cf_error *err)
{
    int nt = sim->n_tets;
    for (int t = 0; t < nt; t++)
        sim->tet_frag[t] = cf_world_tet_fragment(sim->world, t);
    sim->topology_changed = 1;
    /* Bucket the new fragments' tets: start[k] .. start[k + 1] in list. */
    int *start = calloc((size_t)n + 1, sizeof(int)), *list = malloc(((size_t)nt + 1) * sizeof(int));
    int *faces = malloc(((size_t)nt * 12 + 1) * sizeof(int)), *crack = malloc(((size_t)nt * 4 + 1) * sizeof(int));
    cf_status st = start && list && faces && crack ? CF_OK
                                                    : cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    for (int t = 0; st == CF_OK && t < nt; t++) {
        int k = sim->tet_frag[t] - first;
        if (k >= 0 && k < n)
            start[k + 1]++;
    }
    for (int k = 0; st == CF_OK && k < n; k++)
        start[k + 1] += start[k];
    int *fill = st == CF_OK ? calloc((size_t)n + 1, sizeof(int)) : NULL;
    if (st == CF_OK && !fill)
        st = cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    for (int t = 0; st == CF_OK && t < nt; t++) {
        int k = sim->tet_frag[t] - first;
        if (k >= 0 && k < n)
            list[start[k] + fill[k]++] = t;
    }
    for (int k = 0; st == CF_OK && k < n; k++) {
        int m = cf_boundary_faces(sim->rest_tets, &list[start[k]], start[k + 1] - start[k], faces);
        if (m < 0) {
            st = cf_error_set(err, CF_ERR_NOMEM, "out of memory");
            break;
        }
        for (int i = 0; i < m; i++) {
            face_key key = key_of(&faces[3 * i]);
            crack[i] = !bsearch(&key, sim->outer, (size_t)sim->n_outer, sizeof key, face_cmp);
        }
        st = cf_h5_add_surfaces(sim->h5, faces, crack, m, &info[k].surface_first, err);
        info[k].surface_count = m;
    }
    free(start), free(list), free(faces), free(crack), free(fill);
    return st;
}

/* The rest mesh into the file, and what the surfaces need of it. */
static cf_status write_rest_mesh(cf_sim *sim, const cf_scene *sc, cf_error *err)
{
    cf_world *w = sim->world;
    int nn = cf_world_rest_node_count(w), nt = cf_world_tet_count(w);
    sim->n_tets = nt;
    sim->rest_tets = malloc(((size_t)nt * 4 + 1) * sizeof(int));
    sim->tet_frag = malloc(((size_t)nt + 1) * sizeof(int));
    sim->outer = malloc(((size_t)nt * 4 + 1) * sizeof(face_key));
    double *X = malloc(((size_t)nn * 3 + 1) * sizeof(double));
    int *faces = malloc(((size_t)nt * 12 + 1) * sizeof(int));
    cf_status st = sim->rest_tets && sim->tet_frag && sim->outer && X && faces
                       ? CF_OK
                       : cf_error_set(err, CF_ERR_NOMEM, "out of memory for the rest mesh");
    if (st == CF_OK) {
        cf_world_rest_nodes(w, X);
        for (int t = 0; t < nt; t++)
            cf_world_rest_tet(w, t, &sim->rest_tets[4 * t]);
        int m = cf_boundary_faces(sim->rest_tets, NULL, nt, faces);
        if (m < 0)
            st = cf_error_set(err, CF_ERR_NOMEM, "out of memory for the rest mesh");
        for (int i = 0; i < m; i++)
            sim->outer[i] = key_of(&faces[3 * i]);
        sim->n_outer = m > 0 ? m : 0;
        qsort(sim->outer, (size_t)sim->n_outer, sizeof *sim->outer, face_cmp);
    }
    if (st == CF_OK)
        st = cf_h5_write_rest_mesh(sim->h5, X, nn, sim->rest_tets, nt, err);
    cf_visual vis = {0}; /* the bodies' finer surfaces, riding on the rest tets */
    cf_world_stats ws;
    cf_world_stats_get(w, &ws);
    if (st == CF_OK)
        st = cf_visual_embed(&sc->world, sc->sources, &sim->meshes, X, nn, sim->rest_tets, nt,
                             ws.threads, &vis, err);
    if (st == CF_OK && vis.n_triangles > 0)
        st = cf_h5_write_visual(sim->h5, vis.vertices, vis.n_vertices, vis.triangles, vis.tet,
                                vis.n_triangles, err);
    cf_visual_free(&vis);
    free(X), free(faces);
    return st;
}

/* Fragment records, hand-off rows and event lines for what the world did. */
static cf_status drain_events(cf_sim *sim, cf_error *err)
{
    int n;
    const cf_event *ev = cf_world_events(sim->world, &n);
    cf_status st = CF_OK;
    for (int i = 0; i < n && st == CF_OK; i++) {
        const cf_event *e = &ev[i];
        if (e->type == CF_EVENT_FRAGMENTS && sim->h5) {
            cf_frag_info *info = calloc((size_t)e->count, sizeof *info);
            if (!info)
                return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
            for (int k = 0; k < e->count; k++)
                cf_world_fragment_info(sim->world, e->first + k, &info[k]);
            double t0 = cf_wall_time();
            st = write_surfaces(sim, info, e->first, e->count, err);
            sim->output_time += cf_wall_time() - t0;
            if (st == CF_OK)
                st = cf_h5_add_fragments(sim->h5, info, e->count, err);
            free(info);
        } else if (e->type == CF_EVENT_HANDOFF) {
            const cf_handoff_record *r = &e->handoff;
            event_line(sim,
                       "hand-off t=%.4f s: fragment %d %s, linear momentum error %.2e, "
                       "handoff_loss %.4g J, %d fragments alive",
                       r->time, r->fragment, r->direction ? "fracture -> rigid" : "rigid -> fracture",
                       r->momentum_error, r->handoff_loss, e->alive);
            if (sim->h5)
                st = cf_h5_add_handoff(sim->h5, r, err);
        }
    }
    cf_world_clear_events(sim->world);
    return st;
}

/* The obstacles, for readers that draw them (python/cohfrac/render.py):
 * /parameters/obstacle_{type (0 plane, 1 sphere, 2 box, 3 mesh), point,
 * normal, center (at t = 0), radius, half_extents, velocity}. */
static cf_status write_obstacles(cf_sim *sim, cf_error *err)
{
    const cf_world_def *d = cf_world_definition(sim->world);
    int n = d->n_obstacles;
    if (n == 0)
        return CF_OK;
    double *buf = malloc((size_t)n * 3 * 7 * sizeof(double));
    if (!buf)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    double *type = buf, *radius = buf + n, *vec = buf + 2 * n;
    static const char *const names[] = {"point", "normal", "center", "half_extents", "velocity"};
    for (int j = 0; j < n; j++) {
        const cf_obstacle *o = &d->obstacles[j];
        const double *v[] = {o->point, o->normal, o->center, o->half_extents, o->velocity};
        type[j] = o->type, radius[j] = o->radius;
        for (int q = 0; q < 5; q++)
            memcpy(&vec[3 * (q * n + j)], v[q], 3 * sizeof(double));
    }
    cf_status st = cf_h5_write_parameter(sim->h5, "obstacle_type", type, n, NULL, err);
    if (st == CF_OK)
        st = cf_h5_write_parameter(sim->h5, "obstacle_radius", radius, n, "m", err);
    for (int q = 0; q < 5 && st == CF_OK; q++) {
        char name[64];
        snprintf(name, sizeof name, "obstacle_%s", names[q]);
        st = cf_h5_write_parameter(sim->h5, name, &vec[3 * q * n], 3 * n,
                                   q == 1 ? NULL : q == 4 ? "m s-1" : "m", err);
    }
    free(buf);
    return st;
}

/* What a reader needs to bound the run's outcome (tests/checks/check_physics.py). */
static cf_status write_initial_bounds(cf_sim *sim, cf_error *err)
{
    cf_initial_bounds b;
    cf_world_initial_bounds(sim->world, &b);
    const struct {
        const char *name;
        const double *v;
        int n;
        const char *unit;
    } p[] = {{"initial_lower", b.lower, 3, "m"},
             {"initial_upper", b.upper, 3, "m"},
             {"total_mass", &b.mass, 1, "kg"},
             {"initial_energy", &b.energy, 1, "J"},
             {"max_initial_speed", &b.max_speed, 1, "m s-1"},
             {"max_obstacle_speed", &b.max_obstacle_speed, 1, "m s-1"},
             {"release_speed", &b.release_speed, 1, "m s-1"}};
    cf_status st = CF_OK;
    for (size_t i = 0; i < sizeof p / sizeof p[0] && st == CF_OK; i++)
        st = cf_h5_write_parameter(sim->h5, p[i].name, p[i].v, p[i].n, p[i].unit, err);
    return st == CF_OK ? write_obstacles(sim, err) : st;
}

/* Close the output after `err` ended the run.  A close that fails too
 * (HDF5 out of memory part way through writing its metadata) adds its own
 * message, which says when the file may not open. */
static void close_after_error(cf_sim *sim, cf_error *err)
{
    cf_error cerr;
    if (sim->h5 && cf_h5_close(sim->h5, &cerr) != CF_OK && err) {
        size_t n = strlen(err->msg);
        snprintf(err->msg + n, sizeof err->msg - n, "; then closing it: %s", cerr.msg);
    }
    sim->h5 = NULL;
}

static void tick(void *user, double t);

cf_status cf_sim_create(const cf_scene *sc, const cf_run_options *opt, cf_sim **out,
                        cf_error *err)
{
    *out = NULL;
    cf_status st = cf_scene_check(sc, err);
    if (st != CF_OK)
        return st;
    const cf_world_def *def = &sc->world;
    cf_sim *sim = calloc(1, sizeof *sim);
    if (!sim)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    sim->opt = *opt;
    sim->wall_start = cf_wall_time();
    snprintf(sim->name, sizeof sim->name, "%s", sc->name);
    sim->duration = sc->duration;
    sim->output = sc->output;
    /* The world reads a copy whose meshes point at what mesh preparation made. */
    cf_world_def w = *def;
    size_t nb = (size_t)def->n_bodies, no = (size_t)def->n_obstacles;
    w.bodies = malloc((nb + 1) * sizeof *w.bodies);
    w.obstacles = malloc((no + 1) * sizeof *w.obstacles);
    st = w.bodies && w.obstacles ? CF_OK : cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    if (st == CF_OK) {
        if (nb) /* (a definition without obstacles may hold a NULL list) */
            memcpy(w.bodies, def->bodies, nb * sizeof *w.bodies);
        if (no)
            memcpy(w.obstacles, def->obstacles, no * sizeof *w.obstacles);
        if (opt->threads > 0)
            w.solver.threads = opt->threads;
    }
    /* The file first, with the scene in it: a run stopped during mesh
     * preparation or convex decomposition (minutes on a large mesh) still
     * leaves a readable file that says what was run. */
    struct stat out_stat;
    if (st == CF_OK && sc->output.file[0] && stat(sc->output.file, &out_stat) == 0 &&
        S_ISDIR(out_stat.st_mode))
        st = cf_error_set(err, CF_ERR_OUTPUT,
                          "cannot write the output to %s: it is a directory (give a file "
                          "in it, e.g. -o %s/%s.h5)",
                          sc->output.file, sc->output.file, sc->name);
    if (st == CF_OK && sc->output.file[0] && !opt->force &&
        access(sc->output.file, F_OK) == 0 && !cf_h5_is_output(sc->output.file))
        st = cf_error_set(err, CF_ERR_OUTPUT,
                          "refusing to overwrite %s: it is not a cohfrac output file (give "
                          "another output file, or --force to overwrite it)",
                          sc->output.file);
    if (st == CF_OK && sc->output.file[0])
        st = cf_h5_open(sc->output.file, sc->name, sc->resolved, &sim->h5, err);
    if (st == CF_OK)
        st = cf_world_meshes_load(&w, sc->sources, opt->mesh_dir, &sim->meshes, err);
    if (st == CF_OK)
        st = cf_world_create(&w, &sim->world, err);
    if (st == CF_OK) {
        cf_world_set_tick(sim->world, tick, sim);
        sim->n_steps = lround(ceil(sim->duration / cf_world_dt_outer(sim->world) - 1e-9));
        double dt = cf_world_dt_fracture(sim->world);
        cf_eta_rule rule = {dt, w.solver.quiet_steps * dt, w.solver.quiet_growth,
                            w.solver.max_fracture_time};
        cf_eta_init(&sim->eta, &rule);
    }
    if (st == CF_OK && w.solver.threads == 0) { /* the default: adapts to the host */
        cf_world_stats ws;
        cf_world_stats_get(sim->world, &ws);
        sim->threads_max = sim->threads_now = sim->threads_least = ws.threads;
    }
    free(w.bodies), free(w.obstacles);
    if (st == CF_OK && sim->h5) {
        st = write_initial_bounds(sim, err);
        double t0 = cf_wall_time();
        if (st == CF_OK)
            st = write_rest_mesh(sim, sc, err);
        sim->output_time += cf_wall_time() - t0;
    }
    if (st == CF_OK)
        st = drain_events(sim, err);
    if (st != CF_OK) {
        close_after_error(sim, err);
        cf_sim_destroy(sim);
        return st;
    }
    *out = sim;
    return CF_OK;
}

cf_status cf_sim_create_text(const char *name, const char *text, const char *const *overrides,
                             int n_overrides, const cf_run_options *opt, cf_sim **out,
                             cf_error *err)
{
    *out = NULL;
    const char *mesh_dir = opt && opt->mesh_dir ? opt->mesh_dir : cf_default_mesh_dir();
    cf_scene sc;
    cf_status st = cf_scene_load_text(name, text, overrides, n_overrides, mesh_dir, &sc, err);
    if (st != CF_OK)
        return st;
    st = cf_sim_create(&sc, opt, out, err);
    cf_scene_free(&sc);
    return st;
}

void cf_sim_destroy(cf_sim *sim)
{
    if (!sim)
        return;
    if (sim->h5)
        cf_h5_close(sim->h5, NULL);
    cf_world_destroy(sim->world);
    cf_world_meshes_free(&sim->meshes);
    free(sim->rest_tets), free(sim->outer), free(sim->tet_frag);
    free(sim);
}

static cf_status write_cracks(cf_sim *sim, cf_error *err)
{
    int n = cf_world_cohesive_count(sim->world);
    cf_crack_row *rows = malloc((size_t)(n > 0 ? n : 1) * sizeof *rows);
    if (!rows)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory writing %d crack rows", n);
    for (int e = 0; e < n; e++)
        cf_world_crack(sim->world, e, &rows[e]);
    cf_status st = cf_h5_add_cracks(sim->h5, rows, n, err);
    free(rows);
    return st;
}

/* The tets of fracture-mode fragments as they are now: deformed corners,
 * stress and damage (/fracture_mode), for the viewers. */
static cf_status write_fracture_tets(cf_sim *sim, double time, cf_error *err)
{
    cf_world *w = sim->world;
    int nt = cf_world_tet_count(w), n;
    cf_status st;
    double *stress = malloc((size_t)nt * 6 * sizeof(double));
    double *damage = malloc((size_t)nt * sizeof(double));
    double *corners = malloc((size_t)nt * 12 * sizeof(double));
    int *tet = malloc((size_t)nt * sizeof(int));
    n = stress && damage && corners && tet ? cf_world_fracture_tets(w, tet, stress, damage) : -1;
    if (n < 0) {
        st = cf_error_set(err, CF_ERR_NOMEM, "out of memory writing the fracture-mode tets");
    } else {
        for (int k = 0; k < n; k++)
            cf_world_tet_positions(w, tet[k], &corners[12 * k]);
        st = cf_h5_add_fracture_tets(sim->h5, n, tet, corners, stress, damage, time, err);
    }
    free(stress), free(damage), free(corners), free(tet);
    return st;
}

static cf_status write_frame(cf_sim *sim, cf_error *err)
{
    if (!sim->h5)
        return CF_OK;
    double t0 = cf_wall_time();
    cf_world *w = sim->world;
    int cap = cf_world_fragments_ever(w);
    cf_fragment_state *fs = malloc((size_t)(cap > 0 ? cap : 1) * sizeof *fs);
    cf_frag_frame *fr = malloc((size_t)(cap > 0 ? cap : 1) * sizeof *fr);
    if (!fs || !fr) {
        free(fs), free(fr);
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory");
    }
    int n = cf_world_fragments(w, fs, cap), n_fracture = 0;
    for (int i = 0; i < n; i++) {
        cf_frag_frame *o = &fr[i];
        o->id = fs[i].id;
        o->mode = fs[i].mode;
        memcpy(o->com, fs[i].com, sizeof o->com);
        memcpy(o->quat, fs[i].quat, sizeof o->quat);
        memcpy(o->v, fs[i].v, sizeof o->v);
        memcpy(o->w, fs[i].w, sizeof o->w);
        n_fracture += fs[i].mode == 1;
    }
    double t = cf_world_time(w);
    long step = cf_world_step_count(w);
    cf_status st = CF_OK;
    unsigned long long mem = cf_h5_memory(sim->h5); /* as of the last frame */
    sim->output_peak = mem > sim->output_peak ? mem : sim->output_peak;
    cf_world_stats ws;
    cf_world_stats_get(w, &ws);
    cf_ledger l;
    cf_world_ledger(w, &l);
    const struct {
        const char *name, *unit;
        double value;
    } obs[] = {
        {"energy_kinetic", "J", l.kinetic},
        {"energy_strain", "J", l.strain},
        {"energy_cohesive_stored", "J", l.cohesive_stored},
        {"energy_cohesive_dissipated", "J", l.cohesive_dissipated},
        {"energy_plastic_dissipated", "J", l.plastic_dissipated},
        {"work_gravity", "J", l.work_gravity},
        {"work_boundary", "J", l.work_boundary},
        {"work_obstacles", "J", l.work_obstacles},
        {"energy_contact_removed", "J", l.contact},
        {"energy_rigid_integration_removed", "J", l.integration},
        {"energy_pbd_removed", "J", l.pbd},
        {"energy_damping_removed", "J", l.damping},
        {"energy_handoff_loss", "J", l.handoff},
        {"energy_residual", "J", l.residual},
        {"momentum_x", "kg m s-1", l.momentum[0]},
        {"momentum_y", "kg m s-1", l.momentum[1]},
        {"momentum_z", "kg m s-1", l.momentum[2]},
        {"angular_momentum_x", "kg m2 s-1", l.angular_momentum[0]},
        {"angular_momentum_y", "kg m2 s-1", l.angular_momentum[1]},
        {"angular_momentum_z", "kg m2 s-1", l.angular_momentum[2]},
        {"fragment_count", NULL, n},
        {"cohesive_elements", NULL, ws.cohesive},
        {"crack_area", "m2", cf_world_crack_area(w)},
        {"fragments_in_fracture_mode", NULL, n_fracture},
        {"handoff_momentum_error_max", NULL, ws.max_momentum_error},
    };
    if (st == CF_OK && sim->topology_changed) {
        st = cf_h5_write_tet_fragments(sim->h5, step, t, sim->tet_frag, sim->n_tets, err);
        sim->topology_changed = 0;
    }
    for (size_t i = 0; i < sizeof obs / sizeof obs[0] && st == CF_OK; i++)
        st = cf_h5_write_observable(sim->h5, obs[i].name, obs[i].unit, step, t, obs[i].value,
                                    err);
    if (st == CF_OK && sim->output.cracks)
        st = write_cracks(sim, err);
    if (st == CF_OK && sim->output.fields && n_fracture > 0)
        st = write_fracture_tets(sim, t, err);
    /* The frame last: its write flushes everything above with it, so a
     * frame on disk has its observables, cracks and map. */
    if (st == CF_OK)
        st = cf_h5_write_frame(sim->h5, step, t, fr, n, err);
    sim->frames_written += st == CF_OK;
    free(fs), free(fr);
    double took = cf_wall_time() - t0;
    sim->output_time += took, sim->frame_time += took;
    return st;
}

/* Simulated time reached, s: inside a rigid step, the heartbeat's (tick). */
static double time_reached(const cf_sim *sim)
{
    return fmax(cf_world_time(sim->world), sim->t_inner);
}

/* The run now, for the ETA: inside a rigid step the spell now running has
 * run as far as the heartbeat's time. */
static void eta_sample(cf_sim *sim)
{
    cf_world *w = sim->world;
    cf_step_stats st;
    cf_world_step_stats(w, &st);
    double t0 = cf_world_time(w), t = time_reached(sim);
    cf_eta_sample s = {.t = t, .tet_steps = (double)st.tet_steps,
                       .cracks = cf_world_cohesive_count(w),
                       .spell = st.spell_time > 0 ? st.spell_time + (t - t0) : 0};
    for (int i = 0; i < CF_STAGE_COUNT; i++) {
        s.wall += st.stage[i];
        s.fracture_wall += i == CF_STAGE_RIGID_STEP ? 0 : st.stage[i];
    }
    cf_eta_add(&sim->eta, &s);
}

/* Remaining wall time of the run, s (eta.h): the spell now running (held
 * by the landings under way), the landings to come, the rest of the
 * simulated time, and the frames left at the wall per frame so far (the
 * rest mesh and the fragments' surfaces are written once, at the start
 * and as fragments are born: over the first millisecond of a drop they
 * read as 50 s per simulated second). */
static double eta(const cf_sim *sim)
{
    cf_world *w = sim->world;
    double now = time_reached(sim), left = fmax(0.0, sim->duration - now);
    double per_frame = sim->frames_written > 0 ? sim->frame_time / sim->frames_written : 0;
    double frames_left = sim->output.frame_interval > 0 ? ceil(left / sim->output.frame_interval) : 0;
    cf_step_stats st;
    cf_world_step_stats(w, &st);
    /* The landings under way and to come; without the memory for them,
       none (the ETA is a forecast, not part of the run). */
    int cap = cf_world_fragments_ever(w), n = 0;
    cf_landing *l = malloc((size_t)cap * sizeof *l);
    cf_eta_landing *el = malloc((size_t)cap * sizeof *el);
    if (l && el) {
        n = cf_world_landings(w, sim->duration, l, cap);
        for (int i = 0; i < n; i++)
            el[i] = (cf_eta_landing){.under_way = l[i].under_way, .t = l[i].time - now,
                                     .tets = l[i].n_tets, .hold = l[i].hold};
    }
    double eta = cf_eta_left(&sim->eta, left, st.tets, el, n, frames_left * per_frame);
    free(l), free(el);
    return eta;
}

/* Progress: simulated time, mode, fragments and an ETA (eta). */
static void progress(cf_sim *sim, int final)
{
    if (!sim->opt.progress)
        return;
    double now = cf_wall_time();
    int term = tty();
    if (now - sim->last_sample >= 0.1) {
        eta_sample(sim);
        sim->last_sample = now;
    }
    if (!final && now - sim->last_progress < (term ? 0.2 : 10.0))
        return;
    sim->last_progress = now;
    cf_world *w = sim->world;
    long done = cf_world_step_count(w), total = sim->n_steps;
    double frac = total > 0 ? fmin(1.0, (double)done / (double)total) : 1.0;
    cf_world_stats ws;
    cf_world_stats_get(w, &ws);
    double left = final ? 0 : eta(sim);
    double t = fmin(time_reached(sim), sim->duration);
    const char *mode = ws.in_fracture ? "fracture" : "rigid";
    if (term) {
        char bar[31];
        int fill = (int)(30 * frac);
        for (int i = 0; i < 30; i++)
            bar[i] = i < fill ? '#' : '.';
        bar[30] = 0;
        fprintf(stderr, "\r\033[K[%s] t=%.4f/%.4g s  %-8s  fragments %d  cohesive %d  ETA %.0f s",
                bar, t, sim->duration, mode, ws.alive, ws.cohesive, left);
        sim->bar_shown = !final;
        if (final)
            fputc('\n', stderr);
    } else {
        fprintf(stderr, "t=%.4f/%.4g s (%3.0f%%)  %s  fragments %d  cohesive %d  ETA %.0f s\n",
                t, sim->duration, 100 * frac, mode, ws.alive, ws.cohesive, left);
    }
}

/* The world's heartbeat inside a long step (a fracture spell of many
 * sub-steps, the decomposition of many pieces): the display moves on
 * between rigid steps too. */
static void tick(void *user, double t)
{
    cf_sim *sim = user;
    sim->t_inner = t;
    progress(sim, 0);
}

/* Runnable tasks of other processes now: the count in /proc/loadavg less
 * this process's running threads; -1 where /proc cannot say. */
static int others_runnable(void)
{
    FILE *f = fopen("/proc/loadavg", "r");
    double a, b, c;
    int running = -1, total, own = 0;
    if (!f)
        return -1;
    int ok = fscanf(f, "%lf %lf %lf %d/%d", &a, &b, &c, &running, &total) == 5;
    fclose(f);
    DIR *d = ok ? opendir("/proc/self/task") : NULL;
    if (!d)
        return -1;
    for (struct dirent *e; (e = readdir(d));) {
        char path[300], buf[512];
        if (e->d_name[0] == '.')
            continue;
        snprintf(path, sizeof path, "/proc/self/task/%s/stat", e->d_name);
        FILE *s = fopen(path, "r");
        if (!s)
            continue;
        size_t n = fread(buf, 1, sizeof buf - 1, s);
        fclose(s);
        buf[n] = 0;
        const char *p = strrchr(buf, ')'); /* the state follows the name */
        own += p && p[1] == ' ' && p[2] == 'R';
    }
    closedir(d);
    return running > own ? running - own : 0;
}

/* With the default thread count, use the cores other processes leave free
 * (at least one), looked at every quarter second and smoothed over about
 * a second.  OpenMP threads spin at every barrier, so on a host whose
 * cores are all taken two threads wait for each other's turn: `make run`
 * took 6.5 times as long with two threads as with one beside two busy
 * processes.  The bits do not depend on the count. */
static void balance_threads(cf_sim *sim)
{
    double now = cf_wall_time();
    if (sim->threads_max < 2 || now - sim->last_balance < 0.25)
        return;
    sim->last_balance = now;
    int others = others_runnable();
    if (others < 0)
        return;
    sim->busy += 0.3 * (others - sim->busy);
    int want = sim->threads_max - (int)lround(sim->busy);
    want = want < 1 ? 1 : want;
    if (want != sim->threads_now) {
        cf_world_set_threads(sim->world, want);
        sim->threads_now = want;
        if (want < sim->threads_least)
            sim->threads_least = want;
    }
}

cf_status cf_sim_advance(cf_sim *sim, cf_error *err)
{
    if (sim->loop_start == 0)
        sim->loop_start = cf_wall_time();
    cf_world *w = sim->world;
    /* The run owns time: regular steps, the last one cut short so that the
     * run ends at the duration (ceil(duration / dt) steps in all). */
    long step = cf_world_step_count(w);
    double dt_step = cf_world_dt_outer(w), rest = sim->duration - (double)step * dt_step;
    if (step == sim->n_steps - 1 && rest < (1 - 1e-9) * dt_step)
        dt_step = rest;
    cf_status st = cf_world_step(w, dt_step, err);
    cf_status st2 = drain_events(sim, st == CF_OK ? err : NULL);
    if (st == CF_OK)
        st = st2;
    double t = cf_world_time(w), dt = cf_world_dt_outer(w);
    if (st == CF_OK && (t >= sim->next_frame - 1e-9 * dt || cf_sim_done(sim))) {
        st = write_frame(sim, err);
        while (sim->next_frame <= t + 1e-9 * dt)
            sim->next_frame += sim->output.frame_interval;
    }
    progress(sim, 0);
    balance_threads(sim);
    return st;
}

cf_status cf_sim_run(cf_sim *sim, cf_error *err)
{
    cf_world_stats ws;
    cf_world_stats_get(sim->world, &ws);
    if (sim->opt.progress)
        fprintf(stderr, "cohfrac: %d nodes, %d tets, %d fragment(s); dt_cfl = %.4g s, "
                        "dt_fracture/dt_cfl = %.4g, dt_rigid/dt_cfl = %.4g\n",
                ws.nodes, ws.tets, ws.alive, ws.dt_cfl, ws.dt_fracture / ws.dt_cfl,
                ws.dt_outer / ws.dt_cfl);
    cf_status st = write_frame(sim, err);
    sim->next_frame = sim->output.frame_interval;
    int last_written = 1;
    while (st == CF_OK && !cf_sim_done(sim)) {
        if (sim->opt.stop && *sim->opt.stop) {
            /* A signal: the state after this step as the last frame. */
            if (!last_written)
                st = write_frame(sim, err);
            if (st == CF_OK)
                st = cf_error_set(err, CF_ERR_INTERRUPTED,
                                  "interrupted at t = %.6g s; the output file holds every "
                                  "frame up to then and is closed",
                                  cf_world_time(sim->world));
            break;
        }
        long frames = sim->frames_written;
        st = cf_sim_advance(sim, err);
        last_written = sim->frames_written > frames;
    }
    progress(sim, 1);
    if (st != CF_OK) {
        close_after_error(sim, err);
        return st;
    }
    cf_error cerr;
    if (sim->h5 && cf_h5_close(sim->h5, &cerr) != CF_OK) {
        *err = cerr;
        st = cerr.code;
    }
    sim->h5 = NULL;
    return st;
}

void cf_sim_memory(const cf_sim *sim, cf_memory *m)
{
    cf_world_memory(sim->world, m);
    m->output = sim->output_peak;
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

/* The cohesive elements by where they end: between two fragments or inside
 * one, and how many of each still hold (not every node pair failed).  One
 * between fragments that holds would be a bond the hand-off cut, which it
 * never does (docs/physics.md §5.1). */
static void print_cohesive(const cf_world *w, FILE *out)
{
    int n = cf_world_cohesive_count(w), between = 0, between_holding = 0, holding = 0;
    for (int e = 0; e < n; e++) {
        cf_crack_row r;
        cf_world_crack(w, e, &r);
        int apart = cf_world_tet_fragment(w, r.tets[0]) != cf_world_tet_fragment(w, r.tets[1]);
        between += apart;
        between_holding += apart && !r.failed;
        holding += !apart && !r.failed;
    }
    fprintf(out, "cohesive elements  %d", n);
    if (n > 0)
        fprintf(out, ": %d between fragments (%d holding), %d inside one (%d holding)", between,
                between_holding, n - between, holding);
    fputc('\n', out);
}

void cf_sim_print_summary(const cf_sim *sim, FILE *out)
{
    const cf_world *w = sim->world;
    const cf_world_def *d = cf_world_definition(w);
    cf_world_stats p;
    cf_world_stats_get(w, &p);
    double wall = cf_wall_time() - sim->wall_start;
    fprintf(out, "\n== cohfrac summary: %s ==\n", sim->name);
    static const char *constraints[] = {"pbd", "xpbd", "none"};
    fprintf(out, "simulated time     %.4g s in %ld rigid steps (dt_rigid %.3g s, backend %s)\n",
            cf_world_time(w), cf_world_step_count(w), p.dt_outer,
            d->solver.mode == CF_RUN_FRACTURE ? "none: fracture mode only"
            : d->solver.rigid_backend == CF_RIGID_BULLET ? "bullet" : "pbd");
    fprintf(out, "constraints        %s\n", constraints[d->solver.constraints]);
    fprintf(out, "mesh               %d tets, %d nodes (%d after duplication)\n", p.tets,
            p.nodes_input, p.nodes);
    fprintf(out, "time step          dt_fracture %.3g s = %.4g dt_cfl (dt_cfl %.4g s)\n",
            p.dt_fracture, p.dt_fracture / p.dt_cfl, p.dt_cfl);
    if (p.mass_scaled > 0)
        fprintf(out, "mass scaling       %d tets below %g of the median tet's step: +%.3g kg "
                "(%.3g %% of the mass), their wave speed down to %.3g of c_d at the least\n",
                p.mass_scaled, d->solver.mass_scaling, p.mass_added,
                100.0 * p.mass_added / p.mass_total, p.wave_speed_least);
    fprintf(out, "steps per mode     rigid %ld, fracture %ld (threads %d", p.steps_rigid,
            p.steps_fracture, sim->threads_max ? sim->threads_max : p.threads);
    if (sim->threads_least < sim->threads_max)
        fprintf(out, ", down to %d while other processes held the cores", sim->threads_least);
    fprintf(out, ")\n");
    fprintf(out, "fragments          %d alive (%d in fracture mode), %d ever\n", p.alive,
            p.in_fracture, p.ever);
    if (p.debris > 0)
        fprintf(out, "debris             %d fragments, %.4g kg (%.2f%% of the mass), spheres in "
                     "the rigid step (docs/physics.md §9.2)\n",
                p.debris, p.debris_mass, 100 * p.debris_mass / fmax(p.mass_alive, 1e-300));
    print_cohesive(w, out);
    fprintf(out, "hand-offs          %d, max linear momentum error %.3g (relative), "
                 "handoff_loss %.4g J\n",
            p.handoffs, p.max_momentum_error, p.handoff_loss);
    if (p.rigid_with_hulls > 0)
        fprintf(out, "convex hulls       %d over %d rigid fragments; hull volume / tet volume - 1: "
                     "median %.3g, worst %.3g; decomposition %.2f s (%.1f%% of wall time)\n",
                p.hulls, p.rigid_with_hulls, p.hull_error_median, p.hull_error_worst,
                p.stage[CF_STAGE_CONVEX_DECOMPOSITION],
                100 * p.stage[CF_STAGE_CONVEX_DECOMPOSITION] / fmax(wall, 1e-300));
    print_memory(sim, out);
    double staged = sim->output_time, solver = 0; /* the solver's stages: its step */
    for (int i = 0; i < CF_STAGE_COUNT; i++)
        staged += p.stage[i];
    for (int i = CF_STAGE_SOLVER_FIRST; i <= CF_STAGE_SOLVER_LAST; i++)
        solver += p.stage[i];
    cf_ledger l;
    cf_world_ledger(w, &l);
    double scale = fmax(fabs(l.initial) + fabs(l.work_gravity) + fabs(l.work_boundary) +
                            fabs(l.work_obstacles),
                        1e-300);
    fprintf(out, "energy ledger (J)  kinetic %.6g | strain %.6g | cohesive stored %.6g | "
                 "cohesive dissipated %.6g | plastic dissipated %.6g\n",
            l.kinetic, l.strain, l.cohesive_stored, l.cohesive_dissipated, l.plastic_dissipated);
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
            (unsigned long long)cf_world_state_hash(w));
    fprintf(out, "wall time          %.2f s\n", wall);
    /* The step's stages (cohfrac/world.h, docs/architecture.md), four to a
     * line, then what the run loop spent outside the steps. */
    for (int i = 0; i < CF_STAGE_COUNT; i++)
        fprintf(out, "%s%s %.2f s", i % 4 == 0 ? (i ? "\n  " : "  ") : " | ",
                cf_stage_name((cf_stage)i), p.stage[i]);
    fprintf(out, "\n  output %.2f s | other %.2f s\n", sim->output_time, wall - staged);
    if (p.steps_fracture > 0)
        fprintf(out, "per fracture step  %.3f ms\n", 1e3 * solver / (double)p.steps_fracture);
    if (sim->output.file[0])
        fprintf(out, "output             %s\n", sim->output.file);
}
