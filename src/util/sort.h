/* Sorting plain arrays of numbers. */
#ifndef COHFRAC_SORT_H
#define COHFRAC_SORT_H

#include <stdlib.h>

static inline int cf_double_order(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* v[0..n) in ascending order. */
static inline void cf_doubles_sort(double *v, int n)
{
    qsort(v, (size_t)n, sizeof(double), cf_double_order);
}

#endif
