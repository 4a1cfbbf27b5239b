#!/bin/sh
# Real art meshes mesh (docs/reliability.md): Debian's glmark2 horse.3ds and
# cat.3ds intersect themselves (the cat also has holes) and were refused
# before CGAL's repair.  Each must now give a valid Tet4 mesh within 25 % of
# 5,000 tets (`cohfrac mesh` checks orientation, degeneracy and that the
# tets fill the surface before it writes), say on stderr what the repair
# changed, and keep its temporary files to itself; with --no-repair each is
# refused as before (exit 2) and nothing is written.
#   tests/mesh_repair.sh COHFRAC
set -u
exe=$1
models=/usr/share/glmark2/models
if [ ! -f "$models/horse.3ds" ]; then
    echo "glmark2-data is not installed (make test's set-up installs it): not checked"
    exit 0
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/tmp"
fails=0
for m in horse cat; do
    TMPDIR="$tmp/tmp" "$exe" mesh "$models/$m.3ds" -o "$tmp/$m" --target-tets 5000 \
        > "$tmp/$m.log" 2>&1
    rc=$?
    tets=$(sed -n 's/^tets //p' "$tmp/$m.stamp" 2>/dev/null)
    report=$(grep -c "repaired with CGAL" "$tmp/$m.log")
    left=$(ls -A "$tmp/tmp" | wc -l)
    echo "$m.3ds: exit $rc, ${tets:-no} tets, repair reported: $report, temporary files left: $left"
    grep "repaired with CGAL" "$tmp/$m.log" | cut -c1-400
    if [ "$rc" != 0 ] || [ "$report" != 1 ] || [ "$left" != 0 ] ||
        [ "${tets:-0}" -lt 3750 ] || [ "${tets:-0}" -gt 6250 ]; then
        cat "$tmp/$m.log"
        fails=$((fails + 1))
    fi
    "$exe" mesh "$models/$m.3ds" -o "$tmp/$m-raw" --target-tets 5000 --no-repair -q \
        > "$tmp/$m-raw.log" 2>&1
    rc=$?
    echo "$m.3ds --no-repair: exit $rc"
    if [ "$rc" != 2 ] || [ -e "$tmp/$m-raw.ele" ]; then
        cat "$tmp/$m-raw.log"
        fails=$((fails + 1))
    fi
done
exit $fails
