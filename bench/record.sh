#!/bin/sh
# Append the machine-readable line of a `cohfrac bench` run to
# bench/results/<machine>.csv, one file per kind of machine (the CPU model
# and its core count, e.g. amd-epyc-2cpu), one row per run, with the date
# and the commit; the file and its header are made on first use.
#   bench/record.sh BENCH_OUTPUT [RESULTS_DIR]
# Exit 1 when BENCH_OUTPUT holds no `bench:` line.
set -eu
out=$1
dir=${2:-$(dirname "$0")/results}
line=$(grep '^bench: tets=' "$out" | tail -1) || { echo "bench/record.sh: no 'bench:' line in $out" >&2; exit 1; }
cpu=$(lscpu 2>/dev/null | sed -n 's/^Model name:[[:space:]]*//p' | head -1)
machine=$(printf '%s-%scpu' "${cpu:-unknown}" "$(nproc)" | tr 'A-Z' 'a-z' | sed 's/[^a-z0-9]\{1,\}/-/g; s/^-//; s/-$//')
commit=$(git -C "$(dirname "$0")" rev-parse --short HEAD 2>/dev/null || echo unknown)
csv=$dir/$machine.csv
mkdir -p "$dir"
[ -s "$csv" ] || echo "date,commit,tets,step_ms,floor_ms,ratio,speedup_2t,peer_ratio" > "$csv"
# key=value pairs in the line's order; a value the run did not give stays empty.
val() { printf '%s\n' "$line" | tr ' ' '\n' | sed -n "s/^$1=//p"; }
echo "$(date -u +%Y-%m-%dT%H:%M:%SZ),$commit,$(val tets),$(val step_ms),$(val floor_ms),$(val ratio),$(val speedup_2t),$(val peer_ratio)" >> "$csv"
echo "bench: recorded in $csv"
