#!/usr/bin/python3
"""The noise floor of tests/checks/bunny_table.py (agree, noise_floor) on
runs whose answer is known by counting.

Seed 1: three draws alike (3 pieces, largest 20 %): every pair and the
triple agree, 1.  Seed 2: counts 2, 4, 3 with the largest 20 %: of the
pairs only (2, 4) differs by more than 1, so 2/3 of the pairs agree and
the triple does not.  Seed 3: counts alike, largest 10, 20, 30 %: the pairs
(10, 20) and (20, 30) lie within 0.15 and (10, 30) does not, 2/3; the
triple spans 0.20, 0.  The chance that every seed agrees is the product:
4/9 for pairs, 0 for triples.  A mesh with fewer draws than the set size
reads nan.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bunny_table import agree, noise_floor  # noqa: E402


def run(seed, draw, count, largest):
    return {"mesh": "m", "seed": seed, "draw": draw, "pieces": [0.05] * count, "largest": largest}


runs = ([run(1, d, 3, 0.20) for d in range(3)]
        + [run(2, d, c, 0.20) for d, c in enumerate((2, 4, 3))]
        + [run(3, d, 3, b) for d, b in enumerate((0.10, 0.20, 0.30))])
fails = 0


def check(name, ok, value):
    global fails
    print(("ok    " if ok else "FAIL  ") + f"{name}: {value}")
    fails += not ok


for name, a, b, expected in (("counts 3 and 4", run(1, 0, 3, 0.2), run(1, 1, 4, 0.2), True),
                             ("counts 2 and 4", run(1, 0, 2, 0.2), run(1, 1, 4, 0.2), False),
                             ("largest 10 and 24 %", run(1, 0, 3, 0.10), run(1, 1, 3, 0.24), True),
                             ("largest 10 and 26 %", run(1, 0, 3, 0.10), run(1, 1, 3, 0.26), False)):
    got = agree(a, b)
    check(f"{name} {'agree' if expected else 'do not agree'}", got == expected, got)
per, p = noise_floor(runs, "m", [1, 2, 3], 2)
check("pairs, per seed", all(abs(a - b) < 1e-12 for a, b in zip(per, (1, 2 / 3, 2 / 3))), per)
check("pairs, every seed", abs(p - 4 / 9) < 1e-12, p)
per, p = noise_floor(runs, "m", [1, 2, 3], 3)
check("triples, per seed", per == [1.0, 0.0, 0.0], per)
check("triples, every seed", p == 0.0, p)
per, p = noise_floor(runs, "m", [1, 2, 3], 4)
check("more meshes than draws", all(math.isnan(x) for x in per) and math.isnan(p), per)
sys.exit(1 if fails else 0)
