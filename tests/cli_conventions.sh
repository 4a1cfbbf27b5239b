#!/bin/sh
# Command-line conventions: every subcommand's --help prints its own usage
# and exits 0, --version works after any subcommand, and a scene runs from
# another working directory: its meshes are found without --mesh-dir, its
# output lands beside the scene (or where -o says, relative to the working
# directory), and nothing is created where the user stands.
#   tests/cli_conventions.sh COHFRAC SCENES_DIR
set -u
exe=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
scenes=$(cd "$2" && pwd)
fails=0
check() { # check WHAT CONDITION...
    what=$1; shift
    if "$@"; then echo "ok: $what"; else echo "FAIL: $what"; fails=$((fails + 1)); fi
}

for sub in run compare mesh study stability bench render export; do
    out=$("$exe" "$sub" --help 2>&1); rc=$?
    check "cohfrac $sub --help exits 0" [ $rc -eq 0 ]
    check "cohfrac $sub --help shows its own usage" \
        sh -c 'printf "%s" "$1" | grep -q "cohfrac $2 "' - "$out" "$sub"
    v=$("$exe" "$sub" --version 2>&1); rc=$?
    check "cohfrac $sub --version exits 0" sh -c '[ $1 -eq 0 ] && printf "%s" "$2" | grep -q "^cohfrac [0-9]"' - $rc "$v"
done

# A copy of a scene in a directory of its own, run from a third directory.
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/project" "$tmp/elsewhere"
cp "$scenes/verification/free_spin.lua" "$tmp/project/spin.lua"
cd "$tmp/elsewhere" || exit 1
env -u COHFRAC_MESH_DIR "$exe" run ../project/spin.lua -q --set duration=0.005 >run.log 2>&1
rc=$?
check "a scene runs from another directory (exit $rc)" [ $rc -eq 0 ]
check "its output lands beside the scene" [ -f "$tmp/project/out/free_spin.h5" ]
check "the summary names that file" grep -q "output .*$tmp/project/out/free_spin.h5" run.log
check "the run ends at the duration exactly" grep -q "simulated time     0.005 s" run.log
left=$(ls -A "$tmp/elsewhere" | grep -v '^run.log$')
check "nothing is created in the working directory ($left)" [ -z "$left" ]
env -u COHFRAC_MESH_DIR "$exe" run ../project/spin.lua -q --set duration=0.002 -o here.h5 >/dev/null 2>&1
check "-o is relative to the working directory" [ -f "$tmp/elsewhere/here.h5" ]

[ $fails -eq 0 ] && echo "all command-line conventions hold" || echo "$fails failed"
exit $((fails != 0))
