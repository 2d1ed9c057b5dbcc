"""Reads back what `errp run <e-puck scenario> --save X.rrd` wrote, with an
independent client (rerun-sdk[datafusion] 0.36.3), and checks the values of
the trajectory, the belief and the detections against the run's printed
output.

usage: python check_epuck.py RRD STDOUT_FILE START_X_CM START_Y_CM
"""

import math
import re
import subprocess
import sys

import rerun as rr


def column(store, entity: str, component: str):
    table = store.reader(index="sim_time", contents=f"{entity}/**").to_arrow_table()
    name = f"{entity}:{component}"
    assert name in table.column_names, f"{name} missing: {table.column_names}"
    return [v for v in table.column(name).to_pylist() if v is not None]


def main(rrd: str, stdout_file: str, start_x: float, start_y: float) -> None:
    subprocess.run(["rerun", "rrd", "verify", rrd], check=True)
    printed = subprocess.run(
        ["rerun", "rrd", "print", rrd], check=True, capture_output=True, text=True
    ).stdout
    assert "Blueprint" in printed, "no default layout"

    out = open(stdout_file).read()
    row = re.search(
        r"^\s+1\s+(.+?)\s+(\d+\.\d)\s+(\d+)\s+(\d+)\s+(\d+)\s+(\d+)\s", out, re.M
    )
    assert row, out
    converged, secs, detected = row.group(1).strip(), float(row.group(2)), int(row.group(3))

    store = rr.experimental.RrdReader(rrd).stream().collect()

    # Belief: one bar chart of 25 probabilities per 62.5 ms window.
    bars = [v[0]["buffer"] for v in column(store, "/belief/bars", "BarChart:values")]
    windows = round(secs / 0.0625)
    assert abs(len(bars) - windows) <= 1, (len(bars), windows)
    for b in bars:
        assert len(b) == 25 and abs(sum(b) - 1.0) < 1e-6 and min(b) >= 0.0, b
    final = bars[-1]

    # Trajectory: starts at the start, stays in the arena.
    strips = column(store, "/arena/trajectory", "LineStrips2D:strips")
    path = strips[-1][0]
    assert math.dist(path[0], (start_x, start_y)) < 1.0, path[0]
    for x, y in path:
        assert -0.5 <= x <= 200.5 and -0.5 <= y <= 200.5, (x, y)
    walked = sum(math.dist(a, b) for a, b in zip(path, path[1:]))

    # Detections: as many red marks as detected errors printed.
    marks = column(store, "/arena/detections", "Points2D:positions")
    assert len(marks[-1]) == detected, (len(marks[-1]), detected)

    # The goals carry the city names; the converged city's belief is >= p_c.
    labels = column(store, "/arena/goals", "Points2D:labels")[-1]
    positions = column(store, "/arena/goals", "Points2D:positions")[-1]
    names = [l.replace(" (target)", "") for l in labels]
    if "WRONG" not in converged and converged != "time-out":
        i = names.index(converged)
        assert final[i] >= 0.4, (converged, final[i])
        assert math.dist(path[-1], positions[i]) < 5.0, (path[-1], positions[i])
    print(
        f"{rrd}: {len(bars)} belief updates, trajectory of {len(path)} points "
        f"({walked:.0f} cm), {detected} detections, ends on {converged}"
    )


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4]))
