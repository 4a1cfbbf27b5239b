#!/usr/bin/python3
"""Print how many frames a cohfrac output holds when every per-frame
dataset agrees (the frame's step, its fields, every observable), else -1
(also when one is missing); -2 and exit 2 when h5py cannot open or read
the file.  Used by the interruption tests and the failing-allocator test
(docs/reliability.md).  Given several files (one h5py start-up for all),
one line each, in order.

usage: tests/frames_consistent.py RUN.h5 [RUN.h5 ...]
"""
import sys

import h5py


def frames(f):
    if "particles" not in f:  # stopped before the first frame: the scene only
        return 0
    try:
        g = f["particles/fragments"]
        counts = {len(g["position/step"])} | {g[k + "/value"].shape[0] for k in
                  ("id", "position", "orientation", "velocity", "angular_velocity", "mode")}
        counts |= {o["value"].shape[0] for o in f["observables"].values()}
    except KeyError as e:  # a frame's dataset missing: not a whole frame
        print(f"{f.filename}: {e}", file=sys.stderr)
        return -1
    return counts.pop() if len(counts) == 1 else -1


status = 0
for path in sys.argv[1:]:
    try:
        f = h5py.File(path, "r")
        n = frames(f)
        f.close()
    except (OSError, RuntimeError) as e:  # not HDF5, or its metadata broken
        print(f"cannot open or read {path}: {e}", file=sys.stderr)
        n, status = -2, 2
    print(n)
sys.exit(status)
