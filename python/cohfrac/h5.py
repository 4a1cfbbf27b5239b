#!/usr/bin/python3
"""Read a cohfrac output file (docs/output.md) with h5py and numpy only.

    from cohfrac import h5         # installed; from a source tree, python/ on sys.path
    run = h5.load("out/bunny_drop.h5")
    run.times                      # [T] s, one per frame
    run.fragments                  # records: parent, birth_time, mass, n_tets, com_rest, ...
    frag = run.fragment(0)         # one fragment: surface triangles, crack flags, rest nodes
    for pid, verts, tris, crack in run.surfaces_at(-1):   # every alive fragment, posed
        ...                        # verts [n][3] m in the world, tris [m][3] into verts
    run.pose(fragment_id, frame)   # (com [3] m, rotation [3][3]) or None when not alive
    run.children(fragment_id)      # the family tree
    run.observables["energy_kinetic"]  # Series(time [K] s, value [K], unit "J")

Shapes and units follow the file: positions in m, times in s, quaternions
(w, x, y, z) rotating the rest shape about its rest centre of mass
(com_rest) onto the current one: x = com + R (X - com_rest).
"""
import collections

import h5py
import numpy as np

Series = collections.namedtuple("Series", "time value unit")
Fragment = collections.namedtuple(
    "Fragment", "id parent birth_time mass n_tets com_rest triangles crack")


def quat_to_matrix(q):
    """Rotation matrix [3][3] of a unit quaternion (w, x, y, z)."""
    w, x, y, z = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


