#!/usr/bin/env python3
"""Estimates a sweep's wall time on N ranks from its measured run costs (the "seconds" of
`apps/sweep ... --json`, or of any JSON list of {"seconds": s}): the runs are handed out in order,
each to the rank that frees first, as apps/sweep's dynamic scheduling does (queues and messages
not modelled). Prints, per N, the estimated wall time, the ideal sum/N, the longest run (no schedule
beats it) and the efficiency.

    scripts/sweep-scaling.py RESULTS.json [--repeat K] [--ranks 1,2,8,...]

--repeat K schedules K copies of the runs (a K times larger sweep with the same cost spread).
A second column gives the wall time had the runs been handed out longest first (which needs
their costs in advance): the gap between the two is what the run order costs."""
import heapq
import json
import sys


def makespan(costs, n):
    ranks = [0.0] * n
    heapq.heapify(ranks)
    for c in costs:
        heapq.heappush(ranks, heapq.heappop(ranks) + c)
    return max(ranks)


def main():
    args = sys.argv[1:]
    if not args or args[0].startswith("-"):
        sys.exit(__doc__)
    runs = json.load(open(args[0]))
    repeat, ranks = 1, [1, 2, 4, 8, 16, 32, 64, 128, 256]
    if "--repeat" in args:
        repeat = int(args[args.index("--repeat") + 1])
    if "--ranks" in args:
        ranks = [int(r) for r in args[args.index("--ranks") + 1].split(",")]
    costs = [float(r["seconds"]) for r in runs] * repeat
    total, longest = sum(costs), max(costs)
    print("%d runs, %.2f s in all, the longest %.3f s (%.0fx the median)"
          % (len(costs), total, longest, longest / max(sorted(costs)[len(costs) // 2], 1e-3)))
    print("%6s %10s %14s %10s %10s" % ("ranks", "wall (s)", "longest first", "sum/N (s)", "efficiency"))
    lpt = sorted(costs, reverse=True)
    for n in ranks:
        w = makespan(costs, n)
        print("%6d %10.3f %14.3f %10.3f %9.0f%%" % (n, w, makespan(lpt, n), total / n, 100.0 * total / (n * w)))


main()
