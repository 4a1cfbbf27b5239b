#!/usr/bin/python3
"""Plots of `cohfrac compare`: compare_plot.py COMPARE.csv OUT.png [TITLE]

2x2 panels from the time series written by src/cli/compare.c:
  COM distance (bullet vs pbd, each backend vs the analytic reference),
  orientation difference (and, for a symmetric top, the precession angle),
  kinetic-energy drift per backend, linear and angular momentum drifts.
Magnitudes on log axes where they span decades.  Debian python3 and
python3-matplotlib (Agg backend, no display, no network).  The PNG is
written to OUT.png.tmp and renamed.  Exit 3 when matplotlib is missing,
2 on a bad CSV.
"""
import csv
import math
import os
import sys

from mpl_agg import pyplot, save_png

plt = pyplot("compare_plot.py")

COLOURS = {"bullet": "tab:blue", "pbd": "tab:orange", "ref": "black"}


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise ValueError("no rows in " + path)
    cols = {}
    for key in rows[0]:
        cols[key] = [float(r[key]) if r[key] not in ("", None) else math.nan for r in rows]
    return cols


def positive(values):
    """|x| with zeros and NaN masked, for log axes."""
    return [abs(v) if v == v and v != 0 else math.nan for v in values]


def plot_log(ax, t, values, **kw):
    y = positive(values)
    if any(v == v for v in y):
        ax.plot(t, y, **kw)
        return True
    return False


def finish(ax, title, ylabel, logged):
    ax.set_title(title, fontsize=10)
    ax.set_xlabel("time (s)")
    ax.set_ylabel(ylabel)
    if logged:
        ax.set_yscale("log")
    ax.grid(True, which="both", alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8)


def main(argv):
    if len(argv) < 3:
        sys.stderr.write(__doc__)
        return 2
    csv_path, png_path = argv[1], argv[2]
    title = argv[3] if len(argv) > 3 else os.path.basename(os.path.dirname(csv_path))
    try:
        c = read(csv_path)
    except (OSError, ValueError, KeyError) as e:
        sys.stderr.write("compare_plot.py: cannot read %s: %s\n" % (csv_path, e))
        return 2
    t = c["time"]
    fig, axes = plt.subplots(2, 2, figsize=(11, 8))

    ax = axes[0][0]
    logged = plot_log(ax, t, c["com_dist"], color="tab:green", label="bullet vs pbd")
    for b in ("bullet", "pbd"):
        logged |= plot_log(ax, t, c["ref_err_" + b], color=COLOURS[b], ls="--",
                           label=b + " vs analytic")
    finish(ax, "centre-of-mass distance", "m", logged)

    ax = axes[0][1]
    logged = plot_log(ax, t, c["orient_diff"], color="tab:green", label="bullet vs pbd")
    finish(ax, "orientation difference", "rad", logged)
    if any(v == v for v in c["axis_angle_ref"]):
        # the top: unwrapped precession angle on a second axis
        tw = ax.twinx()
        for b in ("bullet", "pbd"):
            a = unwrap(c["axis_angle_" + b])
            tw.plot(t, a, color=COLOURS[b], lw=0.8, alpha=0.7, label=b + " precession angle")
        tw.plot(t, c["axis_angle_ref"], color=COLOURS["ref"], lw=0.8, ls=":",
                label="analytic precession")
        tw.set_ylabel("precession angle (rad)")
        tw.legend(fontsize=8, loc="lower right")

    ax = axes[1][0]
    logged = False
    for b in ("bullet", "pbd"):
        logged |= plot_log(ax, t, c["ke_drift_" + b], color=COLOURS[b], label=b)
    finish(ax, "|kinetic-energy drift| (KE - M g.x)", "relative", logged)

    ax = axes[1][1]
    logged = False
    for b in ("bullet", "pbd"):
        logged |= plot_log(ax, t, c["p_drift_" + b], color=COLOURS[b], label=b + " linear")
        logged |= plot_log(ax, t, c["l_drift_" + b], color=COLOURS[b], ls="--",
                           label=b + " angular")
    finish(ax, "momentum drift", "relative", logged)

    fig.suptitle(title)
    save_png(fig, png_path)
    return 0


def unwrap(values):
    out, prev, shift = [], None, 0.0
    for v in values:
        if v != v:
            out.append(math.nan)
            continue
        if prev is not None:
            d = v - prev
            shift -= 2 * math.pi * math.floor((d + math.pi) / (2 * math.pi))
        prev = v
        out.append(v + shift)
    return out


if __name__ == "__main__":
    sys.exit(main(sys.argv))
