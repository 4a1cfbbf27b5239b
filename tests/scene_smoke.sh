#!/bin/sh
# Smoke test of every scene script: each file under scenes/ (recursively,
# verification/ and compare/ included) must load and run a few rigid steps.
#
# usage: scene_smoke.sh COHFRAC_EXE MESH_DIR [SCENES_DIR]
#
# Each scene runs as
#   cohfrac run SCENE --set duration=<3 x its dt_rigid> --set output.file="" -q
# with dt_rigid read from the file's first `dt_rigid = <number>` (the
# default 1e-3 s when the file sets none).  Scenes whose body is the full
# prepared mesh "bunny" (~200k tets, made only by `make run`) run with
# --set bodies[1].mesh="bunny_small" instead, the mesh the test fixture
# `bunny_small` prepares.  Primitive meshes (gmsh) are cached in MESH_DIR,
# so a second run skips the meshing.  Exits non-zero, naming every scene
# that failed with its exit code and output, when any run fails.
set -u
exe=$1
meshes=$2
scenes=${3:-$(dirname "$0")/../scenes}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fails=0
count=0
find "$scenes" -name '*.lua' | sort >"$tmp/list"
while IFS= read -r scene; do
    count=$((count + 1))
    dt=$(sed -n 's/.*dt_rigid *= *\([0-9.eE+-]*\).*/\1/p' "$scene" | head -n 1)
    [ -n "$dt" ] || dt=1e-3
    set -- --set "duration=3*$dt" --set 'output.file=""'
    note=""
    if grep -q 'mesh *= *"bunny"' "$scene"; then
        set -- "$@" --set 'bodies[1].mesh="bunny_small"'
        note=" (bunny_small)"
    fi
    start=$(date +%s)
    "$exe" run "$scene" --mesh-dir "$meshes" -q "$@" >"$tmp/log" 2>&1 </dev/null
    rc=$?
    secs=$(($(date +%s) - start))
    if [ "$rc" -eq 0 ]; then
        echo "ok    ${secs}s  $scene$note"
    else
        echo "FAIL  exit $rc  $scene$note"
        sed 's/^/      /' "$tmp/log"
        fails=$((fails + 1))
    fi
done <"$tmp/list"
if [ "$count" -eq 0 ]; then
    echo "no scene found under $scenes"
    exit 1
fi
echo "$count scenes, $fails failed"
[ "$fails" -eq 0 ]
