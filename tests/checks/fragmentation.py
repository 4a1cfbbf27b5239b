#!/usr/bin/python3
"""Fragmentation benchmarks: the plaster sphere drop ladder and its mesh convergence.

usage: fragmentation.py COHFRAC [--size ci|full] [--seeds N] [-o DIR] [-j N]
                          [--known FILE] [--set KEY=VALUE ...]

Runs scenes/plaster_sphere_drop.lua (a gypsum plaster sphere striking a
rigid floor) after Wu, Chau and Yu (Powder Technology 2004), who broke
spheres of 50 and 75 mm at 1-9 m/s (struck on an anvil by a falling
weight, docs/physics.md section 15), at their sizes and those speeds and
more, and checks
  threshold   the threshold speed (the lowest speed of the ladder at which
              the largest piece is below 90 % of the mass, on average over
              the seeds) of the 50 mm
              and 75 mm spheres agree within a factor 0.8-1.25;
  largest_D   at the threshold, the largest piece is 30-70 % of the mass;
  tau_D       at twice the threshold, the exponent tau of the fragment-mass
              distribution n(m) ~ m^-tau is 1.45-1.85 (theory for solid 3D
              bodies: 1.67), fitted over at least 1.5 decades above 10
              element masses;
and, for the 50 mm sphere at twice its threshold on element sizes of 1,
1/2 and 1/4 of the cohesive length l_ch = E G_I / sigma_max^2 (12.5 mm;
the CI size stops at 1/3),
  conv_crack  crack area within 15 % between the two finest meshes;
  conv_tau    tau within 0.15 between them;
  one_tet     mass in one-tet fragments below 1 % and falling with refinement;
  residual    ledger residual at most 1 % in every run, and every run within
              the physical bounds of tests/checks/check_physics.py.

The CI size climbs each diameter's ladder only up to the first speed at
which every seed breaks (its largest piece below 90 %): no check reads a
faster case.  The full size runs every speed.

Every case is dropped with the strength seeds 1..N (--seeds, 3 by default),
as the experiments dropped many spheres at each speed: one seed is one
sphere of a random material, and the largest piece of one seed can differ
from the next seed's by 20 points of mass near the threshold (docs/physics.md
§15).  A case's largest piece, one-tet mass and crack area are the means over
its seeds, its fragments are pooled for tau (as the experiments pooled the
fragments of their spheres), and its residual is the worst seed's.

tau is the maximum-likelihood exponent of a power law fitted over the
fragments from m_min = 10 element masses to the largest, m_max: the law
truncated to that range (Aban, Meerschaert and Panorska, J Am Stat Assoc
101:270, 2006; tau_fit); its range is log10(m_max / m_min) decades.

Each sphere's own threshold (the lowest speed at which that seed's largest
piece is below 90 %) and its largest piece there are reported beside the
checks, which read the means: whether each sphere splits or chips at its own
threshold, which a mean over seeds that break at different speeds hides.

Writes DIR/fragmentation.json (every run's figures), DIR/fragmentation.md
(the tables) and DIR/fragmentation.png (the cumulative mass distributions
on log-log axes beside the slopes of tau = 1.45 and 1.85); runs are cached
in DIR/runs/ (rerun when the program or the scene is newer; a variant made with --set,
passed to every run as `cohfrac run --set`, is cached under its own name).  Checks named in the
--known file (one "name reason..." per line; "name@ci" or "name@full" for
one size only) are known not to hold yet: they must fail, and the exit
status is 0 when the failing checks are exactly those; 1 otherwise; 2 on a
run that could not be made or read.
"""
import argparse
import hashlib
import concurrent.futures
import json
import math
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import check_physics  # noqa: E402
import fragment_stats  # noqa: E402

SCENE = os.path.join(HERE, "..", "..", "scenes", "plaster_sphere_drop.lua")
L_CH = 0.0125  # m, E G_I / sigma_max^2 of the scene's plaster
SIZES = {
    # ladder element size, speeds (m/s), convergence element sizes, whether
    # the ladder stops at the first speed that breaks every sphere (no check
    # reads a speed above it: see climb)
    "ci": (L_CH / 2, [6, 7, 8, 9, 10, 11, 12, 13], [L_CH, L_CH / 2, L_CH / 3], True),
    "full": (L_CH / 2, [4, 5, 6, 7, 7.5, 8, 8.5, 9, 10, 11, 12, 13, 14], [L_CH, L_CH / 2, L_CH / 4],
             False),
}
DIAMETERS = (0.050, 0.075)  # m


