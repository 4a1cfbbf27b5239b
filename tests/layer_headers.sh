#!/bin/sh
# The compiler enforces the layering (docs/architecture.md): with each
# module's own include path, as CMake gives it to that module, a header of
# the module's own layer compiles and a header of every layer above it, of
# the engine's private folder, or of a library the layer must not use, is
# not found.
#   tests/layer_headers.sh CC MODULE=DIR:DIR:... ...
# Exit 0 when every probe goes as expected, 1 otherwise (each failure named).
set -u
cc=$1
shift
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fails=0

# probe MODULE DIRS HEADER: 0 when HEADER compiles on DIRS, 1 when it is not
# found, 2 on any other error (a probe that fails for another reason proves
# nothing about visibility).
probe() {
    flags=$(printf '%s\n' "$2" | tr ':' '\n' | sed '/^$/d; s/^/-I/')
    # shellcheck disable=SC2086
    if printf '#include "%s"\n' "$3" | $cc -std=c11 -fsyntax-only $flags -x c - 2> "$tmp/err"; then
        return 0
    fi
    grep -q "No such file" "$tmp/err" && return 1
    cat "$tmp/err"
    return 2
}

# expect MODULE DIRS OWN_HEADER FORBIDDEN_HEADER...
expect() {
    module=$1 dirs=$2 own=$3
    shift 3
    probe "$module" "$dirs" "$own"
    if [ $? -eq 0 ]; then
        echo "ok: $module sees its own $own"
    else
        echo "FAIL: $module does not compile its own $own"; fails=$((fails + 1))
    fi
    for h in "$@"; do
        probe "$module" "$dirs" "$h"
        case $? in
        1) echo "ok: $module cannot see $h" ;;
        0) echo "FAIL: $module sees $h, a header above its layer"; fails=$((fails + 1)) ;;
        *) echo "FAIL: $module: the probe of $h failed for another reason"; fails=$((fails + 1)) ;;
        esac
    done
}

cli_h='bench.h compare.h study.h stability.h'
io_h='cohfrac/scene.h cohfrac/sim.h cohfrac/h5_output.h cohfrac/cohfrac.h lua.h hdf5.h cf_gltf.h'
mesh_h='cohfrac/mesh.h cohfrac/surface.h'
for arg in "$@"; do
    module=${arg%%=*}
    dirs=${arg#*=}
    case $module in
    util)   expect util "$dirs" cohfrac/error.h $mesh_h $io_h $cli_h solid.h ;;
    engine) expect engine "$dirs" cohfrac/world.h $mesh_h $io_h $cli_h ;;
    mesh)   expect mesh "$dirs" cohfrac/surface.h cohfrac/scene.h cohfrac/sim.h cohfrac/h5_output.h \
                $cli_h solid.h fracture.h ;;
    io)     expect io "$dirs" cohfrac/sim.h $cli_h solid.h fracture.h ;;
    cli)    expect cli "$dirs" bench.h solid.h fracture.h ;;
    *)      echo "layer_headers: unknown module '$module'" >&2; exit 2 ;;
    esac
done
[ $# -eq 5 ] || { echo "FAIL: expected the five modules, got $#"; fails=$((fails + 1)); }
exit $((fails != 0))
