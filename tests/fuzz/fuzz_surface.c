/* libFuzzer harness: what `cohfrac mesh` does with a surface after reading
 * it (the reading itself is assimp's): the closedness check, enclosed
 * volume, self-intersection search, valence-3 repair and decimation, on a
 * surface made from the input bytes.
 *   byte 0          vertex count n (1..64)
 *   then 3 n bytes  coordinates, signed, on a grid of 1/16 (coincident,
 *                   coplanar and collinear corners are common)
 *   then 3 bytes a triangle, indices mod n, until the input ends */
#include "cohfrac/surface.h"

#include <stdint.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    int n = 1 + data[0] % 64;
    if (size < 1 + 3 * (size_t)n)
        return 0;
    cf_surface s = {0};
    s.n_verts = n;
    s.n_tris = (int)((size - 1 - 3 * (size_t)n) / 3);
    if (s.n_tris == 0 || s.n_tris > 2000)
        return 0;
    s.v = malloc(3 * (size_t)n * sizeof *s.v);
    s.tri = malloc(3 * (size_t)s.n_tris * sizeof *s.tri);
    for (int i = 0; i < 3 * n; i++)
        s.v[i] = (int8_t)data[1 + i] / 16.0;
    const uint8_t *t = data + 1 + 3 * n;
    for (int i = 0; i < 3 * s.n_tris; i++)
        s.tri[i] = t[i] % n;
    char why[256];
    int closed = cf_surface_check_closed(&s, why, sizeof why);
    (void)cf_surface_volume(&s);
    int pairs[64];
    cf_surface_self_intersections(&s, pairs, 32);
    if (closed == 1) {
        cf_surface_repair_valence3(&s);
        cf_surface_decimate(&s, s.n_tris / 2);
    }
    cf_surface_free(&s);
    return 0;
}
