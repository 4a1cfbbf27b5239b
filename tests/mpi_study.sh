#!/bin/sh
# Studies and stability maps over MPI ranks (docs/scale-out.md), on one
# machine over loopback:
#   1. `mpirun -np 2 cohfrac study` runs every case exactly once and its
#      study.md table equals the single-process one (wall time, speed-up,
#      memory and Pareto columns aside: they are measured, not computed);
#   2. one rank killed mid-study: mpirun stops, and the re-run completes
#      only the cases that had not finished, with the same table;
#   3. `mpirun -np 2 cohfrac stability --quick` gives the single-process
#      map (stability.csv without its wall-time column).
#   tests/mpi_study.sh COHFRAC MPIRUN SOURCE_DIR
set -u
exe=$1
mpirun=$2
src=$3
. "$(dirname "$0")/expect.sh"
# Debian's Open MPI refuses to start as root unless told; -oversubscribe:
# two ranks on however many cores this machine has.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl=self,vader,tcp OMPI_MCA_btl_tcp_if_include=lo
mpi="$mpirun -np 2 --oversubscribe"

# A box falling in fracture mode: 1-3 s a case at these steps.
scene="$tmp/fall.lua"
sed -e 's/duration = 0.1/duration = 0.2/' "$src/tests/data/study_free_fall.lua" >"$scene"
vary="solver.dt_fracture=1e-6,1.5e-6,2e-6,2.5e-6"

# The table without the measured columns (wall, speed-up, peak RSS, Pareto)
# and without the cache marker.
table() {
    sed -n '/^| case/,/^$/p' "$1/study.md" | cut -d'|' -f1-4,8-16 | sed 's/ (cached)//'
}
# How many progress lines "[k/N] label: ..." name how many different cases.
runs_of() {
    grep '^\[[0-9]*/[0-9]*\]' "$1" | sed 's/^[^]]*\] \([^:]*\):.*/\1/' >"$tmp/labels"
    echo "$(wc -l <"$tmp/labels") $(sort -u "$tmp/labels" | wc -l)"
}

expect 0 "single-process study" "$exe" study "$scene" --vary "$vary" -o "$tmp/one" -t 1
cp "$tmp/log" "$tmp/one.log"
expect 0 "the same study over 2 MPI ranks" $mpi "$exe" study "$scene" --vary "$vary" \
    -o "$tmp/two" -t 1
cp "$tmp/log" "$tmp/two.log"
expect 0 "both ranks ran cases" sh -c "grep -q '(rank 0)' '$tmp/two.log' &&
    grep -q '(rank 1)' '$tmp/two.log'"
expect 0 "every case ran exactly once (5 runs of 5 cases)" test "$(runs_of "$tmp/two.log")" = "5 5"
table "$tmp/one" >"$tmp/one.table"
table "$tmp/two" >"$tmp/two.table"
expect 0 "the table has its 5 cases" test "$(grep -c '^| ' "$tmp/one.table")" -eq 6
expect 0 "study.md table over 2 ranks equals the single-process one" \
    diff "$tmp/one.table" "$tmp/two.table"

# Kill rank 1 once the first case has finished; mpirun then stops the job.
rm -rf "$tmp/kill"
$mpi "$exe" study "$scene" --vary "$vary" -o "$tmp/kill" -t 1 >"$tmp/kill1.log" 2>&1 &
launcher=$!
i=0
while [ "$(ls "$tmp/kill/runs/"*.meta 2>/dev/null | wc -l)" -lt 1 ] && [ $i -lt 600 ]; do
    sleep 0.1; i=$((i + 1))
done
killed=0
for p in $(pgrep -P $launcher); do
    if tr '\0' '\n' <"/proc/$p/environ" 2>/dev/null | grep -qx 'OMPI_COMM_WORLD_RANK=1'; then
        kill -9 "$p" && killed=1
    fi
done
wait $launcher
rc=$?
expect 0 "rank 1 killed mid-study, mpirun stopped (exit $rc)" sh -c "[ $killed -eq 1 ] && [ $rc -ne 0 ]"
done1=$(ls "$tmp/kill/runs/"*.meta 2>/dev/null | wc -l)
expect 0 "the re-run after the lost rank" $mpi "$exe" study "$scene" --vary "$vary" \
    -o "$tmp/kill" -t 1
cp "$tmp/log" "$tmp/kill2.log"
left=$((5 - done1))
expect 0 "the re-run reuses the $done1 finished cases and runs only the other $left" \
    sh -c "grep -q '5 cases ($done1 cached)' '$tmp/kill2.log'"
expect 0 "... each of those $left once" test "$(runs_of "$tmp/kill2.log")" = "$left $left"
table "$tmp/kill" >"$tmp/kill.table"
expect 0 "the resumed study's table equals the single-process one" \
    diff "$tmp/one.table" "$tmp/kill.table"

# The stability map: the same cases, results and order in the files.
expect 0 "single-process stability --quick" "$exe" stability --quick -o "$tmp/s1" -q
expect 0 "stability --quick over 2 MPI ranks" $mpi "$exe" stability --quick -o "$tmp/s2" -q
cut -d, -f1-12 "$tmp/s1/stability.csv" >"$tmp/s1.csv"
cut -d, -f1-12 "$tmp/s2/stability.csv" >"$tmp/s2.csv"
expect 0 "stability.csv over 2 ranks equals the single-process one (wall time aside)" \
    diff "$tmp/s1.csv" "$tmp/s2.csv"

echo "$fails failed"
[ "$fails" -eq 0 ]
