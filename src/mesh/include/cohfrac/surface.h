/* cohfrac — closed triangle surfaces and mesh preparation.
 *
 * Reads surfaces through assimp (OBJ, OFF, STL, PLY, glTF, 3DS, FBX,
 * COLLADA, ...), decimates them with meshoptimizer, finds and repairs
 * self-intersections, and turns a closed surface into a Tet4 mesh by running
 * the `tetgen` program (run as a program, never linked: AGPL).
 */
#ifndef COHFRAC_SURFACE_H
#define COHFRAC_SURFACE_H

#include "cohfrac/error.h"
#include "cohfrac/mesh.h"

#include <signal.h>

typedef struct cf_surface {
    int n_verts;
    int n_tris;
    double *v; /* [n_verts][3] vertex positions (file units) */
    int *tri;  /* [n_tris][3] 0-based, counter-clockwise seen from outside */
} cf_surface;

/* Load a surface with assimp (Debian libassimp-dev): every format it reads,
 * chosen by the extension (.obj, .off, .stl ASCII or binary, .ply, .gltf,
 * .glb, .3ds, .fbx, .dae, ...).  Every mesh of the file, node transforms
 * applied, polygons triangulated, corners at one position joined (normals,
 * texture coordinates and colours are dropped first); points, lines and
 * triangles with a repeated corner are dropped.  Coordinates as the file
 * has them (file units), read in single precision (assimp's; about 7
 * digits).  Vertices come in first-use order, triangles in file order;
 * unused vertices are not kept.  On error `s` is left empty.
 * Errors: CF_ERR_FILE_OPEN (missing, unreadable, a directory, or an
 * extension assimp does not know), CF_ERR_MESH_PARSE (assimp's reason, the
 * file named; no triangles; a coordinate that is not finite),
 * CF_ERR_MESH_INDEX (a face index past the vertex list), CF_ERR_NOMEM. */
cf_status cf_surface_load(const char *path, cf_surface *s, cf_error *err);

/* 1 when cf_surface_load reads files named like `path` (an extension
 * assimp supports, any case). */
int cf_surface_format_known(const char *path);

/* Write as OFF, 0-based, coordinates with %.17g (used to hand the surface
 * to tetgen).  Error CF_ERR_OUTPUT. */
cf_status cf_surface_write_off(const cf_surface *s, const char *path, cf_error *err);

/* Find pairs of triangles that intersect other than at a shared vertex or
 * edge.  Writes up to `max_pairs` pairs into pairs[2*k], pairs[2*k+1]
 * (triangle indices, 0-based; pairs sorted, lower index first) and returns
 * the total number found, -1 when out of memory.  Shared vertices and edges
 * of neighbouring triangles do not count; touching elsewhere does.  Uses
 * double-precision orientation tests (exact for exactly coplanar input such
 * as axis-aligned faces) and a uniform grid, O(n) for even meshes.  A
 * triangle with a repeated corner intersects every triangle near it. */
int cf_surface_self_intersections(const cf_surface *s, int *pairs, int max_pairs);

/* Repair the defect class of docs/scenes.md: a valence-3 vertex whose three
 * triangles overlap their neighbours.  Such a vertex is removed and its three
 * triangles replaced by the one triangle of its three neighbours.  Only
 * vertices touching an intersecting pair are considered; a vertex is kept
 * when the cap triangle already exists or a neighbour would drop below
 * valence 3.  Repeats (intersection search, removal) until no intersection
 * is left or nothing more can be removed.  Returns the number of vertices
 * removed (>= 0), -1 when out of memory.  The surface is compacted (dead
 * triangles and unused vertices dropped, order otherwise kept).  It does
 * not promise that no intersection remains: check afterwards. */
int cf_surface_repair_valence3(cf_surface *s);

/* Enclosed volume (divergence theorem), file units cubed; positive when the
 * triangles are counter-clockwise seen from outside. */
double cf_surface_volume(const cf_surface *s);

/* Reverse the orientation of every triangle (inside-out surfaces). */
void cf_surface_flip(cf_surface *s);

/* Drop vertices no triangle uses, renumbering the rest in order.  Returns
 * the number dropped, -1 when out of memory. */
int cf_surface_remove_unused(cf_surface *s);

/* Is the surface a closed, consistently oriented 2-manifold (every edge in
 * exactly two triangles with opposite directions, one fan per vertex)?
 * Returns 1 yes, 0 no (with the first problem, naming vertex/triangle
 * indices, in `why` if non-NULL), -1 out of memory. */
