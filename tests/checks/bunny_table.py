#!/usr/bin/python3
"""The plaster bunny drop on several meshes and strength seeds, with draws.

usage: bunny_table.py COHFRAC [--size ci|full] [--meshes M,M,...] [--seeds N]
                      [--draws K] [-m MESH_DIR] [-o DIR] [-j N] [--known FILE]
                      [--set KEY=VALUE ...]

Runs scenes/plaster_bunny_drop.lua on each mesh (--size full: bunny_1k,
bunny_4k and bunny_small, 979, 3,867 and 15,040 tets, 4 draws; --size ci,
the default: the first two, 3 draws) with the strength seeds 1..N (5 by
default) and checks the table of docs/physics.md §14.16:
  count_sN    seed N's pieces of at least 5 % of the mass agree within 1
              between the meshes;
  largest_sN  seed N's largest piece's share agrees within 0.15;
  chips       fragments of at most 4 tets carry at most 5 % of the mass,
              in every run;
  physics     every run lies within tests/checks/check_physics.py's bounds,
              its ledger residual at most 1 %.

Draws.  One run per seed and mesh is one draw of a sensitive process: the
bunny dropped 1 nm higher breaks into other pieces, as it does with another
step or another seed (docs/physics.md §14.34 and §14.42).  With --draws K
each seed and mesh is run K times, draw k starting the bunny k nm higher
(k = 0 is the scene as shipped), and count and largest then compare each
mesh's median over its draws.  The report adds each mesh's range over the
draws, and two figures over the pairs of runs of one seed, for two draws on
one mesh (how far the process agrees with itself) and for two draws on two
meshes: how often they agree as the table asks, and how much of the mass of
their pieces of at least 5 % they break into the same pieces, the same
regions of the rest body (`shared`: the count and the largest share can
agree while the pieces are other parts of the bunny).  Where the figures on
one mesh and across meshes are alike, the mesh changes the outcome no more
than a nanometre does.  With at least as many draws as meshes, the report
also gives the table's noise floor (`noise_floor`): how often a table of one
run per seed and mesh, the issue's form, would pass on copies of one mesh,
its draws standing for the meshes (docs/physics.md §14.46).  Each mesh's
pooled line also gives the share of its failed crack area that parts two
fragments (fragment_stats.parted_area over the crack area; the rest is
cracks that run into a piece and stop, docs/physics.md §14.43).

Writes DIR/bunny_table.md (the table) and DIR/bunny_table.json (every run's
figures); runs are cached in DIR/runs/ (rerun when the program or the scene
is newer; a variant made with --set is cached under its own name).  Checks
named in the --known file (as tests/checks/fragmentation.py reads it) are
known not to hold yet: they must fail.  Exit status 0 when the failing
checks are exactly the known ones, 1 otherwise, 2 on a run that could not be
made or read.
"""
import argparse
import concurrent.futures
import itertools
import json
import os
import sys

import h5py
import numpy as np
import scipy.spatial

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import check_physics  # noqa: E402
import fragment_stats  # noqa: E402
from fragmentation import add_study_arguments, cached_run, known_verdict, read_known  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "scenes", "plaster_bunny_drop.lua")
START_Z = 0.001 + 0.1147  # m: the scene's starting height, as scenes/plaster_bunny_drop.lua writes it
DRAW_STEP = 1e-9  # m: draw k starts k nm higher
CHIP_TETS = 4
SIZES = {"ci": ("bunny_1k,bunny_4k", 3), "full": ("bunny_1k,bunny_4k,bunny_small", 4)}


def run(exe, out_dir, mesh_dir, extra, mesh, seed, draw):
    """One drop; returns its figures (cached by name in out_dir/runs)."""
    sets = [f'bodies[1].mesh="{mesh}"', f"material.strength.seed={seed}"]
    if draw:
        sets.append(f"bodies[1].position={{0,0,{START_Z + draw * DRAW_STEP!r}}}")
    tag, h5 = cached_run(exe, SCENE, out_dir, f"{mesh}_s{seed}_d{draw}", sets, extra, mesh_dir)
    if draw == 0:
        start_height(h5)
    f = fragment_stats.stats(h5, CHIP_TETS)
    bounds = {}
    plausible = check_physics.check_file(h5, quiet=True, figures=bounds)
    return {"mesh": mesh, "seed": seed, "draw": draw, "tag": tag, "pieces": f["pieces_5pct"],
            "largest": f["largest"], "chips": f["chip_share"], "crack_area": f["crack_area"],
            "parted_area": f["parted_area"],
            "fragments": f["fragments"], "n_tets": f["n_tets"],
            "residual": float(bounds["residual_share"]), "plausible": bool(plausible)}


