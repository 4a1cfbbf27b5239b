#!/bin/sh
# Allocation failure anywhere is an error, not a crash (docs/reliability.md).
# tests/failalloc.c, loaded with LD_PRELOAD, makes the N-th allocation of a
# run return NULL.  Two short runs:
#   bunny  the bunny drop for 10 ms: scene script, TetGen mesh, convex
#          decomposition, Bullet world, HDF5 output, a few rigid steps
#   box    tests/data/box_break.lua hitting the ground at once, 10 ms:
#          fracture mode, cohesive insertion, fragments, hand-offs both ways
# Each runs once with the allocator counting (T calls) and noting each call
# site (a stack of three callers, one in cohfrac, at its first call), then
# with one failing call at POINTS points from call 1 to call T (sparse
# through the first 200, where the scene script and start-up allocate, then
# geometric) and at POINTS / 2 call sites evenly spread over the sites
# noted (different code, where the counts would land in the same loop), and
# with every call failing from every third of those points on (memory gone
# for good: the error path itself cannot allocate).  Each run must end
# by exit, never a signal, nor hang: exit 0 (the failed call was one that
# may fail: Lua and HDF5 collect garbage and try again), or exit 5 with
# "cohfrac: error" and a message that says out of memory; an output file
# left behind must open with h5py, every per-frame dataset holding the
# same number of frames.
# POINTS "sites" sweeps every call site instead, each both ways (about
# 600 sites, 1,200 runs: minutes).
#   tests/failalloc.sh COHFRAC LIBFAILALLOC SOURCE_DIR MESH_DIR [POINTS|sites]
set -u
exe=$1
lib=$2
src=$3
meshes=$4
points=${5:-20}

# AddressSanitizer must be the first library loaded and replaces malloc
# itself: nothing to preload there (exit 77: ctest's skip).
if [ -n "${ASAN_OPTIONS:-}" ] || [ ! -f "$lib" ] || ldd "$exe" | grep -q libasan; then
    echo "skip  failing allocator: not under AddressSanitizer"
    exit 77
fi
. "$(dirname "$0")/expect.sh"
mkdir -p "$tmp/h5"
# Two threads, so libgomp starts its thread; on a shared machine libgomp's
# spinning threads wait for each other for seconds (passive: they sleep).
export OMP_WAIT_POLICY=passive

# libgomp's own allocations are left out of the count: it ends the process
# on any of them failing (gomp_malloc -> gomp_fatal -> exit 1), which
# cohfrac's exit guard turns into exit 5 (src/cli/main.c, checked once
# below).
filter=COHFRAC_FAIL_ALLOC_SKIP=libgomp

# run NAME AT COUNT: one run of scene NAME, its allocation AT (0: none) and
# the COUNT - 1 after it (or 'all') failing, counted as $filter says; sets
# rc, and leaves stderr in $tmp/err and the allocator's report
# (tests/failalloc.c) in $tmp/report.
sites=
run() {
    rm -f "$tmp/o.h5" "$tmp/o.xdmf" "$tmp/report"
    case $1 in
    bunny) set -- "$1" "$2" "$3" "$src/scenes/source/bunny_drop.lua" -m "$meshes" ;;
    box) set -- "$1" "$2" "$3" "$src/tests/data/box_break.lua" --set 'bodies[1].position={0,0,0.1005}' \
        --set 'bodies[1].velocity={0,0,-4.4}' --set output.frame_interval=0.001 ;;
    esac
    at=$2 count=$3
    shift 3
    # The allocator is preloaded into cohfrac alone, not into timeout or sh.
    timeout 60 sh -c 'a=$1 c=$2 r=$3 l=$4 f=$5 w=$6 x=$7 s=$8; shift 8
        export "$f" COHFRAC_FAIL_ALLOC_SITES="$w"
        COHFRAC_FAIL_ALLOC_AT=$a COHFRAC_FAIL_ALLOC_COUNT=$c COHFRAC_FAIL_ALLOC_REPORT=$r \
        LD_PRELOAD=$l exec "$x" run "$s" "$@"' sh \
        "$at" "$count" "$tmp/report" "$lib" "$filter" "$sites" "$exe" "$@" -q -t 2 \
        --set duration=0.01 -o "$tmp/o.h5" --force >/dev/null 2>"$tmp/err"
    rc=$?
}

