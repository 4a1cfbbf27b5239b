#!/usr/bin/python3
"""The fragments of a cohfrac run at its last frame, as the fracture tables count them.

usage: fragment_stats.py OUT.h5 [OUT.h5 ...] [--chip-tets N] [--json]

For each file prints one line: the fragments alive at the last frame, the
pieces holding at least 5 % of the mass (their shares, largest first), the
share of the mass in chips (fragments of at most N tets, default 4), the
share of the mass in debris (docs/physics.md §9.2; chips may be debris), the
fastest fragment (m/s), the crack area (m^2, facets whose cohesive
element has failed at every node pair, one side) and the parted area (m^2,
the rest area of the facets between two tets of different fragments:
the crack that closes pieces off; below the crack area by the cracks that
run into a piece and stop, docs/physics.md §14.43).  With --json, one
JSON object per file instead.  Exit status 0, or 2 when a file cannot be
read.
"""
import argparse
import json
import sys

import h5py
import numpy as np


def last_frame(path):
    """The fragments alive at the last frame: mass (kg), tets, speed (m/s)
    and debris flag, one entry each, and the crack area (m^2, nan when the
    file has none)."""
    with h5py.File(path, "r") as f:
        ids = f["particles/fragments/id/value"][-1]
        vel = f["particles/fragments/velocity/value"][-1]
        mass = f["fragments/mass"][()]
        n_tets = f["fragments/n_tets"][()]
        debris = f["fragments/debris"][()] if "fragments/debris" in f else np.zeros_like(n_tets)
        crack = f["observables/crack_area/value"][-1] if "observables/crack_area" in f else float("nan")
    alive = ids >= 0
    ids = ids[alive]
    return mass[ids], n_tets[ids], np.linalg.norm(vel[alive], axis=1), debris[ids], float(crack)


def parted_area(X, T, frag):
    """The rest area (m^2) of the interior facets of a Tet4 mesh whose two
    tets lie in different fragments.  X (n, 3) rest nodes (m), T (t, 4)
    tets (node indices), frag (t,) each tet's fragment."""
    faces = np.sort(T[:, [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]].reshape(-1, 3), axis=1)
    owner = np.repeat(np.arange(len(T)), 4)
    order = np.lexsort(faces.T[::-1])
    faces, owner = faces[order], owner[order]
    twin = np.flatnonzero((faces[1:] == faces[:-1]).all(axis=1))  # a facet and the next: one facet
    cut = twin[frag[owner[twin]] != frag[owner[twin + 1]]]
    P = X[faces[cut]]
    return float(0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1).sum())


def tet_volumes(X, T):
    """The rest volume (m^3) of each Tet4: X (n, 3) rest nodes (m), T (t, 4)
    tets (node indices); (t,)."""
    P = X[T]
    return np.abs(np.einsum("ij,ij->i", np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]),
                            P[:, 3] - P[:, 0])) / 6


def rest_partition(path):
    """The rest mesh and each tet's fragment at the last frame: X (m), T, frag."""
    with h5py.File(path, "r") as f:
        return f["mesh/rest/nodes"][()], f["mesh/rest/tets"][()], f["mesh/tet_fragment/value"][-1]


def stats(path, chip_tets):
    m, nt, speed, debris, crack = last_frame(path)
    total = m.sum()
    share = np.sort(m / total)[::-1]
    return {
        "file": path,
        "fragments": int(len(m)),
        "n_tets": int(nt.sum()),
        "largest": float(share[0]) if len(share) else 0.0,
        "pieces_5pct": [round(float(s), 4) for s in share[share >= 0.05]],
        "pieces_1pct": int((share >= 0.01).sum()),
        "chip_share": float(m[nt <= chip_tets].sum() / total),
        "debris_share": float(m[debris != 0].sum() / total),
        "fastest": float(speed.max()) if len(speed) else 0.0,
        "crack_area": crack,
        "parted_area": parted_area(*rest_partition(path)),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--chip-tets", type=int, default=4)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    for p in a.files:
        try:
            s = stats(p, a.chip_tets)
        except (OSError, KeyError) as e:
            print(f"fragment_stats.py: {p}: {e}", file=sys.stderr)
            return 2
        if a.json:
            print(json.dumps(s))
        else:
            pieces = ", ".join(f"{100 * x:.1f}" for x in s["pieces_5pct"])
            print(f"{p}: {s['fragments']} fragments, {len(s['pieces_5pct'])} pieces >= 5 % "
                  f"({pieces}), {s['pieces_1pct']} >= 1 %, chips {100 * s['chip_share']:.1f} %, "
                  f"debris {100 * s['debris_share']:.1f} %, "
                  f"fastest {s['fastest']:.2f} m/s, crack area {s['crack_area']:.4g} m^2, "
                  f"parted {s['parted_area']:.4g} m^2")
    return 0


if __name__ == "__main__":
    sys.exit(main())
