#!/usr/bin/python3
"""Plot a run's large pieces: every alive fragment's surface at chosen
times, the fragments holding at least a share of the alive mass in colour
(the four largest), the rest grey, each view framed on the large pieces.

usage: plot_pieces.py OUT.h5 [-t T ...] [--share S] [-o PNG]
  -t, --time T   simulated time of a view, s (repeatable; default the last frame)
  --share S      smallest share of the mass drawn in colour (default 0.05)
  -o, --output   the PNG to write (default OUT_pieces.png beside OUT.h5)
Reads the file with python/cohfrac/h5.py; matplotlib draws it.
"""
import argparse
import os
import sys

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

# The test checkers and the reader, from the source tree.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "checks"))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from cohfrac import h5 as cohfrac_h5  # noqa: E402

COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e"]


def view(ax, run, frame, share):
    """Draw frame `frame`; return its title."""
    mass = run.fragments["mass"]
    alive = [i for i in range(run.n_fragments) if run.pose(i, frame) is not None]
    total = sum(mass[i] for i in alive)
    large = [i for i in sorted(alive, key=lambda i: -mass[i])[:len(COLOURS)]
             if mass[i] >= share * total]
    # The view frames the large pieces, or every piece when none is large
    # (a body shattered into crumbs), or a unit box when nothing is drawn.
    framed = []
    for pid, verts, tris, _ in run.surfaces_at(frame):
        colour = COLOURS[large.index(pid)] if pid in large else "#999999"
        if pid in large or not large:
            framed.append(verts)
        ax.add_collection3d(Poly3DCollection(verts[tris], facecolor=colour, edgecolor="k",
                                             linewidths=0.1, alpha=0.9))
    if framed:
        lo, hi = np.min([v.min(0) for v in framed], 0), np.max([v.max(0) for v in framed], 0)
    else:
        lo, hi = np.full(3, -0.5), np.full(3, 0.5)
    mid, r = (lo + hi) / 2, 0.65 * float(np.max(hi - lo))
    ax.set_xlim(mid[0] - r, mid[0] + r)
    ax.set_ylim(mid[1] - r, mid[1] + r)
    ax.set_zlim(mid[2] - r, mid[2] + r)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.view_init(elev=25, azim=-60)
    shares = ", ".join(f"{100 * mass[i] / total:.1f} %" for i in large)
    return (f"t = {run.times[frame]:.3f} s, {len(alive)} alive\n"
            f"pieces >= {100 * share:g} %: {shares or 'none'} (grey: the rest)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file")
    ap.add_argument("-t", "--time", type=float, action="append")
    ap.add_argument("--share", type=float, default=0.05)
    ap.add_argument("-o", "--output")
    a = ap.parse_args()
    try:
        run = cohfrac_h5.load(a.file)
    except (OSError, KeyError) as e:
        print(f"plot_pieces.py: cannot read {a.file}: {e}", file=sys.stderr)
        return 2
    frames = [run.frame_at(t) for t in a.time] if a.time else [len(run.times) - 1]
    fig = plt.figure(figsize=(5.5 * len(frames), 5.2))
    for k, frame in enumerate(frames):
        ax = fig.add_subplot(1, len(frames), k + 1, projection="3d")
        ax.set_title(view(ax, run, frame, a.share), fontsize=10)
    fig.suptitle(os.path.basename(a.file), fontsize=11)
    fig.tight_layout()
    out = a.output or os.path.splitext(a.file)[0] + "_pieces.png"
    fig.savefig(out, dpi=90)
    print(f"plot_pieces.py: wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
