#!/usr/bin/env python3
"""The runs `errp inspect` recomputes from a recording against what `errp
run` printed when it made the recording: the per-run table, the summary and
the calibration, byte for byte.

    scripts/inspect_equals_run.py [SCENARIO] [RUNS] [SEED]

Runs `$ERRP` (default target/release/errp) on SCENARIO (default the
Mexico-to-Pisa run) with RUNS runs (100) at SEED (5), saving the recording,
inspects it, prints the comparison and the inspected per-run table, and
exits 1 on any difference. scripts/readme_figures.sh reruns it (figure
inspect_equals_run), so CI checks it on 100 runs with the release build.
"""

import os
import subprocess
import sys
import tempfile


def block(text: str, start: str, until: str) -> list:
    """The lines from the one starting with `start` up to (not including)
    the first empty line or the next line starting with `until`."""
    out, on = [], False
    for line in text.splitlines():
        if line.startswith(start):
            on = True
        if on:
            if not line or (out and line.startswith(until)):
                break
            out.append(line)
    return out


def main() -> int:
    errp = os.environ.get("ERRP", "target/release/errp")
    scenario = sys.argv[1] if len(sys.argv) > 1 else "scenarios/mexico_to_pisa.toml"
    runs = sys.argv[2] if len(sys.argv) > 2 else "100"
    seed = sys.argv[3] if len(sys.argv) > 3 else "5"
    with tempfile.TemporaryDirectory() as tmp:
        rrd = os.path.join(tmp, "r.rrd")
        run = subprocess.run(
            [errp, "run", scenario, "--runs", runs, "--seed", seed, "--quiet", "--save", rrd],
            capture_output=True, text=True, check=True,
        ).stdout
        inspected = subprocess.run(
            [errp, "inspect", rrd], capture_output=True, text=True, check=True
        ).stdout
    failed = 0
    for what, start, until in [
        ("calibration", "SVM decoder", " run"),
        ("per-run table", " run  converged", "Summary"),
        ("summary", "Summary over", "Wrote"),
    ]:
        a, b = block(run, start, until), block(inspected, start, until)
        same = a == b and len(a) > 0
        failed += not same
        print(f"{what}: {len(a)} lines printed by errp run, {len(b)} recomputed by "
              f"errp inspect: {'identical' if same else 'DIFFERENT'}")
        if not same:
            for x, y in zip(a, b):
                if x != y:
                    print(f"  run:     {x}\n  inspect: {y}")
                    break
    print()
    print("\n".join(block(inspected, " run  converged", "Summary")))
    return 1 if failed else 0


if __name__ == "__main__":
    if {"-h", "--help"} & set(sys.argv[1:]):
        print(__doc__.strip())
        sys.exit(0)
    sys.exit(main())