int cf_surface_check_closed(const cf_surface *s, char *why, size_t why_len);

/* Repair a surface that is not a closed manifold or intersects itself, with
 * CGAL's Polygon Mesh Processing (bullet_bridge/cf_cgal.h, Debian
 * libcgal-dev, run in the program cohfrac-repair): equal points joined,
 * degenerate and repeated triangles removed, one orientation, holes
 * closed, and intersections removed (overlapping closed parts become the
 * surface of their union, else the surface is cut along its intersections
 * and the parts inside removed); where no exact repair holds (non-manifold
 * edges), the surface's alpha wrap.  `s` is replaced; `report` (len bytes)
 * says what changed, one line.  CF_ERR_MESH_PARSE when CGAL cannot repair
 * it, CF_ERR_NOMEM.  The result is rounded to double: check it again. */
cf_status cf_surface_repair(cf_surface *s, char *report, size_t len, cf_error *err);

/* Replace `s` by its alpha wrap (CGAL alpha_wrap_3, bullet_bridge/cf_cgal.h):
 * a closed 2-manifold without self-intersections standing `offset` outside
 * `s`, closed over features thinner than about `alpha` (file units, > 0).
 * CF_ERR_MESH_PARSE when CGAL fails, CF_ERR_NOMEM. */
cf_status cf_surface_wrap(cf_surface *s, double alpha, double offset, cf_error *err);

/* Replace the closed manifold `s` by its isotropic remeshing towards edge
 * length `edge` (file units; CGAL, bullet_bridge/cf_cgal.h, run in
 * cohfrac-repair): near-equilateral triangles on the same shape, so that
 * no tet with a face on the surface is a sliver (docs/physics.md §3.1).
 * The result may intersect itself: check it.  Errors as cf_surface_wrap. */
cf_status cf_surface_remesh(cf_surface *s, double edge, cf_error *err);

/* Reduce to about `target_tris` triangles with meshoptimizer's
 * topology-preserving edge collapse (meshopt_simplify, Debian
 * libmeshoptimizer-dev: quadric error, no flipped triangles, the kept
 * vertices keep their positions), then drop unused vertices and repair
 * valence-3 vertices (cf_surface_repair_valence3: tetgen turns those into
 * slivers where the surface is flat).  Reproducible.  Stops early when no
 * valid collapse is left.  Returns the new triangle count, -1 when out of
 * memory.  It does not test for self-intersections: check afterwards. */
int cf_surface_decimate(cf_surface *s, int target_tris);

/* Split every triangle in four at its edge midpoints (one new vertex per
 * edge, shared by the triangles on both sides): the same surface, four
 * times the triangles, orientation kept.  For a surface too coarse for the
 * tet count asked.  0, or -1 when out of memory or past INT_MAX (then `s`
 * is unchanged apart from spare vertex capacity). */
int cf_surface_subdivide(cf_surface *s);

void cf_surface_free(cf_surface *s);

/* Seconds `cohfrac mesh` may take (all its tetgen runs) before the tetgen
 * run going on is stopped (CF_ERR_EXTERNAL). */
#define CF_MESH_TIME_LIMIT 300.0

/* Options for `cohfrac mesh`. */
typedef struct cf_mesh_prep_opts {
    const char *input;    /* surface file (any format cf_surface_load reads) */
    const char *output;   /* output base: writes <output>.node/.ele */
    int target_tets;      /* approximate number of tets wanted (0: tetgen -pq default) */
    int verbose;          /* print what is done to stderr */
    int no_repair;        /* 1: refuse an open or self-intersecting surface (after the
                             valence-3 repair) instead of repairing it with CGAL */
    double time_limit;    /* s for the whole preparation; 0: CF_MESH_TIME_LIMIT */
    const volatile sig_atomic_t *stop; /* NULL, or a flag a signal handler raises: tetgen
                                          is stopped, the temporary files removed, and
                                          CF_ERR_INTERRUPTED returned */
} cf_mesh_prep_opts;

