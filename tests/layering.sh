#!/bin/sh
# The module rule (tests/check_layering.sh, run by every build) holds on the
# tree, and catches a break: an engine source that includes a Lua, an HDF5,
# a mesh-preparation or a scene header, or that opens a file.
#   tests/layering.sh SOURCE_DIR
set -u
root=$1
fails=0
sh "$root/tests/check_layering.sh" "$root/src" || { echo "FAIL: the tree breaks the rule"; fails=1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for bad in '#include <lua.h>' '#include <hdf5.h>' '#include "cohfrac/mesh.h"' \
           '#include "cohfrac/scene.h"' '#include "cohfrac/h5_output.h"' \
           'static void f(void) { fopen("x", "w"); }'; do
    rm -rf "$tmp/src" && cp -r "$root/src" "$tmp/src"
    printf '%s\n' "$bad" >> "$tmp/src/engine/world_step.c"
    if sh "$root/tests/check_layering.sh" "$tmp/src" 2>/dev/null; then
        echo "FAIL: not caught in the engine: $bad"; fails=$((fails + 1))
    else
        echo "ok: caught in the engine: $bad"
    fi
done
rm -rf "$tmp/src" && cp -r "$root/src" "$tmp/src"
printf '#include "solid.h"\n' >> "$tmp/src/mesh/mesh_hollow.c"
if sh "$root/tests/check_layering.sh" "$tmp/src" 2>/dev/null; then
    echo "FAIL: mesh preparation reaching into the engine's private headers not caught"
    fails=$((fails + 1))
else
    echo "ok: caught: mesh preparation including an engine-private header"
fi
exit $((fails != 0))
