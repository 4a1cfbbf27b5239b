/* Convex decomposition of a fragment for its Bullet collision shape
 * (docs/physics.md §9): convex hulls of the fragment's parts inside convex cells,
 * made by recursive bisection with planes until the hulls fit the tets.
 *
 * Error measure (reported per fragment): hull_volume / tet_volume - 1, the
 * summed volume of the hulls over the fragment's tet volume.  0 for a convex
 * fragment, > 0 where a hull bridges a concavity. */
#ifndef COHFRAC_DECOMPOSE_H
#define COHFRAC_DECOMPOSE_H

#include "solid.h"

typedef struct cf_hulls {
    double *pts;        /* [start[n_hulls]][3] hull vertices (rest frame), m */
    int *start;         /* [n_hulls + 1] first vertex of each hull */
    int n_hulls;
    double hull_volume; /* m^3, sum over the hulls */
    double tet_volume;  /* m^3 */
} cf_hulls;

/* Called with `user` after each cut of a decomposition: a large piece's
 * takes seconds, and a progress display should not stand still meanwhile. */
typedef void (*cf_decompose_tick)(void *user);

/* Decompose `tets` ([nt], rest positions s->X) into at most max_hulls convex
 * hulls: start from one cell (all space) and cut the cell whose hull
 * exceeds the fragment's volume inside it the most, by the plane through the
 * median of its pieces' centroids normal to their principal axis of spread,
 * until hull_volume <= (1 + max_error) tet_volume, max_hulls is reached, or
 * no cell of at least 2 min_tets tets is left to cut.  Tets straddling a cut
 * are clipped, so hulls meet on the cutting planes without overlap.
 * Deterministic.  tick(user) after each cut, unless tick is NULL.  Returns
 * 0, or -1 out of memory (out is then empty).  Free with cf_hulls_free. */
int cf_decompose(const cf_solid *s, const int *tets, int nt, double max_error, int max_hulls,
                 int min_tets, cf_hulls *out, cf_decompose_tick tick, void *user);

/* hull_volume / tet_volume - 1. */
double cf_hulls_error(const cf_hulls *h);

void cf_hulls_free(cf_hulls *h);

#endif
