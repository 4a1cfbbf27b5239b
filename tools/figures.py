#!/usr/bin/python3
"""The source chapter's fracture figures, run and checked against what its
text says each one shows (docs/scenes.md, "The chapter's figures").

    tools/figures.py COHFRAC_EXE [-m MESH_DIR] [-o DIR] [-j JOBS] [--seeds N]
                     [--md FILE] [--sheet PNG]

Runs every scene of FIGURES at its defaults (`cohfrac run SCENE -t 1`)
with the material's strength seeds 1 to N (3 by default; seed 1 is the
scene as shipped, the others `--set material.strength.seed=S`: each seed
is another specimen of the same material, and an outcome that one
specimen shows and the next does not is not yet the material's).  For each
scene, from seed 1: fragments, the largest and next pieces' shares of the
mass, pieces of at least 5 % and 1 %, the mass in chips (fragments of at
most 4 tets), the fastest piece against tests/checks/check_physics.py's
bound; for every seed, whether the outcome the text describes holds (6.11b
against 6.11a of the same seed).  Writes DIR/figures.md (a table; with
--md the same table replaces the section between the markers in that
file), DIR/figures.json, and a sheet of pictures of seed 1 before the
break and at the end (tools/plot_pieces.py's drawing, one row per figure;
--sheet copies it).

Exit status: 0 when every outcome holds for every seed, 1 when one does
not, 2 when a run fails.
"""
import argparse
import concurrent.futures
import json
import os
import subprocess
import sys

# The test checkers and the reader, from the source tree.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "checks"))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
import numpy as np  # noqa: E402

import check_physics  # noqa: E402
import fragment_stats  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = os.path.join(HERE, "..", "scenes")
CHIP_TETS = 4
CHIPS_MAX = 0.10  # every scene: chips carry at most 10 % of the mass


def at_least(n, share):
    return lambda f: len([s for s in f["shares"] if s >= share]) >= n


# figure, scene, what the chapter's text says, the outcome that says it, its test
FIGURES = [
    ("6.3", "bunny_drop", "each separate component of the bunny will be treated as a rigid body",
     "at least 3 pieces of at least 5 %", at_least(3, 0.05)),
    ("6.11a", "sphere_strength_5mPa", "the sphere collides and breaks with smax = 5 mPa",
     "at least 2 pieces of at least 5 %", at_least(2, 0.05)),
    ("6.11b", "sphere_strength_0.5uPa", "breaks even more",
     "more pieces of at least 1 % than 6.11a, and not into single tets",
     None),  # compared with 6.11a below
    ("6.12", "hollow_sphere_break", "the sphere falls and breaks in half",
     "the two largest pieces each at least 25 %",
     lambda f: len(f["shares"]) >= 2 and f["shares"][1] >= 0.25),
    ("6.13", "bunny_hit_by_sphere", "the bunny mesh fragments much",
     "the largest at most 70 %, at least 3 pieces of at least 5 %",
     lambda f: f["shares"][0] <= 0.70 and at_least(3, 0.05)(f)),
    ("6.14", "glass_plate", "breaking when hitting the ground",
     "at least 3 pieces of at least 5 %", at_least(3, 0.05)),
]


def run(exe, scene, seed, mesh_dir, out_dir):
    h5 = os.path.join(out_dir, f"{scene}_s{seed}.h5")
    cmd = [exe, "run", os.path.join(SCENES, scene + ".lua"), "-q", "-t", "1", "-o", h5,
           "--force", "--set", f"material.strength.seed={seed}"] + \
        (["-m", mesh_dir] if mesh_dir else [])
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{scene}, seed {seed}: cohfrac exit {r.returncode}: "
                           f"{r.stderr.strip()[-400:]}")
    m, nt, speed, debris, crack = fragment_stats.last_frame(h5)
    share = np.sort(m / m.sum())[::-1]
    bounds = {}
    plausible = check_physics.check_file(h5, quiet=True, figures=bounds)
    return {"scene": scene, "seed": seed, "file": h5, "fragments": int(len(m)),
            "shares": [float(s) for s in share],
            "pieces_5": int((share >= 0.05).sum()), "pieces_1": int((share >= 0.01).sum()),
            "chips": float(m[nt <= CHIP_TETS].sum() / m.sum()),
            "single_tets": float(m[nt == 1].sum() / m.sum()),
            "fastest": bounds.get("fastest", float("nan")),
            "bound": bounds.get("speed_bound", float("nan")),
            "plausible": bool(plausible), "failed_checks": bounds.get("failed", [])}


def judge(results):
    """Sets each run's "outcome" (what the text says holds) and "ok" (and
    its chips and physical bounds too); True when every run is ok."""
    by = {(r["scene"], r["seed"]): r for r in results}
    for (scene, seed), f in by.items():
        test = next(t for _, s, _, _, t in FIGURES if s == scene)
        if test is None:  # 6.11b: more than 6.11a of the same seed, not single tets
            a = by[("sphere_strength_5mPa", seed)]
            holds = f["pieces_1"] > a["pieces_1"] and f["single_tets"] < 0.5
        else:
            holds = bool(test(f))
        f["outcome"] = holds
        f["ok"] = holds and f["chips"] <= CHIPS_MAX and f["plausible"]
    return all(f["ok"] for f in results)


