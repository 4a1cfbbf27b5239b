#!/bin/sh
# Run every scene of scenes/ at its default settings, one after another, and
# print a Markdown table of what each run's summary says: mesh size,
# simulated time, wall time, fragments at the end, and how the run ended.
#
# usage: tools/scene_times.sh [COHFRAC_EXE [MESH_DIR [SCENES_DIR]]]
#   defaults: build/cohfrac, build/meshes (or $COHFRAC_MESH_DIR), scenes/
#
# scenes/verification/ and scenes/compare/ are left out (ctest runs those).
# Each run writes its HDF5 file to a temporary directory (removed at the
# end) instead of out/; every other setting is the scene's own.  "wall" is
# the run's own wall time from its summary (gmsh meshes a primitive the
# first time it is used, a few seconds more, cached afterwards).  Progress
# goes to stderr, the table to stdout:
#   tools/scene_times.sh > times.md
set -u
here=$(dirname "$0")
exe=${1:-$here/../build/cohfrac}
meshes=${2:-${COHFRAC_MESH_DIR:-$here/../build/meshes}}
scenes=${3:-$here/../scenes}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

find "$scenes" -name '*.lua' ! -path '*/verification/*' ! -path '*/compare/*' | sort >"$tmp/list"
echo "| scene | nodes / tets | simulated | wall | fragments at the end | end |"
echo "|---|---|---|---|---|---|"
fails=0
while IFS= read -r scene; do
    name=${scene#"$scenes"/}
    echo "running $name ..." >&2
    "$exe" run "$scene" --mesh-dir "$meshes" -q -o "$tmp/run.h5" >"$tmp/log" 2>&1 </dev/null
    rc=$?
    rm -f "$tmp/run.h5" "$tmp/run.xdmf"
    # "mesh               3982 tets, 1334 nodes (1975 after duplication)"
    mesh=$(sed -n 's/^mesh  *\([0-9]*\) tets, \([0-9]*\) nodes.*/\2 \/ \1/p' "$tmp/log" | head -n 1)
    # "simulated time     1 s in 500 rigid steps ..."
    sim=$(sed -n 's/^simulated time  *\([^ ]*\) s .*/\1 s/p' "$tmp/log" | head -n 1)
    wall=$(sed -n 's/^wall time  *\([^ ]*\) s.*/\1 s/p' "$tmp/log" | head -n 1)
    # "fragments          164 alive (0 in fracture mode), 166 ever"
    frag=$(sed -n 's/^fragments  *\([0-9]*\) alive.*/\1/p' "$tmp/log" | head -n 1)
    if [ "$rc" -eq 0 ]; then
        end="ok"
    else
        fails=$((fails + 1))
        why=$(sed -n 's/^cohfrac: error \[\([A-Z_]*\)\].*/\1/p' "$tmp/log" | head -n 1)
        end="exit $rc${why:+ ($why)}"
        sed 's/^/    /' "$tmp/log" | head -n 3 >&2
    fi
    echo "| \`$name\` | ${mesh:--} | ${sim:--} | ${wall:--} | ${frag:--} | $end |"
    echo "  $name: ${wall:-?} wall, ${frag:-?} fragments, $end" >&2
done <"$tmp/list"
[ "$fails" -eq 0 ]
