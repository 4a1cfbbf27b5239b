#!/usr/bin/python3
"""The parted area of tests/checks/fragment_stats.py (parted_area) on a
Tet4 mesh whose answer is known in closed form.

The unit cube as n^3 = 4^3 cubes, each cut into Kuhn's six tets (the
paths from corner 000 to 111 along the axes), with nodes and tets in a
shuffled order.  Facets parted between two fragments, m^2:
  one fragment                       0
  the halves x < 0.5 and x > 0.5     1 (the plane x = 0.5)
  the eight octants                  3 (three planes)
  every tet its own fragment         3 (n - 1) + 3 sqrt(2) n (the n - 1
                                     planes of each axis, and in each cube
                                     six facets through its diagonal, each
                                     of area sqrt(2) / 2 / n^2)
"""
import itertools
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fragment_stats import parted_area  # noqa: E402

N = 4
rng = np.random.default_rng(20261128)


def kuhn_cube(n):
    """Nodes (m) and tets of the unit cube as n^3 cubes of six tets each."""
    idx = lambda i, j, k: (i * (n + 1) + j) * (n + 1) + k  # noqa: E731
    X = np.array([(i, j, k) for i in range(n + 1) for j in range(n + 1) for k in range(n + 1)],
                 dtype=float) / n
    T = []
    for i, j, k in itertools.product(range(n), repeat=3):
        for perm in itertools.permutations(range(3)):
            p = [i, j, k]
            path = [idx(*p)]
            for axis in perm:
                p[axis] += 1
                path.append(idx(*p))
            T.append(path)
    return X, np.array(T)


X, T = kuhn_cube(N)
relabel = rng.permutation(len(X))  # node i becomes relabel[i]
Xs = np.empty_like(X)
Xs[relabel] = X
Ts = relabel[T][rng.permutation(len(T))]
cen = Xs[Ts].mean(axis=1)
fails = 0


def check(name, frag, expected):
    global fails
    got = parted_area(Xs, Ts, np.asarray(frag))
    ok = abs(got - expected) <= 1e-12 * max(1.0, expected)
    print(("ok    " if ok else "FAIL  ") + f"{name}: {got:.15g} m^2 (closed form {expected:.15g})")
    fails += not ok


check("one fragment", np.zeros(len(Ts), dtype=int), 0.0)
check("halves at x = 0.5", (cen[:, 0] > 0.5).astype(int), 1.0)
check("octants", ((cen > 0.5) * [1, 2, 4]).sum(axis=1), 3.0)
check("every tet alone", np.arange(len(Ts)), 3 * (N - 1) + 3 * math.sqrt(2) * N)
sys.exit(1 if fails else 0)
