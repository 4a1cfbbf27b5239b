#!/usr/bin/python3
"""Check a glTF export (cohfrac export) against the run it came from.

    tests/checks/check_gltf.py OUT.h5 OUT.glb

Reads the .glb's JSON and binary chunks (glTF 2.0 container: a 12-byte
header, then length-type-data chunks) with the standard library and numpy,
and checks: one node per fragment that has a surface, each with a mesh;
one animation with translation, rotation and scale channels per node;
the largest fragment's last key equals its HDF5 pose at the last frame
(glTF +y up: cohfrac (x, y, z) is (x, z, -y)); its mesh has the surface's
triangle count; a fragment is hidden (scale 0) exactly where it is not
alive; each node's crack faces are a primitive of the material "crack"
(as many as the file's crack faces), and its extras hold the fragment's
record (fragment, mass, parent, birth_time, n_tets; mode 0, 1 or -1).
With a visual surface (/visual), every visual triangle is drawn by exactly
one fragment alive at the end, in place of the rest mesh's outer faces.  Exit status 0 when all hold, 1 otherwise.
"""
import json
import os
import struct
import sys

# The reader, from the source tree's Python package.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))
import h5py
import numpy as np

from cohfrac import h5 as cohfrac_h5  # noqa: E402

COMPONENTS = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}
DTYPES = {5126: np.float32, 5125: np.uint32}


def read_glb(path):
    data = open(path, "rb").read()
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    if magic != b"glTF" or version != 2 or length != len(data):
        raise ValueError(f"{path}: not a glTF 2.0 binary ({magic}, version {version})")
    off, doc, binary = 12, None, b""
    while off < length:
        n, kind = struct.unpack_from("<I4s", data, off)
        chunk = data[off + 8:off + 8 + n]
        if kind == b"JSON":
            doc = json.loads(chunk)
        elif kind == b"BIN\x00":
            binary = chunk
        off += 8 + n
    return doc, binary


def accessor(doc, binary, i):
    a = doc["accessors"][i]
    v = doc["bufferViews"][a["bufferView"]]
    k = COMPONENTS[a["type"]]
    start = v.get("byteOffset", 0) + a.get("byteOffset", 0)
    arr = np.frombuffer(binary, DTYPES[a["componentType"]], a["count"] * k, start)
    return arr.reshape(a["count"], k) if k > 1 else arr


def main(h5, glb):
    run = cohfrac_h5.load(h5)
    doc, binary = read_glb(glb)
    fails = []
    with_surface = [i for i in range(run.n_fragments) if len(run.fragment(i).triangles)]
    nodes = doc["nodes"]
    if len(nodes) != len(with_surface):
        fails.append(f"{len(nodes)} nodes for {len(with_surface)} fragments with a surface")
    anims = doc.get("animations", [])
    if len(anims) != 1:
        fails.append(f"{len(anims)} animations, expected 1")
    byname = {n["name"]: k for k, n in enumerate(nodes)}
    chans = {}
    for c in anims[0]["channels"] if anims else []:
        chans[(c["target"]["node"], c["target"]["path"])] = anims[0]["samplers"][c["sampler"]]
    masses = run.fragments["mass"]
    with h5py.File(h5, "r") as f:  # a visual surface replaces the rest mesh's outer faces
        n_visual = len(f["visual/triangles"]) if "visual" in f else None
    n_outer_end = 0
    alive_end = run.alive(-1)
    big = max(alive_end, key=lambda i: masses[i])
    k = byname.get(f"fragment_{big}")
    checked = 0
    for i in with_surface:
        node = byname.get(f"fragment_{i}")
        if node is None or "mesh" not in nodes[node]:
            fails.append(f"fragment {i}: no node with a mesh")
            continue
        if any((node, p) not in chans for p in ("translation", "rotation", "scale")):
            fails.append(f"fragment {i}: missing an animation channel")
            continue
        scale = accessor(doc, binary, chans[(node, "scale")]["output"])[:, 0]
        alive = run.ids[:, i] >= 0 if i < run.ids.shape[1] else np.zeros(len(run.times), bool)
        if not np.array_equal(scale > 0, alive):
            fails.append(f"fragment {i}: shown at {int((scale > 0).sum())} keys, alive at "
                         f"{int(alive.sum())} frames")
        checked += 1
    if k is not None:
        tr = accessor(doc, binary, chans[(k, "translation")]["output"])[-1]
        com = run.position[-1, big]
        want = np.array([com[0], com[2], -com[1]])
        err = np.abs(tr - want).max()
        if err > 1e-5 * max(1.0, np.abs(want).max()):
            fails.append(f"fragment {big}: last key {tr} against the HDF5's {want}")
        prims = doc["meshes"][nodes[k]["mesh"]]["primitives"]
        ntri = sum(doc["accessors"][p["indices"]]["count"] // 3 for p in prims)
        if n_visual is None and ntri != len(run.fragment(big).triangles):
            fails.append(f"fragment {big}: {ntri} triangles in the mesh, "
                         f"{len(run.fragment(big).triangles)} in the file")
    # Crack faces: a second primitive with the material "crack", holding as
    # many triangles as the fragment's surface has crack faces.
    materials = [m.get("name") for m in doc.get("materials", [])]
    n_inner = 0
    for i in with_surface:
        node = byname.get(f"fragment_{i}")
        if node is None:
            continue
        prims = doc["meshes"][nodes[node]["mesh"]]["primitives"]
        inner = sum(doc["accessors"][p["indices"]]["count"] // 3 for p in prims
                    if materials[p["material"]] == "crack")
        want = int(np.count_nonzero(run.fragment(i).crack))
        if inner != want:
            fails.append(f"fragment {i}: {inner} triangles with the crack material, {want} "
                         f"crack faces in the file")
        n_inner += inner
        if i in alive_end:
            n_outer_end += sum(doc["accessors"][p["indices"]]["count"] // 3 for p in prims) - inner
        # Extras: the fragment's record, as the HDF5 has it.
        ex = nodes[node].get("extras", {})
        rec = {"fragment": i, "mass": masses[i], "parent": run.fragments["parent"][i],
               "birth_time": run.fragments["birth_time"][i],
               "n_tets": run.fragments["n_tets"][i]}
        for key, v in rec.items():
            if key not in ex or abs(ex[key] - float(v)) > 1e-12 * max(1.0, abs(float(v))):
                fails.append(f"fragment {i}: extras {key} = {ex.get(key)}, the file has {v}")
                break
        if ex.get("mode") not in (0, 1, -1):
            fails.append(f"fragment {i}: extras mode = {ex.get('mode')}")
    # Every visual triangle rides with exactly one fragment alive at the end.
    if n_visual is not None and n_outer_end != n_visual:
        fails.append(f"the fragments alive at the end draw {n_outer_end} visual triangles, the "
                     f"file has {n_visual}")
    if k is not None:
        print(f"{glb}: {len(nodes)} nodes, {len(anims)} animation, {checked} fragments' "
              f"channels checked; largest fragment {big} ({masses[big]:.4g} kg) ends at "
              f"({com[0]:.4f}, {com[1]:.4f}, {com[2]:.4f}) m, glTF key off by {err:.2g} m; "
              f"{n_inner} crack faces with the crack material; extras match the file")
    for m in fails:
        print("FAIL:", m)
    return 1 if fails else 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        sys.exit(1)
    sys.exit(main(sys.argv[1], sys.argv[2]))
