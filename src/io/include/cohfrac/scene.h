/* cohfrac — scenes: a Lua 5.4 script that returns a table, read into a
 * cf_scene: the engine's world definition (cohfrac/types.h, the physics)
 * and what a run does with it (its name, duration and output).
 *
 * The script runs sandboxed (base functions without dofile/loadfile/load of
 * bytecode, plus string, table and math; no io, os, package, debug).  The
 * returned table is checked against the schema below: unknown keys and wrong
 * types are errors that name the key path ("solver.pbd.k_stiffnes").  Every
 * key has a default; `--set key.path=value` overrides anything (the value is
 * a Lua expression: 1e-6, "pbd", {0,0,1}; list items as bodies[1].scale).
 *
 * Schema (SI units; defaults in brackets).  The keys of `material` and
 * `solver` are the settings schema's (cohfrac/settings.h): its table
 * docs/settings.md gives each one's kind, default, allowed values and unit;
 * below they are explained at length:
 *   name            string   ["scene"]
 *   duration        s        [1.0]        simulated time
 *   gravity         {x,y,z}  [{0,0,-9.81}] m/s^2
 *   material = {                          bulk and cohesive properties
 *     E [1e6] Pa, nu [0.3], rho [2400] kg/m^3,
 *     G_I [22] N/m, sigma_max [1e4] Pa, alpha [2],
 *     G_II [=G_I] N/m, tau_max [=sigma_max] Pa, beta [=alpha],
 *     friction [0.5], restitution [0.0],
 *     crack_friction [0]: Coulomb friction coefficient of a cohesive
 *       element's faces pressed together, bonded or failed: in explicit
 *       runs the tangential traction there gains up to crack_friction times
 *       the compression penalty's traction (docs/physics.md §6); 0 none,
 *     compressive_strength [0] Pa: sigma_c > 0 makes the Tet4s crush
 *       (perfect plasticity with sigma_c the uniaxial compressive strength,
 *       in the element frame, the work booked as energy_plastic_dissipated;
 *       docs/physics.md §2.1); 0 keeps them linear elastic,
 *     internal_friction_angle [0] degrees, 0-60: phi > 0 makes the crushing
 *       strength grow with pressure (Drucker-Prager on Mohr-Coulomb's
 *       compression meridian, q <= sigma_c (1 - beta/3) + beta p with
 *       beta = 6 sin phi / (3 - sin phi)); 0 is von Mises at sigma_c,
 *     crushing_strain [0]: with compressive_strength, a Tet4 whose
 *       equivalent plastic strain (plastic work / (sigma_c V)) reaches this
 *       is crushed: its facets are cut without cohesive elements and it
 *       leaves as debris (docs/physics.md §2.2); 0 never,
 *     nucleation_radius [0] m: R_n; with solver.crack_growth "fronts", no
 *       crack nucleates within R_n / ratio^2 of a cracked facet (rest
 *       centroids; ratio: how far the facet exceeds its strength, >= 1):
 *       cracks closer than the cohesive zone would share it; 0: the
 *       cohesive length l_ch = E G_I / sigma_max^2 (docs/physics.md §5.1)
 *     strength = { distribution ["uniform"] | "weibull",
 *                  modulus [10] (Weibull modulus m > 0), seed [1] (integer),
 *                  area [0] m^2 (Weibull reference area A0; 0: l_ch^2 with
 *                  l_ch = E G_I / sigma_max^2, the cohesive length) } }
 *       strength scatter: with "weibull" each interior facet f gets
 *       sigma_max_f = sigma_max w_f, tau_max_f = tau_max w_f, w_f the value
 *       at its rest centroid of a Weibull random field of the material,
 *       P(w <= x) = 1 - exp(-x^m) at every point, correlated over
 *       L = sqrt(A0) (the same weak regions on any mesh of the body);
 *       a facet of rest area A_f > A0 is the weakest link of its regions,
 *       w_f scaled by (A0/A_f)^(1/m) (Zhou and Molinari 2004); the same for
 *       a given seed and placement on any thread count (docs/physics.md
 *       §5.1); the facet's cohesive law keeps G_I, G_II
 *       (its final openings scale with 1/w_f).  Weibull 1951, J Appl Mech
 *       18:293; for dynamic fragmentation Zhou, Molinari, Ramesh 2006, IJIE
 *       33:880.
 *   bodies = { {                          one entry per solid
 *     mesh        string: a prepared mesh name ("bunny", "bunny_small")
 *                 looked up in the mesh directory, a path to a TetGen
 *                 .node/.ele pair (with or without extension), or a path
 *                 to a Gmsh .msh file;                          [required]
 *                 or a primitive table (meshed in the mesh directory):
 *                 {type="box", size={x,y,z} m, cells={nx,ny,nz} [{1,1,1}],
 *                  tets_per_cell [6] (5 or 6)}
 *                 {type="sphere", radius m, mesh_size m}
 *                 {type="hollow_sphere", radius m, thickness m, mesh_size m}
 *                 {type="plate", size={x,y,z} m, mesh_size m}
 *                 {type="notched_beam", size={length,width,height} m,
 *                  notch={depth,width,offset} m, mesh_size m}
 *     scale [1], position [{0,0,0}] m (of the mesh's bounding-box centre),
 *     orientation [{1,0,0,0}] quaternion (w,x,y,z) applied before scale,
 *     initial velocity field v = velocity + angular_velocity x (x - x_com)
 *       + expansion_rate (.) (x - expansion_center):
 *     velocity [{0,0,0}] m/s, angular_velocity [{0,0,0}] rad/s (about the COM),
 *     expansion_rate [0] 1/s: a number (radial) or {x,y,z} (per axis),
 *     expansion_center [the body's centre of mass] m
 *     hollow_layers [0]: integer >= 0; > 0 keeps only the tets within this
 *       many tet layers of the mesh's boundary (layer 1: tets with a boundary
 *       face or a node on the boundary; layer k+1: tets sharing a node with
 *       layer k) and drops the rest, a hollow shell (cf_mesh_hollow); 0 keeps
 *       the solid.  The boundary, hence the bounding box, is unchanged.
 *     visual [none]: path of a finer triangle surface of the same object, in
 *       the mesh's file units (any format assimp reads; relative to the scene
 *       file), placed as the mesh is; the output carries it (/visual), each
 *       triangle riding on the rest tet that holds it, so exports and
 *       renders draw the object's own surface cut along the crack faces
 *       (docs/output.md).  The physics does not read it.
 *   }, ... }
 *   boundary = { {                        prescribed nodes (fracture mode)
 *     region = {type="box", min={..}, max={..}}            nodes inside, m
 *            | {type="plane", point={..}, normal={..}, tolerance [1e-6]}
 *                                          nodes within tolerance m of it
 *            | {type="group", name="..."}  a Gmsh physical group
 *     velocity = {vx,vy,vz} m/s   (prescribed) or fixed = true (velocity 0)
 *     axes ["xyz"]: the prescribed components ("z", "xy", ...)
 *     body [all]: 1-based body index the region applies to
 *   }, ... }  [{}]; needs solver.mode = "fracture"
 *   obstacles = { {type="plane", point={0,0,0}, normal={0,0,1}},
 *                 {type="sphere", center=..., radius=..., velocity={0,0,0}},
 *                 {type="box", center=..., half_extents=..., velocity={0,0,0}},
 *                 {type="mesh", file=..., scale [1], orientation [{1,0,0,0}]
 *                  (w,x,y,z, normalised), position [{0,0,0}] m} }
 *                 [{}]; `type` is required, as are a sphere's center and radius,
 *                 a box's center and half_extents and a mesh's file (no
 *                 sensible default).  Spheres and boxes move at their constant
 *                 velocity m/s (kinematic), planes and meshes are static.
 *                 mesh: a triangle surface (.obj, .off, .stl, or what assimp
 *                 reads: .ply, .gltf, .glb, .3ds, .fbx, .dae, ...), closed or
 *                 open; relative paths start at the scene file's directory
 *                 (as body mesh paths do) and the file must exist; its
 *                 vertices are scaled, then rotated, then moved by position
 *                 (where the file's origin goes).
 *                 Every type also takes friction [1] and restitution [1]:
 *                 factors >= 0 on the material's friction and restitution;
 *                 the contact's coefficient is their product (as Bullet
 *                 combines two bodies' coefficients), so 1 uses the
 *                 material's values and 0 a frictionless / fully plastic
 *                 obstacle (a restitution product above 1 adds energy)
 *   solver = {
 *     mode ["hybrid"]: rigid mode with fracture mode on impact
 *          | "fracture": every body stays in fracture mode (no rigid mode,
 *            no Bullet world) for the whole run
 *     rigid_backend ["bullet"] | "pbd"
 *     dt_rigid [1e-3] s, rigid_substeps [5] (Bullet sub-steps per dt_rigid);
 *       with mode = "fracture" it only paces output and checks, rounded down
 *       to a whole number of fracture steps
 *     ccd [true]: Bullet continuous collision detection for rigid fragments
 *       (no tunnelling of small, fast fragments through thin obstacles)
 *     sleeping = { linear [0.0] m/s, angular [0.0] rad/s }: Bullet
 *       deactivates (puts to sleep) a rigid body whose linear speed and
 *       angular speed both stay below these thresholds for 2 s; a contact
 *       with an awake body wakes it.  Both 0: no sleeping; otherwise both
 *       must be > 0
 *     dt_fracture [5e-6] s, check_interval [1] steps, quiet_steps [400]
 *     quiet_growth [0]: a fracture-mode fragment counts as quiet while the
 *       cohesive elements inserted (and tets crushed) since its quiet count
 *       restarted are at most this fraction of its cohesive elements; 0:
 *       quiet means no insertion (docs/physics.md §9)
 *     cfl_fraction [0]: when > 0, dt_fracture = cfl_fraction x dt_cfl of the
 *       mesh (docs/physics.md §3) instead of the dt_fracture value
 *     max_fracture_time [0.05] s (a fragment returns to rigid mode after this
 *       long in fracture mode even if still cracking)
 *     impact_threshold [0.2] m/s: the normal contact impulse a rigid fragment
 *       receives in one rigid step divided by its mass (m/s, i.e. the
 *       velocity change contact gives it); when it reaches this value the
 *       fragment goes to fracture mode; default 0.2 m/s
 *     elasticity ["corotational"] | "linear"
 *     criterion ["traction"] | "source": cohesive insertion rule, docs/physics.md §5
 *       (facet traction sigma_n >= sigma_max or tau >= tau_max; or the
 *       source's nodal-averaged max principal stress >= 0.9 sigma_max at all
 *       three facet nodes) | "none" (no insertion: elastic only)
 *     crack_growth ["fronts"] | "all": which qualifying facets a check
 *       inserts (docs/physics.md §5.1): "fronts" extends existing cracks
 *       across the edges of their facets, no faster than the Rayleigh wave
 *       speed, and nucleates a new crack only at a facet that touches no
 *       crack and no other facet inserted in that check (a local maximum of
 *       the criterion's ratio); "all" inserts every qualifying facet (the
 *       source's rule)
 *     front_direction ["any"] | "stress": with "fronts" and criterion
 *       "source", which facet across a front edge the crack may take: any
 *       whose vertex ahead reaches the threshold (the source's value at that
 *       vertex), or only one whose own normal stress (the nodal stress ahead
 *       across the facet's normal) reaches its threshold, the highest first:
 *       the maximum tangential stress criterion (docs/physics.md §5.1)
 *     front_threshold ["strength"] | "toughness": with "fronts" and
 *       criterion "source", the stress a front needs ahead of it: its facet's
 *       threshold, or at most K_IC / sqrt(2 pi r), K_IC = sqrt(E G_I) and r
 *       the rest distance of the vertex ahead from the front's edge: the
 *       field of a crack tip at the toughness (docs/physics.md §5.1)
 *     front_max_kink [180] degrees, (0, 180]: with "fronts", the most a
 *       front may turn from the crack facet whose edge it extends (in the
 *       rest shape; 0 straight ahead, 180 folded back onto it); 180: any
 *       (docs/physics.md §5.1)
 *     front_split ["none"] | "plane": with "fronts", "plane" duplicates
 *       each vertex of a new front facet that lies on its crack at once,
 *       cracking with the facet the facets of the vertex's star that part
 *       its tets on the two sides of the facet's plane (rest shape); "none"
 *       duplicates a vertex only once cracked facets cut its star
 *       (docs/physics.md §5.1)
 *     front_split_reach [0] m: with "plane", a split takes no facet whose
 *       rest centroid lies farther from the vertex it parts (a length of
 *       the material, such as l_ch, where the mesh is coarser; 0: no limit)
 *     front_snap ["none"] | "stress": with "fronts", "stress" moves the
 *       vertex ahead of each new front facet (inside the body, on no other
 *       crack, no crushed tet round it) onto the plane through the front's
 *       edge across the largest principal stress there, as far as its
 *       tets' shape allows (docs/physics.md §5.1)
 *     min_piece_tets [4] (integer >= 0): with "fronts", no insertion closes
 *       crack faces around a piece of at most this many tets (the mesh
 *       cannot resolve such a piece; 0: no bound)
 *     min_piece_size [0] m: with "fronts", nor around a piece whose sphere
 *       of equal volume is narrower (a size of the material rather than a
 *       count of elements, docs/physics.md §5.1 rule 4; 0: no bound)
 *     debris_tets [4] (integer >= 0) and debris_size [0] m: a piece of at
 *       most debris_tets tets, or whose sphere of equal volume is narrower
 *       than debris_size, is debris (docs/physics.md §9.2): it leaves
 *       fracture mode at once, never returns to it, and is a sphere of its
 *       own mass and inertia in Bullet.  0 turns each rule off; a real
 *       material's scene may set debris_size to its cohesive length
 *       l_ch = E G_I / sigma_max^2 (the plaster drop does)
 *     crack_plane = {point={..}, normal={..}, tolerance [1e-6] m}: a
 *       pre-selected crack path: only interior facets whose three vertices
 *       lie within tolerance of the plane are candidates for insertion
 *       (still by `criterion`)  [every interior facet]
 *     constraints ["pbd"]: the source's PBD bars | "xpbd": bars with
 *       compliance from E and each bar's tributary volume (Macklin 2016)
 *       | "none": pure explicit elasticity + CZM (needs dt <= dt_cfl)
 *     pbd = { k_stiffness [0.9], iterations [3], k_damping [1.0],
 *             iteration_independent [false]: use k' = 1 - (1-k)^(1/iterations) }
 *     xpbd = { compliance_scale [1] }: bar compliance = scale L^2/(E V_trib)
 *     contact_stiffness [0] Pa/m: crack-face penalty K_p of explicit runs
 *       (constraints = "none"; with PBD/XPBD the crack-contact constraint
 *       keeps the faces apart); 0 = the stability cap of each node pair,
 *       K_p A/3 = 1/(4 dt^2 (1/m_a + 1/m_b))
 *     time_continuity ["tangential"] | "both": with "both" a cohesive
 *       element's normal traction, as its tangential one always does,
 *       rises from zero with that capped stiffness until it meets the PPR
 *       envelope, instead of starting at the strength at zero opening
 *       (docs/physics.md §6)
 *     mass_scaling [0]: mass scaling (docs/physics.md §3.2): a tet
 *       whose stable step h/c_d lies below this fraction of the median
 *       tet's gets the density that raises it to that fraction (the added
 *       mass is printed in the summary); 0 = none, at most 1
 *     bulk_viscosity [0]: linear bulk viscosity b1 of fracture mode
 *       (docs/physics.md §2.3): each tet carries the volumetric viscous
 *       stress b1 rho c_d h tr(R^T dF/dt) I, which damps the mesh's
 *       highest modes (b1 of critical) and is booked as damping; 0 = none,
 *       at most 1 (Abaqus/Explicit's and LS-DYNA's default is 0.06)
 *     obstacle_contact ["kinematic"] | "penalty": how fracture-mode nodes
 *       meet obstacles in explicit runs (docs/physics.md §7.1): "kinematic"
 *       projects each node onto the surface and applies restitution per
 *       node (plastic at restitution 0); "penalty" pushes a node behind the
 *       surface out with a force k d, k = 0.01 m / dt^2 from its lumped mass
 *       (a conservative spring: the body's own elasticity makes the
 *       rebound, and the contact neither takes nor gives energy).  With
 *       PBD or XPBD the projection keeps the kinematic contact.
 *     guard = { max_inverted_fraction [0.01], max_energy_growth [0.5] }:
 *       stop (exit 3) when more than this fraction of the tets of a body's
 *       fragments in fracture mode are inverted, or when the total energy exceeds the initial energy plus
 *       all work input by this fraction of their sum
 *     threads [0] (0: all cores)
 *   }
 *   output = { file ["out/<name>.h5"] ("" for none; a relative path starts at
 *              the scene file's directory, as mesh paths do), frame_interval [0.01] s,
 *              cracks [true with solver.mode = "fracture", else false]: write
 *              every cohesive element's centroid, normal, area, opening and
 *              state at each frame to /cracks, fields [true]: write the
 *              tets of fracture-mode fragments at each frame to
 *              /fracture_mode (deformed corners, stress, damage; 21
 *              doubles and an int per tet, only while a fragment is in
 *              fracture mode) }
 */
