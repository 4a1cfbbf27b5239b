#!/usr/bin/python3
"""Render a cohfrac run: PNG frames and an MP4 of every fragment's surface.

    python/cohfrac/render.py OUT.h5 [-o DIR] [--fps N] [--size WxH] [--from T0] [--to T1]
                    [--slow-motion F] [--glb RUN.glb] [--engine auto|blender|matplotlib]

Writes DIR/frame_0000.png ... and DIR/<name>.mp4 (ffmpeg, H.264); without
-o the frames go to OUT minus .h5 plus "_frames" and the movie beside the
file, as OUT minus .h5 plus ".mp4".  Movie frame k shows the run at
t = T0 + k / (fps F): --from/--to choose the span (default the whole run),
--slow-motion F plays it F times slower (default: one movie frame per
output frame, and never faster than the run).

Engines: `blender` renders the glTF export (--glb, which `cohfrac render`
writes) in Blender headless (Workbench: depth, studio lighting, shadows;
under xvfb-run) with a camera that follows the pieces
(python/cohfrac/render_blender.py); `matplotlib` draws the posed surfaces from a
fixed camera that sees the whole run (no depth buffer).  `auto` (default)
takes Blender when --glb is given and blender and xvfb-run are installed.
Fragments are coloured by id, crack faces in their own colour, debris
small.  Reads the file with python/cohfrac/h5.py.

Exit status: 0 done, 2 the file has no geometry (an older file), 3
matplotlib is missing, 5 ffmpeg or Blender failed or is missing (the PNGs
stay).
"""
import argparse
import os
import shutil
import subprocess
import sys

# The package's parent on the path, so that the reader imports as
# cohfrac.h5 when this file is run as a script (the way `cohfrac render`
# runs it) as well as with `python3 -m cohfrac.render`.
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
except ImportError:
    print("render.py: matplotlib is missing (Debian: python3-matplotlib)", file=sys.stderr)
    sys.exit(3)
import numpy as np

from cohfrac import h5 as cohfrac_h5  # noqa: E402

LIGHT = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])


def shade(rgb, normals):
    """Lambert shading of base colours [n][3] by unit normals [n][3]."""
    lam = np.clip(np.abs(normals @ LIGHT), 0.0, 1.0)
    return np.clip(rgb * (0.35 + 0.65 * lam)[:, None], 0, 1)


DEBRIS_RGB = np.array([0.55, 0.5, 0.45])
DEBRIS_SHRINK = 0.5


def fragment_polys(run, frame, cmap):
    """Triangles [n][3][3] and face colours [n][4] of every alive fragment.
    Debris (docs/physics.md §9.2) is drawn grey and at half its size about
    its centre, so that it reads as crumbs beside the pieces."""
    polys, colours = [], []
    debris = run.fragments.get("debris")
    for i, verts, tris, crack in run.surfaces_at(frame):
        rgb = np.array(cmap(i % 20)[:3])
        if debris is not None and debris[i]:
            c = verts.mean(axis=0)
            verts = c + DEBRIS_SHRINK * (verts - c)
            rgb = DEBRIS_RGB
        tri = verts[tris]
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        n /= np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]
        base = np.tile(rgb, (len(tri), 1))
        base[crack.astype(bool)] *= 0.55
        polys.append(tri)
        colours.append(np.column_stack([shade(base, n), np.ones(len(tri))]))
    if not polys:
        return np.zeros((0, 3, 3)), np.zeros((0, 4))
    return np.concatenate(polys), np.concatenate(colours)


