"""Reads back what `errp run <grid scenario> --save X.rrd` wrote, with the
Rerun CLI (rerun-sdk 0.36.3), and checks it against the run's printed output.

usage: python check_grid.py RRD STDOUT_FILE
"""

import re
import subprocess
import sys
from collections import defaultdict


def main(rrd: str, stdout_file: str) -> None:
    subprocess.run(["rerun", "rrd", "verify", rrd], check=True)
    printed = subprocess.run(
        ["rerun", "rrd", "print", rrd], check=True, capture_output=True, text=True
    ).stdout
    rows = defaultdict(int)
    for m in re.finditer(r"with (\d+) rows .* - (/\S+) - data columns: \[([^\]]*)\]", printed):
        n, entity, columns = int(m.group(1)), m.group(2), m.group(3)
        rows[(entity, columns.split(":")[0])] += n
    out = open(stdout_file).read()
    episodes = len(re.findall(r"^\s+\d+\s+\(\d, \d\)", out, re.M))
    actions = int(re.search(r"over (\d+) actions", out).group(1))
    expect = {
        ("/grid/posterior", "Image"): actions,
        ("/decoder/p_error", "Scalars"): actions,
        ("/belief/true_goal", "Scalars"): actions,
        ("/visits/map", "Image"): episodes,
        ("/grid/goal", "Boxes2D"): episodes,
    }
    for key, n in expect.items():
        assert rows[key] == n, f"{key}: {rows[key]} rows, expected {n}"
    assert rows[("/eeg/FCz", "Scalars")] >= actions * 200, rows[("/eeg/FCz", "Scalars")]
    assert rows[("/log", "TextLog")] == actions + 2 * episodes, rows[("/log", "TextLog")]
    assert rows[("/grid/cells", "Boxes2D")] == 1
    assert "Blueprint" in printed, "no default layout"
    print(f"{rrd}: {episodes} episodes, {actions} actions, all entities present")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
