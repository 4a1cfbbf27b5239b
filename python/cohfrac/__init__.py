"""cohfrac from Python: build a world from dicts, step it, read it as numpy.

    import cohfrac
    world = cohfrac.World({
        "name": "box_drop", "duration": 0.6,
        "material": {"E": 1e5, "sigma_max": 3e3},
        "bodies": [{"mesh": {"type": "box", "size": [0.2, 0.2, 0.2], "cells": [4, 4, 4]},
                    "position": [0, 0, 1]}],
        "obstacles": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]}],
        "solver": {"constraints": "xpbd"},
    })
    world.run()                      # or: while not world.done: world.step()
    frags = world.fragments()        # dict of numpy arrays, one row per fragment
    world.ledger()["residual"]       # J

The scene dict has the keys and units of a scene script (README "Scenes",
src/io/include/cohfrac/scene.h): SI units, lists for vectors, 1-based body and
obstacle lists.  It is turned into the same Lua table a script returns and
checked by the same loader, so a bad key or value raises `CohfracError`
with the message `cohfrac run` would print.  No output file is written
unless the dict has `output = {"file": ...}`.

The library (libcohfrac.so, C) is found from $COHFRAC_LIB, else beside the
installed package (the install's lib directory), else in the source tree's
build/ directory, else on the linker's path.  Built on ctypes and numpy
(Debian: python3-numpy); nothing is compiled for the binding.
"""
import ctypes
import ctypes.util
import math
import os

import numpy as np

__all__ = ["World", "CohfracError", "lua_table", "library", "version"]


class CohfracError(RuntimeError):
    """A cohfrac call failed: `status` is the C status name (CF_ERR_...),
    `exit_code` the `cohfrac` program's exit code for it (README)."""

    def __init__(self, status, exit_code, message):
        super().__init__(f"[{status}] {message}")
        self.status, self.exit_code = status, exit_code


class _Error(ctypes.Structure):
    _fields_ = [("code", ctypes.c_int), ("msg", ctypes.c_char * 1024)]


class _RunOptions(ctypes.Structure):
    _fields_ = [("progress", ctypes.c_int), ("threads", ctypes.c_int),
                ("mesh_dir", ctypes.c_char_p), ("force", ctypes.c_int),
                ("stop", ctypes.c_void_p)]


class _FragmentState(ctypes.Structure):  # cf_fragment_state, cohfrac/world.h
    _fields_ = [("id", ctypes.c_int), ("parent", ctypes.c_int),
                ("birth_time", ctypes.c_double), ("mode", ctypes.c_int),
                ("n_tets", ctypes.c_int), ("mass", ctypes.c_double),
                ("com", ctypes.c_double * 3), ("quat", ctypes.c_double * 4),
                ("v", ctypes.c_double * 3), ("w", ctypes.c_double * 3),
                ("kinetic", ctypes.c_double), ("momentum", ctypes.c_double * 3),
                ("angular_momentum", ctypes.c_double * 3),
                ("principal", ctypes.c_double * 3), ("axes", ctypes.c_double * 9)]


_LEDGER_TERMS = ["kinetic", "strain", "cohesive_stored", "cohesive_dissipated",
                 "plastic_dissipated", "work_gravity", "work_boundary", "work_obstacles",
                 "contact", "pbd", "damping", "handoff", "integration", "initial", "residual"]


class _Ledger(ctypes.Structure):  # cf_ledger, cohfrac/world.h
    _fields_ = [(k, ctypes.c_double) for k in _LEDGER_TERMS] + [
        ("momentum", ctypes.c_double * 3), ("angular_momentum", ctypes.c_double * 3),
        ("mass_moment", ctypes.c_double * 3)]


def _candidates():
    env = os.environ.get("COHFRAC_LIB")
    if env:
        yield env
        return
    here = os.path.dirname(os.path.abspath(__file__))
    try:
        from . import _install  # written by `cmake --install`: the install's lib directory
        yield os.path.join(_install.LIBDIR, "libcohfrac.so")
    except ImportError:
        pass
    yield os.path.join(here, "..", "..", "build", "libcohfrac.so")  # the source tree
    found = ctypes.util.find_library("cohfrac")
    if found:
        yield found


def _load():
    tried = []
    for path in _candidates():
        if os.path.sep in path and not os.path.exists(path):
            tried.append(path)
            continue
        lib = ctypes.CDLL(path)
        _declare(lib)
        return lib
    raise ImportError("libcohfrac.so not found (looked at: " + ", ".join(tried or ["nothing"])
                      + "); build it (make) or install it (make install), or set COHFRAC_LIB")