def start_height(h5):
    """Raises RuntimeError unless the scene starts the bunny at START_Z, from
    which the draws count their nanometres."""
    with h5py.File(h5, "r") as f:
        scene = f["parameters/scene"][()]
    scene = scene.decode() if isinstance(scene, bytes) else str(scene)
    z = [float(line.split("{")[1].split("}")[0].split(",")[2])
         for line in scene.splitlines() if line.strip().startswith("position =")][0]
    if abs(z - START_Z) > 1e-9:
        raise RuntimeError(f"{h5}: the scene starts the bunny at z = {z} m, not at START_Z = "
                           f"{START_Z} m: set START_Z in {__file__} to the scene's")


def partition(h5):
    """The run's rest tets at its last frame: centroids (m), volume shares
    and fragment ids, with a k-d tree of the centroids."""
    X, T, frag = fragment_stats.rest_partition(h5)
    vol = fragment_stats.tet_volumes(X, T)
    cen = X[T].mean(axis=1)
    return cen, vol / vol.sum(), frag, scipy.spatial.cKDTree(cen)


def kept_by(a, b):
    """The share of the mass of a's pieces of at least 5 % that lies in one
    piece of b, each of a's pieces with the piece of b that holds most of
    it, measured on b's tets (each given a's fragment at its centroid);
    nan when a has no such piece."""
    cen_b, vol_b, frag_b, _ = b
    _, near = a[3].query(cen_b)
    frag_a = a[2][near]
    ids, inv = np.unique(frag_a, return_inverse=True)
    size = np.bincount(inv, weights=vol_b)
    big = np.flatnonzero(size >= 0.05)
    kept = 0.0
    for k in big:
        mine = inv == k
        _, j = np.unique(frag_b[mine], return_inverse=True)
        kept += np.bincount(j, weights=vol_b[mine]).max()
    return kept / size[big].sum() if len(big) else float("nan")


def shared(a, b):
    """How far two runs break into the same large pieces: kept_by both ways,
    averaged; 1 when their pieces of at least 5 % are the same regions of
    the rest body, whatever the mesh, near 0 when none is."""
    return 0.5 * (kept_by(a, b) + kept_by(b, a))


def agree(*runs):
    """Runs agree as the table asks: their counts of pieces of at least 5 %
    within 1 of each other, their largest shares within 0.15."""
    counts = [len(r["pieces"]) for r in runs]
    largest = [r["largest"] for r in runs]
    return max(counts) - min(counts) <= 1 and max(largest) - min(largest) <= 0.15


def noise_floor(runs, mesh, seeds, k):
    """How often the table, in the form of one run per seed and mesh, would
    pass if the meshes did not matter at all: k draws of one mesh stand for
    k meshes.  Returns (per seed, the share of the sets of k of the mesh's
    draws that agree; their product, the chance that every seed agrees, the
    seeds being independent draws of the material).  nan where the mesh has
    fewer than k draws of a seed."""
    per = []
    for s in seeds:
        mine = [r for r in runs if r["mesh"] == mesh and r["seed"] == s]
        sets = list(itertools.combinations(mine, k))
        per.append(sum(agree(*c) for c in sets) / len(sets) if sets else float("nan"))
    return per, float(np.prod(per))


def pairs(runs, parts):
    """Each pair of one seed's runs: (mesh, mesh, whether they agree as the
    table asks, the mass they break into the same pieces)."""
    return [(a["mesh"], b["mesh"], agree(a, b), shared(parts[a["tag"]], parts[b["tag"]]))
            for a, b in itertools.combinations(runs, 2)]


