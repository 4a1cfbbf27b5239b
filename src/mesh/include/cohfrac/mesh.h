/* cohfrac — mesh preparation: the TetGen .node/.ele and Gmsh .msh
 * loaders, meshed primitives, hollowing and the checks.  The mesh type
 * itself (cf_mesh) is the engine's, in cohfrac/tetmesh.h.
 *
 * A cf_mesh is a linear tetrahedral mesh in SI units (metres).  Tets are
 * positively oriented: det[x1-x0, x2-x0, x3-x0] > 0 (docs/physics.md §1).
 */
#ifndef COHFRAC_MESH_H
#define COHFRAC_MESH_H

#include "cohfrac/error.h"
#include "cohfrac/tetmesh.h"
#include "cohfrac/types.h"

/* Meshed primitives (scene bodies with `mesh = {type = ...}`), m. */
typedef enum {
    CF_PRIM_NONE = 0,
    CF_PRIM_BOX,           /* structured, in-engine: size, cells, tets_per_cell */
    CF_PRIM_SPHERE,        /* gmsh: radius, mesh_size */
    CF_PRIM_HOLLOW_SPHERE, /* gmsh: radius (outer), thickness, mesh_size */
    CF_PRIM_PLATE,         /* gmsh: size (x, y, thickness z), mesh_size */
    CF_PRIM_NOTCHED_BEAM   /* gmsh: size (length x, width y, height z), notch, mesh_size */
} cf_primitive_type;

typedef struct cf_primitive {
    cf_primitive_type type;
    double size[3];     /* box, plate, notched beam: edge lengths along x, y, z, m */
    int cells[3];       /* box: cells along x, y, z */
    int tets_per_cell;  /* box: 5 or 6 */
    double radius;      /* sphere, hollow sphere: outer radius, m */
    double thickness;   /* hollow sphere: shell thickness, m */
    double notch[3];    /* notched beam: depth (from the bottom face, z), width (x),
                           offset of the notch centre from mid-span (x), m */
    double mesh_size;   /* gmsh characteristic element length, m */
} cf_primitive;

/* Where mesh preparation finds or makes a body's Tet4 mesh, and the finer
 * surface that the output draws: a scene's bodies[i].mesh, hollow_layers
 * and visual.  The engine's cf_body_def holds the mesh made from it. */
typedef struct cf_body_source {
    char mesh[1024];           /* where a loader finds it: resolved path of a TetGen base
                                  (no extension) or a .msh file; "" for a primitive */
    cf_primitive primitive;    /* type CF_PRIM_NONE when `mesh` is a file */
    int hollow_layers;         /* > 0: keep only the tets within this many tet
                                  layers of the surface (a hollow shell); 0 solid */
    char visual[1024];         /* resolved path of a finer triangle surface of the same
                                  object, in the mesh's file units, that the output
                                  carries for drawing (docs/output.md); "" none */
} cf_body_source;


/* Load TetGen files `<base>.node` and `<base>.ele` (`base` may also be given
 * with either extension).  Accepts 0- or 1-based numbering (taken from the
 * first node index), `#` comments, blank lines, attributes and boundary
 * markers (ignored).  Tets must have 4 nodes.
 * Errors: CF_ERR_FILE_OPEN (file missing), CF_ERR_MESH_PARSE (file:line,
 * what was expected), CF_ERR_MESH_INDEX (tet index, node out of range),
 * CF_ERR_MESH_INVERTED (via cf_mesh_check), CF_ERR_NOMEM.
 * On error `m` is left empty (all zero). */
cf_status cf_mesh_load_tetgen(const char *base, cf_mesh *m, cf_error *err);

/* Reject inverted or degenerate tets: every tet needs signed volume
 * > 1e-12 * (mean edge length)^3.  Error CF_ERR_MESH_INVERTED names the first
 * bad tet (0-based) and its volume. */
cf_status cf_mesh_check(const cf_mesh *m, const char *what, cf_error *err);

/* Total volume, m^3 (sum of signed tet volumes). */
double cf_mesh_volume(const cf_mesh *m);

/* Signed volume of the tet (a,b,c,d): det[b-a, c-a, d-a] / 6, m^3. */
double cf_tet_volume(const double a[3], const double b[3], const double c[3], const double d[3]);

/* As cf_mesh_load_tetgen, but without cf_mesh_check: for raw mesher output
 * whose orientation is fixed afterwards with cf_mesh_orient_positive. */
cf_status cf_mesh_load_tetgen_unchecked(const char *base, cf_mesh *m, cf_error *err);

/* Swap nodes 2 and 3 of every tet with negative signed volume, so that
 * det[x1-x0, x2-x0, x3-x0] > 0.  Returns the number of tets flipped. */
int cf_mesh_orient_positive(cf_mesh *m);

/* What sets a Tet4 mesh's explicit step (src/mesh/mesh_quality.c). */
typedef struct cf_mesh_quality {
    double min_dihedral; /* smallest dihedral angle of any tet, degrees */
    double dt_ratio;     /* dt_cfl of the worst tet over that of the median one: the
                          * ratio of twice their inradii (dt_cfl = h / c_d,
                          * docs/physics.md §3); 1 for a uniform mesh */
    int worst_tet;       /* the tet that sets dt_cfl (0-based), -1 without tets */
} cf_mesh_quality;

/* The quality of m; NANs and worst_tet -1 for an empty mesh or no memory. */
cf_mesh_quality cf_mesh_quality_of(const cf_mesh *m);

