#!/bin/sh
# Every shipped scene against physical bounds: each scene under scenes/ runs
# at coarse settings (its own mesh, and the duration a line
# "-- plausibility: --set ..." in its header asks for, e.g. the first part of
# a long run), then tests/checks/check_physics.py checks the output.  Checks listed
# in tests/plausibility_known.txt may fail for their scene (and must: a
# listed failure that passes is reported, to be removed from the list).
#
# usage: plausibility.sh COHFRAC_EXE MESH_DIR [SCENES_DIR]
# Exit status 0 when every scene passes (known failures aside), 1 otherwise.
set -u
exe=$1
meshes=$2
here=$(dirname "$0")
scenes=${3:-$here/../scenes}
known=$here/plausibility_known.txt
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fails=0
count=0
find "$scenes" -name '*.lua' | sort >"$tmp/list"
while IFS= read -r scene; do
    count=$((count + 1))
    rel=${scene#"$scenes"/}
    set -- $(sed -n 's/^-- plausibility: *//p' "$scene" | head -n 1)
    start=$(date +%s)
    "$exe" run "$scene" --mesh-dir "$meshes" -q -o "$tmp/out.h5" "$@" >"$tmp/log" 2>&1 </dev/null
    rc=$?
    secs=$(($(date +%s) - start))
    if [ "$rc" -ne 0 ]; then
        echo "FAIL  exit $rc  $rel"
        sed 's/^/      /' "$tmp/log" | tail -n 5
        fails=$((fails + 1))
        continue
    fi
    /usr/bin/python3 "$here/checks/check_physics.py" "$tmp/out.h5" >"$tmp/check" 2>&1
    failed=$(sed -n 's/^  FAIL  \([a-z]*\).*/\1/p' "$tmp/check" | sort | tr '\n' ' ')
    expected=$(awk -v s="$rel" '$1 == s {print $2}' "$known" | sort | tr '\n' ' ')
    if [ "$failed" = "$expected" ]; then
        echo "ok    ${secs}s  $rel${expected:+  (known: $expected)}"
    else
        echo "FAIL  ${secs}s  $rel: failed [${failed}], known [${expected}]"
        sed 's/^/      /' "$tmp/check"
        fails=$((fails + 1))
    fi
done <"$tmp/list"
echo "$count scenes, $fails not as expected"
[ "$fails" -eq 0 ]
