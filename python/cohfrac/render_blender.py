"""Inside Blender (headless): render a cohfrac glTF export, frame by frame,
with depth, lighting and shadows (Workbench), from a camera that follows
the pieces.  Run by python/cohfrac/render.py:

    xvfb-run -a blender -b -P python/cohfrac/render_blender.py -- \
        RUN.glb OUT_DIR FPS W H T0 N SLOW FLOOR_Z

Writes OUT_DIR/frame_0000.png ...: movie frame k shows the run at
t = T0 + k / (FPS * SLOW) s, for k < N.  The camera looks from the
side and above (+z up) at the mass-weighted centre of the pieces shown,
from as far as keeps the pieces that carry 95 % of the mass in view (it
backs off at once and closes in slowly, so it does not jitter); before
the first break that is the whole body, which then fills most of the
frame.  A grey floor is drawn at FLOOR_Z (nan: none).  Each fragment keeps
its export colour; crack faces their own material.
"""
import math
import os
import sys

import bpy
import mathutils

args = sys.argv[sys.argv.index("--") + 1:]
glb, out_dir = args[0], args[1]
fps, width, height = float(args[2]), int(args[3]), int(args[4])
t0, n_frames, slow, floor_z = float(args[5]), int(args[6]), float(args[7]), float(args[8])

bpy.ops.wm.read_factory_settings(use_empty=True)
# Flat shading: the default of Debian's Blender 3.4 fails with numpy 1.24
# (docs/output.md); the surfaces are flat-faceted anyway.
bpy.ops.import_scene.gltf(filepath=glb, import_shading="FLAT")
scene = bpy.context.scene
pieces = [o for o in scene.objects if o.type == "MESH"]
anim_fps = scene.render.fps / scene.render.fps_base  # the importer's keys: t * anim_fps

scene.render.engine = "BLENDER_WORKBENCH"
scene.render.resolution_x, scene.render.resolution_y = width, height
scene.render.resolution_percentage = 100
shading = scene.display.shading
shading.light = "STUDIO"
shading.color_type = "MATERIAL"
shading.show_shadows = True
shading.show_cavity = False  # screen-space, slow in software GL
scene.world = bpy.data.worlds.new("sky")  # the background where the floor ends
scene.world.color = (0.80, 0.84, 0.90)
scene.display.shadow_focus = 0.9
scene.display.render_aa = "FXAA"  # one sample: multisampling is slow in software GL

if math.isfinite(floor_z):
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0, 0, floor_z))
    floor = bpy.context.active_object
    mat = bpy.data.materials.new("floor")
    mat.diffuse_color = (0.62, 0.62, 0.64, 1.0)
    floor.data.materials.append(mat)
else:
    floor = None

cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
scene.collection.objects.link(cam)
scene.camera = cam
cam.data.lens = 50
half_fov = 0.5 * min(cam.data.angle_x, cam.data.angle_y)
view = mathutils.Vector((math.cos(math.radians(-60)) * math.cos(math.radians(20)),
                         math.sin(math.radians(-60)) * math.cos(math.radians(20)),
                         math.sin(math.radians(20))))


def shown():
    """(centre, size, mass) of the pieces visible at the current frame; the
    others (scale 0: not yet born, or split) are left out of the render."""
    out = []
    for o in pieces:
        o.hide_render = o.matrix_world.to_scale()[0] < 0.5
        if o.hide_render:
            continue
        corners = [o.matrix_world @ mathutils.Vector(c) for c in o.bound_box]
        lo = mathutils.Vector([min(c[k] for c in corners) for k in range(3)])
        hi = mathutils.Vector([max(c[k] for c in corners) for k in range(3)])
        mass = float(o.get("mass", 1.0))
        out.append(((lo + hi) / 2, (hi - lo).length / 2, mass))
    return out


os.makedirs(out_dir, exist_ok=True)
radius, target = None, None
for k in range(n_frames):
    t = t0 + k / (fps * slow)
    f = t * anim_fps
    scene.frame_set(int(math.floor(f)), subframe=f - math.floor(f))
    items = shown()
    total = sum(m for _, _, m in items) or 1.0
    centre = sum((c * m for c, _, m in items), mathutils.Vector()) / total
    # The pieces carrying 95 % of the mass, nearest the centre first.
    items.sort(key=lambda it: (it[0] - centre).length)
    need, acc = 0.0, 0.0
    for c, size, m in items:
        need = max(need, (c - centre).length + size)
        acc += m
        if acc >= 0.95 * total:
            break
    need = max(need, 1e-3)
    # Back off at once, close in slowly; the aim follows smoothly.
    radius = need if radius is None or need > radius else 0.9 * radius + 0.1 * need
    target = centre if target is None else target.lerp(centre, 0.3)
    distance = 0.95 * radius / math.sin(half_fov)
    cam.location = target + distance * view
    cam.rotation_euler = (target - cam.location).to_track_quat("-Z", "Y").to_euler()
    cam.data.clip_start, cam.data.clip_end = distance / 100, distance * 100
    if floor is not None:
        floor.scale = (8 * distance, 8 * distance, 1)
        floor.location = (target.x, target.y, floor_z)
    scene.render.filepath = os.path.join(out_dir, f"frame_{k:04d}.png")
    bpy.ops.render.render(write_still=True)
    if (k + 1) % 20 == 0 or k + 1 == n_frames:
        print(f"render: frame {k + 1}/{n_frames} (t = {t:.4f} s)", file=sys.stderr, flush=True)
print(f"rendered {n_frames} frames")
