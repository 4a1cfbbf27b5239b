#!/bin/sh
# Every shipped scene against physical bounds: each scene under scenes/ runs
# at coarse settings (its own mesh, and the duration a line
# "-- plausibility: --set ..." in its header asks for, e.g. the first part of
# a long run), then tests/checks/check_physics.py checks the output.  Checks listed
# in tests/plausibility_known.txt may fail for their scene (and must: a
# listed failure that passes is reported, to be removed from the list).
#
# The scenes run JOBS at a time (2 by default), each on one thread: a
# run's outcome does not depend on its thread count (the state hash is the
# same at 1 and 2 threads), and the longest scene alone scales poorly over
# two threads, so two one-thread runs keep both cores busy.  Each lane takes
# the next scene nobody has taken (an atomic mkdir claims it); the report
# lists the scenes in their sorted order whatever order they finished in.
#
# usage: plausibility.sh COHFRAC_EXE MESH_DIR [SCENES_DIR [JOBS]]
# Exit status 0 when every scene passes (known failures aside), 1 otherwise.
set -u
exe=$1
meshes=$2
here=$(dirname "$0")
scenes=${3:-$here/../scenes}
jobs=${4:-2}
known=$here/plausibility_known.txt
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
find "$scenes" -name '*.lua' | sort >"$tmp/list"
count=$(wc -l <"$tmp/list")

# one N SCENE: run and check scene number N; its report line goes to
# $tmp/report.N, and $tmp/fail.N exists when it is not as expected.
# (Each lane is a subshell of its own, so the functions' variables are the
# lane's.)
one() {
    n=$1
    scene=$2
    rel=${scene#"$scenes"/}
    out=$tmp/out.$n
    set -- $(sed -n 's/^-- plausibility: *//p' "$scene" | head -n 1)
    start=$(date +%s)
    "$exe" run "$scene" --mesh-dir "$meshes" -q -t 1 -o "$out.h5" "$@" >"$out.log" 2>&1 </dev/null
    rc=$?
    secs=$(($(date +%s) - start))
    if [ "$rc" -ne 0 ]; then
        { echo "FAIL  exit $rc  $rel"; sed 's/^/      /' "$out.log" | tail -n 5; } >"$tmp/report.$n"
        : >"$tmp/fail.$n"
        return
    fi
    /usr/bin/python3 "$here/checks/check_physics.py" "$out.h5" >"$out.check" 2>&1
    failed=$(sed -n 's/^  FAIL  \([a-z]*\).*/\1/p' "$out.check" | sort | tr '\n' ' ')
    expected=$(awk -v s="$rel" '$1 == s {print $2}' "$known" | sort | tr '\n' ' ')
    if [ "$failed" = "$expected" ]; then
        echo "ok    ${secs}s  $rel${expected:+  (known: $expected)}" >"$tmp/report.$n"
    else
        { echo "FAIL  ${secs}s  $rel: failed [${failed}], known [${expected}]"
          sed 's/^/      /' "$out.check"; } >"$tmp/report.$n"
        : >"$tmp/fail.$n"
    fi
    rm -f "$out.h5" "$out.xdmf"
}

# lane: take the next unclaimed scene until none is left.
lane() {
    i=0
    while IFS= read -r scene; do
        i=$((i + 1))
        mkdir "$tmp/claim.$i" 2>/dev/null && one "$i" "$scene"
    done <"$tmp/list"
}

k=0
while [ $k -lt "$jobs" ]; do
    lane &
    k=$((k + 1))
done
wait

fails=0
i=0
while [ $i -lt "$count" ]; do
    i=$((i + 1))
    cat "$tmp/report.$i" 2>/dev/null || { echo "FAIL  scene $i of $count was not run"; : >"$tmp/fail.$i"; }
    [ -e "$tmp/fail.$i" ] && fails=$((fails + 1))
done
echo "$count scenes, $fails not as expected"
[ "$fails" -eq 0 ]