def cached_run(exe, scene, out_dir, tag, sets, extra, mesh_dir=None):
    """`cohfrac run scene` on one thread with --set `sets` and then `extra`
    (a variant, whose hash joins the tag), into out_dir/runs/TAG.h5, unless
    a run that finished there is newer than the program and the scene.
    Returns (tag, the file's path); raises RuntimeError when cohfrac fails."""
    if extra:
        tag += "_" + hashlib.sha1("\n".join(extra).encode()).hexdigest()[:8]
    h5 = os.path.join(out_dir, "runs", tag + ".h5")
    done = h5 + ".done"  # written after a run that finished
    newest = max(os.path.getmtime(exe), os.path.getmtime(scene))  # the program or the scene
    if not os.path.exists(done) or os.path.getmtime(done) < newest:
        cmd = [exe, "run", scene, "-t", "1", "-q", "-o", h5, "--force"]
        cmd += ["--mesh-dir", mesh_dir] if mesh_dir else []
        for s in sets + extra:
            cmd += ["--set", s]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"{tag}: cohfrac exit {r.returncode}: {r.stderr.strip()[-400:]}")
        open(done, "w").close()
    return tag, h5


def run(exe, out_dir, extra, diameter, speed, h, seed=1):
    """One drop, with the settings `extra` (cohfrac run --set) on top;
    returns its figures (cached by name in out_dir/runs)."""
    R = diameter / 2
    sets = [f"bodies[1].mesh.radius={R!r}", f"bodies[1].mesh.mesh_size={h!r}",
            f"bodies[1].position={{0,0,{R + 0.0005!r}}}",
            f"bodies[1].velocity={{0,0,{-speed!r}}}", f"material.strength.seed={seed}"]
    tag, h5 = cached_run(exe, SCENE, out_dir, f"D{1000 * diameter:g}_v{speed:g}_h{1000 * h:.3g}_s{seed}",
                         sets, extra)
    return dict(figures(h5), tag=tag, diameter=diameter, speed=speed, h=h, seed=seed)


def merge(runs):
    """One case's figures over its seeds' runs: means of the largest
    piece, one-tet mass and crack area, the fragments pooled, the worst
    residual; `seeds` keeps each run's largest piece and fragment count."""
    worst = max(runs, key=lambda r: r["residual"])
    mean = lambda k: float(np.mean([r[k] for r in runs]))  # noqa: E731
    return {
        "fragments": mean("fragments"),
        "masses": sorted((m for r in runs for m in r["masses"]), reverse=True),
        "largest": mean("largest"),
        "one_tet": mean("one_tet"),
        "crack_area": mean("crack_area"),
        "residual": worst["residual"],
        "plausible": all(r["plausible"] for r in runs),
        "n_tets": runs[0]["n_tets"],
        "tag": worst["tag"],
        "bad": [r["tag"] for r in runs if not r["plausible"]],
        "diameter": runs[0]["diameter"], "speed": runs[0]["speed"], "h": runs[0]["h"],
        "seeds": [{"seed": r["seed"], "largest": r["largest"], "fragments": r["fragments"],
                   "crack_area": r["crack_area"], "tag": r["tag"]} for r in runs],
    }


def figures(h5):
    m, nt, _, _, crack = fragment_stats.last_frame(h5)
    total = float(m.sum())
    m_e = total / float(nt.sum())
    bounds = {}
    plausible = check_physics.check_file(h5, quiet=True, figures=bounds)
    return {
        "fragments": int(len(m)),
        "masses": sorted((m / m_e).tolist(), reverse=True),  # in element masses
        "largest": float(m.max() / total),
        "one_tet": float(m[nt == 1].sum() / total),
        "crack_area": crack,
        "residual": float(bounds["residual_share"]),
        "plausible": bool(plausible),
        "n_tets": int(nt.sum()),
    }


