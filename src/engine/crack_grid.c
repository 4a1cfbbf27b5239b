#include "crack_grid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void cf_crack_grid_init(cf_crack_grid *g, double cell)
{
    memset(g, 0, sizeof *g);
    g->cell = cell;
}

void cf_crack_grid_free(cf_crack_grid *g)
{
    free(g->ijk), free(g->head), free(g->next), free(g->c);
    memset(g, 0, sizeof *g);
}

static unsigned slot_hash(const int ijk[3], int cap)
{
    unsigned h = (unsigned)ijk[0] * 73856093u ^ (unsigned)ijk[1] * 19349663u ^
                 (unsigned)ijk[2] * 83492791u;
    return h & (unsigned)(cap - 1);
}

/* The slot of cell ijk: where it is, or the empty slot where it would go. */
static int find_slot(const cf_crack_grid *g, const int ijk[3])
{
    unsigned s = slot_hash(ijk, g->cap);
    while (g->head[s] >= 0 && memcmp(&g->ijk[3 * s], ijk, 3 * sizeof(int)) != 0)
        s = (s + 1) & (unsigned)(g->cap - 1);
    return (int)s;
}

static void cell_of(const cf_crack_grid *g, const double c[3], int ijk[3])
{
    for (int k = 0; k < 3; k++)
        ijk[k] = (int)floor(c[k] / g->cell);
}

/* Twice the slots, every cell placed again; 0 or -1. */
static int grow_table(cf_crack_grid *g)
{
    cf_crack_grid old = *g;
    int cap = g->cap ? 2 * g->cap : 64;
    int *ijk = malloc((size_t)cap * 3 * sizeof(int)), *head = malloc((size_t)cap * sizeof(int));
    if (!ijk || !head) {
        free(ijk), free(head);
        return -1;
    }
    for (int s = 0; s < cap; s++)
        head[s] = -1;
    g->ijk = ijk, g->head = head, g->cap = cap;
    for (int s = 0; s < old.cap; s++)
        if (old.head[s] >= 0) {
            int to = find_slot(g, &old.ijk[3 * s]);
            memcpy(&g->ijk[3 * to], &old.ijk[3 * s], 3 * sizeof(int));
            g->head[to] = old.head[s];
        }
    free(old.ijk), free(old.head);
    return 0;
}

int cf_crack_grid_add(cf_crack_grid *g, const double c[3])
{
    if (g->n == g->cap_items) {
        int cap = g->cap_items ? 2 * g->cap_items : 64;
        int *next = realloc(g->next, (size_t)cap * sizeof(int));
        if (!next)
            return -1;
        g->next = next;
        double *cc = realloc(g->c, (size_t)cap * 3 * sizeof(double));
        if (!cc)
            return -1;
        g->c = cc, g->cap_items = cap;
    }
    if (2 * (g->used + 1) > g->cap && grow_table(g)) /* at most half full */
        return -1;
    int ijk[3];
    cell_of(g, c, ijk);
    int s = find_slot(g, ijk);
    if (g->head[s] < 0) {
        memcpy(&g->ijk[3 * s], ijk, sizeof ijk);
        g->used++;
    }
    memcpy(&g->c[3 * g->n], c, 3 * sizeof(double));
    g->next[g->n] = g->head[s];
    g->head[s] = g->n++;
    return 0;
}

int cf_crack_grid_near(const cf_crack_grid *g, const double c[3], double r)
{
    if (g->n == 0)
        return 0;
    int ijk[3];
    cell_of(g, c, ijk);
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++) {
                int q[3] = {ijk[0] + dx, ijk[1] + dy, ijk[2] + dz};
                for (int i = g->head[find_slot(g, q)]; i >= 0; i = g->next[i]) {
                    const double *p = &g->c[3 * i];
                    double d2 = (p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) +
                                (p[2] - c[2]) * (p[2] - c[2]);
                    if (d2 <= r * r)
                        return 1;
                }
            }
    return 0;
}