#ifndef COHFRAC_SCENE_H
#define COHFRAC_SCENE_H

#include "cohfrac/error.h"
#include "cohfrac/mesh.h"
#include "cohfrac/types.h"

/* Where and what a run writes (the scene's `output` table). */
typedef struct cf_output_settings {
    char file[1024];             /* the HDF5 file; "" writes none */
    double frame_interval;       /* s between frames */
    int cracks;                  /* write /cracks at frames */
    int fields;                  /* write /fracture_mode (deformed tets, stress, damage of
                                    fracture-mode fragments) at frames */
} cf_output_settings;

/* A run: the world's physics and what the run loop (cohfrac/sim.h) does
 * with it.  Start from cf_default_scene() and fill in, or load a script. */
typedef struct cf_scene {
    char name[128];              /* the run's name: the output file's default name,
                                    messages, the HDF5 root's attribute */
    double duration;             /* s of simulated time */
    cf_world_def world;          /* what cf_world_create builds */
    cf_body_source *sources;     /* [world.n_bodies]: where each body's mesh comes from
                                    (mesh preparation makes world.bodies[i].tet_mesh) */
    cf_output_settings output;
    char *resolved;              /* the resolved scene as Lua text (every key, defaults
                                    filled, mesh paths absolute); loading it again gives
                                    this scene; NULL for a scene built in C */
} cf_scene;

