#!/usr/bin/env python3
"""The runs seed that makes an e-puck scenario's single run representative.

    scripts/representative_seed.py SCENARIO [--candidates N] [--reference-runs N]

The rule, stated in the README: among the first runs of the runs seeds 1..N
(the scenario's `seed`; its `[user] seed`, and so the decoder, stay as they
are), the one that reaches the goal nearest the median time and the median
detections of the scenario's user, each distance in units of its
interquartile range (ties: the lower seed). The medians are those of the
runs that reach the goal among `--reference-runs` runs at runs seed 1000, a
seed outside the candidates. It never looks at how a run looks, only at
these two numbers. Prints the table and the chosen seed; exits 1 if the
scenario's own `seed` is not the chosen one, so `scripts/readme_figures.sh
--check` fails when the rule and the file disagree.
"""

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile

ROW = re.compile(r"^\s*(\d+)\s+(.+?)\s+([0-9.]+)\s+(\d+)\s+(\d+)\s+(\d+)\s+(\d+)\s")


def runs(errp, text, seed, n):
    """(converged on, time, detected) of each run of `text` at runs seed `seed`."""
    text = re.sub(r"(?m)^seed = \d+", f"seed = {seed}", text, count=1)
    text = re.sub(r"(?m)^runs = \d+", f"runs = {n}", text, count=1)
    with tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False) as f:
        f.write(text)
        path = f.name
    try:
        out = subprocess.run(
            [errp, "run", path, "--quiet"], check=True, capture_output=True, text=True
        ).stdout
    finally:
        os.unlink(path)
    rows = []
    for line in out.splitlines():
        m = ROW.match(line)
        if m:
            rows.append((m.group(2).strip(), float(m.group(3)), int(m.group(4))))
    if len(rows) != n:
        sys.exit(f"error: expected {n} runs from errp run, read {len(rows)}")
    return rows


def iqr(values):
    q = statistics.quantiles(values, n=4)
    return max(q[2] - q[0], 1e-9)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenario")
    ap.add_argument("--candidates", type=int, default=40)
    ap.add_argument("--reference-runs", type=int, default=200)
    args = ap.parse_args()
    errp = os.environ.get("ERRP", "target/release/errp")
    with open(args.scenario) as f:
        text = f.read()
    goal = re.search(r'(?m)^goal = "([^"]+)"', text).group(1)
    own = int(re.search(r"(?m)^seed = (\d+)", text).group(1))
    reference = [r for r in runs(errp, text, 1000, args.reference_runs) if r[0] == goal]
    if len(reference) < 4:
        sys.exit(f"error: only {len(reference)} reference runs reach {goal}")
    times = [r[1] for r in reference]
    dets = [r[2] for r in reference]
    mt, md = statistics.median(times), statistics.median(dets)
    it, idet = iqr(times), iqr(dets)
    print(
        f"{args.scenario}: {len(reference)} of {args.reference_runs} reference runs "
        f"(runs seed 1000) reach {goal}; median time {mt:.1f} s (IQR {it:.1f}), "
        f"median detections {md:g} (IQR {idet:g})"
    )
    print(" seed  converged on     time (s)  detected  distance")
    best = None
    for seed in range(1, args.candidates + 1):
        (city, t, d), = runs(errp, text, seed, 1)
        dist = abs(t - mt) / it + abs(d - md) / idet if city == goal else float("inf")
        print(f" {seed:4d}  {city:<15} {t:9.1f} {d:9d}  {dist:8.3f}")
        if best is None or dist < best[0]:
            best = (dist, seed)
    print(f"representative runs seed: {best[1]} (the scenario's seed: {own})")
    if best[1] != own:
        sys.exit(1)


if __name__ == "__main__":
    main()
