"""Reads a finished `errp sweep` directory back and recomputes its summary.

Usage: check_sweep.py DIR LEVELS EPISODES

Checks, independently of the Rust code: every file is there and whole; the
episodes are one row per (level, episode) in order, each ending in the
CRC-32 of the rest of its line (recomputed with zlib); every summary statistic
(success rate, Wilson interval, mean/sd/median cost of the successful
episodes, Pearson r and p against online accuracy, via NumPy and SciPy; for
the e-puck the detector's mean hit rate and false alarms per minute)
matches what summary.csv says; sweep.json records the parameters; the plots
are a PNG and an SVG document.
"""

import csv
import json
import math
import sys
import xml.etree.ElementTree as ET
import zlib
from pathlib import Path

import numpy as np
from scipy import stats


def close(a, b, tol=2e-6):
    if a is None or b is None:
        return a is None and b is None
    return abs(a - b) <= tol * max(1.0, abs(b))


def num(s):
    return None if s == "" else float(s)


def main():
    d = Path(sys.argv[1])
    levels, episodes = int(sys.argv[2]), int(sys.argv[3])
    manifest = json.loads((d / "sweep.json").read_text())
    spec = manifest["spec"]
    assert manifest["shard"] is None, manifest["shard"]
    assert spec["episodes"] == episodes, spec
    assert len(manifest["decoders"]) >= 1
    task = spec["task"]
    cost = "actions" if task == "grid" else "time_secs"

    rows = list(csv.DictReader(open(d / "episodes.csv", newline="")))
    assert len(rows) == levels * episodes, len(rows)
    for i, r in enumerate(rows):
        assert int(r["level"]) == i // episodes and int(r["episode"]) == i % episodes, (i, r)
        assert r["success"] in ("0", "1")
    lines = (d / "episodes.csv").read_bytes().split(b"\n")
    assert lines[0].endswith(b",crc32") and lines[-1] == b"", lines[0]
    for i, line in enumerate(lines[1:-1]):
        body, crc = line.rsplit(b",", 1)
        assert crc.decode() == f"{zlib.crc32(body):08x}", (i + 2, line)

    summary = list(csv.DictReader(open(d / "summary.csv", newline="")))
    assert len(summary) == levels, len(summary)
    for s in summary:
        lv = [r for r in rows if r["level"] == s["level"]]
        n = len(lv)
        ok = [r for r in lv if r["success"] == "1"]
        rate = len(ok) / n
        assert int(s["episodes"]) == n
        assert close(float(s["success_rate"]), rate), (s, rate)
        z = 1.959963984540054
        centre = (rate + z * z / (2 * n)) / (1 + z * z / n)
        half = z * math.sqrt(rate * (1 - rate) / n + z * z / (4 * n * n)) / (1 + z * z / n)
        assert close(float(s["success_lo95"]), max(0.0, centre - half)), s
        assert close(float(s["success_hi95"]), min(1.0, centre + half)), s
        c = np.array([float(r[cost]) for r in ok])
        if len(c):
            assert close(float(s[f"{cost}_mean"]), c.mean()), (s, c.mean())
            assert close(float(s[f"{cost}_median"]), float(np.median(c))), s
        if len(c) > 1:
            assert close(float(s[f"{cost}_sd"]), c.std(ddof=1)), s
        pairs = [(float(r["online_accuracy"]), float(r[cost])) for r in ok if r["online_accuracy"] != ""]
        if len(pairs) >= 3 and len({p[0] for p in pairs}) > 1 and len({p[1] for p in pairs}) > 1:
            res = stats.pearsonr([p[0] for p in pairs], [p[1] for p in pairs])
            assert close(num(s[f"r_online_{cost}"]), res.statistic, 1e-5), (s, res)
            assert abs(num(s[f"p_online_{cost}"]) - res.pvalue) <= 1e-5 + 1e-3 * res.pvalue, (s, res)

        if task == "epuck":
            # The detector's online operating point: per-episode means.
            for col in ("hit_rate", "false_alarms_per_min"):
                v = [float(r[col]) for r in lv if r[col] != ""]
                if v:
                    assert close(float(s[col]), float(np.mean(v))), (col, s, np.mean(v))
            for r in lv:
                by_phase = sum(int(r[c]) for c in ("detected_turning", "detected_driving", "detected_on_goal"))
                assert by_phase == int(r["detected"]), r
    if task == "epuck":
        for dec in manifest["decoders"]:
            assert 0.0 <= dec["online_hit_rate"] <= 1.0, dec
            assert dec["online_false_alarms_per_min"] >= 0.0, dec

    png = (d / "sweep.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000, len(png)
    root = ET.parse(d / "sweep.svg").getroot()
    assert root.tag.endswith("svg"), root.tag
    texts = [t.text or "" for t in root.iter() if t.tag.endswith("text")]
    assert any("accuracy" in t for t in texts), texts[:10]
    print(f"sweep ok: {task}, {levels} levels x {episodes} episodes, summary recomputed")


if __name__ == "__main__":
    main()