/* Load, report self-intersections (face indices) and repair them, check the
 * surface is a closed manifold, coarsen it if `target_tets` needs it, run
 * tetgen, orient every tet positively, check the tets' total volume against
 * the surface's enclosed volume (1e-5 relative), peel the boundary caps
 * thinner than 0.25 of the median tet (cf_mesh_peel_slivers: the surface
 * changes by their volume, about 0.1-0.2 % of it), print the smallest
 * dihedral angle and dt_cfl of the worst tet over the median's (verbose),
 * and write
 * <output>.node/.ele (0-based, %.17g; coordinates in the surface's file
 * units and axes: no scaling or rotation).  The output directory is created
 * if missing.  Skips all work (printing "cached" when verbose) when the
 * outputs exist and are newer than the input and were made with the same
 * options and input (path, size, mtime; the stamp file <output>.stamp
 * records them).
 * Size: target_tets = N > 0 gives N tets within about 5 % (deterministic:
 * the same input always gives the same mesh): tetgen -pYq2.0 keeps the
 * surface; a surface too fine for N is decimated first (about 2.4 tets per
 * surface triangle) and a maximum tet volume -a fills up to N.  N = 0 runs
 * plain tetgen -pq on the full surface.  The stamp lists the options used.
 * Bounded: with a target, tetgen may add at most N points (-S N: about 4 N
 * tets), and the tetgen run going on when opts->time_limit runs out is
 * stopped.
 * The program is `tetgen` from PATH, or $COHFRAC_TETGEN; temporary files go
 * to $TMPDIR (default /tmp) and are removed.
 * A surface too coarse for N is subdivided (cf_surface_subdivide) before
 * the fill.  When the closest mesh is more than 25 % from N, nothing is
 * written: CF_ERR_USAGE names the count reached and what to ask for.
 * Errors: as cf_surface_load, CF_ERR_USAGE (missing paths, N < 0, N not
 * reachable within 25 %),
 * CF_ERR_MESH_PARSE (surface not closed or encloses no volume: names the
 * edge/vertex), CF_ERR_SURFACE_INTERSECT (intersections left after repair:
 * lists face pairs; a decimation that folds the surface is retried with
 * more triangles, up to the full surface), CF_ERR_EXTERNAL (tetgen missing
 * or failed: its output is quoted; or its tets do not fill the surface),
 * CF_ERR_MESH_INVERTED (degenerate tet in tetgen's output), CF_ERR_OUTPUT,
 * CF_ERR_NOMEM, CF_ERR_INTERRUPTED (opts->stop raised).  Temporary files are
 * removed on every return. */
cf_status cf_mesh_prepare(const cf_mesh_prep_opts *opts, cf_error *err);

/* The meshes a world definition names, made by mesh preparation: each
 * body's Tet4 mesh from its source (a prepared mesh or file, or a
 * primitive meshed and cached in `mesh_dir`; then hollowed when
 * hollow_layers > 0) and each mesh obstacle's surface.  Owns them; cf_world_meshes_free releases. */
typedef struct cf_world_meshes {
    int n_bodies, n_obstacles;
    cf_mesh *bodies;        /* [n_bodies] */
    cf_surface *obstacles;  /* [n_obstacles], empty for other types */
} cf_world_meshes;

/* Make what `def` needs and point def->bodies[i].tet_mesh (from src[i],
 * src[def->n_bodies]; NULL makes no body mesh) and the mesh obstacles'
 * vertices/triangles at it (those already set are kept).
 * `mesh_dir`: where primitives are meshed and cached (NULL: the user's
 * mesh cache, cf_default_mesh_dir).  Errors: those of cf_mesh_load,
 * cf_mesh_primitive, cf_mesh_hollow (the message names the body) and
 * cf_surface_load; CF_ERR_SCENE_VALUE for a surface with no triangle.
 * On error `out` is left empty and `def` unchanged. */
cf_status cf_world_meshes_load(cf_world_def *def, const cf_body_source *src, const char *mesh_dir,
                               cf_world_meshes *out, cf_error *err);
void cf_world_meshes_free(cf_world_meshes *m);

/* Where prepared meshes and meshed primitives live when no directory is
 * given, following the XDG base directory convention for caches:
 * $COHFRAC_MESH_DIR, else $XDG_CACHE_HOME/cohfrac/meshes (an absolute
 * XDG_CACHE_HOME), else $HOME/.cache/cohfrac/meshes, else
 * /tmp/cohfrac-meshes.  Never the working directory or the build tree, so
 * an installed program finds the same meshes from anywhere.  The string
 * lives until the program ends. */
const char *cf_default_mesh_dir(void);

#endif