class Run:
    """A whole output file in memory (geometry, poses, records, observables)."""

    def __init__(self, path):
        with h5py.File(path, "r") as f:
            self.path = path
            self.name = f.attrs.get("scene_name", "")
            if isinstance(self.name, bytes):
                self.name = self.name.decode()
            self.scene = f["parameters/scene"][()]
            if isinstance(self.scene, bytes):
                self.scene = self.scene.decode()
            parts = f["particles/fragments"]
            # whole frames only: a killed run's file may hold one partial row
            t = int(f.attrs.get("frames", len(parts["position/step"])))
            self.steps = parts["position/step"][:t]
            self.times = parts["position/time"][:t]
            self.ids = parts["id/value"][:t]
            self.position = parts["position/value"][:t]
            self.orientation = parts["orientation/value"][:t]
            self.velocity = parts["velocity/value"][:t]
            self.mode = parts["mode/value"][:t]
            fr = f["fragments"]
            self.fragments = {k: fr[k][:] for k in fr.keys()}
            self.rest_nodes = f["mesh/rest/nodes"][:] if "mesh/rest/nodes" in f else None
            self.rest_tets = f["mesh/rest/tets"][:] if "mesh/rest/tets" in f else None
            if "surfaces/triangles" in f:
                self.surface_triangles = f["surfaces/triangles"][:]
                self.surface_crack = f["surfaces/crack"][:]
            else:
                self.surface_triangles = np.zeros((0, 3), int)
                self.surface_crack = np.zeros(0, int)
            self.tet_map_times = (f["mesh/tet_fragment/time"][:] if "mesh/tet_fragment" in f
                                  else np.zeros(0))
            self.tet_maps = (f["mesh/tet_fragment/value"][:] if "mesh/tet_fragment" in f
                             else np.zeros((0, 0), np.int32))
            vis = f.get("visual")
            self.visual = ({k: vis[k][:] for k in ("vertices", "triangles", "tet")}
                           if vis is not None else None)
            fm = f.get("fracture_mode")
            self.fracture_rows = ({k: fm[k][:len(fm["time"])] for k in fm.keys()}
                                  if fm is not None else None)
            self.observables = {}
            for name, g in f["observables"].items():
                unit = g["value"].attrs.get("unit", "")
                if isinstance(unit, bytes):
                    unit = unit.decode()
                self.observables[name] = Series(g["time"][:], g["value"][:], unit)
            self.parameters = {k: f["parameters"][k][()] for k in f["parameters"].keys()
                               if k != "scene"}
            self.obstacles = read_obstacles(self.parameters)

    @property
    def n_fragments(self):
        return len(self.fragments["parent"])

    def fragment(self, i):
        """Fragment i's record with its surface (triangles on rest_nodes)."""
        fr = self.fragments
        a = int(fr["surface_first"][i]) if "surface_first" in fr else 0
        n = int(fr["surface_count"][i]) if "surface_count" in fr else 0
        return Fragment(i, int(fr["parent"][i]), float(fr["birth_time"][i]),
                        float(fr["mass"][i]), int(fr["n_tets"][i]),
                        fr["com_rest"][i] if "com_rest" in fr else np.zeros(3),
                        self.surface_triangles[a:a + n], self.surface_crack[a:a + n])

    def children(self, i):
        """Ids of the fragments born of fragment i."""
        return [int(j) for j in np.nonzero(self.fragments["parent"] == i)[0]]

    def alive(self, frame):
        """Ids of the fragments alive at a frame (index into times; -1 the last)."""
        ids = self.ids[frame]
        return [int(j) for j in ids[ids >= 0]]

    def pose(self, i, frame):
        """(com [3] m, R [3][3]) of fragment i at a frame, None when not alive."""
        if i >= self.ids.shape[1] or self.ids[frame, i] < 0:
            return None
        return self.position[frame, i], quat_to_matrix(self.orientation[frame, i])

    def frame_at(self, t):
        """The last frame at or before time t, s."""
        return max(0, int(np.searchsorted(self.times, t, side="right")) - 1)

    def surfaces_at(self, frame):
        """Every alive fragment's surface at a frame, posed in the world:
        yields (id, vertices [n][3] m, triangles [m][3] into vertices, crack [m])."""
        for i in self.alive(frame):
            frag = self.fragment(i)
            if len(frag.triangles) == 0:
                continue
            used, tris = np.unique(frag.triangles, return_inverse=True)
            com, R = self.pose(i, frame)
            verts = (self.rest_nodes[used] - frag.com_rest) @ R.T + com
            yield i, verts, tris.reshape(-1, 3), frag.crack

    def visual_at(self, frame):
        """The object's own surface (/visual) on every alive fragment at a
        frame, posed: yields (id, vertices [n][3] m, triangles [m][3]); each
        visual triangle rides with the fragment that owns its tet.  Nothing
        when the file has no /visual."""
        if self.visual is None:
            return
        # The split by fragment changes only with the tet map: kept per map.
        key = int(np.searchsorted(self.tet_map_times, self.times[frame], side="right"))
        if getattr(self, "_visual_key", None) != key:
            owner = self.tet_fragments_at(frame)[self.visual["tet"]]
            order = np.argsort(owner, kind="stable")
            ids, first = np.unique(owner[order], return_index=True)
            parts = {}
            for j, i in enumerate(ids):
                tri = self.visual["triangles"][order[first[j]:(first[j + 1] if j + 1 < len(ids)
                                                                else len(order))]]
                used, tris = np.unique(tri, return_inverse=True)
                parts[int(i)] = (used, tris.reshape(-1, 3))
            self._visual_key, self._visual_parts = key, parts
        for i in self.alive(frame):
            if i not in self._visual_parts:
                continue
            used, tris = self._visual_parts[i]
            com, R = self.pose(i, frame)
            verts = (self.visual["vertices"][used] - self.fragments["com_rest"][i]) @ R.T + com
            yield i, verts, tris

    def tet_fragments_at(self, frame):
        """The fragment of every rest tet at a frame ([nt] ids; 0 before the
        first map: the first body)."""
        k = int(np.searchsorted(self.tet_map_times, self.times[frame], side="right")) - 1
        if k < 0:
            return np.zeros(len(self.rest_tets), np.int32)
        return self.tet_maps[k]

    def fracture_tets_at(self, frame):
        """The tets of fracture-mode fragments at a frame, deformed
        (/fracture_mode): dict of tet [n], corners [n][4][3] m, stress
        [n][6] Pa (xx yy zz yz xz xy), damage [n]; None when the file has
        none at that frame (rigid only, or output.fields = false)."""
        r = self.fracture_rows
        if r is None:
            return None
        sel = r["time"] == self.times[frame]
        if not sel.any():
            return None
        return dict(tet=r["tet"][sel], corners=r["corners"][sel].reshape(-1, 4, 3),
                    stress=r["stress"][sel], damage=r["damage"][sel])

    def bounds(self):
        """Box (lo [3], hi [3]) around the rest mesh and every fragment's centre."""
        pts = [self.rest_nodes] if self.rest_nodes is not None else []
        pos = self.position.reshape(-1, 3)
        pts.append(pos[np.isfinite(pos).all(axis=1)])
        allp = np.concatenate(pts)
        return allp.min(axis=0), allp.max(axis=0)