/* Peel boundary slivers: remove each tet thinner than `fraction` of the
 * median h (twice the inradius, as measured before peeling) that has two or
 * three faces on the surface, where removing it leaves the surface a closed
 * 2-manifold (an edge flip of the surface, or one surface node fewer).
 * Nodes no tet uses any more are dropped and the rest renumbered in order.
 * *peeled gets the tets removed, *volume their volume (m^3).  Errors:
 * CF_ERR_USAGE (the mesh has node groups, whose numbering would break),
 * CF_ERR_NOMEM. */
cf_status cf_mesh_peel_slivers(cf_mesh *m, double fraction, int *peeled, double *volume,
                               cf_error *err);

/* Write `<base>.node` and `<base>.ele` (0-based, coordinates with %.17g so
 * they read back bit-exactly; `base` may carry either extension).  Each file
 * is written under a temporary name and renamed.  Errors: CF_ERR_OUTPUT,
 * CF_ERR_NOMEM. */
cf_status cf_mesh_write_tetgen(const cf_mesh *m, const char *base, cf_error *err);

/* Load a Gmsh MSH file: version 4.1 (ASCII or binary) or 2.2 (ASCII).
 * Only 4-node tetrahedra (element type 4) become tets; every element of a
 * physical group (any type) adds its nodes to the group; the groups become
 * named node sets (m->groups, sorted by dimension then tag, named by their
 * physical name, or "<dim>:<tag>" when unnamed).  Node i is the i-th node of
 * the file (tags may have gaps or any order); nodes no tet uses are kept.
 * Tets are re-oriented to positive volume, then checked as cf_mesh_check.
 * Sections other than $MeshFormat, $PhysicalNames, $Entities, $Nodes and
 * $Elements are skipped.
 * Errors: CF_ERR_FILE_OPEN; CF_ERR_MESH_PARSE (file:line, or file: byte N in
 * binary files; what was expected); CF_ERR_MESH_FORMAT (version 4.0 or
 * other unsupported version, 2.2 binary, an unknown element type, or no
 * 4-node tetrahedra: the message says how to re-export, e.g.
 * `gmsh -3 -format msh41 file.geo`); CF_ERR_MESH_INDEX (an element refers
 * to a node not in $Nodes); CF_ERR_MESH_INVERTED; CF_ERR_NOMEM.  On error
 * `m` is left empty. */
cf_status cf_mesh_load_gmsh(const char *path, cf_mesh *m, cf_error *err);

/* Load a volume mesh by extension: `.msh` (Gmsh), else a TetGen pair. */
cf_status cf_mesh_load(const char *path, cf_mesh *m, cf_error *err);

/* A structured box centred at the origin: size[k] m along axis k split into
 * cells[k] cells, each cut into 5 (alternating) or 6 (Kuhn) positive tets;
 * both meshes are conforming.  Node (i,j,k) of the grid has index
 * (k*(cells[1]+1) + j)*(cells[0]+1) + i.  No groups.
 * Errors: CF_ERR_SCENE_VALUE (non-positive size or cells, tets_per_cell not 5
 * or 6), CF_ERR_NOMEM. */
cf_status cf_mesh_box(const double size[3], const int cells[3], int tets_per_cell, cf_mesh *m,
                      cf_error *err);

/* Mesh a primitive: a box in-engine; the others by running
 * `gmsh -3 -format msh41` ($COHFRAC_GMSH overrides the program) on a
 * generated .geo script (OpenCASCADE kernel, Mesh.CharacteristicLengthMax =
 * mesh_size), cached in `cache_dir` (created if missing; NULL or "" means
 * ".") as <type>_<16 hex digits: FNV-1a hash of the script, which prints
 * every parameter>.msh, with the .geo beside it.  The mesh is written under
 * a temporary name, then renamed, so a second call just loads the cache.
 * Each primitive is centred at the origin (bounding-box centre).  Notched
 * beam: the slot is cut up from the bottom face z = -size[2]/2, through the
 * whole width y.
 * Errors: CF_ERR_SCENE_VALUE (bad parameters), CF_ERR_EXTERNAL (gmsh
 * missing or failed: its output is quoted), CF_ERR_OUTPUT (cache not
 * writable), the errors of cf_mesh_load_gmsh, CF_ERR_NOMEM. */
cf_status cf_mesh_primitive(const cf_primitive *p, const char *cache_dir, cf_mesh *m,
                            cf_error *err);

/* Hollow a mesh out (scene key bodies[i].hollow_layers): keep only the tets
 * within `layers` tet layers of the boundary and drop the rest.  The
 * boundary is the set of faces used by one tet only; layer 1 is every tet
 * with a boundary face or a node on the boundary, layer k+1 every tet that
 * shares a node with a tet of layer k.  Nodes no kept tet uses are dropped
 * and the others renumbered in their old order; tets keep their order and
 * orientation; node groups lose the dropped nodes and are renumbered
 * (still ascending).  The boundary, hence the bounding box, is unchanged.
 * Errors (the mesh is then left as it was): CF_ERR_SCENE_VALUE when
 * layers < 1, when nothing would be removed (every tet is within `layers`
 * of the boundary: a coarse mesh) or nothing kept (no tets); CF_ERR_NOMEM. */
cf_status cf_mesh_hollow(cf_mesh *m, int layers, cf_error *err);

#endif
