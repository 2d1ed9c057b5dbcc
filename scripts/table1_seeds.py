#!/usr/bin/env python3
"""Table 1 over several seeds, scored against the paper.

    python3 scripts/table1_seeds.py [--errp PATH (default $ERRP or target/release/errp)] [--seeds 10]

Runs `errp table1 --seed S` for S = 1..N (EEG per action, the defaults) and
prints, per subject and goal set, our mean actions over the N x 5 runs
against the paper's, in standard errors: z = (ours - paper) / sqrt(paper
sd^2 / 5 + our sd^2 / (5 N)); the accuracy row (the mean over runs, as the paper's)
against the paper's, and the pooled accuracy (every action once: what the
decoder is calibrated to); how many
seeds reached all 20 goals of a goal set; and how many gave a negative r.
The fixed goals are what `errp fit grid` fits; the free goals and r are
held out. Exit code 0 whatever the verdict: this measures, it does not test.
"""

import argparse
import math
import os
import re
import subprocess
import sys

PAPER = {  # (subject, goals): (actions mean, sd, accuracy %)
    ("S1", "fixed"): (16, 2, 83.14),
    ("S1", "free"): (23, 9, 78.75),
    ("S2", "fixed"): (43, 9, 69.49),
    ("S2", "free"): (21, 7, 82.48),
    ("S3", "fixed"): (23, 12, 72.49),
    ("S3", "free"): (16, 6, 88.18),
    ("S4", "fixed"): (17, 5, 76.35),
    ("S4", "free"): (23, 11, 78.66),
}

ROW = re.compile(
    r"^(S\d) (fixed|free)\s+(\d+)/5\s+(\d+)\+-(\d+) .*?([\d.]+)\+-[\d.]+ \[[\d.]+\+-[\d.]+\]\s+([\d.]+)\s*$"
)
R = re.compile(r"accuracy vs total time \((fixed|free) goals\): r = ([-\d.]+|NaN)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--errp", default=os.environ.get("ERRP", "target/release/errp"))
    ap.add_argument("--seeds", type=int, default=10)
    args = ap.parse_args()
    # (subject, goals) -> list of (reached, mean actions, sd actions, accuracy)
    cells = {k: [] for k in PAPER}
    rs = {"fixed": [], "free": []}
    setting = None
    for seed in range(1, args.seeds + 1):
        out = subprocess.run(
            [args.errp, "table1", "--seed", str(seed), "--quiet"],
            check=True, capture_output=True, text=True,
        ).stdout
        for line in out.splitlines():
            if line.startswith("Fixed pairs"):
                setting = line
            m = ROW.match(line)
            if m:
                s, g, reached, mean, sd, acc, pooled = m.groups()
                cells[(s, g)].append(
                    (int(reached), float(mean), float(sd), float(acc), float(pooled))
                )
            m = R.search(line)
            if m:
                rs[m.group(1)].append(float(m.group(2)))
        print(f"seed {seed} done", file=sys.stderr)
    n = args.seeds
    print(f"errp table1, seeds 1-{n} ({5 * n} runs per subject and goal set); {setting}:")
    print(
        "| subject | actions ours [paper] | z | within | accuracy ours [paper] | within 2 points "
        "| pooled accuracy |"
    )
    print("|---|---|---|---|---|---|---|")
    for goals, limit in (("fixed", 2.0), ("free", 2.5)):
        for s in ("S1", "S2", "S3", "S4"):
            runs = cells[(s, goals)]
            pm, psd, pacc = PAPER[(s, goals)]
            # Pool the per-seed means and sds (5 runs each) into the mean and
            # sd over all runs.
            mean = sum(r[1] for r in runs) / len(runs)
            ss = sum(4 * r[2] ** 2 + 5 * (r[1] - mean) ** 2 for r in runs)
            sd = math.sqrt(ss / (5 * len(runs) - 1))
            z = (mean - pm) / math.sqrt(psd**2 / 5 + sd**2 / (5 * len(runs)))
            acc = sum(r[3] for r in runs) / len(runs)
            pooled = sum(r[4] for r in runs) / len(runs)
            print(
                f"| {s} {goals} | {mean:.1f} +- {sd:.1f} [{pm} +- {psd}] | {z:+.1f} | "
                f"{'yes' if abs(z) <= limit else 'NO'} ({limit} SE) | {acc:.1f} [{pacc}] | "
                f"{'yes' if abs(acc - pacc) <= 2 else 'NO'} | {pooled:.1f} |"
            )
    for goals in ("fixed", "free"):
        all20 = sum(
            all(cells[(s, goals)][k][0] == 5 for s in ("S1", "S2", "S3", "S4")) for k in range(n)
        )
        neg = sum(r < 0 for r in rs[goals])
        print(
            f"{goals} goals: all 20 reached in {all20}/{n} seeds; r negative in {neg}/{n} "
            f"(r: {', '.join(f'{r:.2f}' for r in rs[goals])})"
        )


if __name__ == "__main__":
    main()