def _declare(lib):
    P, I, D, S = ctypes.c_void_p, ctypes.c_int, ctypes.c_double, ctypes.c_char_p
    sig = {
        "cf_sim_create_text": (I, [S, S, ctypes.POINTER(S), I, ctypes.POINTER(_RunOptions),
                                   ctypes.POINTER(P), ctypes.POINTER(_Error)]),
        "cf_sim_advance": (I, [P, ctypes.POINTER(_Error)]),
        "cf_sim_run": (I, [P, ctypes.POINTER(_Error)]),
        "cf_sim_done": (I, [P]),
        "cf_sim_world": (P, [P]),
        "cf_sim_destroy": (None, [P]),
        "cf_world_time": (D, [P]),
        "cf_world_fragments": (I, [P, ctypes.POINTER(_FragmentState), I]),
        "cf_world_ledger": (None, [P, ctypes.POINTER(_Ledger)]),
        "cf_world_tet_count": (I, [P]),
        "cf_world_tet_fragment": (I, [P, I]),
        "cf_world_tet_positions": (I, [P, I, ctypes.POINTER(D)]),
        "cf_world_rest_node_count": (I, [P]),
        "cf_world_rest_nodes": (None, [P, ctypes.POINTER(D)]),
        "cf_world_rest_tet": (I, [P, I, ctypes.POINTER(I)]),
        "cf_world_crack_area": (D, [P]),
        "cf_world_state_hash": (ctypes.c_uint64, [P]),
        "cf_status_name": (S, [I]),
        "cf_status_exit_code": (I, [I]),
        "cf_version": (S, []),
    }
    for name, (res, args) in sig.items():
        f = getattr(lib, name)
        f.restype, f.argtypes = res, args


_lib = None


def library():
    """The loaded libcohfrac (ctypes.CDLL), loaded on first use."""
    global _lib
    if _lib is None:
        _lib = _load()
    return _lib


def version():
    """The loaded library's version, "MAJOR.MINOR.PATCH" (cf_version)."""
    return library().cf_version().decode()


def _lua_string(s):
    out = s.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n").replace("\r", "\\r")
    return '"' + out.replace("\0", "\\0") + '"'


def lua_table(value):
    """The Lua text of a scene value: dicts become tables with named keys,
    lists, tuples and numpy arrays become sequences, None is left out.
    Raises TypeError for anything else."""
    if isinstance(value, dict):
        items = []
        for k, v in value.items():
            if v is None:
                continue
            if not isinstance(k, str):
                raise TypeError(f"scene keys are strings, got {k!r}")
            key = k if k.isidentifier() else "[" + _lua_string(k) + "]"
            items.append(f"{key} = {lua_table(v)}")
        return "{" + ", ".join(items) + "}"
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return "{" + ", ".join(lua_table(v) for v in value) + "}"
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        v = float(value)
        if math.isnan(v):
            return "(0/0)"
        if math.isinf(v):
            return "math.huge" if v > 0 else "-math.huge"
        return repr(v)
    if isinstance(value, str):
        return _lua_string(value)
    raise TypeError(f"a scene value cannot be {type(value).__name__}: {value!r}")


def _check(status, err):
    if status != 0:
        lib = library()
        raise CohfracError(lib.cf_status_name(status).decode(), lib.cf_status_exit_code(status),
                           err.msg.decode(errors="replace"))


