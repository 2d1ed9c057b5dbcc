#!/usr/bin/env python3
"""Per accuracy of an `errp fit epuck` directory: runs, runs that reached the
goal, the median time of those runs, and the median time to the goal over
every run (a run on a wrong city counted as never reaching it).

    python3 scripts/fit_tables.py fit-epuck
"""
import csv
import glob
import statistics
import sys


def main(out):
    for scenario in ("mexico_to_pisa", "lisbon_to_tokyo"):
        rows = []
        for path in sorted(glob.glob(f"{out}/{scenario}/seed-*/episodes.csv")):
            with open(path, newline="") as f:
                rows += list(csv.DictReader(f))
        if not rows:
            sys.exit(f"error: {out}/{scenario}/seed-*/episodes.csv: no runs")
        print(scenario)
        print("accuracy  runs  reached  median time of those (s)  median time to goal (s)")
        for a in sorted({float(r["accuracy"]) for r in rows}):
            level = [r for r in rows if float(r["accuracy"]) == a]
            ok = [float(r["time_secs"]) for r in level if r["success"] == "1"]
            every = sorted(float(r["time_secs"]) if r["success"] == "1" else float("inf")
                           for r in level)
            to_goal = every[len(every) // 2]
            print(f"{a:8.3f}  {len(level):4d}  {len(ok):7d}  "
                  f"{statistics.median(ok) if ok else float('nan'):24.1f}  "
                  f"{'never' if to_goal == float('inf') else f'{to_goal:.1f}':>23}")


if __name__ == "__main__":
    if {"-h", "--help"} & set(sys.argv[1:]):
        print(__doc__.strip())
        sys.exit(0)
    if len(sys.argv) != 2:
        sys.exit("usage: fit_tables.py FIT_DIR")
    main(sys.argv[1])
