#!/usr/bin/python3
"""Check the geometry in a cohfrac output file (docs/output.md).

    tests/checks/check_geometry.py OUT.h5

For every fragment alive at the end:
  - its surface (/surfaces rows of its record) is closed and consistently
    oriented: every edge runs as often in one direction as in the other
    (twice in all, or four times where two parts touch along it);
  - the volume it encloses (divergence theorem) equals the rest volume of
    its tets (from the last /mesh/tet_fragment row) to round-off: the
    triangles are outward and none is missing;
  - a triangle is marked as a crack face exactly when it is not on the rest
    mesh's own boundary;
and the posed surfaces at the last frame lie in the box the run's
parameters allow (above any floor plane, less a tolerance).  Also: every
fragment has at least one tet and a positive mass, every observable's
value has a unit attribute or is a count, and every unit in
the file is spelled one way, UDUNITS style as H5MD asks ("m s-1", "kg m2":
powers as trailing integers, no "/" or "^").

Exit status 0 when everything holds, 1 otherwise (each failure printed).
"""
import collections
import os
import sys

# The reader, from the source tree's Python package.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))
import h5py
import numpy as np

from cohfrac import h5 as cohfrac_h5  # noqa: E402

COUNTS = {"fragment_count", "cohesive_elements", "fragments_in_fracture_mode",
          "handoff_momentum_error_max"}


def main(path):
    run = cohfrac_h5.load(path)
    fails = []
    with h5py.File(path, "r") as f:
        tet_frag = f["mesh/tet_fragment/value"][-1]
        n_tets, mass = f["fragments/n_tets"][:], f["fragments/mass"][:]
    # Every fragment ever made is made of tets and has their mass (a record
    # with no tets would be a glTF node with no mesh, a body of no shape).
    for i in np.flatnonzero((n_tets < 1) | ~(mass > 0)):
        fails.append(f"fragment {i}: {n_tets[i]} tets, mass {mass[i]:.4g} kg")
    X, tets = run.rest_nodes, run.rest_tets
    # The rest mesh's own boundary faces, as sorted triples.
    faces = np.concatenate([tets[:, [0, 1, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 3]],
                            tets[:, [1, 2, 3]]])
    keys, counts = np.unique(np.sort(faces, axis=1), axis=0, return_counts=True)
    outer = {tuple(k) for k in keys[counts == 1]}
    a, b, c, d = (X[tets[:, i]] for i in range(4))
    tet_vol = np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)) / 6.0
    alive = run.alive(-1)
    worst_vol, n_crack = 0.0, 0
    for i in alive:
        fr = run.fragment(i)
        tri = fr.triangles
        edges = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
        # Closed: each directed edge as often as its reverse (an edge where
        # two parts of a fragment touch may carry four triangles).
        directed = collections.Counter(map(tuple, edges))
        if any(directed[(e[1], e[0])] != k for e, k in directed.items()):
            fails.append(f"fragment {i}: surface not closed and consistently oriented "
                         f"({len(tri)} triangles)")
            continue
        p, q, r = X[tri[:, 0]], X[tri[:, 1]], X[tri[:, 2]]
        enclosed = np.einsum("ij,ij->", p, np.cross(q, r)) / 6.0
        volume = tet_vol[tet_frag == i].sum()
        rel = abs(enclosed - volume) / volume
        worst_vol = max(worst_vol, rel)
        if rel > 1e-9:
            fails.append(f"fragment {i}: surface encloses {enclosed:.9g} m^3, its tets "
                         f"{volume:.9g} m^3")
        crack = np.array([tuple(sorted(t)) not in outer for t in tri])
        n_crack += int(crack.sum())
        if not np.array_equal(crack, fr.crack.astype(bool)):
            fails.append(f"fragment {i}: crack flags differ from the rest mesh's boundary")
    lo = run.parameters.get("initial_lower")
    floor = [o for o in run.obstacles if o["type"] == "plane" and o["normal"][2] > 0.9]
    size = float(np.max(run.parameters["initial_upper"] - lo)) if lo is not None else 1.0
    zmin = min((v[:, 2].min() for _, v, _, _ in run.surfaces_at(-1)), default=np.inf)
    if floor and zmin < floor[0]["point"][2] - 0.05 * size:
        fails.append(f"a posed surface reaches z = {zmin:.4g} m, below the floor at "
                     f"{floor[0]['point'][2]:.4g} m by more than 5% of the body's size")
    for name, s in run.observables.items():
        if not s.unit and name not in COUNTS:
            fails.append(f"/observables/{name} has no unit attribute")
    units = []
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, o: units.append((name, o.attrs["unit"]))
                     if "unit" in o.attrs else None)
    for name, u in units:
        u = u.decode() if isinstance(u, bytes) else str(u)
        if "/" in u or "^" in u or "*" in u:
            fails.append(f"/{name}: unit '{u}' is not UDUNITS style (write 'm s-1', 'kg m2')")
    print(f"{path}: {len(alive)} fragments alive, surfaces closed and outward, enclosed "
          f"volume = tet volume within {worst_vol:.2g} (relative), {n_crack} crack faces, "
          f"lowest posed vertex z = {zmin:.4g} m")
    for m in fails:
        print("FAIL:", m)
    return 1 if fails else 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        sys.exit(1)
    sys.exit(main(sys.argv[1]))