OBSTACLE_TYPES = ("plane", "sphere", "box", "mesh")


def read_obstacles(params):
    """The scene's obstacles from /parameters/obstacle_* (written at t = 0):
    a list of dicts with type, point, normal (planes), center (at t = 0),
    radius, half_extents, velocity (m, m/s)."""
    if "obstacle_type" not in params:
        return []
    types = np.atleast_1d(params["obstacle_type"]).astype(int)
    n = len(types)
    vec = {k: np.reshape(params[f"obstacle_{k}"], (n, 3))
           for k in ("point", "normal", "center", "half_extents", "velocity")}
    radius = np.atleast_1d(params["obstacle_radius"])
    return [dict(type=OBSTACLE_TYPES[t], radius=float(radius[j]),
                 **{k: v[j] for k, v in vec.items()}) for j, t in enumerate(types)]



def von_mises(s):
    """Von Mises stress of Voigt rows [n][6] (xx yy zz yz xz xy), Pa."""
    xx, yy, zz, yz, xz, xy = s.T
    return np.sqrt(0.5 * ((xx - yy) ** 2 + (yy - zz) ** 2 + (zz - xx) ** 2)
                   + 3.0 * (yz ** 2 + xz ** 2 + xy ** 2))


def export_pvd(run, out_dir, view="visual"):
    """Write a ParaView time series: out_dir/<prefix>_NNNN.vtu (through
    meshio) and out_dir/<name>[_collision].pvd listing them with their
    times.  Each frame holds every rigid fragment's posed surface as
    triangles and, where the file has them (/fracture_mode), the tets of
    fracture-mode fragments as they deform, each tet on its own four
    corners so that cracks open between them.  With view "visual" and a
    /visual surface in the file, a rigid fragment is drawn as its part of
    the object's own surface plus its crack faces; with "collision" (or no
    /visual) as the outer faces of its tets, the mesh the physics sees.
    Point data `velocity` (m s-1: the fragment's rigid motion
    v + w x (x - com) at each point); cell data `fragment` (id), `crack`
    (1 on crack faces), `mode` (0 rigid, 1 fracture), `mass` (kg, the
    fragment's), `stress` (Pa, the Cauchy stress as 6 components xx yy zz
    yz xz xy; 0 on rigid surfaces), `von_mises` (Pa) and `damage` (0-1, the
    largest of the cohesive elements on the tet's faces).  Returns the .pvd
    path."""
    import h5py
    import meshio
    import os
    from xml.sax.saxutils import quoteattr
    with h5py.File(run.path, "r") as f:
        omega = f["particles/fragments/angular_velocity/value"][:len(run.times)]
    visual = view == "visual" and run.visual is not None
    prefix = "frame" if view == "visual" else "collision"
    os.makedirs(out_dir, exist_ok=True)
    entries = []
    for k, t in enumerate(run.times):
        fm = run.fracture_tets_at(k)
        deformed = set()
        if fm is not None:
            frag_of = run.tet_fragments_at(k)[fm["tet"]]
            deformed = set(int(i) for i in np.unique(frag_of))
        blocks, base = [], 0  # (cell type, cells, points, velocities, cell fields)

        def rigid_velocity(i, x):
            return run.velocity[k, i] + np.cross(omega[k, i], x - run.position[k, i])

        def add_surface(i, verts, tri, crack):
            nonlocal base
            n = len(tri)
            blocks.append(("triangle", tri + base, verts, rigid_velocity(i, verts), dict(
                fragment=np.full(n, i, np.int32), crack=crack.astype(np.int32),
                mode=np.full(n, run.mode[k, i], np.int32),
                mass=np.full(n, run.fragments["mass"][i]), stress=np.zeros((n, 6)),
                von_mises=np.zeros(n), damage=np.zeros(n))))
            base += len(verts)

        for i, verts, tri, cr in run.surfaces_at(k):
            if i in deformed:
                continue
            if visual:  # its crack faces here, its outer faces from /visual below
                tri, cr = tri[cr == 1], cr[cr == 1]
            if len(tri):
                add_surface(i, verts, tri, cr)
        if visual:
            for i, verts, tri in run.visual_at(k):
                if i not in deformed:
                    add_surface(i, verts, tri, np.zeros(len(tri)))
        if fm is not None:
            n = len(fm["tet"])
            pts = fm["corners"].reshape(-1, 3)
            vel = np.concatenate([rigid_velocity(int(i), c)
                                  for i, c in zip(frag_of, fm["corners"])])
            blocks.append(("tetra", np.arange(4 * n).reshape(n, 4) + base, pts, vel, dict(
                fragment=frag_of.astype(np.int32), crack=np.zeros(n, np.int32),
                mode=np.ones(n, np.int32), mass=run.fragments["mass"][frag_of],
                stress=fm["stress"], von_mises=von_mises(fm["stress"]), damage=fm["damage"])))
        if not blocks:
            continue
        name = f"{prefix}_{k:04d}.vtu"
        fields = blocks[0][4].keys()
        meshio.write(os.path.join(out_dir, name),
                     meshio.Mesh(np.concatenate([b[2] for b in blocks]),
                                 [(b[0], b[1]) for b in blocks],
                                 point_data={"velocity": np.concatenate([b[3] for b in blocks])},
                                 cell_data={n: [b[4][n] for b in blocks] for n in fields}),
                     binary=True)
        entries.append(f'    <DataSet timestep="{t:.9g}" file={quoteattr(name)}/>')
    pvd = os.path.join(out_dir, (run.name or "run") + ("" if view == "visual" else "_collision")
                       + ".pvd")
    with open(pvd, "w") as f:
        f.write('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
                "  <Collection>\n" + "\n".join(entries) + "\n  </Collection>\n</VTKFile>\n")
    return pvd


