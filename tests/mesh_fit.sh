#!/bin/sh
# The prepared bunnies are fit for fracture (docs/physics.md §3.1): no tet
# sets the explicit step far below the rest.  Reads what `cohfrac mesh`
# measured into each mesh's stamp: the worst tet's dt_cfl over the median
# tet's at least MIN_RATIO, and the smallest dihedral angle at least
# MIN_DIHEDRAL degrees.  Before the surface was remeshed the 3,858- and
# 13,857-tet bunnies gave 0.081 and 0.025 (1.9 and 1.0 degrees), and the
# 201,778-tet one 2.4e-5 (0.0005 degrees).
#   tests/mesh_fit.sh MESH_DIR NAME...
# Exit 0 when every mesh holds, 1 otherwise (each failure named).
set -u
MIN_RATIO=0.15
MIN_DIHEDRAL=4
dir=$1
shift
fails=0
for name in "$@"; do
    stamp=$dir/$name.stamp
    ratio=$(sed -n 's/^dt_cfl_worst_over_median //p' "$stamp")
    angle=$(sed -n 's/^min_dihedral_deg //p' "$stamp")
    tets=$(sed -n 's/^tets //p' "$stamp")
    if [ -z "$ratio" ] || [ -z "$angle" ]; then
        echo "FAIL: $stamp holds no quality (dt_cfl_worst_over_median, min_dihedral_deg)"
        fails=$((fails + 1))
    elif awk -v r="$ratio" -v a="$angle" -v mr=$MIN_RATIO -v ma=$MIN_DIHEDRAL \
        'BEGIN { exit !(r >= mr && a >= ma) }'; then
        echo "ok: $name ($tets tets): worst/median dt_cfl $ratio >= $MIN_RATIO, smallest dihedral $angle >= $MIN_DIHEDRAL deg"
    else
        echo "FAIL: $name ($tets tets): worst/median dt_cfl $ratio (at least $MIN_RATIO), smallest dihedral $angle deg (at least $MIN_DIHEDRAL)"
        fails=$((fails + 1))
    fi
done
[ "$fails" -eq 0 ]
