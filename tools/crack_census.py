#!/usr/bin/python3
"""Where a run's cohesive elements end: between pieces or inside one.

Usage: tools/crack_census.py RUN.h5 [RUN.h5 ...]

A run written with `--set output.cracks=true` (and the default
output.fields) holds every cohesive element at every frame (/cracks) and
the corners of every fracture-mode tet (/fracture_mode).  Each element is
matched to its rest facet at the first frame it appears, by the nearest
face centroid of the fracture-mode tets of that frame; the facet's two
tets then give the fragments it lies between at the last frame
(/mesh/tet_fragment).  An element whose two tets end in different
fragments parts them; one whose tets end in the same fragment is a crack
that stops inside a piece.  Printed for each file: the largest piece's
share of the mass, then for the elements between pieces, inside a piece
and inside the largest piece, their number, their facet area (m^2,
/cracks/area at the last frame) and the share of them whose node pairs
have all failed (/cracks/failed), and how many still hold.  An element
between pieces that still holds would be a bond the hand-off cut (§9).
Elements matched farther than a hundredth of the mesh's median edge from
any face are left out and counted.

docs/physics.md §14.53 reads it.  Exit status: 0 done, 2 a file that is
not a run with cracks and fields (the message names it and what to set).
"""
import os
import sys

import h5py
import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "checks"))
from fragment_stats import rest_partition, tet_volumes  # noqa: E402

FACES = ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3))


def census(path):
    """The census of one run file, as lines of text.  Raises KeyError where
    a dataset is missing."""
    X, tets, frag = rest_partition(path)
    with h5py.File(path, "r") as f:
        ct, el = f["cracks/time"][:], f["cracks/element"][:]
        centroid, area = f["cracks/centroid"][:], f["cracks/area"][:]
        failed = f["cracks/failed"][:]
        ft, ftet = f["fracture_mode/time"][:], f["fracture_mode/tet"][:]
        corners = f["fracture_mode/corners"][:].reshape(-1, 4, 3)
    vol = tet_volumes(X, tets)
    share = np.bincount(frag, weights=vol) / vol.sum()
    largest = int(np.argmax(share))
    edge = np.median(np.linalg.norm(X[tets[:, 1]] - X[tets[:, 0]], axis=1))
    # facet (sorted rest vertices) -> its tets
    tets_of = {}
    for t, tt in enumerate(tets):
        for fc in FACES:
            tets_of.setdefault(tuple(sorted(tt[list(fc)])), []).append(t)
    # each element's first row, and its row at the last frame
    order = np.lexsort((ct, el))
    first_row = {}
    for i in order:
        first_row.setdefault(el[i], i)
    last = ct == ct.max()
    last_row = dict(zip(el[last], np.flatnonzero(last)))
    facet_of, far = {}, 0
    for T in np.unique([ct[i] for i in first_row.values()]):
        rows = np.flatnonzero(ft == T)
        if rows.size == 0:
            continue
        cents = [corners[r][list(fc)].mean(0) for r in rows for fc in FACES]
        keys = [tuple(sorted(tets[ftet[r]][list(fc)])) for r in rows for fc in FACES]
        es = [e for e, i in first_row.items() if ct[i] == T]
        dist, ix = cKDTree(np.array(cents)).query(centroid[[first_row[e] for e in es]])
        for e, j, dd in zip(es, ix, dist):
            if dd > 0.01 * edge:
                far += 1
            else:
                facet_of[e] = keys[j]
    groups = {"between pieces": [], "inside a piece": [], "inside the largest piece": []}
    for e, key in facet_of.items():
        ts = tets_of[key]
        if len(ts) < 2 or e not in last_row:
            continue
        fa, fb = frag[ts[0]], frag[ts[1]]
        i = last_row[e]
        rec = (area[i], failed[i] > 0)
        groups["between pieces" if fa != fb else "inside a piece"].append(rec)
        if fa == fb == largest:
            groups["inside the largest piece"].append(rec)
    out = [f"{path}: largest piece {100 * share[largest]:.1f} %, {len(first_row)} cohesive "
           f"elements, {far} left out (matched farther than {0.01 * edge * 1e3:.2g} mm)"]
    for name, recs in groups.items():
        if not recs:
            out.append(f"  {name}: none")
            continue
        ar = np.array([r[0] for r in recs])
        fl = np.array([r[1] for r in recs])
        out.append(f"  {name}: {len(recs)} elements, {ar.sum():.4f} m^2, "
                   f"{100 * fl.mean():.1f} % failed ({ar[fl].sum():.4f} m^2), "
                   f"{np.count_nonzero(~fl)} still holding")
    return out


def main(argv):
    if len(argv) < 2:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    for path in argv[1:]:
        try:
            print("\n".join(census(path)))
        except (OSError, KeyError) as err:
            print(f"crack_census: {path}: {err}; run the scene with "
                  "--set output.cracks=true (and output.fields, the default)", file=sys.stderr)
            return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
