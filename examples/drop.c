/* A box dropped on a plane through cohfrac's C API, no scene file: a 0.2 m
 * brittle cube falls 1 m onto the ground, cracks on impact, and the
 * fragments it ends as are printed (mass, centre, speed).
 *
 *   cc drop.c $(pkg-config --cflags --libs cohfrac) -o drop && ./drop
 */
#include <cohfrac/cohfrac.h>

#include <math.h>
#include <stdio.h>

int main(void)
{
    cf_error err = {0};
    cf_mesh box;
    const double size[3] = {0.2, 0.2, 0.2};
    const int cells[3] = {4, 4, 4};
    if (cf_mesh_box(size, cells, 6, &box, &err) != CF_OK)
        return fprintf(stderr, "box: %s\n", err.msg), 1;

    cf_world_def def = cf_default_world_def();
    def.material.E = 1e5;                      /* Pa: a soft, brittle solid */
    def.material.sigma_max = def.material.tau_max = 1e3; /* Pa: cracks at a 4.4 m/s impact */
    def.material.G_I = def.material.G_II = 1;  /* N/m: and the cracks open through */
    def.solver.constraints = CF_CONSTRAINTS_XPBD; /* bars with compliance from E */
    cf_body_def body = cf_default_body();
    body.tet_mesh = &box;                      /* read at create only */
    body.position[2] = 1.0;                    /* m, centre above the ground */
    cf_obstacle ground = cf_default_obstacle(CF_OBSTACLE_PLANE); /* z = 0, facing +z */
    def.bodies = &body, def.n_bodies = 1;
    def.obstacles = &ground, def.n_obstacles = 1;

    cf_world *world;
    if (cf_world_create(&def, &world, &err) != CF_OK)
        return fprintf(stderr, "world: %s\n", err.msg), 1;
    cf_mesh_free(&box);
    /* The caller owns time: regular rigid steps to 0.6 s. */
    double dt = cf_world_dt_outer(world);
    while (cf_world_time(world) < 0.6 - 0.5 * dt) {
        if (cf_world_step(world, dt, &err) != CF_OK)
            return fprintf(stderr, "step: %s\n", err.msg), 1;
        int n;
        const cf_event *ev = cf_world_events(world, &n);
        for (int i = 0; i < n; i++)
            if (ev[i].type == CF_EVENT_HANDOFF)
                printf("t = %.3f s: fragment %d goes to %s mode\n", ev[i].time, ev[i].first,
                       ev[i].handoff.direction ? "rigid" : "fracture");
        cf_world_clear_events(world);
    }
    cf_fragment_state f[256];
    int n = cf_world_fragments(world, f, 256);
    printf("%d fragments at t = %.2f s:\n", n, cf_world_time(world));
    for (int i = 0; i < n && i < 256; i++)
        printf("  fragment %3d: %8.4f kg at (%6.3f, %6.3f, %6.3f) m, %.3f m/s\n", f[i].id,
               f[i].mass, f[i].com[0], f[i].com[1], f[i].com[2],
               sqrt(f[i].v[0] * f[i].v[0] + f[i].v[1] * f[i].v[1] + f[i].v[2] * f[i].v[2]));
    cf_world_destroy(world);
    return 0;
}
