#!/bin/sh
# The one-way rule between modules (docs/architecture.md), checked on every
# build: exit 1, naming the file and line, when a source includes a header
# of a module above its own, or when an engine source does file I/O.
#   tests/check_layering.sh SRC_DIR
src=${1:-src}
status=0

# forbid MODULE REGEX WHY: no #include line in src/MODULE matching REGEX.
forbid() {
    hits=$(grep -nE "^[[:space:]]*#[[:space:]]*include[[:space:]]*[<\"]($2)" \
           "$src/$1"/*.c "$src/$1"/*.h 2>/dev/null)
    if [ -n "$hits" ]; then
        echo "$hits" | sed "s|\$| : $3|" >&2
        status=1
    fi
}

cli='cohfrac/(bench|compare|study|stability)\.h|report\.h'
io='lua\.h|lauxlib\.h|lualib\.h|hdf5\.h|H5[A-Za-z]*\.h|h5_quiet\.h|cohfrac/(scene|h5_output|sim)\.h|trajectory\.h'
mesh='cohfrac/(mesh|surface)\.h'
engine_private='solid\.h|def_check\.h|world_events\.h|world_ledger\.h|arena\.h|grow\.h|profile\.h|parallel\.h|tet4\.h|cohesive\.h|cohesive_law\.h|cohesive_ppr\.h|obstacle\.h|insertion\.h|pbd\.h|contact\.h|decompose\.h|fragment\.h|pieces\.h|fracture\.h|handoff\.h|renumber\.h|world_impl\.h|cf_bullet\.h|cf_fcl\.h'

forbid engine "$cli|$io|$mesh|file_text\.h|process\.h" \
    "the engine depends on no Lua, HDF5, mesh preparation, files or programs"
forbid mesh "$cli|$io|$engine_private" \
    "mesh preparation uses the engine's public headers only, and no I/O module"
forbid io "$cli|$engine_private" "I/O uses the engine's public headers only"
forbid util "cohfrac/(world|types|tetmesh|mesh|surface|scene|sim|h5_output)\.h|$engine_private" \
    "util depends on nothing of the project but error.h"

# File I/O calls in the engine (stdio is not included, but say why).
hits=$(grep -nE '\b(fopen|fprintf|printf|fputs|fwrite|popen|getenv|system|posix_spawnp?)[[:space:]]*\(' \
       "$src"/engine/*.c "$src"/engine/*.h 2>/dev/null)
if [ -n "$hits" ]; then
    echo "$hits" | sed 's|$| : the engine does no file I/O; push an event or add a query|' >&2
    status=1
fi
[ $status -eq 0 ] || echo "check_layering: the module rule is broken (docs/architecture.md)" >&2
exit $status
