#!/usr/bin/python3
"""Partition a Tet4 mesh with METIS and report what a distributed fracture
step would exchange (docs/scale-out.md).

usage: tools/partition_stats.py MESH_BASE [PARTS ...]
  MESH_BASE  a TetGen base (MESH_BASE.node, MESH_BASE.ele), e.g.
             build/meshes/bunny
  PARTS      part counts (default 2 4 8 16 32 64)

Runs METIS's `mpmetis` (Debian package `metis`) on the tets' dual graph
with facet adjacency (-ncommon=3, the graph along which cracks run and
forces pass) and prints, per part count, a Markdown table row:

  tets per part     largest / mean (load imbalance)
  cut facets        interior facets whose two tets lie in different parts:
                    the cohesive-insertion candidates a partition boundary
                    holds (ParTopS inserts there with both sides' consent)
  shared nodes      nodes touched by tets of more than one part (per part:
                    largest); their forces are summed across parts
  ghost nodes       per part (largest): the nodes of the one-tet ghost layer
                    (other parts' tets sharing a node with the part) that
                    the part's own tets do not touch
  bytes per step    per part (largest), the message model of
                    docs/scale-out.md: 24 B per shared node for the force
                    sum, 48 B per shared or ghost node for positions and
                    velocities, and 24 B per shared node per PBD iteration
                    (3, the source's)

Needs numpy.  Exit 1 on bad usage or a mesh it cannot read, 2 when
mpmetis is missing or fails.
"""
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

PBD_ITERATIONS = 3


def header(f):
    """The first line that is not blank or a comment, split into words."""
    for line in f:
        w = line.split("#")[0].split()
        if w:
            return w
    raise ValueError(f"{f.name}: no header line")


def read_tets(base):
    """[n_tets, 4] 0-based node indices of BASE.ele (TetGen, 0- or 1-based)."""
    with open(base + ".node") as f:
        n_nodes = int(header(f)[0])
    rows = []
    with open(base + ".ele") as f:
        n_tets = int(header(f)[0])
        for line in f:
            w = line.split("#")[0].split()
            if len(w) >= 5:
                rows.append([int(x) for x in w[1:5]])
    tets = np.array(rows, dtype=np.int64)
    if len(tets) != n_tets:
        raise ValueError(f"{base}.ele: {len(tets)} tets, the header says {n_tets}")
    if tets.min() >= 1 and tets.max() == n_nodes:  # 1-based
        tets -= 1
    return tets, n_nodes


def facet_pairs(tets):
    """[m, 2] the tet pairs that share a facet."""
    faces = np.concatenate([tets[:, [1, 2, 3]], tets[:, [0, 2, 3]],
                            tets[:, [0, 1, 3]], tets[:, [0, 1, 2]]])
    owner = np.tile(np.arange(len(tets)), 4)
    faces.sort(axis=1)
    order = np.lexsort(faces.T[::-1])
    faces, owner = faces[order], owner[order]
    same = np.all(faces[1:] == faces[:-1], axis=1)
    return np.stack([owner[:-1][same], owner[1:][same]], axis=1)


def partition(tets, parts, work):
    """Part of each tet from mpmetis -ncommon=3."""
    mesh = os.path.join(work, "mesh")
    if not os.path.exists(mesh):
        with open(mesh, "w") as f:
            f.write(f"{len(tets)}\n")
            np.savetxt(f, tets + 1, fmt="%d")
    run = subprocess.run(["mpmetis", "-ncommon=3", mesh, str(parts)],
                         capture_output=True, text=True)
    if run.returncode != 0:
        raise RuntimeError(f"mpmetis {parts} failed: {run.stdout[-400:]}{run.stderr[-400:]}")
    return np.loadtxt(f"{mesh}.epart.{parts}", dtype=np.int64)


def stats(tets, n_nodes, pairs, epart, parts):
    counts = np.bincount(epart, minlength=parts)
    cut = epart[pairs[:, 0]] != epart[pairs[:, 1]]
    # touch[p, n]: part p has a tet at node n
    touch = np.zeros((parts, n_nodes), dtype=bool)
    for k in range(4):
        touch[epart, tets[:, k]] = True
    shared_mask = touch.sum(axis=0) > 1
    shared = (touch & shared_mask).sum(axis=1)
    ghost = np.zeros(parts, dtype=np.int64)
    for p in range(parts):
        # other parts' tets with a node of part p, and the nodes they bring
        near = (epart != p) & touch[p][tets].any(axis=1)
        nodes = np.zeros(n_nodes, dtype=bool)
        nodes[tets[near].ravel()] = True
        ghost[p] = (nodes & ~touch[p]).sum()
    per_step = 24 * shared + 48 * (shared + ghost) + 24 * PBD_ITERATIONS * shared
    return {
        "imbalance": counts.max() / counts.mean(),
        "tets": counts.mean(),
        "cut": int(cut.sum()),
        "cut_share": cut.sum() / len(pairs),
        "shared_total": int(shared_mask.sum()),
        "shared_max": int(shared.max()),
        "ghost_max": int(ghost.max()),
        "ghost_share": ((shared + ghost) / touch.sum(axis=1)).max(),
        "bytes_max": int(per_step.max()),
    }


def main(argv):
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(argv) >= 2 else 1
    base = argv[1]
    try:
        parts_list = [int(x) for x in argv[2:]] or [2, 4, 8, 16, 32, 64]
        tets, n_nodes = read_tets(base)
    except (OSError, ValueError) as e:
        print(f"partition_stats: {e}", file=sys.stderr)
        return 1
    if not shutil.which("mpmetis"):
        print("partition_stats: mpmetis not found: install Debian's metis package",
              file=sys.stderr)
        return 2
    pairs = facet_pairs(tets)
    print(f"{base}: {len(tets)} tets, {n_nodes} nodes, {len(pairs)} interior facets; "
          f"METIS mpmetis -ncommon=3; bytes per step with {PBD_ITERATIONS} PBD iterations\n")
    print("| parts | tets per part | largest / mean | cut facets | of interior facets "
          "| shared nodes (all) | shared nodes per part (max) | ghost nodes per part (max) "
          "| halo / own nodes (max) | bytes per step per part (max) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as work:
        for parts in parts_list:
            try:
                s = stats(tets, n_nodes, pairs, partition(tets, parts, work), parts)
            except RuntimeError as e:
                print(f"partition_stats: {e}", file=sys.stderr)
                return 2
            print(f"| {parts} | {s['tets']:.0f} | {s['imbalance']:.3f} | {s['cut']:,} | "
                  f"{100 * s['cut_share']:.2f} % | {s['shared_total']:,} | "
                  f"{s['shared_max']:,} | {s['ghost_max']:,} | {100 * s['ghost_share']:.1f} % | "
                  f"{s['bytes_max'] / 1024:.0f} KiB |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
