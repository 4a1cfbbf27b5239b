/* cohfrac — a surface in a private binary file, for the hand-over to and
 * from cohfrac-repair (src/repair/): the vertices as the machine's doubles,
 * so nothing is rounded on the way (OFF through assimp reads floats). */
#ifndef COHFRAC_SURFACE_RAW_H
#define COHFRAC_SURFACE_RAW_H

#include "cohfrac/surface.h"

/* Writes "cohfrac-surface 1\n", n_verts and n_tris (int), v then tri.
 * CF_ERR_OUTPUT (or CF_ERR_NOMEM) with the path named. */
cf_status cf_surface_write_raw(const cf_surface *s, const char *path, cf_error *err);

/* Reads what cf_surface_write_raw wrote into an empty `s`; CF_ERR_MESH_PARSE
 * for a file that is not one (or is cut short), CF_ERR_FILE_OPEN,
 * CF_ERR_NOMEM. */
cf_status cf_surface_read_raw(const char *path, cf_surface *s, cf_error *err);

#endif
