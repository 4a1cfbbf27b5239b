/* cohfrac — C face of CGAL's Polygon Mesh Processing for the repair of
 * surfaces that `cohfrac mesh` cannot tetrahedralise as they are: art and
 * CAD meshes that are polygon soups (the same point twice, degenerate or
 * repeated triangles, inconsistent orientation, non-manifold vertices),
 * that intersect themselves (overlapping parts of one model), or that have
 * small holes.  The implementation is C++ (CGAL 5.5, Debian's libcgal-dev);
 * no C++ type or exception crosses this header.  Coordinates are the
 * file's (any unit); the repair is exact (CGAL's exact constructions) and
 * the result is rounded to double once, at the end. */
#ifndef COHFRAC_CGAL_BRIDGE_H
#define COHFRAC_CGAL_BRIDGE_H

#ifdef __cplusplus
extern "C" {
#endif

/* How the self-intersections were removed (cfc_repair_report). */
enum {
    CFC_NONE_FOUND,          /* there were none */
    CFC_FIXED_BY_UNION,      /* separate closed parts overlapped: their union */
    CFC_FIXED_BY_AUTOREFINE, /* cut along the intersections, inner patches removed */
    CFC_WRAPPED,             /* the soup wrapped (alpha wrapping): no exact repair held */
    CFC_NOT_FIXED            /* internal: no exact removal worked */
};

/* The alpha wrap's size and distance from the input, against the diagonal
 * of the input's bounding box: alpha = diag / 100 keeps features of a
 * hundredth of the object, far finer than the tets a fracture mesh has;
 * the offset, diag / 2000, is how far the wrap stands off the input. */
#define CFC_WRAP_ALPHA_DIVISOR 100.0
#define CFC_WRAP_OFFSET_DIVISOR 2000.0

/* What cfc_repair_surface changed, for the report `cohfrac mesh` prints. */
typedef struct cfc_repair_report {
    int points_merged;       /* points at one position joined, or left unused */
    int faces_removed;       /* degenerate or repeated triangles removed */
    int faces_reoriented;    /* triangles turned to agree with their neighbours */
    int holes_filled;        /* border cycles closed with new triangles */
    int intersecting_pairs;  /* pairs of triangles that crossed before autorefinement */
    int intersections_fixed; /* CFC_NONE_FOUND ... CFC_NOT_FIXED */
    double wrap_alpha, wrap_offset; /* CFC_WRAPPED: the alpha and offset used (input units) */
    int faces_in, faces_out; /* triangle counts before and after */
} cfc_repair_report;

/* Repair a triangle surface: verts [nv][3], tris [nt][3] 0-based.  In
 * order, with CGAL::Polygon_mesh_processing:
 *   1. repair_polygon_soup: join equal points, drop degenerate and
 *      repeated triangles;
 *   2. the exact repair: orient_polygon_soup (a consistent orientation,
 *      when no vertex or edge must be split for it), stitch_borders and
 *      triangulate_hole on each border cycle left; then, when triangles
 *      intersect, corefine_and_compute_union of the connected components
 *      when they are separate closed surfaces that overlap (a multi-body
 *      model), else experimental::autorefine_and_remove_self_intersections
 *      (cut along the intersections, the patches inside removed);
 *      orient_to_bound_a_volume;
 *   3. when any part of 2 cannot be done (non-manifold edges, holes that
 *      do not close, intersections neither way removes): alpha_wrap_3 of
 *      the soup of step 1 (CFC_WRAPPED), which always gives a closed,
 *      oriented surface without self-intersections, a diagonal over
 *      CFC_WRAP_OFFSET_DIVISOR outside the input.
 * On success returns 0 and sets *v_out ([*nv_out][3]) and *tri_out
 * ([*nt_out][3]), malloc'd, to be freed by the caller, and fills *rep.
 * Returns -1 on failure (message in cfc_last_error(): out of memory, no
 * triangle left, CGAL refused the input) with the outputs untouched.  The
 * result may still intersect itself after rounding to double, or still be
 * open: the caller checks. */
int cfc_repair_surface(const double *verts, int nv, const int *tris, int nt, double **v_out,
                       int *nv_out, int **tri_out, int *nt_out, cfc_repair_report *rep);

/* CGAL's 3D alpha wrapping (alpha_wrap_3) of a triangle surface, which
 * may be anything (open, non-manifold, self-intersecting): a closed,
 * oriented 2-manifold without self-intersections that stands `offset`
 * outside every input triangle and closes over features thinner than about
 * `alpha` (both in input units, > 0).  Outputs and errors as
 * cfc_repair_surface. */
int cfc_wrap_surface(const double *verts, int nv, const int *tris, int nt, double alpha,
                     double offset, double **v_out, int *nv_out, int **tri_out, int *nt_out);

/* CGAL's isotropic remeshing (Polygon Mesh Processing,
 * isotropic_remeshing; Botsch and Kobbelt, SGP 2004) of a closed
 * manifold triangle surface: edges split, collapsed and flipped towards
 * `edge` (input units, > 0) and vertices smoothed tangentially and
 * projected back onto the input, CFC_REMESH_ITERATIONS times.  Its
 * triangles are near equilateral, which the skinny ones of a decimation
 * are not: a tet with a sliver face on the surface sets the explicit
 * step (docs/physics.md §3.1).  The result may intersect itself: the
 * caller checks.  Outputs and errors as cfc_repair_surface. */
#define CFC_REMESH_ITERATIONS 5
int cfc_remesh_surface(const double *verts, int nv, const int *tris, int nt, double edge,
                       double **v_out, int *nv_out, int **tri_out, int *nt_out);

/* Message of the last failure of this thread. */
const char *cfc_last_error(void);

#ifdef __cplusplus
}
#endif

#endif
