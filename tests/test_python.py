#!/usr/bin/python3
"""The Python face (python/cohfrac) against the C library it wraps.

    tests/test_python.py COHFRAC_EXE SOURCE_DIR

- faithful: the box drop of tests/data/box_break.lua built from a dict
  ends in the same state, bit for bit (the state hash), as `cohfrac run`
  on the script;
- physics: a body in free fall for n rigid steps of dt has the momentum
  -m g n dt along z to round-off (the rigid step integrates gravity as a
  constant force), whatever the binding's conversions;
- errors: a bad value raises CohfracError naming the key, with the
  status and exit code of the program (CF_ERR_SCENE_VALUE, 2);
- lua_table: strings with quotes, backslashes and newlines survive.
"""
import os
import re
import subprocess
import sys
import tempfile

exe, src = sys.argv[1], sys.argv[2]
sys.path.insert(0, os.path.join(src, "python"))
import numpy as np  # noqa: E402

import cohfrac  # noqa: E402

fails = 0


def check(what, ok, detail=""):
    global fails
    print(("ok    " if ok else "FAIL  ") + what + (": " + detail if detail else ""))
    fails += not ok


BOX = {"name": "box_break", "duration": 0.3,
       "material": {"E": 1e5, "sigma_max": 3e3},
       "bodies": [{"mesh": {"type": "box", "size": [0.2, 0.2, 0.2], "cells": [4, 4, 4]},
                   "position": [0, 0, 1]}],
       "obstacles": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]}],
       "solver": {"constraints": "xpbd", "threads": 1}}

v = subprocess.run([exe, "--version"], capture_output=True, text=True, check=True).stdout.split()
check("the library's version is the program's", cohfrac.version() == v[-1],
      f"{cohfrac.version()} against {v[-1]}")

with tempfile.TemporaryDirectory() as tmp:
    r = subprocess.run([exe, "run", os.path.join(src, "tests/data/box_break.lua"), "-q", "-t", "1",
                        "--set", "duration=0.3", "-o", os.path.join(tmp, "box.h5")],
                       capture_output=True, text=True, check=True)
    cli_hash = re.search(r"state hash\s+([0-9a-f]{16})", r.stdout).group(1)
with cohfrac.World(BOX, threads=1) as w:
    w.run()
    check("a dict gives the state of the same script run by the program", w.state_hash == cli_hash,
          f"{w.state_hash} against {cli_hash}")
    f, led = w.fragments(), w.ledger()
    check("fragments and ledger come back as numpy arrays",
          f["com"].shape == (len(f["id"]), 3) and abs(f["mass"].sum() - 19.2) < 1e-9
          and led["momentum"].shape == (3,), f"{len(f['id'])} fragments, {f['mass'].sum():.6g} kg")

fall = dict(BOX, name="fall", duration=0.05, obstacles=[])
fall["solver"] = {"dt_rigid": 1e-3, "threads": 1}
with cohfrac.World(fall) as w:
    w.run()
    f = w.fragments()
    m, pz, t = f["mass"][0], f["momentum"][0][2], w.time
    check("free fall: momentum -m g t to round-off", abs(pz + m * 9.81 * t) <= 1e-12 * m * 9.81 * t,
          f"p_z {pz:.15g}, -m g t {-m * 9.81 * t:.15g} kg m/s")
    X, T = w.rest_mesh()
    x = w.tet_positions()
    check("node positions: the rigid body moved by its centre's fall",
          abs((x[:, :, 2].mean() - X[T][:, :, 2].mean()) - (f["com"][0][2] - 1.0)) < 1e-9,
          f"mean corner drop {X[T][:, :, 2].mean() - x[:, :, 2].mean():.6f} m")

try:
    cohfrac.World(dict(BOX, solver={"dt_rigid": -1}))
    check("a bad value raises", False)
except cohfrac.CohfracError as e:
    check("a bad value raises CohfracError naming the key",
          e.status == "CF_ERR_SCENE_VALUE" and e.exit_code == 2 and "solver.dt_rigid" in str(e),
          str(e)[:120])

s = 'a "quoted" \\ back\nslash'
check("lua_table keeps strings", cohfrac.lua_table({"k": s, "v": [1, 2.5, True], "n": None})
      == '{k = "a \\"quoted\\" \\\\ back\\nslash", v = {1, 2.5, true}}')
sys.exit(1 if fails else 0)
