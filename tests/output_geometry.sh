#!/bin/sh
# The output's geometry (docs/output.md) on a cube that cracks on the
# ground: tests/checks/check_geometry.py (closed, outward surfaces enclosing their
# tets' volume, crack faces marked, posed surfaces above the floor, units),
# then `cohfrac export` writes glTF that tests/checks/check_gltf.py reads back
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
/usr/bin/python3 "$src/tests/checks/check_geometry.py" "$tmp/box.h5"
/usr/bin/python3 "$src/python/cohfrac/h5.py" "$tmp/box.h5"
"$exe" export "$tmp/box.h5" --format gltf -o "$tmp/box.glb"
/usr/bin/python3 "$src/tests/checks/check_gltf.py" "$tmp/box.h5" "$tmp/box.glb"
# A file torn by a kill during a flush (docs/output.md): the orientations a
# row short of the other per-frame datasets, the ids a column wider (a
# frame's new fragment), the root attribute `frames` counting the whole
# frames.  The export reads those only (it read the longest two, and the
# orientation past its end).
cp "$tmp/box.h5" "$tmp/torn.h5"
/usr/bin/python3 - "$tmp/torn.h5" <<'PY'
import sys, h5py, numpy as np
with h5py.File(sys.argv[1], "r+") as f:
    q = f["particles/fragments/orientation/value"]
    q.resize(q.shape[0] - 1, axis=0)
    ids = f["particles/fragments/id/value"]
    ids.resize(ids.shape[1] + 1, axis=1)
    f.attrs["frames"] = np.int64(q.shape[0])
PY
"$exe" export "$tmp/torn.h5" --format gltf -o "$tmp/torn.glb"
/usr/bin/python3 "$src/tests/checks/check_gltf.py" "$tmp/torn.h5" "$tmp/torn.glb"
"$exe" export "$tmp/box.h5" --format pvd -o "$tmp/pvd"
/usr/bin/python3 - "$tmp/box.h5" "$tmp/pvd" "$src/python" <<'PY'
# The ParaView series: a .vtu per frame whose cells carry every alive
# fragment (read back with meshio), their velocity field, and a .pvd that
# lists them.
import os, sys
sys.path.insert(0, sys.argv[3])
import meshio, numpy as np
from cohfrac import h5 as cohfrac_h5
run = cohfrac_h5.load(sys.argv[1])
for k in (0, len(run.times) - 1):
    m = meshio.read(os.path.join(sys.argv[2], f"frame_{k:04d}.vtu"))
    got = sorted(set(np.concatenate(m.cell_data["fragment"]).tolist()))
    assert got == sorted(run.alive(k)), (k, got, run.alive(k))
    # velocity: each fragment's rigid motion at its vertices, from the file
    import h5py
    w = h5py.File(sys.argv[1])["particles/fragments/angular_velocity/value"][k]
    fid = np.concatenate(m.cell_data["fragment"])
    tri = m.cells_dict["triangle"]
    for i in got:
        vs = np.unique(tri[fid == i])
        want = run.velocity[k, i] + np.cross(w[i], m.points[vs] - run.position[k, i])
        err = np.abs(m.point_data["velocity"][vs] - want).max()
        assert err <= 1e-9 * (1 + np.abs(want).max()), (k, i, err)
    assert set(m.cell_data) >= {"fragment", "crack", "mode", "mass"}, m.cell_data.keys()
print(f"pvd: frames 0 and {len(run.times) - 1} hold the alive fragments "
      f"({len(run.alive(0))} and {len(run.alive(-1))})")
PY
grep -q 'frame_0000.vtu' "$tmp/pvd/box_break.pvd"
# The object's own surface (/visual): the plaster drop's first 3 ms on the
# 1k-tet bunny carry its 70k-triangle OBJ; the export draws every visual
# triangle once among the fragments alive at the end (check_gltf.py).
"$exe" run "$src/scenes/plaster_bunny_drop.lua" -q -m "$3" -o "$tmp/vis.h5" \
    --set duration=0.003 > "$tmp/vis.txt"

/usr/bin/python3 -c "import h5py,sys; f=h5py.File(sys.argv[1]); t=f['visual/tet'][:]; n=len(f['mesh/rest/tets']); assert len(t) > 50000 and t.min() >= 0 and t.max() < n, (len(t), t.min(), t.max()); print(f'visual: {len(t)} triangles on {n} rest tets')" "$tmp/vis.h5"
"$exe" export "$tmp/vis.h5" --format gltf -o "$tmp/vis.glb"
/usr/bin/python3 "$src/tests/checks/check_gltf.py" "$tmp/vis.h5" "$tmp/vis.glb"
# The ParaView series draws it too: at a frame with every fragment rigid,
# each visual triangle once (crack = 0), and the collision view beside it.
"$exe" export "$tmp/vis.h5" --format pvd -o "$tmp/vispvd" > /dev/null
/usr/bin/python3 - "$tmp/vis.h5" "$tmp/vispvd" "$src/python" <<'PY'
import os, sys
sys.path.insert(0, sys.argv[3])
import meshio
from cohfrac import h5 as cohfrac_h5
run = cohfrac_h5.load(sys.argv[1])
n_vis = len(run.visual["triangles"])
rigid = [k for k in range(len(run.times)) if run.fracture_tets_at(k) is None]
assert rigid, "no frame with every fragment rigid"
k = rigid[-1]
m = meshio.read(os.path.join(sys.argv[2], f"frame_{k:04d}.vtu"))
crack = m.cell_data["crack"][0]
drawn = int((crack == 0).sum())
assert drawn == n_vis, (drawn, n_vis)
assert os.path.exists(os.path.join(sys.argv[2], "plaster_bunny_drop_collision.pvd"))
print(f"pvd: frame {k} draws the {n_vis} visual triangles once, and {int(crack.sum())} crack "
      "faces; the collision view is beside it")
PY
if ! command -v ffmpeg >/dev/null; then
    echo "ffmpeg is not installed (make test's set-up installs it): render not checked"
    exit 0
fi
n_out=$(/usr/bin/python3 -c "import h5py,sys; print(len(h5py.File(sys.argv[1])['particles/fragments/position/step']))" "$tmp/box.h5")
# Both engines, by default a movie frame per output frame.
for engine in matplotlib auto; do
    rm -rf "$tmp/box_frames" "$tmp/box.mp4"
    "$exe" render "$tmp/box.h5" --fps 10 --size 320x240 --engine $engine
    frames=$(ls "$tmp/box_frames" | grep -c '^frame_.*\.png$')
    test -s "$tmp/box.mp4"
    echo "render ($engine): $frames PNG frames and an MP4 of $(wc -c < "$tmp/box.mp4") bytes"
    test "$frames" -eq "$n_out"
done
# A span in slow motion: 0.1 s of the run 5 times slower is 0.5 s, 6 frames at 10 fps.
rm -rf "$tmp/box_frames"
"$exe" render "$tmp/box.h5" --fps 10 --size 320x240 --from 0.4 --to 0.5 --slow-motion 5
test "$(ls "$tmp/box_frames" | grep -c '^frame_.*\.png$')" -eq 6