def tau_fit(masses, m_min=10.0):
    """The power-law exponent of the fragments of at least m_min (element
    masses), fitted over their range [m_min, m_max] (m_max the largest):
    (tau, decades, n); tau is nan with fewer than 3 fragments.

    tau is the maximum-likelihood exponent of the power law truncated to
    that range (Aban, Meerschaert and Panorska, J Am Stat Assoc 101:270,
    2006): with a = tau - 1, r = m_min / m_max and S = sum ln(m_i / m_min),
    the root of n/a - S + n r^a ln r / (1 - r^a) = 0 (the log-likelihood is
    concave in a), found by bisection; its limit as a -> 0 is
    -n ln r / 2 - S.  A body's fragments are bounded by its mass, and
    over the 1.3-2 decades a sphere of a few thousand tets gives, the
    estimator of an unbounded law (1 + n / S, Clauset, Shalizi and Newman
    2009) reads a power law of tau = 1.67 as 1.98 over 1.3 decades and
    1.79 over 2 (tests/checks/test_tau_fit.py).  tau = 1 where the
    likelihood rises towards a flat law (no root above a = 0)."""
    x = np.asarray([m for m in masses if m >= m_min], dtype=float)
    n = len(x)
    if n < 3:
        return float("nan"), 0.0, int(n)
    s, lr = float(np.sum(np.log(x / m_min))), math.log(m_min / x.max())
    decades = -lr / math.log(10)
    if lr == 0:
        return float("nan"), decades, int(n)

    def slope(a):  # the log-likelihood's derivative, falling in a
        return n / a - s - n * math.exp(a * lr) * lr / math.expm1(a * lr)

    lo, hi = 0.0, 1.0
    if -n * lr / 2 - s <= 0:  # the slope's limit as a -> 0
        return 1.0, decades, int(n)
    while slope(hi) > 0:
        lo, hi = hi, 2 * hi
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if slope(mid) > 0 else (lo, mid)
    return 1 + 0.5 * (lo + hi), decades, int(n)


def climb(many, D, h, speeds, stop):
    """The ladder of diameter D on element size h: its cases (many's merged
    figures) by rising speed.  With `stop` it ends at the first speed at
    which every seed's largest piece is below 90 %: there the mean is
    below 90 % too, so the threshold and each sphere's own threshold are
    found, and no check reads a faster case (the full size runs them all)."""
    runs = []
    for v in speeds:
        runs += many([(D, v, h)])
        if stop and all(q["largest"] < 0.9 for q in runs[-1]["seeds"]):
            break
    return runs


def own_thresholds(runs):
    """Each seed's own threshold on a ladder (its merged cases by rising
    speed): [(seed, speed or None, that seed's largest piece there)], the
    lowest speed at which that sphere's largest piece is below 90 %."""
    out = []
    for i, q in enumerate(runs[0]["seeds"] if runs else []):
        hit = next((r for r in runs if r["seeds"][i]["largest"] < 0.9), None)
        out.append((q["seed"], hit and hit["speed"], hit and hit["seeds"][i]["largest"]))
    return out


