/* cohfrac — world definitions: materials, bodies, obstacles, boundary
 * conditions and solver settings (the physics), as plain C structs with
 * defaults (cf_default_*).  The engine (cohfrac/world.h) is created from a
 * cf_world_def and copies what it needs; the Lua scene loader
 * (cohfrac/scene.h) only fills these structs.  Units are SI throughout;
 * the keys, defaults and ranges are those of the scene schema documented
 * in cohfrac/scene.h.
 */
#ifndef COHFRAC_TYPES_H
#define COHFRAC_TYPES_H

#include "cohfrac/error.h"
#include "cohfrac/tetmesh.h"

typedef struct cf_material {
    double E, nu, rho;             /* Pa, -, kg/m^3 */
    double G_I, G_II;              /* fracture energies phi_n, phi_t, N/m */
    double sigma_max, tau_max;     /* cohesive strengths, Pa */
    double alpha, beta;            /* PPR shape parameters */
    double friction, restitution;  /* contact with obstacles */
    int weibull;                   /* strength distribution: 0 uniform, 1 Weibull */
    double weibull_modulus;        /* m, > 0 */
    int strength_seed;
    double compressive_strength;   /* sigma_c, Pa: crushing of the Tet4s, the strength in
                                      uniaxial compression (docs/physics.md §2.1); 0 none
                                      (linear elastic) */
    double strength_area;          /* m^2: Weibull reference area A0: the strength field
                                      is correlated over sqrt(A0), and a facet of area
                                      A > A0 is scaled by (A0/A)^(1/m) (Zhou and Molinari
                                      2004); 0: the cohesive length squared,
                                      (E G_I / sigma_max^2)^2 */
    double nucleation_radius;      /* m, R_n: no crack nucleates within R_n / ratio^2 of
                                      a cracked facet (rest centroids; crack_growth
                                      "fronts"); 0: the cohesive length E G_I / sigma_max^2 */
    double crushing_strain;        /* equivalent plastic strain at which a crushing Tet4
                                      is crushed: cut free of its neighbours, it leaves
                                      as debris (docs/physics.md §2.2); 0 never */
    double internal_friction_angle; /* phi, degrees, [0, 60]: the crushing strength grows
                                      with pressure (Drucker-Prager); 0 von Mises */
    int cohesive_law;              /* index of the cohesive law (material.cohesive_law,
                                      docs/settings.md); 0 PPR */
    double crack_friction;         /* Coulomb coefficient of a cohesive element's faces
                                      pressed together, bonded or failed (explicit runs,
                                      docs/physics.md §6); 0 none */
} cf_material;

typedef struct cf_body_def {
    const cf_mesh *tet_mesh;   /* the body's Tet4 mesh as made (before scale, orientation
                                  and position); not owned, read only by cf_world_create.
                                  Mesh preparation makes it from where the scene says
                                  (cf_body_source, cohfrac/mesh.h; cf_world_meshes_load) */
    double scale;
    double position[3];        /* m, where the bounding-box centre goes */
    double orientation[4];     /* w,x,y,z, normalised */
    double velocity[3];        /* m/s */
    double angular_velocity[3];/* rad/s */
    double expansion_rate[3];  /* 1/s, per axis */
    int has_expansion_center;  /* 0: the body's centre of mass */
    double expansion_center[3];/* m */
} cf_body_def;

typedef enum { CF_REGION_BOX, CF_REGION_PLANE, CF_REGION_GROUP } cf_region_type;

typedef struct cf_boundary {
    cf_region_type type;
    double min[3], max[3];       /* box, m */
    double point[3], normal[3];  /* plane (normal normalised) */
    double tolerance;            /* plane, m */
    char group[64];              /* Gmsh physical group name */
    int body;                    /* 0-based body index, -1 for every body */
    int axes;                    /* prescribed components: bit 0 x, 1 y, 2 z */
    double velocity[3];          /* m/s (zero when fixed) */
} cf_boundary;

/* The obstacle types, X(NAME, name): CF_OBSTACLE_NAME, the scene's
 * `type = "name"` and the engine's kind cf_obstacle_name
 * (src/engine/obstacle_name.c).  A new type is a line here, its parameters
 * in cf_obstacle, its file, and its keys in the scene reader
 * (docs/architecture.md). */
#define CF_OBSTACLE_TYPES(X) X(PLANE, plane) X(SPHERE, sphere) X(BOX, box) X(MESH, mesh)

typedef enum {
#define CF_OBSTACLE_ENUM_(NAME, name) CF_OBSTACLE_##NAME,
    CF_OBSTACLE_TYPES(CF_OBSTACLE_ENUM_)
#undef CF_OBSTACLE_ENUM_
} cf_obstacle_type;

