#!/usr/bin/python3
"""The hand-off cuts no bond: on `make run`'s drop, every cohesive element
between two fragments at the end has failed (docs/physics.md §9).

usage: test_handoff_bonds.py COHFRAC_EXE MESH_DIR SCENE OUT_DIR

Runs SCENE with output.cracks and checks, from the file:
  - /cracks/tets names, for every element, two tets of the rest mesh that
    share a face (three vertices): the facet the element lies on;
  - tests/checks/check_physics.py's `bonds` holds: no element whose two tets
    end in different fragments still holds, and some elements lie between
    fragments (the drop breaks);
  - the check can fail: in a copy of the file with one such element marked
    as holding at the last frame, `bonds` fails.
Exit status 0 when all hold, 1 otherwise.
"""
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_physics import bonds, final_crack_sides  # noqa: E402


def main(exe, meshes, scene, out):
    os.makedirs(out, exist_ok=True)
    run = os.path.join(out, "handoff_bonds.h5")
    subprocess.run([exe, "run", scene, "--mesh-dir", meshes, "-q", "-t", "2", "-o", run,
                    "--set", "output.cracks=true"], check=True, stdout=subprocess.DEVNULL)
    fails = 0

    def report(ok, text):
        nonlocal fails
        fails += not ok
        print(("ok    " if ok else "FAIL  ") + text)

    with h5py.File(run, "r") as f:
        rest = f["mesh/rest/tets"][:]
        pairs = f["cracks/tets"][:]
    shared = [len(set(rest[a]) & set(rest[b])) for a, b in np.unique(pairs, axis=0)]
    report(len(shared) > 0 and min(shared) == 3,
           f"/cracks/tets: {len(shared)} facets, the two tets of each share "
           f"{min(shared, default=0)}-{max(shared, default=0)} vertices (3: a face)")
    between, holding = bonds(run)
    report(between > 0 and holding == 0,
           f"{holding} of the {between} elements between two fragments still hold")

    broken = os.path.join(out, "handoff_bonds_cut.h5")
    shutil.copyfile(run, broken)
    with h5py.File(broken, "r+") as f:
        last, between = final_crack_sides(f)
        f["cracks/failed"][last[between][0]] = 0
    between, holding = bonds(broken)
    report(holding == 1, f"with one of them marked holding, bonds counts {holding} holding (1)")
    os.remove(broken)
    return 1 if fails else 0


if __name__ == "__main__":
    if len(sys.argv) != 5:
        print(__doc__.strip().splitlines()[3], file=sys.stderr)
        sys.exit(2)
    sys.exit(main(*sys.argv[1:]))
