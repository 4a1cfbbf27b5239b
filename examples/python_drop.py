#!/usr/bin/python3
"""A brittle cube dropped on the ground, from Python (cohfrac's ctypes face).

    PYTHONPATH=python python3 examples/python_drop.py      # from the source tree
    python3 examples/python_drop.py                        # after `make install`

Each cell below is one step of a notebook: build the scene as a dict, step
it while watching the fragments appear, then read the fragments and the
energy ledger as numpy arrays.
"""
import numpy as np

import cohfrac

# %% The scene: the keys and SI units of a scene script (README "Scenes").
# A 0.2 m cube of a soft, brittle solid (E 100 kPa, strength 1 kPa) falls
# from 1 m; the ground is a plane.
scene = {
    "name": "python_drop",
    "duration": 0.6,                                   # s
    "material": {"E": 1e5, "sigma_max": 1e3, "G_I": 1},  # Pa, Pa, N/m
    "bodies": [{"mesh": {"type": "box", "size": [0.2, 0.2, 0.2], "cells": [4, 4, 4]},
                "position": [0, 0, 1]}],               # m, the cube's centre
    "obstacles": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]}],
    "solver": {"constraints": "xpbd"},
}

# %% Step it: one rigid step per call; fracture mode sub-cycles inside.
with cohfrac.World(scene, threads=1) as world:
    seen = 1
    while not world.done:
        world.step()
        n = len(world.fragments()["id"])
        if n != seen:
            print(f"t = {world.time:.3f} s: {n} fragments")
            seen = n

    # %% The fragments as numpy arrays, one row each.
    f = world.fragments()
    speed = np.linalg.norm(f["v"], axis=1)
    print(f"{len(f['id'])} fragments at t = {world.time:.2f} s "
          f"(crack area {world.crack_area:.4f} m2):")
    for i in np.argsort(-f["mass"])[:10]:
        print(f"  fragment {f['id'][i]:3d}: {f['mass'][i]:7.3f} kg, {f['n_tets'][i]:3d} tets, "
              f"centre {np.round(f['com'][i], 3)} m, {speed[i]:.3f} m/s")

    # %% The energy ledger: where the fall's energy went (J).
    led = world.ledger()
    gone = {k: led[k] for k in ("contact", "pbd", "damping", "handoff", "integration",
                                 "cohesive_dissipated", "plastic_dissipated")}
    print(f"gravity's work {led['work_gravity']:.2f} J, kinetic now {led['kinetic']:.2f} J, "
          f"removed or dissipated {sum(gone.values()):.2f} J, residual {led['residual']:.3g} J "
          f"({100 * led['residual'] / led['work_gravity']:.1f} % of the work)")

    # %% Where every tet is now, e.g. to draw the pieces.
    corners = world.tet_positions()                  # (n_tets, 4, 3) m
    print(f"lowest corner at z = {corners[:, :, 2].min():.4f} m (the ground is z = 0)")