/* How many types there are (not a value of cf_obstacle_type, so that a
 * switch over the types that misses one is still warned about). */
#define CF_OBSTACLE_ONE_(NAME, name) +1
enum { CF_OBSTACLE_TYPE_COUNT = 0 CF_OBSTACLE_TYPES(CF_OBSTACLE_ONE_) };
#undef CF_OBSTACLE_ONE_

typedef struct cf_obstacle {
    cf_obstacle_type type;
    double point[3], normal[3];  /* plane (normal normalised) */
    double center[3];            /* sphere, box: at t = 0 */
    double radius;               /* sphere, m */
    double half_extents[3];      /* box (axis-aligned), m */
    double velocity[3];          /* sphere, box: constant, m/s */
    const double *vertices;      /* mesh: [n_vertices][3] the surface in its file's frame,
                                    m; not owned, read only by cf_world_create.  NULL:
                                    mesh preparation reads `file` (cf_world_meshes_load) */
    const int *triangles;        /* mesh: [n_triangles][3] 0-based vertex indices */
    int n_vertices, n_triangles;
    char file[1024];             /* mesh: resolved path of a closed or open
                                    triangle surface (.obj/.off/.stl, or a format assimp reads) */
    double scale;                /* mesh: applied first */
    double orientation[4];       /* mesh: w,x,y,z, normalised, then */
    double position[3];          /* mesh: where the file's origin goes, m */
    double friction, restitution;/* factors on the material's values (the
                                    pair's coefficient is their product) */
} cf_obstacle;

typedef enum { CF_RUN_HYBRID, CF_RUN_FRACTURE } cf_run_mode;
typedef enum { CF_RIGID_BULLET, CF_RIGID_PBD } cf_rigid_backend;
typedef enum { CF_ELASTICITY_COROTATIONAL, CF_ELASTICITY_LINEAR } cf_elasticity;
typedef enum { CF_CRITERION_TRACTION, CF_CRITERION_SOURCE, CF_CRITERION_NONE } cf_criterion;
typedef enum { CF_CONSTRAINTS_PBD, CF_CONSTRAINTS_XPBD, CF_CONSTRAINTS_NONE } cf_constraints;
/* Which of the facets that meet the criterion at a check are inserted
 * (docs/physics.md §5.1): those that extend a crack front or nucleate one
 * at a local maximum, or every one (the source's rule). */
typedef enum { CF_GROWTH_FRONTS, CF_GROWTH_ALL } cf_crack_growth;
/* Which facet a crack front may extend onto (docs/physics.md §5.1): any
 * facet across a front edge whose vertex ahead reaches the threshold, or
 * only one whose own normal stress does (the maximum tangential stress
 * criterion; criterion "source"). */
typedef enum { CF_FRONT_ANY, CF_FRONT_STRESS } cf_front_direction;
/* A crack front's threshold (docs/physics.md §5.1): the strength's, or at
 * most the field of a crack tip at the toughness a distance r ahead
 * (K_IC / sqrt(2 pi r)), or at most the far stress that makes a penny
 * crack of the front's radius a critical (K_IC sqrt(pi) / (2 sqrt(a))). */
typedef enum { CF_FRONT_STRENGTH, CF_FRONT_TOUGHNESS, CF_FRONT_CRACK } cf_front_threshold;
/* Where a crack front's vertices are duplicated (docs/physics.md §5.1):
 * only where cracked facets cut a vertex's star, or also the vertices
 * behind a new front facet, split along its plane. */
typedef enum { CF_FRONT_SPLIT_NONE, CF_FRONT_SPLIT_PLANE } cf_front_split;
/* Whether a new front facet's vertex ahead stays where the mesh has it, or
 * moves onto the plane through the front's edge across the largest
 * principal stress (docs/physics.md §5.1). */
typedef enum { CF_FRONT_SNAP_NONE, CF_FRONT_SNAP_STRESS } cf_front_snap;
/* Where a cohesive element's traction rises from zero with the capped
 * stiffness instead of starting at the strength (time continuity,
 * docs/physics.md §6): the tangential traction only, or the normal too. */
typedef enum { CF_CONTINUITY_TANGENTIAL, CF_CONTINUITY_BOTH } cf_time_continuity;
/* How fracture-mode nodes meet obstacles in explicit runs (docs/physics.md §7.1). */
typedef enum { CF_OBSTACLE_CONTACT_KINEMATIC, CF_OBSTACLE_CONTACT_PENALTY } cf_obstacle_contact;

