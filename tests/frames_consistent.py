#!/usr/bin/python3
"""Print how many frames a cohfrac output holds when every per-frame
dataset agrees (the frame's step, its fields, every observable), else -1;
exit 2 when h5py cannot open the file.  Used by the interruption tests
(docs/reliability.md).

usage: tests/frames_consistent.py RUN.h5
"""
import sys

import h5py

try:
    f = h5py.File(sys.argv[1], "r")
except OSError as e:
    print(f"cannot open {sys.argv[1]}: {e}", file=sys.stderr)
    sys.exit(2)
if "particles" not in f:  # stopped before the first frame: the scene only
    print(0)
    sys.exit(0)
g = f["particles/fragments"]
counts = {len(g["position/step"])} | {g[k + "/value"].shape[0] for k in
          ("id", "position", "orientation", "velocity", "angular_velocity", "mode")}
counts |= {o["value"].shape[0] for o in f["observables"].values()}
print(counts.pop() if len(counts) == 1 else -1)
