#!/usr/bin/python3
"""Error against run time of `cohfrac study`:
study_plot.py STUDY.csv OUT.png TOLERANCE TITLE

Left: trajectory error (traj_rel, RMS centre-of-mass distance to the
reference over the reference's travel) against wall time, log-log; the
Pareto front is the stepped line, the tolerance the dashed line, the
cheapest case within it circled, the reference's wall time the dotted
vertical line.  Right: the fragment-mass distribution distance (mass KS)
against wall time.  Cases that did not finish are crosses at their wall
time.  Zero errors are drawn at the axis floor.  Debian python3 and
python3-matplotlib (Agg backend); the PNG is written to OUT.png.tmp and
renamed.  Exit 3 when matplotlib is missing, 2 on a bad CSV.
"""
import csv
import math
import sys

from mpl_agg import pyplot, save_png

plt = pyplot("study_plot.py")


def num(s):
    try:
        return float(s)
    except ValueError:
        return math.nan


def main():
    if len(sys.argv) != 5:
        sys.stderr.write(__doc__)
        return 2
    try:
        with open(sys.argv[1], newline="") as f:
            rows = list(csv.DictReader(f))
        for r in rows:
            r["wall"], r["traj_rel"], r["mass_ks"] = (num(r[k]) for k in ("wall", "traj_rel",
                                                                          "mass_ks"))
        tol = float(sys.argv[3])
    except (OSError, KeyError, ValueError) as e:
        sys.stderr.write(f"study_plot.py: cannot read {sys.argv[1]}: {e}\n")
        return 2
    ref = rows[0]
    cases = rows[1:]
    ok = [r for r in cases if r["exit_code"] == "0"]
    bad = [r for r in cases if r["exit_code"] != "0"]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4))
    for ax, key, label in ((axes[0], "traj_rel", "trajectory error / travel"),
                           (axes[1], "mass_ks", "fragment-mass distribution distance (KS)")):
        vals = [r[key] for r in ok if r[key] > 0 and math.isfinite(r[key])]
        floor = min(vals) / 3 if vals else 1e-6
        top = max(vals + [tol * 3 if key == "traj_rel" else 1.0])

        def y(r):
            v = r[key]
            return v if v > 0 and math.isfinite(v) else floor

        ax.scatter([r["wall"] for r in ok], [y(r) for r in ok], s=22, color="tab:blue",
                   label="finished case", zorder=3)
        if bad:
            ax.scatter([r["wall"] for r in bad], [top for r in bad], marker="x",
                       color="tab:red", label="diverged / failed (at top)", zorder=3)
        if key == "traj_rel":
            front = sorted((r for r in ok if r["pareto"] == "1"), key=lambda r: r["wall"])
            if front:
                xs, ys = [], []
                for r in front:
                    xs.append(r["wall"]), ys.append(y(r))
                ax.step(xs, ys, where="post", color="tab:orange", label="Pareto front",
                        zorder=2)
            ax.axhline(tol, ls="--", color="gray", lw=1, label=f"tolerance {tol:g}")
            for r in ok:
                if r["best"] == "1":
                    ax.scatter([r["wall"]], [y(r)], s=160, facecolors="none",
                               edgecolors="tab:green", lw=2,
                               label=f"cheapest within tolerance (case {r['case']})", zorder=4)
        if math.isfinite(ref["wall"]) and ref["wall"] > 0:
            ax.axvline(ref["wall"], ls=":", color="k", lw=1, label="reference wall time")
        for r in ok:
            ax.annotate(r["case"], (r["wall"], y(r)), fontsize=7, xytext=(3, 3),
                        textcoords="offset points")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("wall time (s)")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7, loc="best")
    fig.suptitle(f"{sys.argv[4]}: error against run time "
                 f"(case numbers as in study.md)", fontsize=10)
    save_png(fig, sys.argv[2])
    return 0


if __name__ == "__main__":
    sys.exit(main())
