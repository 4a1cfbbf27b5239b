#!/usr/bin/python3
"""Where a run's cohesive elements end: between pieces or inside one.

Usage: tools/crack_census.py RUN.h5 [RUN.h5 ...]

A run written with `--set output.cracks=true` holds every cohesive
element at every frame (/cracks), with the two rest tets whose shared face
it lies on (/cracks/tets); those tets give the fragments it lies between
at the last frame (/mesh/tet_fragment).  An element whose two tets end in
different fragments parts them; one whose tets end in the same fragment
is a crack that stops inside a piece.  Printed for each file: the largest
piece's share of the mass, then for the elements between pieces, inside a
piece and inside the largest piece, their number, their facet area (m^2,
/cracks/area at the last frame) and the share of them whose node pairs
have all failed (/cracks/failed), and how many still hold.  An element
between pieces that still holds would be a bond the hand-off cut (§9;
tests/checks/check_physics.py's `bonds`).

docs/physics.md §14.53 reads it.  Exit status: 0 done, 2 a file that is
not a run with cracks (the message names it and what to set).
"""
import os
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "checks"))
from check_physics import last_crack_rows  # noqa: E402
from fragment_stats import rest_partition, tet_volumes  # noqa: E402


def census(path):
    """The census of one run file, as lines of text.  Raises KeyError where
    a dataset is missing."""
    X, tets, frag = rest_partition(path)
    with h5py.File(path, "r") as f:
        last = last_crack_rows(f)
        pair, area = f["cracks/tets"][:][last], f["cracks/area"][:][last]
        failed = f["cracks/failed"][:][last] > 0
    vol = tet_volumes(X, tets)
    share = np.bincount(frag, weights=vol) / vol.sum()
    largest = int(np.argmax(share))
    fa, fb = frag[pair[:, 0]], frag[pair[:, 1]]
    groups = {"between pieces": fa != fb, "inside a piece": fa == fb,
              "inside the largest piece": (fa == fb) & (fa == largest)}
    out = [f"{path}: largest piece {100 * share[largest]:.1f} %, {len(pair)} cohesive elements"]
    for name, sel in groups.items():
        if not sel.any():
            out.append(f"  {name}: none")
            continue
        ar, fl = area[sel], failed[sel]
        out.append(f"  {name}: {np.count_nonzero(sel)} elements, {ar.sum():.4f} m^2, "
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
                  "--set output.cracks=true", file=sys.stderr)
            return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
