/* Node and tet renumbering for memory locality (a Morton space-filling
 * curve), applied once at load: nodes near each other in space, and the
 * tets that hold them, sit near each other in the arrays, so the gathers
 * of the element loop and the bar sweeps hit the caches. */
#ifndef COHFRAC_RENUMBER_H
#define COHFRAC_RENUMBER_H

#include "cohfrac/tetmesh.h"

/* Renumber mesh m in place: nodes by the Morton code of their position in
 * the mesh's bounding box (21 bits per axis), tets by (tet_body, Morton code
 * of the centroid); ties keep the input order.  node_data ([n_nodes]) is
 * permuted with the nodes and tet_body ([n_tets]) with the tets;
 * user_of_tet ([n_tets], out) gets the input index of each new tet.
 * Returns 0, or -1 when out of memory (m untouched). */
int cf_renumber_locality(cf_mesh *m, int *node_data, int *tet_body, int *user_of_tet);

#endif
