/* cohfrac — a body's visual surface, embedded in its rest tets.
 *
 * A scene may give a body `visual`: a finer triangle surface of the same
 * object (the bunny's 70k triangles where the Tet4 mesh has 1k tets), in
 * the mesh's file units.  cf_visual_embed places it as the world placed
 * the mesh (x' = position + scale R (x - c), c the mesh's bounding-box
 * centre) and gives each triangle the rest tet that holds its centroid,
 * or the nearest one (the fine surface lies a little off the coarse
 * mesh's).  A fragment then draws the triangles whose tet it owns, plus
 * its crack faces (docs/output.md). */
#ifndef COHFRAC_VISUAL_H
#define COHFRAC_VISUAL_H

#include "cohfrac/error.h"
#include "cohfrac/surface.h"
#include "cohfrac/types.h"

typedef struct cf_visual {
    int n_vertices, n_triangles;
    double *vertices; /* [n_vertices][3] m, placed as the rest mesh */
    int *triangles;   /* [n_triangles][3] 0-based */
    int *tet;         /* [n_triangles] rest tet holding the triangle */
} cf_visual;

/* The visual surfaces of def's bodies (src[b].visual, "" for none), placed
 * as def places the bodies and embedded in the rest
 * mesh X [nn][3], tets [nt][4] (the world's, after renumbering).
 * `meshes`: the bodies' meshes as loaded (file units), for the placement.
 * `threads`: the OpenMP threads the embedding may use (the run's, >= 1).
 * An empty result when no body has one.  Errors: those of cf_surface_load
 * (the message names the body), CF_ERR_NOMEM. */
cf_status cf_visual_embed(const cf_world_def *def, const cf_body_source *src,
                          const cf_world_meshes *meshes,
                          const double *X, int nn, const int *tets, int nt, int threads,
                          cf_visual *out, cf_error *err);
void cf_visual_free(cf_visual *v);

#endif