def load(path):
    """Read a cohfrac output file: a Run."""
    return Run(path)


if __name__ == "__main__":
    import argparse
    ap = argparse.ArgumentParser(description="Summarise a cohfrac output file, or write "
                                 "its fragments' surfaces as a ParaView time series.")
    ap.add_argument("h5")
    ap.add_argument("--pvd", metavar="DIR", help="write DIR/frame_NNNN.vtu and DIR/<name>.pvd "
                    "and, with a /visual surface, the collision view DIR/<name>_collision.pvd")
    a = ap.parse_args()
    r = load(a.h5)
    if a.pvd:
        print(f"wrote {export_pvd(r, a.pvd)}")
        if r.visual is not None:
            print(f"wrote {export_pvd(r, a.pvd, 'collision')} (the tets' outer faces)")
        raise SystemExit(0)
    last = -1
    print(f"{r.path}: {len(r.times)} frames to t = {r.times[last]:.4g} s, "
          f"{r.n_fragments} fragments ever, {len(r.alive(last))} alive at the end")
    masses = sorted(((r.fragments['mass'][i], i) for i in r.alive(last)), reverse=True)
    for m, i in masses[:5]:
        f = r.fragment(i)
        print(f"  fragment {i}: {m:.4g} kg, {f.n_tets} tets, {len(f.triangles)} surface "
              f"triangles ({int(f.crack.sum())} on cracks)")
