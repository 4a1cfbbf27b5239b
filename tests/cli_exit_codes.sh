#!/bin/sh
# The documented exit codes of the `cohfrac` program, one case per code:
# 0 ok, 1 usage, 2 bad input, 3 diverged, 4 output failed, 5 external failure.
# usage: cli_exit_codes.sh COHFRAC_EXE MESH_DIR
set -u
exe=$1
meshes=$2
. "$(dirname "$0")/expect.sh"
cat >"$tmp/drop.lua" <<LUA
return { name = "tiny", duration = 0.002,
  bodies = { { mesh = "bunny_small", position = {0, 0, 2} } },
  obstacles = { { type = "plane", point = {0, 0, 0}, normal = {0, 0, 1} } },
  output = { file = "$tmp/out/tiny.h5" } }
LUA
echo 'return { bodies = { { mesh = "bunny_small" } }, solver = { dt_rigid = -1 } }' >"$tmp/bad.lua"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$tmp/open.obj"
: >"$tmp/file"

expect 0 "--version" "$exe" --version
expect 0 "a tiny run" "$exe" run "$tmp/drop.lua" --mesh-dir "$meshes" -q
expect 1 "no command" "$exe"
expect 1 "unknown option" "$exe" run --bogus "$tmp/drop.lua"
expect 1 "unknown command" "$exe" rnu "$tmp/drop.lua"
# One line that names the word and the nearest command, not the usage.
[ "$(wc -l <"$tmp/log")" -eq 1 ] && grep -q "unknown command 'rnu'; did you mean 'run'" "$tmp/log" ||
    { echo "FAIL  the unknown command's message"; fails=$((fails + 1)); }
expect 0 "bench --scene: the cost of fracture mode" "$exe" bench --scene "$tmp/drop.lua" \
    -m "$meshes" --set duration=0.001
expect 1 "bench --fracture-ms that is no number" "$exe" bench --scene "$tmp/drop.lua" \
    --fracture-ms soon
expect 1 "bench --set without --scene" "$exe" bench --set duration=1
expect 2 "bench --scene with a bad value" "$exe" bench --scene "$tmp/bad.lua" -m "$meshes"
expect 2 "scene value out of range" "$exe" run "$tmp/bad.lua" --mesh-dir "$meshes"
expect 2 "missing scene file" "$exe" run "$tmp/none.lua"
expect 2 "open surface, --no-repair" "$exe" mesh "$tmp/open.obj" -o "$tmp/m" --no-repair
expect 2 "open surface, repaired: a sheet is no solid" "$exe" mesh "$tmp/open.obj" -o "$tmp/m"
grep -q 'is an open sheet, not a solid' "$tmp/log" ||
    { echo "FAIL  the sheet is not said to be one"; fails=$((fails + 1)); }
# A closed surface with a stray vertex: refused before tetgen, naming it.
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1e10\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n' >"$tmp/far.obj"
expect 2 "a vertex far out" "$exe" mesh "$tmp/far.obj" -o "$tmp/far"
grep -q 'vertex 3 (0-based) at (0, 0, 1e+10)' "$tmp/log" ||
    { echo "FAIL  the far vertex is not named"; fails=$((fails + 1)); }
expect 3 "divergence (dt far above the CFL step, no PBD iterations to hold it)" \
    "$exe" run "$tmp/drop.lua" --mesh-dir "$meshes" -q --set bodies[1].position='{0,0,0.78}' --set bodies[1].velocity='{0,0,-3}' \
    --set material.E=1e9 --set solver.dt_fracture=1e-3 --set solver.dt_rigid=1e-3 \
    --set solver.pbd.k_stiffness=0 --set duration=0.05
# The diverged run's file stays readable, and the plausibility check fails
# it: it never reached its duration (its frames so far may all look fine).
expect 1 "tests/checks/check_physics.py on the diverged run's file" \
    /usr/bin/python3 "$(dirname "$0")/../tests/checks/check_physics.py" "$tmp/out/tiny.h5"
grep -q 'FAIL  complete' "$tmp/log" || { echo "FAIL  no failed 'complete' check"; fails=$((fails + 1)); }
expect 4 "output under a regular file" "$exe" run "$tmp/drop.lua" --mesh-dir "$meshes" -q \
    -o "$tmp/file/x.h5"
mkdir "$tmp/dir"
expect 4 "output path that is a directory" "$exe" run "$tmp/drop.lua" --mesh-dir "$meshes" -q \
    -o "$tmp/dir"
# --force cannot write over a directory: the advice is a file in it.
grep -q "it is a directory (give a file in it, e.g. -o $tmp/dir/tiny.h5)" "$tmp/log" &&
    ! grep -q -- --force "$tmp/log" ||
    { echo "FAIL  the directory output's advice"; fails=$((fails + 1)); }
expect 5 "tetgen missing" env COHFRAC_TETGEN=/nonexistent/tetgen "$exe" mesh \
    /usr/share/glmark2/models/bunny.obj -o "$tmp/b" --target-tets 15000
[ "$fails" -eq 0 ]
