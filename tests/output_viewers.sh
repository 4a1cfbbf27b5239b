#!/bin/sh
# Other tools open the exported fragments of a cube that cracks on the
# ground (tests/data/box_break.lua):
#   blender   Blender 3.4 (Debian `blender`, headless), set up by `cohfrac
#             blender-setup`, imports `cohfrac export`'s glTF with the
#             importer's default options: a mesh object per fragment with a
#             surface, and the largest
#             fragment at the end where the HDF5 file has it (within 1 mm);
#   paraview  ParaView 5.11 (`paraview`, `python3-paraview`, through xvfb-run)
#             plays `cohfrac export --format pvd`: at the last frame the
#             connected surface pieces are the fragments alive; at the first
#             frame with fracture-mode tets, ParaView's volume of those
#             deformed tets is the volume of the corners the HDF5 file has
#             for them (/fracture_mode), damage lies in [0, 1] and the
#             stress is not zero; the XDMF sidecar's fracture_mode grid at
#             that time holds the same tets and volume.
# Skipped, with a line saying so, where the program is not installed.
#   tests/output_viewers.sh blender|paraview COHFRAC SOURCE_DIR MESH_DIR
set -eu
tool=$1
exe=$2
src=$3
need=blender
[ "$tool" = paraview ] && need="pvpython xvfb-run"
for p in $need; do
    if ! command -v "$p" >/dev/null; then
        echo "$p is not installed (make test's set-up installs it): $tool not checked"
        exit 0
    fi
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$exe" run "$src/tests/data/box_break.lua" -q -m "$4" -o "$tmp/box.h5" > /dev/null
# What the HDF5 file says: fragments with a surface, alive at the end, the
# largest of those, the last time and its position there.
set -- $(/usr/bin/python3 - "$tmp/box.h5" "$src/python" <<'PY'
import sys
sys.path.insert(0, sys.argv[2])
from cohfrac import h5 as cohfrac_h5
r = cohfrac_h5.load(sys.argv[1])
n = sum(1 for i in range(r.n_fragments) if len(r.fragment(i).triangles))
big = max(r.alive(-1), key=lambda i: r.fragments["mass"][i])
import numpy as np
deformed = 0.0
for k in range(len(r.times)):
    fm = r.fracture_tets_at(k)
    if fm is not None:
        deformed = sum(abs(np.linalg.det(t[1:] - t[0])) for t in fm["corners"]) / 6
        break
print(n, len(r.alive(-1)), big, r.times[-1], *r.position[-1, big], deformed)
PY
)
n=$1 alive=$2 big=$3 t_end=$4 hx=$5 hy=$6 hz=$7 h5_volume=$8
if [ "$tool" = blender ]; then
    "$exe" export "$tmp/box.h5" --format gltf -o "$tmp/box.glb" > /dev/null
    # As a user would: `cohfrac blender-setup` once, then Blender with its
    # own start-up (user scripts on) and the importer's default options.
    HOME=$tmp "$exe" blender-setup > /dev/null
    HOME=$tmp blender -b --python "$src/tests/checks/blender_check.py" -- \
        "$tmp/box.glb" "$big" "$t_end" > "$tmp/out.txt" 2>&1 || { cat "$tmp/out.txt"; exit 1; }
    got=$(awk '$1 == "objects" {print $2}' "$tmp/out.txt")
    pos=$(awk '$1 == "position" {print $2, $3, $4}' "$tmp/out.txt")
    echo "Blender: $got mesh objects (HDF5: $n fragments with a surface); fragment $big at t = $t_end s: ($pos) m, HDF5 ($hx, $hy, $hz) m"
    [ "$got" = "$n" ]
    /usr/bin/python3 -c "import sys; a = [float(v) for v in sys.argv[1].split()]; b = [float(v) for v in sys.argv[2:]]; sys.exit(max(abs(p - q) for p, q in zip(a, b)) > 1e-3)" "$pos" "$hx" "$hy" "$hz"
    # The set-up never overwrites a file of its script's name that holds
    # something else: exit 4, the file as it was.
    script=$(find "$tmp/.config" -name cohfrac_numpy_bool.py 2>/dev/null | head -n 1)
    if [ -n "$script" ]; then
        echo "# the user's own" > "$script"
        rc=0
        HOME=$tmp "$exe" blender-setup 2> /dev/null || rc=$?
        [ "$rc" = 4 ] && [ "$(cat "$script")" = "# the user's own" ]
        echo "blender-setup beside another file of its name: exit $rc, the file kept"
    fi
else
    "$exe" export "$tmp/box.h5" --format pvd -o "$tmp/pvd" > /dev/null
    HOME=$tmp xvfb-run -a pvpython "$src/tests/checks/paraview_check.py" "$tmp/pvd/box_break.pvd" \
        "$tmp/box.xdmf" > "$tmp/out.txt" 2>&1 || { cat "$tmp/out.txt"; exit 1; }
    pieces=$(awk '$1 == "pieces" {print $2}' "$tmp/out.txt")
    echo "ParaView: $(awk '$1 == "times" {print $2}' "$tmp/out.txt") time steps; at the last, $pieces connected surface pieces; the HDF5 file has $alive fragments alive"
    [ "$pieces" = "$alive" ]
    set -- $(awk '$1 == "fracture" {print $2, $3, $4, $5, $6}' "$tmp/out.txt")
    echo "ParaView: first fracture-mode frame t = $1 s, $2 deformed tets of volume $3 m3 (HDF5 corners: $h5_volume m3), damage up to $4, von Mises stress up to $5 Pa"
    /usr/bin/python3 -c "import sys; v, v0, d, s = map(float, sys.argv[1:]); sys.exit(not (abs(v / v0 - 1) < 1e-9 and 0 <= d <= 1 and s > 0))" "$3" "$h5_volume" "$4" "$5"
    tets=$2
    set -- $(awk '$1 == "xdmf" {print $2, $3}' "$tmp/out.txt")
    echo "ParaView: the XDMF sidecar's fracture_mode grid at that time: ${1:-no} tets of volume ${2:-no} m3"
    [ "${1:-0}" = "$tets" ]
    /usr/bin/python3 -c "import sys; v, v0 = map(float, sys.argv[1:]); sys.exit(not abs(v / v0 - 1) < 1e-9)" "$2" "$h5_volume"
fi
