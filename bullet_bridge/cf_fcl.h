/* cohfrac — C face of FCL (the Flexible Collision Library) for point queries
 * against triangle meshes: mesh obstacles seen by fracture-mode nodes
 * (docs/physics.md §9), and the deforming surfaces of fracture-mode fragments of
 * other bodies (contact_bodies.c).  The implementation is C++; no C++ type
 * or exception crosses this header.  Units SI (m).  Queries are thread-safe on a
 * built mesh (they do not modify it); cff_mesh_update is not. */
#ifndef COHFRAC_FCL_BRIDGE_H
#define COHFRAC_FCL_BRIDGE_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct cff_mesh cff_mesh;

/* Build a bounding-volume hierarchy over a triangle mesh: verts [nv][3] m,
 * tris [nt][3] 0-based, counter-clockwise seen from outside (the outward
 * side).  The arrays are copied.  NULL on error (message in
 * cff_last_error()): nv < 3, nt < 1, a non-finite vertex, an index out of
 * range, a triangle of zero area (repeated or collinear corners). */
cff_mesh *cff_mesh_create(const double *verts, int nv, const int *tris, int nt);
void cff_mesh_destroy(cff_mesh *m);

/* As cff_mesh_create, for a mesh that cff_mesh_update will move often: its
 * hierarchy is of axis-aligned boxes, cheap to refit (oriented boxes, the
 * default, fit tighter but each refit solves an eigenproblem per box). */
cff_mesh *cff_mesh_create_deforming(const double *verts, int nv, const int *tris, int nt);

/* Bytes the mesh holds: FCL's hierarchy (vertices, triangles, bounding
 * volume nodes, primitive indices) and the copies and normals kept here. */
size_t cff_mesh_bytes(const cff_mesh *m);

/* Closest point of the mesh to p, looked for within max_dist (m, >= 0,
 * inclusive up to round-off; INFINITY for no bound).  Returns 1 and fills q
 * (closest point on the mesh, m), n (unit outward normal at q: the
 * triangle's normal, or the angle-weighted pseudo-normal at an edge or
 * vertex, also when p - q is along a face's normal) and *d (signed
 * distance, m: > 0 in front of the surface, < 0 behind it; the sign is
 * exact for a closed, consistently oriented mesh); 0 when no part of the
 * mesh is within max_dist (outputs untouched); -1 on error (NULL argument,
 * non-finite p, negative or NaN max_dist). */
int cff_mesh_closest(const cff_mesh *m, const double p[3], double max_dist, double q[3],
                     double n[3], double *d);

/* As cff_mesh_closest, and also the triangle q lies on (*tri, 0-based, in
 * the order given to cff_mesh_create) and q's barycentric coordinates on it
 * (bary[3], q = bary[0] a + bary[1] b + bary[2] c for its corners in order).
 * tri and bary may be NULL. */
int cff_mesh_closest_tri(const cff_mesh *m, const double p[3], double max_dist, double q[3],
                         double n[3], double *d, int *tri, double bary[3]);

/* Move every vertex to verts [nv][3] (nv as at creation; the triangles
 * stay) and refit the hierarchy to them, for a deforming surface.  A
 * triangle that has become degenerate keeps its last normal.  Returns 0, or
 * -1 on error (NULL argument, a non-finite vertex; the mesh is then
 * unchanged). */
int cff_mesh_update(cff_mesh *m, const double *verts);

/* Message of the last failed call (per thread). */
const char *cff_last_error(void);

#ifdef __cplusplus
}
#endif
#endif
