"""Reads back what `errp run <e-puck scenario> --save X.rrd` wrote, with an
independent client (rerun-sdk[datafusion] 0.36.3, or the newest, 0.41), and checks the values of
the trajectory, the belief and the detections against the run's printed
output.

usage: python check_epuck.py RRD STDOUT_FILE START_X_CM START_Y_CM
"""

import math
import re
import subprocess
import sys

import rerun as rr


def open_store(rrd: str):
    """The recording's chunks, with the reader of this rerun-sdk: 0.36's
    `rerun.experimental.RrdReader`, or `rerun.chunk.RrdReader` from 0.41."""
    chunk = getattr(rr, "chunk", None)
    if chunk is not None and hasattr(chunk, "RrdReader"):
        return chunk.RrdReader(rrd).stream().collect()
    return rr.experimental.RrdReader(rrd).stream().collect()


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

    store = open_store(rrd)

    # Belief: one series per city, a value per 62.5 ms window; the 25 values
    # of a window sum to 1.
    table = store.reader(index="sim_time", contents="/belief/city/**").to_arrow_table()
    series = sorted(c for c in table.column_names if c.endswith(":Scalars:scalars"))
    assert len(series) == 25, series
    rows = [
        [v[0] if isinstance(v, list) else v for v in table.column(c).to_pylist()]
        for c in series
    ]
    windows = round(secs / 0.0625)
    n = sum(1 for v in rows[0] if v is not None)
    assert abs(n - windows) <= 1, (n, windows)
    bars = [list(b) for b in zip(*rows) if all(v is not None for v in b)]
    for b in bars:
        assert abs(sum(b) - 1.0) < 1e-6 and min(b) >= 0.0, b
    # Entity paths escape spaces ("/belief/city/New\\ York").
    city_of = [c.split("/")[3].split(":")[0].replace("\\ ", " ") for c in series]
    final = dict(zip(city_of, bars[-1]))

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

    # The cities carry their names (static labels); the converged city's
    # belief is >= p_c and the robot ends on it.
    cities = store.reader(index=None, contents="/arena/cities").to_arrow_table()
    names = [l for l in cities.column("/arena/cities:Points2D:labels").to_pylist()[0]]
    positions = column(store, "/arena/goals", "Points2D:positions")[-1]
    assert sorted(names) == sorted(city_of), (names, city_of)
    if "WRONG" not in converged and converged != "time-out":
        i = names.index(converged)
        assert final[converged] >= 0.4, (converged, final[converged])
        assert math.dist(path[-1], positions[i]) < 5.0, (path[-1], positions[i])

    # The static overview holds the whole trajectory and every detection.
    overview = store.reader(index=None, contents="/arena/overview/**").to_arrow_table()
    strips = overview.column("/arena/overview/trajectories:LineStrips2D:strips").to_pylist()[0]
    assert strips[-1] == path, (len(strips[-1]), len(path))
    dots = overview.column("/arena/overview/detections:Points2D:positions").to_pylist()[0]
    assert len(dots) == detected, (len(dots), detected)
    print(
        f"{rrd}: {len(bars)} belief updates of 25 cities, trajectory of {len(path)} points "
        f"({walked:.0f} cm), {detected} detections, ends on {converged}"
    )


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4]))
