/* The cracked facets by place: a hash of cubic cells over their rest
 * centroids, for "is there a crack within r of this point" in the
 * nucleation rule (docs/physics.md §5.1) without a pass over every crack. */
#ifndef COHFRAC_CRACK_GRID_H
#define COHFRAC_CRACK_GRID_H

typedef struct cf_crack_grid {
    double cell;     /* m, the cell's edge (the largest radius asked for) */
    int cap, used;   /* hash slots (a power of two, or 0) and cells in use */
    int *ijk;        /* [cap][3] the cell of each slot */
    int *head;       /* [cap] the last facet added to the cell, -1: empty slot */
    int *next;       /* [n] the facet added to the same cell before it, -1 */
    double *c;       /* [n][3] rest centroid of each facet added, m */
    int n, cap_items;
} cf_crack_grid;

/* An empty grid of cells of edge `cell` (m, > 0). */
void cf_crack_grid_init(cf_crack_grid *g, double cell);
void cf_crack_grid_free(cf_crack_grid *g);

/* Adds a point (a cracked facet's rest centroid, m).  0, or -1 out of
 * memory (the grid unchanged). */
int cf_crack_grid_add(cf_crack_grid *g, const double c[3]);

/* Whether a point added lies within r (m, at most the cell's edge) of c. */
int cf_crack_grid_near(const cf_crack_grid *g, const double c[3], double r);

#endif
