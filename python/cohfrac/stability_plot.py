#!/usr/bin/python3
"""Heatmaps of `cohfrac stability`: stability_plot.py STABILITY.csv OUT.png

One row of panels per slice of the map written by src/cli/stability.c
("E x dt", "mass x dt", "speed x dt", "mesh x dt"), one panel per constraint mode; each
cell is green when the case is stable and red when not, labelled with the
criterion that failed first (n = nan, e = energy, i = inverted,
x = escaped) and the first failing step.  Debian python3 and
python3-matplotlib (Agg backend).  The PNG is written to OUT.png.tmp and
renamed.  Exit 3 when matplotlib is missing, 2 on a bad CSV.
"""
import csv
import sys

from mpl_agg import pyplot, save_png

plt = pyplot("stability_plot.py")
from matplotlib.colors import ListedColormap  # noqa: E402

ROWS = {"E x dt": ("E_Pa", "E (Pa)"),
        "mass x dt": ("mass_ratio", "m_impactor / m_target"),
        "speed x dt": ("speed_m_s", "impact speed (m/s)"),
        "mesh x dt": ("mesh", "mesh")}


def main():
    if len(sys.argv) != 3:
        sys.stderr.write(__doc__)
        return 2
    try:
        with open(sys.argv[1], newline="") as f:
            rows = list(csv.DictReader(f))
        modes = list(dict.fromkeys(r["constraints"] for r in rows))
        slices = [s for s in ROWS if any(r["slice"] == s for r in rows)]
    except (OSError, KeyError) as e:
        sys.stderr.write(f"stability_plot.py: cannot read {sys.argv[1]}: {e}\n")
        return 2
    fig, axes = plt.subplots(len(slices), len(modes), squeeze=False,
                             figsize=(3.6 * len(modes), 3.0 * len(slices)))
    cmap = ListedColormap(["#d9534f", "#5cb85c"])
    for i, s in enumerate(slices):
        key, label = ROWS[s]
        sel = [r for r in rows if r["slice"] == s]
        ys = list(dict.fromkeys(r[key] for r in sel))
        xs = sorted({float(r["dt_over_dt_cfl"]) for r in sel})
        for j, m in enumerate(modes):
            ax = axes[i][j]
            grid = [[float("nan")] * len(xs) for _ in ys]
            for r in sel:
                if r["constraints"] != m:
                    continue
                a, b = ys.index(r[key]), xs.index(float(r["dt_over_dt_cfl"]))
                grid[a][b] = int(r["stable"])
                if r["stable"] != "1":
                    ax.text(b, a, f"{r['reason'][0]}{r['first_failing_step']}",
                            ha="center", va="center", fontsize=7)
            ax.imshow(grid, cmap=cmap, vmin=0, vmax=1, origin="lower", aspect="auto")
            ax.set_xticks(range(len(xs)), [f"{x:g}" for x in xs], fontsize=7)
            ax.set_yticks(range(len(ys)), [f"{float(y):.2g}" if key != "mesh" else y
                                           for y in ys], fontsize=7)
            ax.set_title(f"{m}", fontsize=9)
            if i == len(slices) - 1:
                ax.set_xlabel("dt / dt_cfl", fontsize=8)
            if j == 0:
                ax.set_ylabel(label, fontsize=8)
    fig.suptitle("fracture-mode stability (green stable, red: criterion + first failing step)",
                 fontsize=10)
    save_png(fig, sys.argv[2])
    return 0


if __name__ == "__main__":
    sys.exit(main())