typedef struct cf_solver_settings {
    cf_run_mode mode;
    cf_rigid_backend rigid_backend;
    double dt_rigid;
    int rigid_substeps;
    double dt_fracture;
    double cfl_fraction;          /* > 0: dt_fracture = cfl_fraction dt_cfl */
    int check_interval;
    int quiet_steps;
    double quiet_growth;
    double max_fracture_time;
    double impact_threshold;
    int ccd;                      /* Bullet continuous collision detection */
    double sleep_linear, sleep_angular; /* m/s, rad/s; 0, 0: no sleeping */
    cf_elasticity elasticity;
    cf_criterion criterion;
    cf_crack_growth crack_growth;
    cf_front_direction front_direction;
    cf_front_threshold front_threshold;
    double front_max_kink;        /* degrees, (0, 180]: the most a front may turn from the
                                     crack facet it extends (docs/physics.md §5.1); 180:
                                     no limit */
    cf_front_split front_split;
    double front_split_reach;     /* m: a split takes no facet whose rest centroid lies
                                     farther from the vertex it parts; 0: no limit */
    cf_front_snap front_snap;
    int min_piece_tets;           /* no insertion encloses a piece of at most this many
                                     tets in crack faces (fronts growth); 0: no bound */
    double min_piece_size;        /* m: nor one whose equal-volume sphere is narrower;
                                     0: no bound */
    int debris_tets;              /* a piece of at most this many tets is debris; 0: none */
    double debris_size;           /* m: a piece whose equal-volume sphere is narrower is
                                     debris; 0: no size rule */
    int has_crack_plane;
    double crack_plane_point[3], crack_plane_normal[3]; /* normal normalised */
    double crack_plane_tolerance;                    /* m */
    cf_constraints constraints;
    double k_stiffness;
    int iterations;
    double k_damping;
    int iteration_independent;
    double compliance_scale;
    double contact_stiffness;     /* Pa/m, 0 = stability cap */
    cf_time_continuity time_continuity;
    cf_obstacle_contact obstacle_contact; /* explicit runs: kinematic or penalty */
    double mass_scaling;          /* floor of a tet's step over the median's; 0: none */
    double bulk_viscosity;        /* linear bulk viscosity b1 of explicit runs; 0: none */
    double max_inverted_fraction;
    double max_energy_growth;
    int threads;
} cf_solver_settings;

/* A world definition: the physics, everything cf_world_create needs and
 * nothing of a run around it (its name, duration and output file are the
 * I/O layer's cf_scene, cohfrac/scene.h).  Start from
 * cf_default_world_def() and fill in; the Lua scene loader fills one the
 * same way. */
typedef struct cf_world_def {
    double gravity[3];          /* m/s^2 */
    cf_material material;
    int n_bodies;
    cf_body_def *bodies;
    int n_obstacles;
    cf_obstacle *obstacles;
    int n_boundaries;
    cf_boundary *boundaries;
    cf_solver_settings solver;
} cf_world_def;

/* Bounds on the work one setting can ask for (cf_world_def_check rejects
 * more with CF_ERR_SCENE_VALUE): fracture steps in one rigid step
 * (dt_rigid / dt_fracture), and PBD iterations and Bullet sub-steps per
 * step.  A run that needs more is a scene to rethink, not to wait for. */
#define CF_MAX_SUBSTEPS 1000000
#define CF_MAX_ITERATIONS 1000
/* The largest piece solver.min_piece_tets may name. */
#define CF_MAX_PIECE_TETS 64

/* Defaults of every setting, as documented in the scene schema
 * (cohfrac/scene.h); a scene key left out takes the same value. */
cf_material cf_default_material(void);
cf_solver_settings cf_default_solver(void);
/* A body at the origin, unit scale, at rest, with no mesh yet. */
cf_body_def cf_default_body(void);
/* An obstacle of `type` with the schema's defaults (plane through the origin
 * facing +z; sphere, box and mesh still need their geometry). */
cf_obstacle cf_default_obstacle(cf_obstacle_type type);
/* No bodies, no obstacles, the defaults above, gravity (0, 0, -9.81) m/s^2. */
cf_world_def cf_default_world_def(void);

/* Check a definition as cf_world_create does: every value in the range the
 * schema documents, each body with a mesh, each mesh obstacle with a surface.
 * Errors: CF_ERR_SCENE_VALUE naming the key path ("solver.dt_rigid",
 * "bodies[2].scale") with the value and the allowed range, as the scene
 * loader words them. */
cf_status cf_world_def_check(const cf_world_def *def, cf_error *err);

#endif