def seeds_held(results, scene):
    """The seeds for which everything holds for scene (after judge)."""
    return sorted(r["seed"] for r in results if r["scene"] == scene and r["ok"])


def table(results):
    """The figures of seed 1 and, per figure, the seeds for which all holds."""
    by = {(r["scene"], r["seed"]): r for r in results}
    seeds = sorted({r["seed"] for r in results})
    rows = ["| figure | scene | the text says | outcome asked | fragments | largest / next | "
            "pieces >= 5 % / 1 % | chips | fastest / bound (m/s) | holds (seed 1) | "
            f"seeds {seeds[0]}-{seeds[-1]} that hold |",
            "|---|---|---|---|---|---|---|---|---|---|---|"]
    for fig, scene, says, asked, _ in FIGURES:
        f = by[(scene, seeds[0])]
        held = seeds_held(results, scene)
        held_text = (", ".join(str(s) for s in held) if held else "none") + \
            f" ({len(held)} of {len(seeds)})"
        nxt = f["shares"][1] if len(f["shares"]) > 1 else 0.0
        verdict = "yes" if f["ok"] else ("no" + ("" if f["outcome"] else ": outcome")
                                         + ("" if f["chips"] <= CHIPS_MAX else ": chips")
                                         + ("" if f["plausible"] else
                                            ": " + ", ".join(f["failed_checks"])))
        rows.append(f"| {fig} | `{scene}` | \"{says}\" | {asked} | {f['fragments']} | "
                    f"{100 * f['shares'][0]:.1f} / {100 * nxt:.1f} % | "
                    f"{f['pieces_5']} / {f['pieces_1']} | {100 * f['chips']:.1f} % | "
                    f"{f['fastest']:.3g} / {f['bound']:.3g} | {verdict} | {held_text} |")
    return "\n".join(rows) + "\n"


def sheet(results, path):
    """Before the break and at the end, one row per figure (the pieces of
    at least 5 % in colour, tools/plot_pieces.py)."""
    from cohfrac import h5 as cohfrac_h5
    import plot_pieces
    plt = plot_pieces.plt
    fig = plt.figure(figsize=(9, 4.2 * len(results)))
    for row, r in enumerate(results):
        run = cohfrac_h5.load(r["file"])
        for col, frame in enumerate((0, len(run.times) - 1)):
            ax = fig.add_subplot(len(results), 2, 2 * row + col + 1, projection="3d")
            title = plot_pieces.view(ax, run, frame, 0.05)
            ax.set_title(f"{r['scene']}: {title}", fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=70)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("cohfrac")
    ap.add_argument("-m", "--mesh-dir")
    ap.add_argument("-o", "--output", default="build/figures")
    ap.add_argument("-j", "--jobs", type=int, default=1)
    ap.add_argument("--seeds", type=int, default=3,
                    help="run the strength seeds 1 to N of each scene (default 3)")
    ap.add_argument("--md", help="a markdown file whose figures section gets the table")
    ap.add_argument("--sheet", help="copy the sheet of pictures here")
    a = ap.parse_args()
    if a.seeds < 1:
        print(f"figures.py: --seeds {a.seeds}: give at least 1", file=sys.stderr)
        return 2
    os.makedirs(a.output, exist_ok=True)
    cases = [(f[1], seed) for seed in range(1, a.seeds + 1) for f in FIGURES]
    try:
        with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
            results = list(pool.map(lambda c: run(a.cohfrac, c[0], c[1], a.mesh_dir, a.output),
                                    cases))
    except RuntimeError as e:
        print(f"figures.py: {e}", file=sys.stderr)
        return 2
    ok = judge(results)
    md = table(results)
    with open(os.path.join(a.output, "figures.md"), "w") as f:
        f.write(md)
    with open(os.path.join(a.output, "figures.json"), "w") as f:
        json.dump(results, f, indent=1)
    png = os.path.join(a.output, "figures.png")
    sheet([r for r in results if r["seed"] == 1], png)
    if a.sheet:
        import shutil
        shutil.copyfile(png, a.sheet)
    if a.md:
        text = open(a.md).read()
        start, end = "<!-- figures: start -->", "<!-- figures: end -->"
        if start in text and end in text:
            head, rest = text.split(start, 1)
            text = head + start + "\n" + md + end + rest.split(end, 1)[1]
            open(a.md, "w").write(text)
    print(md)
    held = [len(seeds_held(results, f[1])) == a.seeds for f in FIGURES]
    print(f"figures.py: {sum(held)} of {len(FIGURES)} figures hold for every seed of 1-{a.seeds} "
          f"({sum(r['ok'] for r in results)} of {len(results)} runs); {png}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
