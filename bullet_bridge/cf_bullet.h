/* cohfrac — C face of the Bullet rigid-body world (double-precision Bullet,
 * BT_USE_DOUBLE_PRECISION).  The implementation is the only C++ in the
 * project; no C++ type or exception crosses this header.
 *
 * Bodies are referred to by an integer id (>= 0) returned at creation and
 * valid until removed.  Units SI; quaternions (w,x,y,z) body->world.
 * A dynamic body's frame is its principal-axes frame centred at its centre of
 * mass: the caller gives the principal moments and the hull points in that
 * frame.  Functions returning int return -1 on error and leave a message for
 * cfb_last_error().
 */
#ifndef COHFRAC_BULLET_BRIDGE_H
#define COHFRAC_BULLET_BRIDGE_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct cfb_world cfb_world;

typedef struct cfb_state {
    double pos[3];   /* centre of mass, m */
    double quat[4];  /* w,x,y,z: principal frame -> world */
    double v[3];     /* m/s */
    double w[3];     /* rad/s, world frame */
} cfb_state;

/* Create a world with gravity (m/s^2).  NULL on failure. */
cfb_world *cfb_world_create(const double gravity[3]);
void cfb_world_destroy(cfb_world *w);

/* Static plane through `point` with unit `normal`. Returns an id. */
int cfb_add_plane(cfb_world *w, const double point[3], const double normal[3],
                  double friction, double restitution);
/* Sphere / axis-aligned box obstacle; kinematic when velocity is non-zero
 * (moves at constant velocity, infinite mass), static otherwise. */
int cfb_add_sphere(cfb_world *w, const double center[3], double radius,
                   const double velocity[3], double friction, double restitution);
int cfb_add_box(cfb_world *w, const double center[3], const double half_extents[3],
                const double velocity[3], double friction, double restitution);

/* Dynamic body whose collision shape is the convex hull of `pts`
 * ([n][3], principal frame, m).  mass in kg, inertia = principal moments
 * (kg m^2).  `margin` is the collision margin (m).  Returns the id. */
int cfb_add_hull_body(cfb_world *w, double mass, const double inertia[3], const double *pts,
                      int n, double margin, const cfb_state *s, double friction,
                      double restitution);

/* Remove a body (its id becomes invalid). */
void cfb_remove_body(cfb_world *w, int id);

void cfb_get_state(const cfb_world *w, int id, cfb_state *s);
void cfb_set_state(cfb_world *w, int id, const cfb_state *s);

/* Do not generate contacts between bodies a and b. */
void cfb_ignore_pair(cfb_world *w, int a, int b);

/* Put body `id` in collision family `family` (>= 0), replacing any earlier
 * one: bodies of one family never collide with each other (fragments born in
 * one split, whose convex hulls overlap).  -1 leaves every family.
 * Returns 0, or -1 on error. */
int cfb_set_family(cfb_world *w, int id, int family);

/* Advance by dt seconds in `substeps` equal fixed sub-steps (Bullet's
 * semi-implicit Euler).  Returns 0, or -1 on bad arguments. */
int cfb_step(cfb_world *w, double dt, int substeps);

/* Sum of normal contact impulses (N s) applied to body `id` during the last
 * cfb_step (all sub-steps), against any other body; -1 for an invalid id. */
double cfb_contact_impulse(const cfb_world *w, int id);

/* Number of dynamic bodies currently in the world. */
int cfb_body_count(const cfb_world *w);

/* Message of the last failed call (static storage). */
const char *cfb_last_error(void);

#ifdef __cplusplus
}
#endif
#endif
