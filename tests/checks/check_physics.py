#!/usr/bin/python3
"""Check a cohfrac run file against physical bounds (docs/physics.md, "Plausibility").

usage: check_physics.py OUT.h5 [OUT.h5 ...] [--quiet]

For each file, from /parameters (written by the engine at t = 0) and the
ledger in /observables:

  speed     every fragment alive at the last frame is no faster than
            1.1 (v0 + 2 U + sqrt(2 g H) + v_r): v0 the fastest node at t = 0
            (max_initial_speed), U the fastest kinematic obstacle or
            prescribed node (max_obstacle_speed; a body hit by a wall moving
            at U leaves at most at 2U), H the fall: the top of the bodies at
            t = 0 (initial_upper) above the lowest centre any fragment ever
            reaches, along gravity; v_r the release speed (release_speed,
            0 in files without it): a piece cut free from material held at
            its strength (or crushed, at its compressive strength) springs
            back at about sigma / (rho c);
  energy    kinetic energy at every frame <= the input: initial (kinetic +
            strain at t = 0) + gravity's work + the prescribed nodes' work
            (when positive) + 1/2 M (2U)^2 for kinematic impactors;
  dissipation  energy_cohesive_dissipated and energy_plastic_dissipated
            (crushing; absent in older files) are never negative and never
            fall (by more than 1e-9 of the input, round-off);
  residual  |energy_residual| <= 1% of the input at every frame;
  complete  the last frame is at the scene's duration: a run that stopped
            early (diverged, exit 3, or interrupted) has no end to check,
            and its frames so far may all look fine.
  bonds     (files written with output.cracks only) no cohesive element
            that still holds lies between two fragments at the end: the
            hand-off keeps pieces joined by an element whose node pairs
            have not all failed as one body (docs/physics.md §9), so an
            element whose two tets (/cracks/tets) end in different
            fragments (/mesh/tet_fragment) has failed (/cracks/failed).

Prints one line per check with the figure and its bound.  Exit status 0
when every check of every file holds, 1 when one fails, 2 when a file
cannot be read or lacks a dataset (the message names it).
"""
import argparse
import sys

import h5py
import numpy as np

REQUIRED_PARAMETERS = ("initial_upper", "total_mass", "initial_energy", "max_initial_speed",
                       "max_obstacle_speed")
REQUIRED_OBSERVABLES = ("energy_kinetic", "energy_cohesive_dissipated", "energy_residual",
                        "work_gravity", "work_boundary")


def scene_value(scene, key):
    """The text after `key =` on the resolved scene's top-level line for key
    (written at two spaces' indent), without its trailing comma; None when
    the scene text has no such line."""
    for line in scene.splitlines():
        name, _, value = line.partition("=")
        if line.startswith("  " + key) and name.strip() == key:
            return value.strip().rstrip(",")
    return None


def gravity_of(scene):
    """The scene's gravity vector (m/s^2) from the resolved scene text."""
    value = scene_value(scene, "gravity")
    if value is None or "{" not in value:
        return np.zeros(3)
    return np.array([float(x) for x in value.strip("{}").split(",")])


def duration_of(scene):
    """The run's duration (s) from the resolved scene text."""
    value = scene_value(scene, "duration")
    if value is None:
        raise KeyError("duration in /parameters/scene")
    return float(value)


def read(path):
    """The figures the checks need, or raises KeyError naming what is missing."""
    with h5py.File(path, "r") as f:
        for n in REQUIRED_PARAMETERS:
            if f"parameters/{n}" not in f:
                raise KeyError(f"/parameters/{n} (written by this cohfrac at t = 0: run the scene again)")
        for n in REQUIRED_OBSERVABLES:
            if f"observables/{n}/value" not in f:
                raise KeyError(f"/observables/{n}")
        if "particles/fragments/velocity/value" not in f:
            raise KeyError("/particles/fragments/velocity")
        scene = f["parameters/scene"][()]
        scene = scene.decode() if isinstance(scene, bytes) else str(scene)
        p = {n: np.asarray(f[f"parameters/{n}"][()], dtype=float) for n in REQUIRED_PARAMETERS}
        o = {n: np.asarray(f[f"observables/{n}/value"][()], dtype=float)
             for n in REQUIRED_OBSERVABLES}
        p["last_time"] = (float(f["observables/energy_kinetic/time"][-1])
                          if len(f["observables/energy_kinetic/time"]) else 0.0)
        frames = len(f["particles/fragments/position/step"])
        pos = f["particles/fragments/position/value"][:frames]
        vel = f["particles/fragments/velocity/value"][:frames]
        p["release_speed"] = (np.asarray(f["parameters/release_speed"][()], dtype=float)
                              if "parameters/release_speed" in f else 0.0)
        plastic = "observables/energy_plastic_dissipated/value"
        o["energy_plastic_dissipated"] = (np.asarray(f[plastic][()], dtype=float) if plastic in f
                                          else np.zeros(0))
    return scene, p, o, pos, vel


def last_crack_rows(f):
    """The /cracks rows of the last frame written (one per cohesive element
    then) in the open run file f: their indices, empty where there are none."""
    time = f["cracks/time"][:]
    return np.flatnonzero(time == time.max()) if len(time) else np.zeros(0, dtype=int)


def final_crack_sides(f):
    """The /cracks rows of the last frame in the open run file f (as
    last_crack_rows), and for each whether its element's two tets
    (/cracks/tets) end in different fragments (/mesh/tet_fragment)."""
    last = last_crack_rows(f)
    tets = f["cracks/tets"][:][last]
    frag = f["mesh/tet_fragment/value"][-1]
    return last, frag[tets[:, 0]] != frag[tets[:, 1]]


