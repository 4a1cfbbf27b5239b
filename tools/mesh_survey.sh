#!/bin/sh
# Run `cohfrac mesh --target-tets N` on each surface file given and print a
# Markdown table: triangles read, exit code, tets made and their
# distance from the target (or the first line of the error), wall time, and
# whether any temporary file was left (docs/reliability.md).
#
# usage: [COHFRAC=EXE] tools/mesh_survey.sh TARGET FILE...
#   COHFRAC default build/cohfrac
# Each run gets its own empty TMPDIR, checked afterwards; meshes are written
# to a scratch directory and removed.  Progress on stderr, the table on
# stdout.  Debian's cura STL files (docs/reliability.md):
#   apt-get download cura && dpkg-deb -x cura_*.deb cura
#   m=cura/usr/share/cura/resources/meshes
#   tools/mesh_survey.sh 20000 $m/*.stl $m/*.STL > survey.md
set -u
if [ $# -lt 2 ]; then
    echo "usage: tools/mesh_survey.sh TARGET FILE..." >&2
    exit 1
fi
target=$1
shift
exe=${COHFRAC:-$(dirname "$0")/../build/cohfrac}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "| file | triangles | exit | result | wall (s) | temporary files left |"
echo "|---|---|---|---|---|---|"
for f in "$@"; do
    [ -f "$f" ] || continue
    name=$(basename "$f")
    mkdir -p "$work/tmp" "$work/out"
    echo "meshing $name ..." >&2
    t0=$(date +%s.%N)
    TMPDIR="$work/tmp" timeout 600 "$exe" mesh "$f" -o "$work/out/m" --target-tets "$target" \
        >"$work/log" 2>&1
    rc=$?
    t1=$(date +%s.%N)
    tris=$(sed -n 's/.*: [0-9]* vertices, \([0-9]*\) triangles$/\1/p' "$work/log" | head -1)
    if [ $rc -eq 0 ]; then
        tets=$(sed -n 's/^tets //p' "$work/out/m.stamp")
        result=$(awk -v n="$tets" -v t="$target" 'BEGIN { printf "%d tets (%+.1f %%)", n, 100 * (n / t - 1) }')
    else
        result=$(grep -m1 'error\|cohfrac:' "$work/log" | sed 's/^cohfrac: error \[[A-Z_]*\]: //' |
            awk -v p="$f" '{ i = index($0, p); if (i) $0 = substr($0, 1, i - 1) "FILE" substr($0, i + length(p)); print }' |
            sed 's/|/\\|/g' | cut -c1-170)
    fi
    left=$(ls -A "$work/tmp" | wc -l)
    wall=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')
    printf '| %s | %s | %s | %s | %s | %s |\n' "$name" "${tris:--}" "$rc" "$result" "$wall" "$left"
    rm -rf "$work/tmp" "$work/out"
done
