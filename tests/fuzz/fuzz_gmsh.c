/* libFuzzer harness: the Gmsh .msh loader (2.2 and 4.x, ASCII and binary)
 * and the mesh checks. */
#include "cohfrac/mesh.h"
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_write("m.msh", data, size);
    cf_mesh m;
    cf_error err;
    if (cf_mesh_load_gmsh(path, &m, &err) == CF_OK)
        cf_mesh_free(&m);
    return 0;
}