# Whether the last failed allocation was HDF5's own (made from libhdf5).
hdf5_failed() {
    awk '/^failed call/ { on = 1; next } /^(signal|calls)/ { on = 0 }
         on && /libhdf5/ { found = 1 } END { exit !found }' "$tmp/report" 2>/dev/null
}

# Whether the crash came inside HDF5: the first frame under the signal
# that is neither the allocator's handler nor libc's.
crashed_in_hdf5() {
    awk '/^signal/ { on = 1; next } /^calls/ { on = 0 }
         on && !/failalloc|libc\.so/ && !where { where = $0 }
         END { exit where !~ /libhdf5/ }' "$tmp/report" 2>/dev/null
}

# Known, tolerated: HDF5 1.10 (Debian 12's 1.10.8) does not survive its own
# allocations failing.  It writes through the NULL of an unchecked malloc
# (the per-thread error stack, H5E__get_stack), recurses without end when
# its error classes could not be registered at start-up (H5E_printf_stack
# <-> H5I_inc_ref), frees what it never allocated on the way out of a
# failed H5O_create or H5Dclose, and calls exit(-1) when its identifier
# table cannot grow (H5I_register).  It has no allocator hook to give it
# memory another way, and returns no error to us first.  A crash is
# tolerated only when it came inside HDF5 after HDF5's own allocation
# failed; the exit(-1) is caught by cohfrac's exit guard (exit 5 with a
# message).  Either way HDF5 stopped part way through writing: the output
# is then as after a SIGKILL inside HDF5, and is not checked.
hdf5_ended_it() {
    hdf5_failed && { { [ "$rc" -gt 128 ] && crashed_in_hdf5; } ||
        { [ "$rc" -eq 5 ] && grep -q 'a library ended the process' "$tmp/err"; }; }
}

# The injection points for a run of T calls: 1 2 3 5 8 ... 200 (sparse),
# then geometric to T, POINTS in all, each once.
spread() {
    awk -v t="$1" -v p="$points" 'BEGIN {
        split("1 2 3 5 8 13 21 34 55 89 144 200", s, " ");
        n = 0;
        for (i = 1; i <= 12 && n < p / 2 && s[i] < t; i++) { print s[i]; n++ }
        m = p - n; last = s[i - 1];
        for (k = 1; k <= m; k++) {
            v = int(last * exp(log(t / last) * k / m));
            if (v > last) { print v; last = v }
        }
    }'
}

