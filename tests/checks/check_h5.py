#!/usr/bin/python3
"""Print a summary of a cohfrac output file and check its invariants.

Usage: tests/checks/check_h5.py RUN.h5 [--quiet]

Reads the layout documented in src/io/include/cohfrac/h5_output.h with h5py (Debian
package python3-h5py; hence /usr/bin/python3).  Exits 0 when the file is
consistent, 1 when a check fails, 2 when it cannot be read.  Works on a file
whose run is still going or was killed: T is taken from the step dataset.
"""
import sys

try:
    import h5py
    import numpy as np
except ImportError as e:  # pragma: no cover - depends on the machine
    sys.exit(f"check_h5: {e} (install python3-h5py and python3-numpy)")

FIELDS = ("id", "position", "orientation", "velocity", "angular_velocity", "mode")
WIDTH = {"position": 3, "orientation": 4, "velocity": 3, "angular_velocity": 3}
FRAGMENT_COLUMNS = ("parent", "birth_time", "mass", "n_tets", "inertia_principal")
HANDOFF_COLUMNS = ("time", "fragment", "direction", "momentum_error", "handoff_loss")


def text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def summarize(f, say):
    problems = []
    say(f"file: {f.filename}")
    for key in ("creator", "version", "units", "up_axis", "quaternion_order", "scene_name"):
        if key not in f.attrs:
            problems.append(f"root attribute {key!r} missing")
        else:
            say(f"  {key}: {text(f.attrs[key])}")
    if "h5md" in f:
        say(f"  h5md version: {list(f['h5md'].attrs.get('version', []))}")
    scene = text(f["parameters/scene"][()]) if "parameters/scene" in f else None
    if scene is None:
        problems.append("/parameters/scene missing")
    else:
        lines = scene.splitlines()
        say(f"  scene: {len(lines)} lines" + (f", first: {lines[0][:70]!r}" if lines else ""))

    p = f["particles/fragments"]
    step, time = p["id/step"][()], p["id/time"][()]
    T = len(step)
    if len(time) != T:
        problems.append(f"step has {T} rows but time has {len(time)}")
    if "frames" in f.attrs and int(f.attrs["frames"]) != T:
        problems.append(f"the root attribute frames is {int(f.attrs['frames'])}, but step has {T} rows")
    if T > 1 and np.any(np.diff(step) < 0):
        problems.append("step is not non-decreasing")
    N = p["id/value"].shape[1]
    say(f"frames: T = {T}" + (f", t = {time[0]:g} .. {time[-1]:g} s, steps {step[0]} .. {step[-1]}" if T else ""))
    say(f"fragment columns: N = {N}")
    for name in FIELDS:
        v = p[name]["value"]
        if v.shape[0] < T or v.shape[1] != N:
            problems.append(f"{name}/value has shape {v.shape}, expected ({T}, {N}, ...)")
        if name in WIDTH and v.shape[2:] != (WIDTH[name],):
            problems.append(f"{name}/value has shape {v.shape}")
        if len(p[name]["step"]) != T:
            problems.append(f"{name}/step has {len(p[name]['step'])} rows, expected {T}")
    if T:
        ids = p["id/value"][:T]
        alive = ids >= 0
        cols = np.broadcast_to(np.arange(N), ids.shape)
        if np.any(ids[alive] != cols[alive]):
            problems.append("id/value holds an id outside its own column")
        pos = p["position/value"][:T]
        if np.any(np.isnan(pos[alive]).any(axis=-1)):
            problems.append("an alive fragment has a NaN position")
        if np.any(~np.isnan(pos[~alive]).all(axis=-1)):
            problems.append("a column that is not alive holds a position (fill should be NaN)")
        mode = p["mode/value"][:T]
        if np.any(mode[~alive] != -1):
            problems.append("mode is not -1 where the fragment is not alive")
        counts = alive.sum(axis=1)
        say(f"  alive per frame: first {counts[0]}, last {counts[-1]}, max {counts.max()}")

    fr = f["fragments"]
    lens = {c: len(fr[c]) for c in FRAGMENT_COLUMNS if c in fr}
    if len(set(lens.values())) > 1:
        problems.append(f"/fragments columns differ in length: {lens}")
    n = lens.get("parent", 0)
    say(f"fragment records: {n}")
    if n:
        parents = fr["parent"][()]
        if np.any((parents < -1) | (parents >= np.arange(n))):
            problems.append("a parent is not -1 or an earlier fragment")
        say(f"  initial bodies: {int((parents == -1).sum())}, total mass {fr['mass'][()].sum():.6g} kg")

    obs = f.get("observables", {})
    say(f"observables: {len(obs)}")
    for name in sorted(obs):
        g = obs[name]
        k = len(g["step"])
        if len(g["time"]) < k or len(g["value"]) < k:
            problems.append(f"observable {name}: step/time/value lengths differ")
        last = f", last {g['value'][k - 1]:.6g} at t = {g['time'][k - 1]:g} s" if k else ""
        say(f"  {name}: {k} samples{last}")

    h = f["handoffs"]
    k = len(h["time"])
    if any(len(h[c]) < k for c in HANDOFF_COLUMNS):
        problems.append("/handoffs columns differ in length")
    say(f"hand-offs: {k}" + (f", max momentum error {h['momentum_error'][:k].max():.3g}" if k else ""))
    return problems


def main(argv):
    args = [a for a in argv[1:] if not a.startswith("--")]
    quiet = "--quiet" in argv
    if len(args) != 1:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    say = (lambda s: None) if quiet else print
    try:
        # locking=False: the writer may still be running (it takes no lock).
        with h5py.File(args[0], "r", locking=False) as f:
            problems = summarize(f, say)
    except (OSError, KeyError) as e:
        print(f"check_h5: cannot read {args[0]}: {e}", file=sys.stderr)
        return 2
    for p in problems:
        print(f"check_h5: {args[0]}: {p}", file=sys.stderr)
    if not problems:
        say("ok")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
