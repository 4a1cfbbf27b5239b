/* libFuzzer harness: the TetGen loader and the mesh checks.  The input is
 * the .node text, a line "---", then the .ele text. */
#include "cohfrac/mesh.h"
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const uint8_t *sep = NULL;
    for (size_t i = 0; i + 5 <= size && !sep; i++)
        if (!memcmp(data + i, "\n---\n", 5))
            sep = data + i;
    size_t nn = sep ? (size_t)(sep - data) : size;
    fuzz_write("m.node", data, nn);
    const char *ele = sep ? fuzz_write("m.ele", sep + 5, size - nn - 5) : fuzz_write("m.ele", data, 0);
    (void)ele;
    cf_mesh m;
    cf_error err;
    if (cf_mesh_load_tetgen(fuzz_path("m"), &m, &err) == CF_OK)
        cf_mesh_free(&m);
    return 0;
}