def add_study_arguments(ap):
    """The options a study of runs takes: -o DIR, -j N, --known FILE and
    --set KEY=VALUE (repeatable)."""
    ap.add_argument("-o", "--output", default=None)
    ap.add_argument("-j", "--jobs", type=int, default=1)
    ap.add_argument("--known", default=None)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="a scene setting for every run (cohfrac run --set)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cohfrac")
    ap.add_argument("--size", choices=SIZES, default="ci")
    ap.add_argument("--seeds", type=int, default=3,
                    help="strength seeds per case (1..N; default 3)")
    add_study_arguments(ap)
    a = ap.parse_args()
    out = a.output or os.path.join("build", "fragmentation", a.size)
    os.makedirs(os.path.join(out, "runs"), exist_ok=True)
    h_ladder, speeds, h_conv, stop = SIZES[a.size]
    pool = concurrent.futures.ThreadPoolExecutor(max(1, a.jobs))

    def many(cases):
        seeds = range(1, max(1, a.seeds) + 1)
        futs = [[pool.submit(run, a.cohfrac, out, a.set, *c, seed) for seed in seeds]
                for c in cases]
        return [merge([f.result() for f in fs]) for fs in futs]

    def walk(D):
        """Diameter D's cases: its ladder, the threshold case (None when
        no speed breaks it), twice the threshold, and for the first
        diameter the mesh convergence there."""
        runs = climb(many, D, h_ladder, speeds, stop)
        t = next((r for r in runs if r["largest"] < 0.9), None)
        twice = many([(D, 2 * t["speed"], h_ladder)])[0] if t else None
        conv = many([(D, 2 * t["speed"], h) for h in h_conv]) if t and D == DIAMETERS[0] else []
        return runs, t, twice, conv

    try:  # the diameters walk side by side, sharing the pool's workers
        with concurrent.futures.ThreadPoolExecutor(len(DIAMETERS)) as walkers:
            walked = dict(zip(DIAMETERS, walkers.map(walk, DIAMETERS)))
    except (RuntimeError, OSError, KeyError) as e:
        print(f"fragmentation.py: {e}", file=sys.stderr)
        return 2
    ladder = {D: w[0] for D, w in walked.items()}
    threshold = {D: w[1] for D, w in walked.items()}
    twice = {D: w[2] for D, w in walked.items()}
    conv = walked[DIAMETERS[0]][3]

    checks = []
    t50, t75 = (threshold[D] for D in DIAMETERS)
    ratio = t50["speed"] / t75["speed"] if t50 and t75 else float("nan")
    checks.append(("threshold", 0.8 <= ratio <= 1.25,
                   f"threshold speeds {t50 and t50['speed']} m/s (50 mm) and "
                   f"{t75 and t75['speed']} m/s (75 mm), ratio {ratio:.3g} (0.8-1.25)"))
    for D in DIAMETERS:
        t, d = threshold[D], f"{1000 * D:g}"
        big = t["largest"] if t else float("nan")
        spread = (" (seeds " + ", ".join(f"{100 * q['largest']:.1f}" for q in t["seeds"]) + " %)"
                  if t else "")
        checks.append((f"largest_{d}", 0.3 <= big <= 0.7,
                       f"{d} mm at the threshold: largest piece {100 * big:.1f} % on average{spread}"
                       f" (30-70 %)"))
        tau, dec, n = tau_fit(twice[D]["masses"]) if twice[D] else (float("nan"), 0, 0)
        if twice[D]:
            twice[D]["tau"], twice[D]["decades"] = tau, dec
        checks.append((f"tau_{d}", 1.45 <= tau <= 1.85 and dec >= 1.5,
                       f"{d} mm at twice the threshold: tau {tau:.3g} (1.45-1.85) from {n} "
                       f"fragments over {dec:.2f} decades (>= 1.5)"))
    for r in conv:
        r["tau"], r["decades"], _ = tau_fit(r["masses"])
    if len(conv) == 3:
        a1, a2 = conv[1]["crack_area"], conv[2]["crack_area"]
        rel = abs(a2 - a1) / max(a2, 1e-300)
        checks.append(("conv_crack", rel <= 0.15,
                       f"crack area {a1:.4g} and {a2:.4g} m^2 on the two finest, {100 * rel:.1f} % "
                       f"apart (<= 15 %)"))
        dt = abs(conv[2]["tau"] - conv[1]["tau"])
        checks.append(("conv_tau", dt <= 0.15,
                       f"tau {conv[1]['tau']:.3g} and {conv[2]['tau']:.3g} on the two finest, "
                       f"{dt:.3g} apart (<= 0.15)"))
        ot = [r["one_tet"] for r in conv]
        checks.append(("one_tet", ot[-1] < 0.01 and ot[0] >= ot[1] >= ot[2],
                       "mass in one-tet fragments " + ", ".join(f"{100 * x:.2f}" for x in ot)
                       + " % (below 1 %, falling)"))
    every = [r for runs in ladder.values() for r in runs] + [r for r in twice.values() if r] + conv
    worst = max(every, key=lambda r: r["residual"])
    bad = [tag for r in every for tag in r["bad"]]
    checks.append(("residual", worst["residual"] <= 0.01 and not bad,
                   f"{len(every)} cases ({sum(len(r['seeds']) for r in every)} runs), "
                   f"largest residual {100 * worst['residual']:.3g} % "
                   f"({worst['tag']}); outside tests/checks/check_physics.py: {', '.join(bad) or 'none'}"))

    own = {D: own_thresholds(runs) for D, runs in ladder.items()}
    write_report(out, a.size, ladder, threshold, twice, conv, checks, own)
    known = read_known(a.known, a.size)
    failed = {c[0] for c in checks if not c[1]}
    for name, good, text in checks:
        mark = "ok  " if good else ("known" if name in known else "FAIL")
        print(f"  {mark:<5} {name:<11} {text}")
    for D in DIAMETERS:
        print(f"  info  {1000 * D:g} mm, each sphere's own threshold: {sphere_line(own[D])}")
    return known_verdict("fragmentation.py", [c[0] for c in checks], failed, known, a.known,
                         f"{out}/fragmentation.md")


def known_verdict(prog, names, failed, known, path, report):
    """Prints a FIXED line for each known failure that holds now and the
    summary; the exit status: 0 when the failing checks are exactly the
    known ones among `names`, 1 otherwise."""
    for name in sorted(set(known) - failed):
        print(f"  FIXED {name:<11} listed in {path} but holds now: remove it from the list")
    print(f"{prog}: {len(names)} checks, {len(failed)} failing "
          f"({len(failed & set(known))} known); report in {report}")
    return 0 if failed == set(known) & set(names) else 1