def obstacle_artists(ax, run, t, lo, hi):
    """Draw the obstacles at time t inside the box lo..hi."""
    for o in run.obstacles:
        c = np.asarray(o["center"]) + t * np.asarray(o["velocity"])
        if o["type"] == "plane":
            n = np.asarray(o["normal"])
            p = np.asarray(o["point"])
            if abs(n[2]) > 0.9:          # a floor: a square under the run
                z = p[2] - (n[0] * 0 + n[1] * 0)
                sq = np.array([[lo[0], lo[1], z], [hi[0], lo[1], z],
                               [hi[0], hi[1], z], [lo[0], hi[1], z]])
                ax.add_collection3d(Poly3DCollection([sq], facecolor=(0.82, 0.82, 0.78, 1),
                                                     edgecolor=(0.6, 0.6, 0.6, 1)))
        elif o["type"] == "sphere":
            u, v = np.mgrid[0:2 * np.pi:24j, 0:np.pi:12j]
            r = o["radius"]
            ax.plot_surface(c[0] + r * np.cos(u) * np.sin(v), c[1] + r * np.sin(u) * np.sin(v),
                            c[2] + r * np.cos(v), color=(0.55, 0.6, 0.7), alpha=0.5,
                            linewidth=0)
        elif o["type"] == "box":
            h = np.asarray(o["half_extents"])
            corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1)
                                for sz in (-1, 1)]) * h + c
            faces = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4],
                     [1, 3, 7, 5]]
            ax.add_collection3d(Poly3DCollection([corners[f] for f in faces],
                                                 facecolor=(0.55, 0.6, 0.7, 0.4),
                                                 edgecolor=(0.4, 0.4, 0.5, 0.6)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("h5")
    ap.add_argument("-o", "--output", help="directory for the frames and the movie")
    ap.add_argument("--fps", type=int, default=24)
    ap.add_argument("--size", default="960x720", help="WxH in pixels")
    ap.add_argument("--from", dest="t0", type=float, help="first time shown, s")
    ap.add_argument("--to", dest="t1", type=float, help="last time shown, s")
    ap.add_argument("--slow-motion", type=float,
                    help="play F times slower than the run (default: one movie frame per "
                         "output frame, at least real time)")
    ap.add_argument("--glb", help="the run's glTF export (cohfrac export), for Blender")
    ap.add_argument("--engine", choices=("auto", "blender", "matplotlib"), default="auto")
    a = ap.parse_args()
    run = cohfrac_h5.load(a.h5)
    if run.rest_nodes is None:
        print(f"render.py: {a.h5} holds no geometry (/mesh/rest): written by an older "
              "cohfrac; run the scene again", file=sys.stderr)
        return 2
    if a.slow_motion is None:
        step = float(np.median(np.diff(run.times))) if len(run.times) > 1 else 1.0
        a.slow_motion = max(1.0, 1.0 / (a.fps * step)) if step > 0 else 1.0
    if not a.slow_motion > 0:
        print("render.py: --slow-motion needs a factor > 0", file=sys.stderr)
        return 1
    out = a.output or os.path.splitext(a.h5)[0] + "_frames"
    os.makedirs(out, exist_ok=True)
    for old in os.listdir(out):  # frames of an earlier render would join the movie
        if old.startswith("frame_") and old.endswith(".png"):
            os.remove(os.path.join(out, old))
    w, h = (int(x) for x in a.size.lower().split("x"))
    t0 = run.times[0] if a.t0 is None else max(a.t0, run.times[0])
    t1 = run.times[-1] if a.t1 is None else min(a.t1, run.times[-1])
    if t1 < t0:
        print(f"render.py: nothing to show between {t0} and {t1} s (the run covers "
              f"{run.times[0]}-{run.times[-1]} s)", file=sys.stderr)
        return 1
    floor = [o for o in run.obstacles if o["type"] == "plane" and abs(o["normal"][2]) > 0.9]
    blender = shutil.which("blender") and shutil.which("xvfb-run")
    engine = a.engine if a.engine != "auto" else ("blender" if a.glb and blender else "matplotlib")
    if engine == "blender":
        if not (a.glb and blender):
            print("render.py: the Blender engine needs --glb and the Debian packages blender "
                  "and xvfb", file=sys.stderr)
            return 5
        script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "render_blender.py")
        cmd = ["xvfb-run", "-a", "blender", "-b", "-noaudio", "-P", script, "--", a.glb, out,
               str(a.fps), str(w), str(h), repr(t0), str(len(movie_times(a, t0, t1))),
               repr(a.slow_motion),
               repr(floor[0]["point"][2]) if floor else "nan"]
        r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        n = len([f for f in os.listdir(out) if f.startswith("frame_")])
        if r.returncode != 0 or n == 0:
            print(f"render.py: Blender failed (status {r.returncode}); its output ends:\n"
                  + r.stdout[-1500:], file=sys.stderr)
            return 5
        return movie(a, run, out, n)
    return draw_matplotlib(a, run, out, w, h, t0, t1, floor)


def movie_times(a, t0, t1):
    """The run's time at each movie frame: t0 + k / (fps F), up to t1."""
    n = int(np.floor((t1 - t0) * a.fps * a.slow_motion + 1e-9)) + 1
    return t0 + np.arange(n) / (a.fps * a.slow_motion)


def draw_matplotlib(a, run, out, w, h, t0, t1, floor):
    """The frames through matplotlib: a fixed camera on the whole run."""
    lo, hi = run.bounds()
    pad = 0.15 * (hi - lo).max()
    lo, hi = lo - pad, hi + pad
    if floor:
        lo[2] = min(lo[2], floor[0]["point"][2])
    cmap = plt.get_cmap("tab20")
    # Movie frame k shows the output frame nearest t0 + k / (fps F).
    want = movie_times(a, t0, t1)
    frames = [int(np.argmin(np.abs(run.times - t))) for t in want]
    dpi = 100
    for k, fr in enumerate(frames):
        fig = plt.figure(figsize=(w / dpi, h / dpi), dpi=dpi)
        ax = fig.add_subplot(projection="3d")
        ax.set_xlim(lo[0], hi[0]), ax.set_ylim(lo[1], hi[1]), ax.set_zlim(lo[2], hi[2])
        ax.set_box_aspect(hi - lo)
        ax.view_init(elev=18, azim=-60)
        ax.set_axis_off()
        ax.computed_zorder = False  # the floor first, then the fragments over it
        t = run.times[fr]
        obstacle_artists(ax, run, t, lo, hi)
        polys, colours = fragment_polys(run, fr, cmap)
        if len(polys):
            ax.add_collection3d(Poly3DCollection(polys, facecolors=colours, edgecolors="none"))
        n_alive = len(run.alive(fr))
        ax.set_title(f"{run.name}   t = {t:.3f} s   {n_alive} fragment{'s' * (n_alive != 1)}",
                     fontsize=11)
        fig.subplots_adjust(0, 0, 1, 0.95)
        fig.savefig(os.path.join(out, f"frame_{k:04d}.png"), dpi=dpi)
        plt.close(fig)
        if sys.stderr.isatty():
            print(f"\rrender: frame {k + 1}/{len(frames)} (t = {t:.3f} s)", end="",
                  file=sys.stderr, flush=True)
        elif (k + 1) % 20 == 0 or k + 1 == len(frames):
            print(f"render: frame {k + 1}/{len(frames)} (t = {t:.3f} s)", file=sys.stderr)
    if sys.stderr.isatty():
        print(file=sys.stderr)
    return movie(a, run, out, len(frames))


def movie(a, run, out, n_frames):
    """frame_*.png in `out` to an MP4 with ffmpeg."""
    movie = (os.path.join(out, (run.name or "run") + ".mp4") if a.output
             else os.path.splitext(a.h5)[0] + ".mp4")
    ffmpeg = shutil.which("ffmpeg")
    if not ffmpeg:
        print("render.py: ffmpeg is missing (Debian: ffmpeg): PNG frames only", file=sys.stderr)
        return 5
    cmd = [ffmpeg, "-y", "-loglevel", "error", "-framerate", str(a.fps), "-i",
           os.path.join(out, "frame_%04d.png"), "-c:v", "libx264", "-pix_fmt", "yuv420p",
           "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", movie]
    if subprocess.run(cmd).returncode != 0:
        print(f"render.py: ffmpeg failed: PNG frames in {out}", file=sys.stderr)
        return 5
    print(f"render: {n_frames} frames, {movie} ({n_frames / a.fps:.1f} s at {a.fps} fps)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
