#!/bin/sh
# SIGKILL cannot be caught: what is on disk is what the last frame's flush
# left there, and the root attribute `frames` counts the frames that flush
# made whole (docs/reliability.md).  Two ways to kill the bunny drop:
#  - by the clock: at 0.5 s (mesh preparation and convex decomposition
#    still going; the file exists about 30 ms after start, but on this
#    machine's disk a write-back can stall file creation for a few hundred
#    ms: 0.3 s failed now and then), at 1 s, and at TRIALS - 2 moments
#    spread over the rest of the run;
#  - inside a write (tests/killwrite.c, when KILLWRITE is not "none"): in
#    place of TRIALS of its pwrite calls spread over the run, so that most
#    kills fall inside an HDF5 flush, which a kill by the clock hits only
#    now and then (about one CI run in five before the attribute).
# The moments and calls come from a fixed pseudo-random sequence
# (reproducible).  After each kill the file must open, every per-frame
# dataset hold `frames` rows or one more, partial row, and the counted
# steps read (tests/frames_consistent.py --killed).
#   tests/sigkill.sh COHFRAC SOURCE_DIR MESH_DIR KILLWRITE [TRIALS]
set -u
exe=$1
src=$2
meshes=$3
killwrite=$4
trials=${5:-20}
. "$(dirname "$0")/expect.sh"

# check WHAT: the file the kill left, counted.
check() {
    if [ ! -f "$tmp/k.h5" ]; then
        echo "FAIL  SIGKILL $1: no file"; fails=$((fails + 1)); return
    fi
    frames=$(/usr/bin/python3 "$src/tests/frames_consistent.py" --killed "$tmp/k.h5" 2>&1)
    case "$frames" in
    ''|*[!0-9]*) echo "FAIL  SIGKILL $1: $frames"; fails=$((fails + 1)) ;;
    *) echo "ok    SIGKILL $1: the file opens, $frames whole frames" ;;
    esac
}

# The drop, run to its end or to the chosen write.
drop() {
    "$exe" run "$src/scenes/source/bunny_drop.lua" -q -m "$meshes" -o "$tmp/k.h5" >/dev/null 2>&1
}

# Moments in tenths of a second: 5, 10, then 11..75 from a linear
# congruential sequence (the drop runs about 2.5-8 s here).
moments="5 10"
x=12345
i=2
while [ $i -lt "$trials" ]; do
    x=$(( (x * 1103515245 + 12345) % 2147483648 ))
    moments="$moments $(( 11 + x % 65 ))"
    i=$((i + 1))
done

for m in $moments; do
    rm -f "$tmp/k.h5" "$tmp/k.xdmf"
    "$exe" run "$src/scenes/source/bunny_drop.lua" -q -m "$meshes" -o "$tmp/k.h5" >/dev/null 2>&1 &
    pid=$!
    t="$(echo "$m" | sed 's/.$/.&/; s/^\./0./')"
    sleep "$t"
    kill -KILL $pid 2>/dev/null
    wait $pid 2>/dev/null
    check "at $t s"
done

if [ "$killwrite" != none ]; then
    # One whole run counts the calls; the kills fall between the first 2 %
    # (the file is made under a temporary name and renamed once flushed)
    # and the end.
    rm -f "$tmp/k.h5"
    COHFRAC_KILL_WRITE_COUNT="$tmp/calls" LD_PRELOAD="$killwrite" drop
    calls=$(cat "$tmp/calls" 2>/dev/null || echo 0)
    if [ "$calls" -lt 100 ]; then
        echo "FAIL  the drop made $calls pwrite calls: is $killwrite loaded?"; fails=$((fails + 1))
        calls=0
    fi
    i=0
    while [ "$calls" -gt 0 ] && [ $i -lt "$trials" ]; do
        x=$(( (x * 1103515245 + 12345) % 2147483648 ))
        at=$(( calls / 50 + x % (calls - calls / 50) ))
        rm -f "$tmp/k.h5" "$tmp/k.xdmf"
        COHFRAC_KILL_AT_WRITE=$at LD_PRELOAD="$killwrite" drop
        check "in place of pwrite call $at of $calls"
        i=$((i + 1))
    done
fi
echo "$fails failed"
[ "$fails" -eq 0 ]
