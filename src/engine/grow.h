/* Growth of the engine's growable arrays. */
#ifndef COHFRAC_GROW_H
#define COHFRAC_GROW_H

#include <stdlib.h>

/* Room for at least n elements of `elem` bytes in *v, whose capacity is
 * *cap elements: doubled from *cap (from `first` when it is 0) until n
 * fit.  The elements held are kept; the new ones are not initialised.
 * Returns 0, or -1 out of memory with *v and *cap as they were. */
static inline int cf_grow_to(void **v, int *cap, int n, size_t elem, int first)
{
    if (n <= *cap)
        return 0;
    int c = *cap ? *cap : first;
    while (c < n)
        c *= 2;
    void *p = realloc(*v, (size_t)c * elem);
    if (!p)
        return -1;
    *v = p, *cap = c;
    return 0;
}

#endif
