#!/usr/bin/python3
"""Check a cohfrac HDF5 run file against closed-form expectations.

usage: check_run.py FILE.h5 [--min-fragments N] [--max-momentum-error E]
                            [--max-fall-error E]

Prints and checks:
  * the layout: /parameters/scene, /particles/fragments/{id,position,
    orientation,velocity,angular_velocity,mode}, /fragments/{parent,
    birth_time}, /observables/{energy_kinetic,fragment_count,
    cohesive_elements}, /handoffs;
  * free fall before the first impact: the centre of mass of fragment 0
    against z0 - g t^2/2 (g from the scene's gravity), error relative to the
    fall height up to the last frame before the impact;
  * fragments alive at the end (>= --min-fragments);
  * every hand-off's linear momentum error (<= --max-momentum-error);
  * the convex decomposition of the fragments handed to Bullet: median
    hull-volume error (hull volume / tet volume - 1) of the fragments
    decomposed into more than one hull <= --max-hull-error (a fragment of
    one hull is its own convex hull, whose overfill is the piece's shape,
    not a choice of the decomposition), and every hull-volume error
    >= -1e-9 (hulls cover their tets).
Exit status 0 when every check holds, 1 otherwise.
"""
import argparse
import re
import sys

import h5py
import numpy as np


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file")
    ap.add_argument("--min-fragments", type=int, default=2)
    ap.add_argument("--max-hull-error", type=float, default=0.10)
    ap.add_argument("--max-momentum-error", type=float, default=1e-9)
    ap.add_argument("--max-fall-error", type=float, default=1e-3)
    a = ap.parse_args()
    ok = True

    def check(cond, what):
        nonlocal ok
        print(("  ok    " if cond else "  FAIL  ") + what)
        ok &= bool(cond)

    with h5py.File(a.file, "r") as f:
        print(f"{a.file}:")
        need = ["parameters/scene", "fragments/parent", "fragments/birth_time", "handoffs"]
        need += [f"particles/fragments/{n}/value" for n in
                 ("id", "position", "orientation", "velocity", "angular_velocity", "mode")]
        need += [f"observables/{n}/value" for n in
                 ("energy_kinetic", "energy_residual", "fragment_count", "cohesive_elements")]
        missing = [n for n in need if n not in f]
        check(not missing, "datasets present" + (f" (missing {missing})" if missing else ""))
        if missing:
            return 1
        scene = f["parameters/scene"][()]
        scene = scene.decode() if isinstance(scene, bytes) else str(scene)
        m = re.search(r"gravity\s*=\s*\{\s*([-+0-9.eE]+)\s*,\s*([-+0-9.eE]+)\s*,\s*([-+0-9.eE]+)", scene)
        g = -float(m.group(3)) if m else 9.81
        t = f["particles/fragments/position/time"][()]
        pos = f["particles/fragments/position/value"][()]
        ids = f["particles/fragments/id/value"][()]
        ho = f["handoffs"]
        ho_time = ho["time"][()] if isinstance(ho, h5py.Group) else ho["time"]
        ho_err = ho["momentum_error"][()] if isinstance(ho, h5py.Group) else ho["momentum_error"]
        t_impact = float(ho_time[0]) if len(ho_time) else float(t[-1])
        pre = t <= t_impact + 1e-12
        z = pos[pre, 0, 2]
        z_exact = pos[0, 0, 2] - 0.5 * g * t[pre] ** 2
        height = max(pos[0, 0, 2] - z_exact[-1], 1e-300)
        err = np.max(np.abs(z - z_exact)) / height
        print(f"  free fall until t = {t[pre][-1]:.4f} s (impact at {t_impact:.4f} s): "
              f"fall {height:.4f} m, max |z - (z0 - g t^2/2)| = {err * height:.3e} m "
              f"= {err:.2e} of the fall height")
        check(err <= a.max_fall_error, f"free-fall error <= {a.max_fall_error:g} of the fall height")
        alive = int(np.sum(ids[-1] >= 0))
        print(f"  fragments alive at t = {t[-1]:.4f} s: {alive}; "
              f"ever: {len(f['fragments/parent'])}; hand-offs: {len(ho_time)}")
        check(alive >= a.min_fragments, f">= {a.min_fragments} fragments at the end")
        worst = float(np.max(ho_err)) if len(ho_err) else 0.0
        print(f"  hand-off linear momentum error: max {worst:.3e} (relative)")
        check(worst <= a.max_momentum_error,
              f"every hand-off conserves momentum to {a.max_momentum_error:g}")
        nh = f["fragments/n_hulls"][()]
        err = f["fragments/hull_volume_error"][()]
        he, many = err[nh > 0], err[nh > 1]
        if len(he):
            med = float(np.median(many)) if len(many) else 0.0
            print(f"  convex decomposition: {len(he)} fragments, {int(np.sum(nh))} hulls; "
                  f"hull-volume error median {med:.4f} over the {len(many)} of more than one "
                  f"hull, worst {float(np.max(he)):.4f}")
            check(med <= a.max_hull_error,
                  f"median hull-volume error (more than one hull) <= {a.max_hull_error:g}")
            check(float(np.min(he)) >= -1e-9, "hulls cover their tets")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
