#!/bin/sh
# The installed package works for a program that uses it: install the build
# into a scratch prefix, then build examples/drop.c against it both ways,
# with `pkg-config --cflags --libs cohfrac` and with find_package(cohfrac),
# and run both (they must agree on the fragments).
#   tests/install_example.sh BUILD_DIR SOURCE_DIR
set -eu
build=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix
cmake --install "$build" --prefix "$prefix" >/dev/null
libdir=$(dirname "$(find "$prefix" -name 'libcohfrac.so' | head -1)")
export LD_LIBRARY_PATH="$libdir${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"

export PKG_CONFIG_PATH="$libdir/pkgconfig"
cc -std=c11 -Wall -Wextra -pedantic -Werror "$src/examples/drop.c" \
    $(pkg-config --cflags --libs cohfrac) -o "$tmp/drop_pkgconfig"
"$tmp/drop_pkgconfig" > "$tmp/pkgconfig.txt"
echo "pkg-config build: $(grep 'fragments at' "$tmp/pkgconfig.txt")"

cmake -S "$src/examples" -B "$tmp/examples" -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$tmp/examples" >/dev/null
"$tmp/examples/drop" > "$tmp/cmake.txt"
echo "find_package build: $(grep 'fragments at' "$tmp/cmake.txt")"

grep -q 'fragments at t = 0.60 s' "$tmp/pkgconfig.txt"
cmp "$tmp/pkgconfig.txt" "$tmp/cmake.txt"
echo "both builds ran and printed the same fragments"

# The installed program, run from /: `run` (a sphere meshed by gmsh and
# cached in the XDG cache, not the build tree), then `render` and `export` with the helpers
# installed beside it (a marker in the installed copy shows which ran).
export XDG_CACHE_HOME="$tmp/cache"
unset COHFRAC_MESH_DIR
site=$(find "$prefix/lib" -path '*dist-packages/cohfrac/__init__.py' | head -1)
[ -n "$site" ] || { echo "FAIL: the Python package is not installed"; exit 1; }
py=$(dirname "$site")
for f in render.py h5.py; do
    sed -i '/^if __name__ == "__main__":/i print("installed helper", file=__import__("sys").stderr)' "$py/$f"
done
cp "$src/tests/data/box_break.lua" "$tmp/box.lua"
# The surface repair runs the installed cohfrac-repair (libexec/cohfrac,
# found beside the program): mark it, then mesh a box with a face missing.
rep=$prefix/libexec/cohfrac/cohfrac-repair
[ -x "$rep" ] || { echo "FAIL: $rep was not installed"; exit 1; }
mv "$rep" "$rep.real"
printf '#!/bin/sh\ntouch "$0.used"\nexec "$0.real" "$@"\n' > "$rep"
chmod +x "$rep"
printf 'OFF\n8 10 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n3 0 2 3\n3 0 3 1\n3 4 5 7\n3 4 7 6\n3 0 1 5\n3 0 5 4\n3 2 6 7\n3 2 7 3\n3 0 4 6\n3 0 6 2\n' > "$tmp/open.off"
cd /
"$prefix/bin/cohfrac" run "$tmp/box.lua" -q --set duration=0.05 -o "$tmp/box.h5" \
    --set 'bodies[1].mesh={type="sphere", radius=0.1, mesh_size=0.05}' > "$tmp/run.txt"
ls "$tmp/cache/cohfrac/meshes/"sphere_*.msh >/dev/null 2>&1 ||
    { echo "FAIL: the sphere was not meshed in the XDG cache"; exit 1; }
"$prefix/bin/cohfrac" export "$tmp/box.h5" --format gltf -o "$tmp/box.glb"
"$prefix/bin/cohfrac" export "$tmp/box.h5" --format pvd -o "$tmp/pvd" 2> "$tmp/pvd.txt"
grep -q 'installed helper' "$tmp/pvd.txt" || { echo "FAIL: export pvd did not run the installed helper"; exit 1; }
[ -f "$tmp/pvd/box_break.pvd" ] && [ -s "$tmp/box.glb" ]
env -u COHFRAC_REPAIR "$prefix/bin/cohfrac" mesh "$tmp/open.off" -o "$tmp/open" -q 2> "$tmp/mesh.txt"
[ -f "$rep.used" ] || { echo "FAIL: mesh did not run the installed cohfrac-repair"; cat "$tmp/mesh.txt"; exit 1; }
grep -q '1 hole(s) filled' "$tmp/mesh.txt" || { echo "FAIL: the open box was not closed"; cat "$tmp/mesh.txt"; exit 1; }
echo "installed mesh from /: $(grep -o '1 hole(s) filled' "$tmp/mesh.txt") by the installed cohfrac-repair"
echo "installed run from /: $(grep -m1 '^fragments' "$tmp/run.txt"); export gltf and pvd written"
if command -v ffmpeg >/dev/null; then
    "$prefix/bin/cohfrac" render "$tmp/box.h5" --fps 10 --size 320x240 -o "$tmp/movie" 2> "$tmp/render.txt"
    grep -q 'installed helper' "$tmp/render.txt" || { echo "FAIL: render did not run the installed helper"; exit 1; }
    [ -s "$tmp/movie/box_break.mp4" ]
    echo "installed render from /: a $(du -k "$tmp/movie/box_break.mp4" | cut -f1) kB MP4"
fi

# The Python package, installed where Debian's python3 looks under the
# prefix (lib/python3.X/dist-packages), loads the installed library.
lib=$(env -u COHFRAC_LIB PYTHONPATH="$(dirname "$(dirname "$site")")" /usr/bin/python3 -c \
    'import cohfrac; print(cohfrac.library()._name)')
case "$lib" in "$prefix"/*) ;; *) echo "FAIL: import cohfrac loaded $lib, not the install's"; exit 1 ;; esac
echo "import cohfrac from the install: $lib"