def read_known(path, size):
    """The known failures of `size`: {name: reason}."""
    known = {}
    if path:
        with open(path) as f:
            for line in f:
                line = line.strip()
                if line and not line.startswith("#"):
                    name, _, why = line.partition(" ")
                    name, _, only = name.partition("@")
                    if only in ("", size):
                        known[name] = why.strip()
    return known


def sphere_line(own):
    """'seed 1 at 9 m/s (63.7 %), ...' for own_thresholds' list."""
    return ", ".join(f"seed {s} at {v:g} m/s ({100 * big:.1f} %)" if v else f"seed {s} unbroken"
                     for s, v, big in own)


def write_report(out, size, ladder, threshold, twice, conv, checks, own):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with open(os.path.join(out, "fragmentation.json"), "w") as f:
        json.dump({"size": size, "ladder": {f"{D:g}": r for D, r in ladder.items()},
                   "twice": {f"{D:g}": r for D, r in twice.items()}, "convergence": conv,
                   "checks": [{"name": n, "ok": g, "text": t} for n, g, t in checks],
                   "own_thresholds": {f"{D:g}": [{"seed": s, "speed": v, "largest": big}
                                                 for s, v, big in o] for D, o in own.items()}},
                  f, indent=1)
    lines = [f"# Plaster sphere drop ladder ({size} size)", "",
             "Means over the strength seeds; the largest piece of each seed in brackets; the worst residual.",
             "",
             "| diameter | speed (m/s) | tets | fragments | largest (each seed) | one-tet mass | crack area (m²) | residual |",
             "|---|---|---|---|---|---|---|---|"]

    def each(r):
        return ", ".join(f"{100 * q['largest']:.1f}" for q in r["seeds"])

    for D, runs in ladder.items():
        for r in runs + ([twice[D]] if twice[D] else []):
            mark = " (threshold)" if threshold[D] is r else (" (2x)" if twice[D] is r else "")
            lines.append(f"| {1000 * D:g} mm | {r['speed']:g}{mark} | {r['n_tets']} | {r['fragments']:.4g} | "
                         f"{100 * r['largest']:.1f} % ({each(r)}) | {100 * r['one_tet']:.2f} % | "
                         f"{r['crack_area']:.4g} | {100 * r['residual']:.2f} % |")
    lines += ["", "Each sphere's own threshold (the lowest speed at which that seed's largest piece is "
              "below 90 %) and its largest piece there; the checks read the means above:", ""]
    lines += [f"- {1000 * D:g} mm: {sphere_line(o)}" for D, o in own.items()]
    lines += ["", "Mesh convergence (50 mm, twice the threshold):", "",
              "| element size | tets | fragments | largest (each seed) | tau (decades) | one-tet mass | crack area (m²) | residual |",
              "|---|---|---|---|---|---|---|---|"]
    for r in conv:
        lines.append(f"| {1000 * r['h']:.3g} mm (l_ch/{L_CH / r['h']:.3g}) | {r['n_tets']} | {r['fragments']:.4g} | "
                     f"{100 * r['largest']:.1f} % ({each(r)}) | {r['tau']:.3g} ({r['decades']:.2f}) | "
                     f"{100 * r['one_tet']:.2f} % | {r['crack_area']:.4g} | {100 * r['residual']:.2f} % |")
    lines += ["", "Checks:", ""] + [f"- {'ok' if g else 'FAIL'} `{n}`: {t}" for n, g, t in checks]
    with open(os.path.join(out, "fragmentation.md"), "w") as f:
        f.write("\n".join(lines) + "\n")

    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    curves = [(f"{1000 * D:g} mm at {r['speed']:g} m/s", r) for D, r in twice.items() if r]
    curves += [(f"50 mm, h = l_ch/{L_CH / r['h']:.3g}", r) for r in conv]
    for label, r in curves:
        m = np.sort(np.asarray(r["masses"]))[::-1]
        ax.loglog(m, np.arange(1, len(m) + 1), drawstyle="steps-post", label=label)
    x = np.array([10.0, 1e4])
    for tau, style in ((1.45, ":"), (1.85, "--")):
        ax.loglog(x, 30 * (x / 10) ** (1 - tau), "k" + style, lw=0.8, label=f"slope of tau = {tau}")
    ax.axvline(10, color="0.6", lw=0.6)
    ax.set_xlabel("fragment mass m (element masses)")
    ax.set_ylabel("fragments of mass >= m")
    ax.set_title("plaster sphere drop: cumulative fragment masses, seeds pooled")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "fragmentation.png"), dpi=110)


if __name__ == "__main__":
    sys.exit(main())
