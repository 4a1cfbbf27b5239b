/* libFuzzer harness: the scene loader (sandboxed Lua, the schema, the
 * overrides), on the input as the script text.  Meshes are not made. */
#include "cohfrac/scene.h"
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    static const char *const sets[] = {"duration=0.5"};
    cf_scene def;
    cf_error err;
    if (cf_scene_load_text("fuzz.lua", text, sets, 1, fuzz_path("meshes"), &def, &err) == CF_OK)
        cf_scene_free(&def);
    free(text);
    return 0;
}