def mean_of(ps, i, same):
    """The mean of field i over the pairs on one mesh (same) or on two."""
    v = [p[i] for p in ps if (p[0] == p[1]) == same]
    return float(np.nanmean(v)) if v else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cohfrac")
    ap.add_argument("--size", choices=SIZES, default="ci")
    ap.add_argument("--meshes", help="comma-separated mesh names (default: the size's)")
    ap.add_argument("--seeds", type=int, default=5, help="strength seeds 1..N (default 5)")
    ap.add_argument("--draws", type=int,
                    help="runs per seed and mesh, each 1 nm higher (default: the size's)")
    ap.add_argument("-m", "--mesh-dir", help="where the prepared meshes live (cohfrac run -m)")
    add_study_arguments(ap)
    a = ap.parse_args()
    meshes = [m for m in (a.meshes or SIZES[a.size][0]).split(",") if m]
    seeds = range(1, max(1, a.seeds) + 1)
    draws = range(max(1, a.draws or SIZES[a.size][1]))
    a.output = a.output or os.path.join("build", "bunny_table", a.size)
    os.makedirs(os.path.join(a.output, "runs"), exist_ok=True)
    # the slow meshes first, so that the pool's last runs are short ones
    cases = [(m, s, d) for m in reversed(meshes) for d in draws for s in seeds]
    with concurrent.futures.ThreadPoolExecutor(max(1, a.jobs)) as pool:
        futs = [pool.submit(run, a.cohfrac, a.output, a.mesh_dir, a.set, *c) for c in cases]
        try:
            runs = [f.result() for f in futs]
        except (RuntimeError, OSError, KeyError) as e:
            for f in futs:
                f.cancel()
            print(f"bunny_table.py: {e}", file=sys.stderr)
            return 2

    median = lambda v: float(np.median(v))  # noqa: E731
    parts = {r["tag"]: partition(os.path.join(a.output, "runs", r["tag"] + ".h5")) for r in runs}
    rows, checks, every_pair = [], [], []
    for s in seeds:
        mine = [r for r in runs if r["seed"] == s]
        per = {m: [r for r in mine if r["mesh"] == m] for m in meshes}
        counts = {m: median([len(r["pieces"]) for r in per[m]]) for m in meshes}
        big = {m: median([r["largest"] for r in per[m]]) for m in meshes}
        ok_count = max(counts.values()) - min(counts.values()) <= 1
        ok_big = max(big.values()) - min(big.values()) <= 0.15
        ps = pairs(mine, parts)
        every_pair += ps
        within, across, same_within, same_across = (mean_of(ps, i, same) for i, same in
                                                    ((2, True), (2, False), (3, True), (3, False)))
        checks += [(f"count_s{s}", ok_count), (f"largest_s{s}", ok_big)]
        rows.append({"seed": s, "counts": counts, "largest": big, "count_ok": ok_count,
                     "largest_ok": ok_big, "agree_within": within, "agree_across": across,
                     "shared_within": same_within, "shared_across": same_across,
                     "range": {m: [min(len(r["pieces"]) for r in per[m]),
                                   max(len(r["pieces"]) for r in per[m]),
                                   min(r["largest"] for r in per[m]),
                                   max(r["largest"] for r in per[m])] for m in meshes}})
    chips = max(r["chips"] for r in runs)
    bad = [r["tag"] for r in runs if not r["plausible"] or r["residual"] > 0.01]
    checks += [("chips", chips <= 0.05), ("physics", not bad)]
    pooled = {m: (median([r["largest"] for r in runs if r["mesh"] == m]),
                  median([len(r["pieces"]) for r in runs if r["mesh"] == m]),
                  median([r["crack_area"] for r in runs if r["mesh"] == m]),
                  float(np.nanmedian([r["parted_area"] / r["crack_area"] if r["crack_area"] > 0
                                      else np.nan for r in runs if r["mesh"] == m])))
              for m in meshes}
    w_all, a_all, sw_all, sa_all = (float(np.mean([r[k] for r in rows])) for k in
                                    ("agree_within", "agree_across", "shared_within",
                                     "shared_across"))

    n_draws = len(draws)
    what = "median over the draws" if n_draws > 1 else "one run"
    lines = [f"# The plaster bunny drop: {len(meshes)} meshes, seeds 1-{len(seeds)}, "
             f"{n_draws} draw(s) each", "",
             f"Pieces of at least 5 % (the largest share, %), {what}, on "
             + " / ".join(f"{m} ({next(r['n_tets'] for r in runs if r['mesh'] == m)} tets)"
                          for m in meshes)
             + (f"; settings: {' '.join(a.set)}" if a.set else "") + ".", ""]
    head = "| seed | " + " | ".join(meshes) + " | count within 1 | largest within 0.15 |"
    if n_draws > 1:
        head += " pairs agreeing, one mesh | across meshes | same pieces, one mesh | across |"
    lines += [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        cells = []
        for m in meshes:
            c = f"{r['counts'][m]:g} ({100 * r['largest'][m]:.1f})"
            if n_draws > 1:
                lo, hi, blo, bhi = r["range"][m]
                c += f"; {lo}-{hi} ({100 * blo:.0f}-{100 * bhi:.0f})"
            cells.append(c)
        line = (f"| {r['seed']} | " + " | ".join(cells) +
                f" | {'yes' if r['count_ok'] else 'no'} | {'yes' if r['largest_ok'] else 'no'} |")
        if n_draws > 1:
            line += (f" {100 * r['agree_within']:.0f} % | {100 * r['agree_across']:.0f} % |"
                     f" {100 * r['shared_within']:.0f} % | {100 * r['shared_across']:.0f} % |")
        lines.append(line)
    lines += ["", "Pooled over seeds and draws, the medians of the largest share, the count, "
              "the crack area and the share of it that parts two fragments (the rest is cracks "
              "that stop inside a piece): "
              + ", ".join(f"{m} {100 * b:.1f} %, {c:g}, {ca:.3g} m^2 and {100 * pa:.0f} %"
                          for m, (b, c, ca, pa) in pooled.items()) + ".",
              f"Chips (fragments of at most {CHIP_TETS} tets): at most {100 * chips:.2f} % of the "
              f"mass; runs outside check_physics.py or over 1 % residual: {', '.join(bad) or 'none'}."]
    if n_draws > 1:
        by_meshes = {}
        for m1, m2, _, x in every_pair:
            by_meshes.setdefault(tuple(sorted((m1, m2), key=meshes.index)), []).append(x)
        lines.append("The share of their large pieces' mass that two runs of one seed break into the same pieces, by meshes: " +
                     ", ".join(f"{m1} and {m2} {100 * np.nanmean(by_meshes[m1, m2]):.0f} %"
                               for m1, m2 in itertools.combinations_with_replacement(meshes, 2)
                               if (m1, m2) in by_meshes) + ".")
        lines.append(f"Pairs of one seed's runs that agree (counts within 1, largest within 0.15): "
                     f"{100 * w_all:.0f} % on one mesh, {100 * a_all:.0f} % across meshes; "
                     f"the share of the mass of its pieces of at least 5 % that such a pair "
                     f"breaks into the same pieces (the same regions of the rest body): {100 * sw_all:.0f} % on one mesh, "
                     f"{100 * sa_all:.0f} % across meshes.")
    k = len(meshes)
    floor = {m: noise_floor(runs, m, seeds, k) for m in meshes} if k > 1 and n_draws >= k else {}
    if floor:
        lines.append(f"If the meshes did not matter: a table of one run per seed on {k} copies of "
                     f"one mesh ({k} of its draws) meets every seed's checks with a chance of "
                     + ", ".join(f"{100 * p:.1f} % on {m} (per seed "
                                 + " ".join(f"{100 * q:.0f}" for q in per) + " %)"
                                 for m, (per, p) in floor.items()) + ".")
    text = "\n".join(lines) + "\n"
    with open(os.path.join(a.output, "bunny_table.md"), "w") as f:
        f.write(text)
    with open(os.path.join(a.output, "bunny_table.json"), "w") as f:
        json.dump({"meshes": meshes, "draws": n_draws, "set": a.set, "rows": rows,
                   "noise_floor": {m: {"per_seed": per, "all_seeds": p} for m, (per, p) in floor.items()},
                   "runs": runs}, f, indent=1)
    print(text, end="")
    known = read_known(a.known, a.size)
    failed = {name for name, good in checks if not good}
    for name in sorted(failed):
        print(f"  {'known' if name in known else 'FAIL ':<5} {name}")
    return known_verdict("bunny_table.py", [name for name, _ in checks], failed, known, a.known,
                         f"{a.output}/bunny_table.md")


if __name__ == "__main__":
    sys.exit(main())
