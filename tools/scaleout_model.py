#!/usr/bin/python3
"""Predicted speed-up of a study over N MPI ranks from its case times
(docs/scale-out.md).

usage: tools/scaleout_model.py STUDY_CSV [RANKS ...] [--overhead S] [--start S]
  STUDY_CSV   a study.csv (`cohfrac study`): its wall column is the case
              times measured on one rank
  RANKS       rank counts (default 1 2 4 8 16 32)
  --overhead  seconds rank 0 and the case's start add per case (default
              0.05: spawning `cohfrac run`, loading its scene and mesh)
  --start     seconds to start the MPI job (default 0.5, mpirun on one
              machine; larger on a cluster)

The model is the scheduler cohfrac uses: cases sorted largest first,
each handed to the rank that frees up first (greedy list scheduling,
LPT; rank 0 runs cases too).  The makespan is simulated exactly for the
given times; Graham's bound says LPT is within 4/3 - 1/(3N) of the best
possible schedule.  Speed-up S(N) = T(1) / T(N), both with the same
overheads.  Prints a Markdown table.  Exit 1 on bad usage or input.
"""
import csv
import heapq
import sys


def makespan(times, ranks, overhead, start):
    free = [0.0] * ranks
    heapq.heapify(free)
    for t in sorted(times, reverse=True):
        heapq.heappush(free, heapq.heappop(free) + t + overhead)
    return start + max(free)


def main(argv):
    args, ranks, overhead, start = argv[1:], [], 0.05, 0.5
    if not args or args[0] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if args else 1
    path = args.pop(0)
    try:
        while args:
            a = args.pop(0)
            if a == "--overhead":
                overhead = float(args.pop(0))
            elif a == "--start":
                start = float(args.pop(0))
            else:
                ranks.append(int(a))
        with open(path, newline="") as f:
            times = [float(row["wall"]) for row in csv.DictReader(f)]
    except (OSError, ValueError, KeyError, IndexError) as e:
        print(f"scaleout_model: {path}: {e}", file=sys.stderr)
        return 1
    ranks = ranks or [1, 2, 4, 8, 16, 32]
    total, longest = sum(times), max(times)
    print(f"{len(times)} cases, {total:.1f} s in all, longest {longest:.1f} s "
          f"(case times from {path}); {overhead:g} s per case, {start:g} s to start\n")
    print("| ranks | makespan (s) | speed-up | efficiency | bound: total / N or longest |")
    print("|---|---|---|---|---|")
    one = makespan(times, 1, overhead, start)
    for n in ranks:
        t = makespan(times, n, overhead, start)
        limit = total / max(total / n, longest)  # no overheads
        print(f"| {n} | {t:.1f} | {one / t:.2f} | {one / t / n:.2f} | {limit:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
