#!/usr/bin/python3
"""Print how many whole frames a cohfrac output holds, else -1; -2 and
exit 2 when h5py cannot open or read the file.  Used by the interruption
tests and the failing-allocator test (docs/reliability.md).  Given several
files (one h5py start-up for all), one line each, in order.

The count is the root attribute `frames` (written by the run only once a
frame's flush has returned; len(step) in files without it).  A file the
run closed, even after an error, must hold exactly that many rows in every
per-frame dataset (the frame's step, its fields, every observable), else
-1 (also when one is missing).  With --killed (a run that SIGKILL ended,
perhaps during a flush) a dataset may hold one more, partial row.  In both
the counted frames' steps must read and never decrease.

usage: tests/frames_consistent.py [--killed] RUN.h5 [RUN.h5 ...]
"""
import sys

import numpy as np
import h5py


def frames(f, killed):
    if "particles" not in f:  # stopped before the first frame: the scene only
        return 0
    try:
        g = f["particles/fragments"]
        rows = [len(g["position/step"])] + [g[k + "/value"].shape[0] for k in
                ("id", "position", "orientation", "velocity", "angular_velocity", "mode")]
        rows += [o["value"].shape[0] for o in f["observables"].values()]
        whole = int(f.attrs["frames"]) if "frames" in f.attrs else rows[0]
        steps = g["position/step"][:whole]
    except KeyError as e:  # a frame's dataset missing: not a whole frame
        print(f"{f.filename}: {e}", file=sys.stderr)
        return -1
    spare = 1 if killed else 0
    if any(not whole <= r <= whole + spare for r in rows) or len(steps) != whole \
            or np.any(np.diff(steps) < 0):
        print(f"{f.filename}: {whole} whole frames, rows {rows}", file=sys.stderr)
        return -1
    return whole


killed = "--killed" in sys.argv[1:]
status = 0
for path in [a for a in sys.argv[1:] if a != "--killed"]:
    try:
        f = h5py.File(path, "r")
        n = frames(f, killed)
        f.close()
    except (OSError, RuntimeError) as e:  # not HDF5, or its metadata broken
        print(f"cannot open or read {path}: {e}", file=sys.stderr)
        n, status = -2, 2
    print(n)
sys.exit(status)
