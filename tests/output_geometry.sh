#!/bin/sh
# The output's geometry (docs/output.md) on a cube that cracks on the
# ground: tools/check_geometry.py (closed, outward surfaces enclosing their
# tets' volume, crack faces marked, posed surfaces above the floor, units),
# then `cohfrac export` writes glTF that tools/check_gltf.py reads back
# (a node and three channels per fragment, the last pose), and `cohfrac
# render` makes PNG frames and an MP4 of the run.
#   tests/output_geometry.sh COHFRAC SOURCE_DIR MESH_DIR
set -eu
exe=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$exe" run "$src/tests/data/box_break.lua" -q -m "$3" -o "$tmp/box.h5" > "$tmp/run.txt"
grep '^fragments' "$tmp/run.txt"
/usr/bin/python3 "$src/tools/check_geometry.py" "$tmp/box.h5"
/usr/bin/python3 "$src/tools/cohfrac_h5.py" "$tmp/box.h5"
"$exe" export "$tmp/box.h5" --format gltf -o "$tmp/box.glb"
/usr/bin/python3 "$src/tools/check_gltf.py" "$tmp/box.h5" "$tmp/box.glb"
if ! command -v ffmpeg >/dev/null; then
    echo "ffmpeg is not installed (make test's set-up installs it): render not checked"
    exit 0
fi
"$exe" render "$tmp/box.h5" --fps 10 --size 320x240
frames=$(ls "$tmp/box_frames" | grep -c '^frame_.*\.png$')
test -s "$tmp/box.mp4"
echo "render: $frames PNG frames and an MP4 of $(wc -c < "$tmp/box.mp4") bytes"
test "$frames" -eq "$(/usr/bin/python3 -c "import h5py,sys; print(len(h5py.File(sys.argv[1])['particles/fragments/position/step']))" "$tmp/box.h5")"
