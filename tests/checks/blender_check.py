"""Inside Blender (headless): import a cohfrac glTF export and print what
Blender sees, for tests/output_viewers.sh to compare with the HDF5.

    blender -b --python tests/checks/blender_check.py -- OUT.glb FRAGMENT T_END

Prints "objects N" (mesh objects imported) and "position x y z" (fragment
FRAGMENT's world position at time T_END s, after Blender's +y-up to +z-up
conversion)."""
import sys

import bpy

glb, fragment, t_end = sys.argv[sys.argv.index("--") + 1:][:3]
bpy.ops.wm.read_factory_settings(use_empty=True)
# The importer's default options, as File > Import does it: on Debian 12
# they need `cohfrac blender-setup` first (np.bool, numpy 1.24).
bpy.ops.import_scene.gltf(filepath=glb)
scene = bpy.context.scene
meshes = [o for o in scene.objects if o.type == "MESH"]
print("objects", len(meshes))
fps = scene.render.fps / scene.render.fps_base
frame = float(t_end) * fps
scene.frame_set(int(frame), subframe=frame - int(frame))
obj = bpy.data.objects[f"fragment_{fragment}"]
x, y, z = obj.matrix_world.translation
print("position", x, y, z)