total=0
for scene in bunny box; do
    sites=$tmp/sites.$scene
    run $scene 0 1
    sites=
    calls=$(sed -n 's/^calls \([0-9]*\) .*/\1/p' "$tmp/report" 2>/dev/null)
    if [ "$rc" -ne 0 ] || [ -z "$calls" ]; then
        echo "FAIL  $scene: exit $rc without a failing allocation (or no count)"
        tail -5 "$tmp/err"; fails=$((fails + 1)); continue
    fi
    echo "ok    $scene: $calls allocations in a run"
    ok0=0 ok5=0 hdf5=0 i=0
    if [ "$points" = sites ]; then
        list=$(sed -n 's/^site //p' "$tmp/sites.$scene")
    else
        list=$({ spread "$calls"; sed -n 's/^site //p' "$tmp/sites.$scene" |
            awk -v p="$points" '{ s[n++] = $1 } END { for (k = 0; k < p / 2 && n; k++)
                print s[int((k + 0.5) * n / (p / 2))] }'; } | sort -n | uniq)
    fi
    echo "ok    $scene: $(grep -c '^site' "$tmp/sites.$scene") call sites; $(echo $list | wc -w) points"
    for at in $list; do
        i=$((i + 1))
        modes=1
        [ $((i % 3)) -eq 0 ] || [ "$points" = sites ] && modes="1 all"
        for count in $modes; do
            run $scene "$at" "$count"
            total=$((total + 1))
            what="$scene: call $at failing"
            [ "$count" = all ] && what="$scene: every call from $at on failing"
            why=""
            if [ "$rc" -eq 124 ]; then
                why="hung (60 s)"
            elif hdf5_ended_it; then
                hdf5=$((hdf5 + 1))
                rm -f "$tmp/o.h5"
            elif [ "$rc" -gt 128 ]; then
                why="signal $((rc - 128))"
            elif [ "$rc" -eq 0 ]; then
                ok0=$((ok0 + 1))
            elif [ "$rc" -eq 5 ] && grep -q 'cohfrac: error' "$tmp/err" &&
                 grep -Eqi 'out of memory|cannot allocate memory' "$tmp/err"; then
                ok5=$((ok5 + 1))
            else
                why="exit $rc"
            fi
            if [ -n "$why" ]; then
                echo "FAIL  $what: $why"
                sed 's/^/      /' "$tmp/err" | tail -6
                sed 's/^/      /' "$tmp/report" 2>/dev/null | head -30
                fails=$((fails + 1))
            fi
            # HDF5 writes its metadata entry by entry: a flush that runs
            # out of memory part way may leave some written and not the
            # rest, and nothing can write the file whole without memory.
            # cohfrac then says the file may not open; such a file is not
            # checked.
            if [ -f "$tmp/o.h5" ] && ! grep -q 'the file may not open' "$tmp/err"; then
                mv "$tmp/o.h5" "$tmp/h5/$scene.$at.$count.h5"
            fi
        done
    done
    echo "ok    $scene: $ok0 ran through (exit 0), $ok5 out of memory (exit 5)," \
         "$hdf5 ended by HDF5's own failure"
done

# libgomp's allocation failing: exit 5 with libgomp's message and
# cohfrac's, not libgomp's exit 1 (which means a bad command line here).
# The box run has one, its thread pool at the first parallel region: loops
# that run on one thread never enter the runtime (src/engine/parallel.h),
# where each such region used to allocate a team (137,000 of the run's
# 162,000 allocations).
filter=COHFRAC_FAIL_ALLOC_ONLY=libgomp
for at in 1; do
    run box $at 1
    total=$((total + 1))
    if [ "$rc" -eq 5 ] && grep -q 'libgomp: Out of memory' "$tmp/err" &&
       grep -q 'cohfrac: error.*a library ended the process' "$tmp/err"; then
        echo "ok    box: libgomp's allocation $at failing: exit 5, libgomp's message and ours"
    else
        echo "FAIL  box: libgomp's allocation $at failing: exit $rc"
        sed 's/^/      /' "$tmp/err" | tail -4; fails=$((fails + 1))
    fi
    [ -f "$tmp/o.h5" ] && mv "$tmp/o.h5" "$tmp/h5/box.gomp$at.h5"
done

# Every file left behind opens and holds whole frames (one h5py start-up).
set -- "$tmp"/h5/*.h5
if [ -f "$1" ]; then
    /usr/bin/python3 "$src/tests/frames_consistent.py" "$@" >"$tmp/frames" 2>"$tmp/frames.err"
    n=0 bad=0
    for f in "$@"; do
        n=$((n + 1))
        c=$(sed -n "${n}p" "$tmp/frames")
        case "$c" in
        -*|'') echo "FAIL  $(basename "$f" .h5): the output does not open, or its frames disagree ($c)"
               bad=$((bad + 1)) ;;
        esac
    done
    [ $bad -gt 0 ] && { sed 's/^/      /' "$tmp/frames.err" | tail -8; fails=$((fails + bad)); }
    [ $bad -eq 0 ] && echo "ok    all $# output files left open with whole frames"
fi
echo "$total runs with failing allocations, $fails failed"
[ "$fails" -eq 0 ]