class World:
    """A running world built from a scene dict (module docstring).

    scene:    the scene as a dict (keys and units of a scene script)
    mesh_dir: where prepared meshes are found and primitives cached
              (None: $COHFRAC_MESH_DIR, else ~/.cache/cohfrac/meshes)
    threads:  OpenMP threads (None: the scene's solver.threads)
    overrides: "key.path=value" strings, as `cohfrac run --set`
    Raises CohfracError (bad scene, mesh, or an output file it may not write).
    """

    def __init__(self, scene, mesh_dir=None, threads=None, overrides=()):
        lib = library()
        scene = dict(scene)
        scene.setdefault("name", "python")
        output = dict(scene.get("output") or {})
        output.setdefault("file", "")  # no file unless asked for
        scene["output"] = output
        text = ("return " + lua_table(scene)).encode()
        opts = _RunOptions(progress=0, threads=int(threads or 0),
                           mesh_dir=mesh_dir.encode() if mesh_dir else None, force=0, stop=None)
        sets = [s.encode() for s in overrides]
        arr = (ctypes.c_char_p * max(1, len(sets)))(*sets)
        err, sim = _Error(), ctypes.c_void_p()
        _check(lib.cf_sim_create_text(scene["name"].encode(), text, arr, len(sets),
                                      ctypes.byref(opts), ctypes.byref(sim), ctypes.byref(err)),
               err)
        self._sim, self._lib = sim, lib
        self._world = lib.cf_sim_world(sim)

    def close(self):
        """Free the world (and close its output file, which stays readable)."""
        if self._sim:
            self._lib.cf_sim_destroy(self._sim)
            self._sim = self._world = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass

    def _alive(self):
        if not self._sim:
            raise ValueError("the world is closed")
        return self._world

    @property
    def done(self):
        """Whether the scene's duration is reached."""
        self._alive()
        return bool(self._lib.cf_sim_done(self._sim))

    @property
    def time(self):
        """Simulated time, s."""
        return self._lib.cf_world_time(self._alive())

    def step(self):
        """One rigid step (dt_rigid; fracture mode sub-cycles inside it), a
        frame written when one is due.  Raises CohfracError (CF_ERR_DIVERGED:
        the step went non-finite; the world is then left as it was)."""
        self._alive()
        err = _Error()
        _check(self._lib.cf_sim_advance(self._sim, ctypes.byref(err)), err)

    def run(self):
        """Step to the scene's duration and close the output file."""
        self._alive()
        err = _Error()
        _check(self._lib.cf_sim_run(self._sim, ctypes.byref(err)), err)

    def fragments(self):
        """The alive fragments, one row each, in id order: a dict of numpy
        arrays: id, parent (-1: an initial body), birth_time (s), mode
        (0 rigid, 1 fracture), n_tets, mass (kg), com (n, 3) m,
        quat (n, 4) w x y z (rest shape to current), v (n, 3) m/s,
        w (n, 3) rad/s, kinetic (J), momentum (n, 3) kg m/s,
        angular_momentum (n, 3) kg m2/s about the centre of mass."""
        w = self._alive()
        n = self._lib.cf_world_fragments(w, None, 0)
        buf = (_FragmentState * max(1, n))()
        n = self._lib.cf_world_fragments(w, buf, n)
        rows = buf[:n]
        out = {}
        for name, kind in _FragmentState._fields_:
            vals = [getattr(r, name) for r in rows]
            if hasattr(kind, "_length_"):
                out[name] = np.array([list(v) for v in vals], dtype=float).reshape(n, kind._length_)
            else:
                out[name] = np.array(vals, dtype=int if kind is ctypes.c_int else float)
        return out

    def ledger(self):
        """The energy ledger now (docs/physics.md §10): a dict of floats in J
        (kinetic, strain, cohesive_stored, cohesive_dissipated,
        plastic_dissipated, work_*, the removed terms, initial, residual)
        and momentum, angular_momentum (numpy 3-vectors)."""
        led = _Ledger()
        self._lib.cf_world_ledger(self._alive(), ctypes.byref(led))
        out = {k: led.__getattribute__(k) for k in _LEDGER_TERMS}
        out["momentum"] = np.array(led.momentum[:])
        out["angular_momentum"] = np.array(led.angular_momentum[:])
        return out

    def rest_mesh(self):
        """The rest mesh: nodes (n_nodes, 3) m and tets (n_tets, 4), 0-based."""
        w = self._alive()
        nn, nt = self._lib.cf_world_rest_node_count(w), self._lib.cf_world_tet_count(w)
        X = np.zeros((nn, 3))
        self._lib.cf_world_rest_nodes(w, X.ctypes.data_as(ctypes.POINTER(ctypes.c_double)))
        T = np.zeros((nt, 4), dtype=np.int32)
        for t in range(nt):
            self._lib.cf_world_rest_tet(w, t, T[t].ctypes.data_as(ctypes.POINTER(ctypes.c_int)))
        return X, T

    def tet_positions(self):
        """Where each tet's four corners are now: (n_tets, 4, 3) m (rigid
        fragments at their pose, fracture-mode ones deformed)."""
        w = self._alive()
        nt = self._lib.cf_world_tet_count(w)
        x = np.zeros((nt, 4, 3))
        for t in range(nt):
            self._lib.cf_world_tet_positions(w, t, x[t].ctypes.data_as(
                ctypes.POINTER(ctypes.c_double)))
        return x

    def tet_fragment(self):
        """The fragment id of each tet: (n_tets,) int."""
        w = self._alive()
        return np.array([self._lib.cf_world_tet_fragment(w, t)
                         for t in range(self._lib.cf_world_tet_count(w))], dtype=int)

    @property
    def crack_area(self):
        """Total area of the cohesive facets inserted, m2."""
        return self._lib.cf_world_crack_area(self._alive())

    @property
    def state_hash(self):
        """FNV-1a hash of the state (the summary's determinism hash)."""
        return "%016x" % self._lib.cf_world_state_hash(self._alive())
