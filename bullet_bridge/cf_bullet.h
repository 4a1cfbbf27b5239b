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

/* Bytes Bullet's allocator holds now (btAlignedAlloc, which every Bullet
 * object and array goes through), counted by the bridge's allocator hook
 * for the whole process. */
unsigned long long cfb_allocated_bytes(void);

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

/* Convex hull of n points ([n][3], m) by btConvexHullComputer: writes the
 * hull's vertices to `out` ([n][3] capacity; may be NULL) and its volume
 * (m^3) to *volume (may be NULL; 0 for a flat or degenerate hull).
 * The vertices are input points, copied bit for bit.  Points within
 * round-off of a face may or may not count as vertices.
 * Returns the number of hull vertices, or -1 on bad arguments (n < 1,
 * NULL or non-finite points) or when Bullet runs out of memory
 * (cfb_last_error says which). */
int cfb_convex_hull(const double *pts, int n, double *out, double *volume);

/* Dynamic body whose collision shape is a compound of convex hulls (a
 * convex decomposition): hull h is the convex hull of the points
 * pts[start[h] .. start[h+1]) ([.][3], principal frame, m; start has
 * n_hulls + 1 entries, start[0] = 0; each hull needs >= 4 points and
 * >= 4 hull vertices).  `margin` applies to every hull.  One hull gives a plain
 * convex hull shape (no compound).  Otherwise as cfb_add_hull_body. */
int cfb_add_compound_body(cfb_world *w, double mass, const double inertia[3], const double *pts,
                          const int *start, int n_hulls, double margin, const cfb_state *s,
                          double friction, double restitution);

/* Dynamic body whose collision shape is a sphere of `radius` (m) about
 * its centre of mass, with the given mass (kg) and principal moments
 * (kg m^2): debris, whose contact needs no more than its size
 * (docs/physics.md §9.2).  Otherwise as cfb_add_hull_body. */
int cfb_add_sphere_body(cfb_world *w, double mass, const double inertia[3], double radius,
                        const cfb_state *s, double friction, double restitution);

/* Continuous collision detection for dynamic body `id`: when it moves more
 * than motion_threshold (m) in a sub-step, Bullet sweeps a sphere of radius
 * swept_radius (m, best somewhat below the body's inner radius) from its
 * centre of mass along the motion and stops the body at the first hit
 * (bodies it does not collide with, by cfb_ignore_pair or cfb_set_family,
 * are not hit).  0, 0 turns it off.  Returns 0, or -1: invalid id, body not
 * dynamic, values not both > 0 or both 0, or a compound body (Bullet
 * sweeps convex shapes only). */
int cfb_set_ccd(cfb_world *w, int id, double motion_threshold, double swept_radius);

/* Sleeping for every dynamic body, present and future: a body slower than
 * `linear` (m/s) and `angular` (rad/s) for 2 s is deactivated (velocity set
 * to 0) until a contact with an awake body, cfb_set_state or
 * cfb_apply_impulse wakes it; Bullet sleeps by island, so bodies in contact
 * sleep together.  Kinematic bodies never sleep.  While asleep a body's
 * contacts are not solved and cfb_contact_impulse keeps reporting the
 * impulses of the last solve (for a body at rest, its resting load).
 * 0, 0 (the default) keeps every body awake (and wakes sleeping ones).
 * Returns 0, or -1 (values not both > 0 or both 0, non-finite). */
int cfb_set_sleeping(cfb_world *w, double linear, double angular);

/* 1 when dynamic body `id` is asleep, 0 awake (always 0 for static and
 * kinematic bodies), -1 on error. */
int cfb_is_sleeping(const cfb_world *w, int id);

/* Apply impulse J (N s, world frame) at the world point p (m) to dynamic
 * body `id` (changes its linear and angular velocity at once; wakes it).
 * Returns 0, or -1 (invalid id, not dynamic, non-finite input). */
int cfb_apply_impulse(cfb_world *w, int id, const double J[3], const double p[3]);

/* World-frame bounding box (m) of body `id`'s shape now, collision margin
 * included: the smallest one for hulls, compounds, spheres and boxes, the
 * vertices' box for a triangle mesh.  A plane whose normal lies along an
 * axis: the half-space behind it and Bullet's contact breaking threshold
 * (1 mm, as cfb_world_create sets it) in front, +-1e30 along the other
 * axes; any other plane: +-1e30 in every direction.  Returns 0 or -1. */
int cfb_get_aabb(const cfb_world *w, int id, double lo[3], double hi[3]);

/* Deepest penetration (m, > 0) between the shapes of bodies a and b in
 * their current poses; 0 when they do not touch; -1 on error.  The shapes
 * are the collision shapes, margins included (a hull grown by its margin:
 * two hulls overlapping by o report o + both margins).  Pairs excluded
 * with cfb_ignore_pair or cfb_set_family are measured all the same.  Two
 * static shapes Bullet cannot test (plane or mesh against plane or mesh)
 * give 0. */
double cfb_pair_penetration(cfb_world *w, int a, int b);

/* Undo cfb_ignore_pair: bodies a and b collide again (both are woken).
 * Nothing happens when the pair was not ignored. */
void cfb_unignore_pair(cfb_world *w, int a, int b);

/* Static triangle-mesh obstacle (world frame): verts [nv][3] m, tris
 * [nt][3] 0-based vertex indices, three distinct ones per triangle.  The
 * arrays are copied.  Bullet's triangles collide on both sides.  Returns
 * the id, or -1. */
int cfb_add_trimesh(cfb_world *w, const double *verts, int nv, const int *tris, int nt,
                    double friction, double restitution);

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
 * semi-implicit Euler).  Returns 0, or -1 on bad arguments or when Bullet
 * ran out of memory, in this call or in an earlier one that could not
 * return an error (cfb_last_error says which; the world is then unusable). */
int cfb_step(cfb_world *w, double dt, int substeps);

/* Sum of normal contact impulses (N s) applied to body `id` during the last
 * cfb_step (all sub-steps), against any other body; -1 for an invalid id. */
double cfb_contact_impulse(const cfb_world *w, int id);

/* The part of cfb_contact_impulse (N s) from static bodies (fixed
 * obstacles: they move nothing, so they bring no new energy to the body);
 * -1 for an invalid id. */
double cfb_contact_impulse_static(const cfb_world *w, int id);

/* Number of dynamic bodies currently in the world. */
int cfb_body_count(const cfb_world *w);

/* Message of the last failed call (static storage). */
const char *cfb_last_error(void);

#ifdef __cplusplus
}
#endif
#endif
