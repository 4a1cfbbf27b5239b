/* cohfrac — Tet4 volume meshes: the TetGen .node/.ele loader and checks.
 *
 * A cf_mesh is a linear tetrahedral mesh in SI units (metres).  Tets are
 * positively oriented: det[x1-x0, x2-x0, x3-x0] > 0 (DESIGN §2).
 */
#ifndef COHFRAC_MESH_H
#define COHFRAC_MESH_H

#include "cohfrac/error.h"

typedef struct cf_mesh {
    int n_nodes;
    int n_tets;
    double *x; /* [n_nodes][3] node positions, m */
    int *tets; /* [n_tets][4] 0-based node indices */
} cf_mesh;

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

/* Write `<base>.node` and `<base>.ele` (0-based, coordinates with %.17g so
 * they read back bit-exactly; `base` may carry either extension).  Each file
 * is written under a temporary name and renamed.  Errors: CF_ERR_OUTPUT,
 * CF_ERR_NOMEM. */
cf_status cf_mesh_write_tetgen(const cf_mesh *m, const char *base, cf_error *err);

/* Release the arrays and zero `m` (NULL or an empty mesh is fine). */
void cf_mesh_free(cf_mesh *m);

#endif
