#!/usr/bin/python3
"""The same-pieces figure of tests/checks/bunny_table.py (shared) on
partitions of a unit cube whose answer is known.

Two "meshes" of the cube: 1,000 and 8,000 random points (fixed seed) as
the centroids of tets of equal volume.  With the cube cut at x = 0.5 on
both meshes the pieces are the same regions: shared is 1 for a mesh
against itself and at least 0.95 across the meshes (the nearest-centroid
map errs only within a point's spacing of the cut).  Cut at x = 0.5 on one
and at y = 0.5 on the other, each half lies half in each of the other's
halves: 0.5 within 0.05.  Pieces under 5 % do not count: a run whose only
piece of at least 5 % is a slab of 10 % reads only that slab, and one with
no such piece reads nan.
"""
import math
import os
import sys

import numpy as np
import scipy.spatial

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bunny_table import shared  # noqa: E402

rng = np.random.default_rng(20261128)


def mesh(n):
    cen = rng.random((n, 3))
    return cen, np.full(n, 1.0 / n), scipy.spatial.cKDTree(cen)


def cut(m, frag):
    return m[0], m[1], np.asarray(frag, dtype=np.int64), m[2]


coarse, fine = mesh(1000), mesh(8000)
fails = 0


def check(name, ok, value):
    global fails
    print(("ok    " if ok else "FAIL  ") + f"{name}: {value:.4f}")
    fails += not ok


for name, m in (("coarse", coarse), ("fine", fine)):
    a = cut(m, m[0][:, 0] < 0.5)
    check(f"the {name} mesh cut at x = 0.5 against itself", abs(shared(a, a) - 1) < 1e-12,
          shared(a, a))
x_coarse, x_fine = cut(coarse, coarse[0][:, 0] < 0.5), cut(fine, fine[0][:, 0] < 0.5)
y_fine = cut(fine, fine[0][:, 1] < 0.5)
check("the same cut on two meshes", shared(x_coarse, x_fine) >= 0.95, shared(x_coarse, x_fine))
check("cuts across each other", abs(shared(x_coarse, y_fine) - 0.5) <= 0.05,
      shared(x_coarse, y_fine))
# a slab of 20 % whole, the rest in crumbs of one tet: only the slab counts
slab = lambda m: np.where(m[0][:, 0] < 0.2, -1, np.arange(len(m[0])))  # noqa: E731
s_coarse, s_fine = cut(coarse, slab(coarse)), cut(fine, slab(fine))
check("a slab among crumbs on two meshes", shared(s_coarse, s_fine) >= 0.9,
      shared(s_coarse, s_fine))
crumbs = cut(coarse, np.arange(1000))
check("no piece of 5 %: nan", math.isnan(shared(crumbs, crumbs)), shared(crumbs, crumbs))
sys.exit(1 if fails else 0)