/* frame_interval 0.01 s, fields on, cracks off, no file. */
cf_output_settings cf_default_output(void);
/* The world's defaults (cf_default_world_def), name "scene", duration 1 s,
 * cf_default_output(). */
cf_scene cf_default_scene(void);

/* Check what the run adds to the world definition: duration > 0, at
 * least one regular step (solver.dt_rigid <= duration), frame_interval
 * > 0.  The world's own values are cf_world_def_check's, at create.
 * Errors: CF_ERR_SCENE_VALUE naming the key. */
cf_status cf_scene_check(const cf_scene *s, cf_error *err);

/* Load and validate a scene script.  `overrides` are "key.path=value"
 * strings applied before validation.  Prepared mesh names are looked up in
 * `mesh_dir` as <mesh_dir>/<name>.node.
 * Errors: CF_ERR_FILE_OPEN, CF_ERR_SCENE_SYNTAX (file:line from Lua),
 * CF_ERR_SCENE_KEY (unknown key path, or missing required key),
 * CF_ERR_SCENE_TYPE (key path, expected and found type),
 * CF_ERR_SCENE_VALUE (key path, value, allowed range), CF_ERR_SCENE_OVERRIDE.
 * On error `out` is left empty. */
cf_status cf_scene_load(const char *path, const char *const *overrides, int n_overrides,
                        const char *mesh_dir, cf_scene *out, cf_error *err);

/* The same for a scene script held in memory: `name` stands for the file in
 * messages, and relative paths start at the working directory.  Errors as
 * cf_scene_load, without CF_ERR_FILE_OPEN for the script itself. */
cf_status cf_scene_load_text(const char *name, const char *text, const char *const *overrides,
                             int n_overrides, const char *mesh_dir, cf_scene *out, cf_error *err);

/* Free what cf_scene_load allocated and zero *s.  NULL and an already
 * freed (zeroed) scene are fine. */
void cf_scene_free(cf_scene *s);

#endif
