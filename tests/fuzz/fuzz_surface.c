/* libFuzzer harness: the surface reader (OBJ, OFF, STL ASCII and binary),
 * then the repair and self-intersection search that `cohfrac mesh` runs on
 * what it read.  The first byte picks the extension. */
#include "cohfrac/surface.h"
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const char *const names[] = {"s.obj", "s.off", "s.stl"};
    if (size < 1)
        return 0;
    const char *path = fuzz_write(names[data[0] % 3], data + 1, size - 1);
    cf_surface s;
    cf_error err;
    if (cf_surface_load(path, &s, &err) == CF_OK) {
        if (s.n_tris <= 2000) {
            int pairs[64];
            cf_surface_self_intersections(&s, pairs, 32);
            cf_surface_repair_valence3(&s);
        }
        cf_surface_free(&s);
    }
    return 0;
}
