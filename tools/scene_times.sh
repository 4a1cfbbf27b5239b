#!/bin/sh
# Run every scene of scenes/ at its default settings, one after another, and
# print a Markdown table of what each run's summary says (mesh size,
# simulated time, wall time, fragments at the end) and what
# tests/checks/check_physics.py finds in its output (docs/physics.md §14):
# the fastest fragment at the end against its bound, the largest kinetic
# energy against the input at that frame, the largest ledger residual as a
# share of the input, and the checks that fail ("ok", or "known: ..." for
# those tests/plausibility_known.txt lists for the scene).  This is the
# scene table of README.md.
#
# usage: [SCENE_TIMEOUT=S] tools/scene_times.sh [COHFRAC_EXE [MESH_DIR [SCENES_DIR]]]
#   defaults: build/cohfrac, the program's mesh directory ($COHFRAC_MESH_DIR or
#   ~/.cache/cohfrac/meshes, as `make run` prepares them), scenes/
#   SCENE_TIMEOUT: stop a run after S seconds of wall time (default 0: no
#   limit); its row then gives how far it got, read from its HDF5 file.
#   Needs /usr/bin/python3 with h5py and numpy, as tests/checks/check_physics.py.
#
# scenes/verification/ and scenes/compare/ are left out (ctest runs those),
# except the source's mixed-mode beam and the elastic impact, whose
# figures the README cites.  Each run writes its HDF5 file to a temporary
# directory (removed at the end) instead of out/; every other setting is
# the scene's own.  "wall" is the run's own wall time from its summary
# (gmsh meshes a primitive the first time it is used, a few seconds more,
# cached afterwards).  Progress goes to stderr, the table to stdout:
#   tools/scene_times.sh > times.md
# Exit status 0 when every run ends and its checks are as expected, 1 otherwise.
set -u
here=$(dirname "$0")
exe=${1:-$here/../build/cohfrac}
meshes=${2:-${COHFRAC_MESH_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/cohfrac/meshes}}
scenes=${3:-$here/../scenes}
checks=$here/../tests/checks
known=$here/../tests/plausibility_known.txt
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

{
    find "$scenes" -name '*.lua' ! -path '*/verification/*' ! -path '*/compare/*'
    echo "$scenes/verification/mixed_mode_beam.lua"
    echo "$scenes/verification/elastic_impact.lua"
} | sort >"$tmp/list"
echo "| scene | tets | simulated | wall | fragments at the end | fastest / bound | kinetic energy / input | residual | check |"
echo "|---|---|---|---|---|---|---|---|---|"
tmo=${SCENE_TIMEOUT:-0}
fails=0
while IFS= read -r scene; do
    name=${scene#"$scenes"/}
    echo "running $name ..." >&2
    if [ "$tmo" -gt 0 ]; then
        timeout "$tmo" "$exe" run "$scene" --mesh-dir "$meshes" -q -o "$tmp/run.h5" \
            >"$tmp/log" 2>&1 </dev/null
    else
        "$exe" run "$scene" --mesh-dir "$meshes" -q -o "$tmp/run.h5" >"$tmp/log" 2>&1 </dev/null
    fi
    rc=$?
    partial=""
    if [ "$rc" -eq 124 ] && [ -f "$tmp/run.h5" ]; then
        # "<time reached> <fragments then> <tets of the first body>" from
        # the last flushed frame (the summary, with the mesh line, never came).
        partial=$(/usr/bin/python3 -c '
import sys, h5py
f = h5py.File(sys.argv[1], "r")
o = f["observables/fragment_count"]
print("%g %d %d" % (o["time"][-1], o["value"][-1], f["fragments/n_tets"][0]))' "$tmp/run.h5" 2>/dev/null)
    fi
    # "fastest / bound|kinetic / input|residual|failed checks" from the output.
    phys=""
    if [ "$rc" -eq 0 ]; then
        phys=$(/usr/bin/python3 - "$checks" "$tmp/run.h5" 2>&1 <<'EOF'
import contextlib, io, sys
sys.path.insert(0, sys.argv[1])
import check_physics
f = {}
with contextlib.redirect_stdout(io.StringIO()):
    check_physics.check_file(sys.argv[2], figures=f)
print(f"{f['fastest']:.4g} / {f['speed_bound']:.4g} m/s|{f['kinetic']:.4g} / {f['kinetic_input']:.4g} J|"
      f"{100 * f['residual_share']:.3g} %|{' '.join(f['failed'])}")
EOF
)
    fi
    rm -f "$tmp/run.h5" "$tmp/run.xdmf"
    # "mesh               3982 tets, 1334 nodes (1975 after duplication)"
    tets=$(sed -n 's/^mesh  *\([0-9]*\) tets.*/\1/p' "$tmp/log" | head -n 1)
    # "simulated time     1 s in 500 rigid steps ..."
    sim=$(sed -n 's/^simulated time  *\([^ ]*\) s .*/\1 s/p' "$tmp/log" | head -n 1)
    wall=$(sed -n 's/^wall time  *\([^ ]*\) s.*/\1 s/p' "$tmp/log" | head -n 1)
    # "fragments          164 alive (0 in fracture mode), 166 ever"
    frag=$(sed -n 's/^fragments  *\([0-9]*\) alive.*/\1/p' "$tmp/log" | head -n 1)
    fast=- kin=- res=-
    if [ "$rc" -eq 0 ]; then
        case "$phys" in
        *\|*\|*\|*)
            fast=${phys%%|*}; phys=${phys#*|}
            kin=${phys%%|*}; phys=${phys#*|}
            res=${phys%%|*}; failed=${phys#*|}
            expected=$(awk -v s="$name" '$1 == s {print $2}' "$known" | sort | tr '\n' ' ')
            failed=$(echo "$failed" | tr ' ' '\n' | sed '/^$/d' | sort | tr '\n' ' ')
            if [ "$failed" = "$expected" ]; then
                end=${expected:+"known: ${expected% }"}
                end=${end:-ok}
            else
                fails=$((fails + 1))
                end="FAIL: ${failed% }${expected:+ (known: ${expected% })}"
            fi ;;
        *)
            fails=$((fails + 1))
            end="cannot check: $(echo "$phys" | tail -n 1)" ;;
        esac
    elif [ "$rc" -eq 124 ]; then
        fails=$((fails + 1))
        end="stopped after $tmo s (SCENE_TIMEOUT)"
        if [ -n "$partial" ]; then
            set -- $partial
            sim="$1 s reached"
            frag="$2 (then)"
            tets="$3"
        fi
        wall="> $tmo s"
    else
        fails=$((fails + 1))
        why=$(sed -n 's/^cohfrac: error \[\([A-Z_]*\)\].*/\1/p' "$tmp/log" | head -n 1)
        end="exit $rc${why:+ ($why)}"
        sed 's/^/    /' "$tmp/log" | head -n 3 >&2
    fi
    echo "| \`$name\` | ${tets:--} | ${sim:--} | ${wall:--} | ${frag:--} | $fast | $kin | $res | $end |"
    echo "  $name: ${wall:-?} wall, ${frag:-?} fragments, $end" >&2
done <"$tmp/list"
[ "$fails" -eq 0 ]