def bonds(path):
    """The cohesive elements between two fragments at the end of a run, and
    how many of them still hold: (between, holding), or None for a file
    written without output.cracks (or before /cracks/tets)."""
    with h5py.File(path, "r") as f:
        if "cracks/tets" not in f or "mesh/tet_fragment/value" not in f:
            return None
        last, between = final_crack_sides(f)
        failed = f["cracks/failed"][:][last]
    return int(np.count_nonzero(between)), int(np.count_nonzero(between & (failed == 0)))


def check_file(path, quiet=False, figures=None):
    """Checks one output; True when all pass.  figures, a dict, receives the
    ledger residual as a share of the input ("residual_share"), the fastest
    fragment and its bound ("fastest", "speed_bound", m/s), the largest
    kinetic energy and the input at that frame ("kinetic", "kinetic_input",
    J) and the names of the checks that failed ("failed")."""
    scene, p, o, pos, vel = read(path)
    g = gravity_of(scene)
    gn = float(np.linalg.norm(g))
    up = -g / gn if gn > 0 else np.array([0.0, 0.0, 1.0])
    v0 = float(p["max_initial_speed"])
    U = float(p["max_obstacle_speed"])
    v_r = float(p["release_speed"])
    M = float(p["total_mass"])
    top = float(np.dot(p["initial_upper"], up)) if gn > 0 else 0.0
    heights = pos @ up
    lowest = float(np.nanmin(heights)) if np.isfinite(heights).any() else top
    H = max(0.0, top - lowest) if gn > 0 else 0.0
    v_bound = 1.1 * (v0 + 2 * U + np.sqrt(2 * gn * H) + v_r)
    speeds = np.linalg.norm(vel[-1], axis=-1) if len(vel) else np.zeros(0)
    v_max = float(np.nanmax(speeds)) if np.isfinite(speeds).any() else 0.0

    work_in = o["work_gravity"] + np.maximum(o["work_boundary"], 0.0)
    input_e = float(p["initial_energy"]) + work_in + 0.5 * M * (2 * U) ** 2
    input_ref = float(np.max(np.maximum(input_e, 1e-300)))
    ke = o["energy_kinetic"]
    ke_excess = float(np.max(ke - input_e)) if len(ke) else 0.0
    k = int(np.argmax(ke)) if len(ke) else None  # the frame of the largest kinetic energy
    ke_max, ke_max_input = (float(ke[k]), float(input_e[k])) if k is not None else (0.0, 0.0)
    dissipated = [d for d in (o["energy_cohesive_dissipated"], o["energy_plastic_dissipated"])
                  if len(d)]
    diss_min = min((float(np.min(d)) for d in dissipated), default=0.0)
    diss_drop = max((float(np.max(d[:-1] - d[1:])) for d in dissipated if len(d) > 1),
                    default=0.0)
    resid = float(np.max(np.abs(o["energy_residual"]))) if len(o["energy_residual"]) else 0.0
    tol = 1e-9 * input_ref
    duration, t_last = duration_of(scene), float(p["last_time"])
    complete = t_last >= duration * (1 - 1e-9)

    checks = [
        ("speed", v_max <= v_bound,
         f"fastest fragment at the end {v_max:.4g} m/s <= {v_bound:.4g} m/s "
         f"(1.1 (v0 {v0:.3g} + 2U {2 * U:.3g} + sqrt(2 g H), H {H:.3g} m, + v_r {v_r:.3g}))"),
        ("energy", ke_excess <= tol,
         f"kinetic energy <= input at every frame (largest {ke_max:.4g} J "
         f"against {ke_max_input:.4g} J then)"),
        ("dissipation", diss_min >= -tol and diss_drop <= tol,
         f"cohesive and plastic dissipation never negative (min {diss_min:.3g} J) and never fall "
         f"(largest fall {max(diss_drop, 0):.3g} J)"),
        ("residual", resid <= 0.01 * input_ref,
         f"ledger residual {resid:.4g} J = {100 * resid / input_ref:.3g}% of the input "
         f"{input_ref:.4g} J (<= 1%)"),
        ("complete", complete,
         f"last frame at t = {t_last:.6g} s against the duration {duration:.6g} s"
         + ("" if complete else " (the run stopped early: its exit status and log say why)")),
    ]
    held = bonds(path)
    if held is not None:
        checks.append(("bonds", held[1] == 0,
                       f"{held[1]} of the {held[0]} cohesive elements between two fragments at "
                       "the end still hold (0: the hand-off cut no bond)"))
    if figures is not None:
        figures["residual_share"] = resid / input_ref
        figures["fastest"], figures["speed_bound"] = v_max, v_bound
        figures["kinetic"], figures["kinetic_input"] = ke_max, ke_max_input
        figures["failed"] = [name for name, good, _ in checks if not good]
    ok = all(c[1] for c in checks)
    if not quiet or not ok:
        print(f"{path}:")
        for name, good, text in checks:
            print(f"  {'ok  ' if good else 'FAIL'}  {name:<11} {text}")
    return ok


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--quiet", action="store_true", help="print only failing files")
    a = ap.parse_args()
    ok = True
    for path in a.files:
        try:
            ok &= check_file(path, a.quiet)
        except (OSError, KeyError) as e:
            print(f"check_physics.py: {path}: cannot check: {e}", file=sys.stderr)
            return 2
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
