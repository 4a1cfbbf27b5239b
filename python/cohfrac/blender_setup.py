"""Make Debian 12's Blender 3.4 import glTF files with its default options.

    python3 blender_setup.py [--check]      (run by `cohfrac blender-setup`)

Debian 12 ships Blender 3.4.1 with numpy 1.24.  The glTF importer's default
shading ("NORMALS", set_poly_smoothing in io_scene_gltf2) builds an array of
dtype `np.bool`, an alias numpy 1.24 removed, so File > Import > glTF fails
for every file that has a mesh ("module 'numpy' has no attribute 'bool'").
Blender 3.5 and later write `bool`.  This puts a startup script,
cohfrac_numpy_bool.py, in Blender's user scripts (where Blender itself says
they live: bpy.utils.user_resource, so BLENDER_USER_SCRIPTS and the XDG
config are honoured) that gives numpy the alias back when it lacks it, the
builtin `bool` that numpy 1.23 and earlier had under that name.

Writes nothing when Blender's numpy still has `bool`, and never overwrites
a file of that name with other content.  --check only says whether the
script is needed and whether it is there.

Exit status: 0 done (or nothing to do), 4 the script could not be written
or another file holds its name, 5 Blender is missing or failed.
"""
import os
import shutil
import subprocess
import sys

NAME = "cohfrac_numpy_bool.py"
SCRIPT = '''"""Installed by `cohfrac blender-setup`: numpy 1.24 removed the alias
np.bool that Blender 3.4's glTF importer uses for its default shading;
give it back as the builtin bool it stood for.  Delete this file to undo."""
import numpy

if "bool" not in vars(numpy):
    numpy.bool = bool


def register():
    pass


def unregister():
    pass
'''

# Asked of Blender with user scripts off (--factory-startup), so what it
# says about numpy is not this script's doing.
PROBE = ("import bpy, numpy; "
         "print('COHFRAC_STARTUP', bpy.utils.user_resource('SCRIPTS', path='startup')); "
         "print('COHFRAC_NEEDS', int('bool' not in vars(numpy)))")


def ask_blender(blender):
    try:
        out = subprocess.run([blender, "-b", "--factory-startup", "--python-expr", PROBE],
                             capture_output=True, text=True, timeout=120).stdout
    except (OSError, subprocess.TimeoutExpired) as e:
        return None, None, str(e)
    vals = dict(line.split(" ", 1) for line in out.splitlines()
                if line.startswith(("COHFRAC_STARTUP ", "COHFRAC_NEEDS ")))
    if len(vals) != 2:
        return None, None, "it printed no scripts directory"
    return vals["COHFRAC_STARTUP"], vals["COHFRAC_NEEDS"] == "1", None


def main(argv):
    check = "--check" in argv
    blender = shutil.which("blender")
    if not blender:
        print("cohfrac: error [external]: blender is not installed (Debian package "
              "`blender`): nothing to set up", file=sys.stderr)
        return 5
    startup, needs, why = ask_blender(blender)
    if startup is None:
        print(f"cohfrac: error [external]: cannot ask {blender} where its scripts are: {why}",
              file=sys.stderr)
        return 5
    path = os.path.join(startup, NAME)
    have = None
    if os.path.exists(path):
        with open(path, encoding="utf-8", errors="replace") as f:
            have = f.read()
    if not needs:
        print(f"Blender's numpy has np.bool: its glTF importer works as it is; nothing written"
              + (f" ({path} is there and does nothing)" if have is not None else ""))
        return 0
    if have == SCRIPT:
        print(f"already set up: {path}")
        return 0
    if have is not None:
        print(f"cohfrac: error [output]: {path} exists with other content: not overwritten; "
              "move it away and run `cohfrac blender-setup` again", file=sys.stderr)
        return 4
    if check:
        print(f"needed, not there: `cohfrac blender-setup` writes {path}")
        return 0
    try:
        os.makedirs(startup, exist_ok=True)
        tmp = f"{path}.{os.getpid()}.tmp"
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(SCRIPT)
        os.replace(tmp, path)
    except OSError as e:
        print(f"cohfrac: error [output]: cannot write {path}: {e}", file=sys.stderr)
        return 4
    print(f"wrote {path}: Blender's glTF importer now works with its default options "
          "(delete the file to undo)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
