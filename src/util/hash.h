/* The 64-bit FNV-1a hash: the state hash of a run, the names of cached
 * primitive meshes and of a study's cached runs. */
#ifndef COHFRAC_HASH_H
#define COHFRAC_HASH_H

#include <stddef.h>
#include <stdint.h>

#define CF_FNV1A_SEED 14695981039346656037ull

/* Continue hash h over n bytes (start from CF_FNV1A_SEED). */
static inline uint64_t cf_fnv1a(uint64_t h, const void *data, size_t n)
{
    const unsigned char *b = data;
    for (size_t i = 0; i < n; i++) {
        h ^= b[i];
        h *= 1099511628211ull;
    }
    return h;
}

#endif
