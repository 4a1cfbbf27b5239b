#include "renumber.h"

#include "linalg.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    uint64_t key;
    int group, index;
} keyed;

static int by_key(const void *a, const void *b)
{
    const keyed *x = a, *y = b;
    if (x->group != y->group)
        return x->group < y->group ? -1 : 1;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return (x->index > y->index) - (x->index < y->index);
}

/* Spread the low 21 bits of v to every third bit. */
static uint64_t spread3(uint64_t v)
{
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffull;
    v = (v | v << 16) & 0x1f0000ff0000ffull;
    v = (v | v << 8) & 0x100f00f00f00f00full;
    v = (v | v << 4) & 0x10c30c30c30c30c3ull;
    v = (v | v << 2) & 0x1249249249249249ull;
    return v;
}

static uint64_t morton(const double p[3], const double lo[3], const double span[3])
{
    uint64_t code = 0;
    for (int k = 0; k < 3; k++) {
        double u = span[k] > 0 ? (p[k] - lo[k]) / span[k] : 0;
        uint64_t q = (uint64_t)(fmin(fmax(u, 0.0), 1.0) * 2097151.0);
        code |= spread3(q) << k;
    }
    return code;
}

int cf_renumber_locality(cf_mesh *m, int *node_data, int *tet_body, int *user_of_tet)
{
    int nn = m->n_nodes, nt = m->n_tets;
    size_t big = (size_t)(nn > nt ? nn : nt);
    keyed *k = malloc(big * sizeof *k);
    int *new_of_node = malloc((size_t)nn * sizeof(int));
    void *tmp = malloc(big * 4 * sizeof(double));
    if (!k || !new_of_node || !tmp) {
        free(k), free(new_of_node), free(tmp);
        return -1;
    }
    double lo[3], hi[3], span[3];
    points_bbox(m->x, nn, lo, hi);
    for (int c = 0; c < 3; c++)
        span[c] = hi[c] - lo[c];
    for (int i = 0; i < nn; i++)
        k[i] = (keyed){morton(&m->x[3 * i], lo, span), 0, i};
    qsort(k, (size_t)nn, sizeof *k, by_key);
    double *x = tmp;
    int *d = tmp;
    for (int i = 0; i < nn; i++)
        new_of_node[k[i].index] = i, memcpy(&x[3 * i], &m->x[3 * k[i].index], 3 * sizeof(double));
    memcpy(m->x, x, (size_t)nn * 3 * sizeof(double));
    for (int i = 0; i < nn; i++)
        d[i] = node_data[k[i].index];
    memcpy(node_data, d, (size_t)nn * sizeof(int));
    for (int t = 0; t < nt; t++) {
        double c[3] = {0, 0, 0};
        for (int j = 0; j < 4; j++) {
            int n = m->tets[4 * t + j] = new_of_node[m->tets[4 * t + j]];
            v3_axpy(0.25, &m->x[3 * n], c);
        }
        k[t] = (keyed){morton(c, lo, span), tet_body[t], t};
    }
    qsort(k, (size_t)nt, sizeof *k, by_key);
    int *tets = tmp;
    for (int t = 0; t < nt; t++)
        memcpy(&tets[4 * t], &m->tets[4 * k[t].index], 4 * sizeof(int));
    memcpy(m->tets, tets, (size_t)nt * 4 * sizeof(int));
    for (int t = 0; t < nt; t++)
        user_of_tet[t] = k[t].index, tet_body[t] = k[t].group;
    free(k), free(new_of_node), free(tmp);
    return 0;
}
