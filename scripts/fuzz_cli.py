#!/usr/bin/env python3
"""Hostile-but-fair use of the `errp` program, case after case.

Usage: fuzz_cli.py ERRP [--seconds N] [--seed S] [--memory-gib G] [--only FAMILY] [--list]
                   [--python PYTHON]

Cases are made by a structured generator: every shipped scenario with one
field (any it has or could have) set to an edge value of every TOML type,
run with `errp run FILE --save OUT/x.rrd`; the same scenarios swept
(`errp sweep --scenario FILE ... --out OUT`); and bad values of every flag of
every command. Each case runs with its address space limited to
--memory-gib (default 4) and a two-minute time-out, and must:

* exit with code 0 or 2: never a panic (101), an abort (134, out of memory)
  or a signal, never a hang;
* on exit 2, print `error: ...` and leave its output directory empty;
* on exit 0, leave only what it announced (no `.partial-` file, no lock).

Grid scenarios run with the oracle decoder and e-puck scenarios with
`--runs 1`, so that a valid case takes seconds. Cases run in a shuffled
order (seeded) until --seconds have passed (default: all of them); the
counts are printed at the end and any failure makes the exit code 1.

A family of damaged recordings (`recording_cases`, about 310, in
fuzz_recordings.py): a grid run's, an e-puck run's and a calibration's
recording cut short at seeded offsets, with bits flipped, doubled, followed
by garbage, reduced to its header or zeroed, each read by `errp inspect
--csv`, which must exit 0 or 2 (naming the file) and leave nothing on 2.

A family of Python calls (`python_cases`, 215, in fuzz_python.py): the
package's public calls, each given a bad value for one argument in a
process of its own (`--python`, the interpreter with the package), which
must succeed or raise TypeError, ValueError or OSError naming the argument.

A family of the simulated user's `[realism]` values (`realism_cases`,
about 2 600, in fuzz_realism.py): every field given an edge value in a
scenario file (`errp run`, `errp realism`, `errp table1 --realism`) and
as a sweep level, which must exit 0 or 2 naming the field or the file.

A family of own-EEG files (`edf_cases`, about 260, in fuzz_edf.py): a
session exported as EDF+ and converted to BDF+, its header fields lying,
cut short, with bits flipped, its records keeping time oddly (a
sub-second start, gaps, a missing time-keeping TAL), its events
annotated twice or as both classes, two channels labelled alike; and the
session written by MNE's export, edfio and pyEDFlib (with the `--python`
interpreter, when it has them). Each is the recording of `errp run
own_eeg.toml`, which must exit 0 or 2 naming the file.

A family of hostile LSL decoder clients (`lsl_cases`, 80, in
fuzz_lsl.py): `errp stream` on a grid and an e-puck scenario beside a
client (the `--python` interpreter, with pylsl) whose decoder stream has
the wrong shape, sends p(error)s that are not probabilities, ids that
name nothing, floods or falls silent, names another session or none,
doubles; and a second session with the same seed on the host. The bridge
must exit 0 or 2 as the contract says (2 naming the stream), never panic
or hang, and leave nothing on 2.

A second family (`hostile_cases`, about 200) changes the program's
surroundings instead of its input: standard output or error closed early
(`| head -1`) or on a full disk (`/dev/full`); FIFOs, sockets, devices
and directories where a regular file belongs (scenarios, outputs, a
sweep's files, cache entries); sweep metadata, rows, locks and cache
entries edited or damaged; outputs that cannot be written; signals at
seeded random moments followed by a resume. Each must also end without a
panic or a hang, leave no temporary or lock, and leave what it did not
write as it was; some check more (a closed pipe exits 0 with the files
written; an edited cache entry is searched again and restored).
"""

import argparse
import math
import os
import random
import resource
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

from fuzz_common import toml_value
from fuzz_edf import edf_cases, make_edf_base, run_edf, writer_cases
from fuzz_hostile import build_base, hostile_cases, run_case, signal_cases
from fuzz_lsl import lsl_cases, run_lsl
from fuzz_python import python_cases, run_python_case
from fuzz_realism import realism_cases, run_realism
from fuzz_recordings import make_bases, recording_cases, run_damage

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = sorted((ROOT / "scenarios").glob("*.toml"))

# Fields of either task (a number indexes an array of tables).
FIELDS = [
    "task", "seed", "name", "decoder", "p_error", "eeg", "bank_per_class", "repeats",
    "runs", "max_secs", "start", "goal", "start_heading_deg", "user.accuracy",
    "user.subject", "user.goals", "user.hit_rate", "user.false_alarms_per_min",
    "user.fov_deg", "user.reaction_latency_ms", "user.reelicit_secs", "user.seed", "free_goals.count",
    "timing.interval_min_secs", "timing.interval_max_secs", "timing.epoch_secs",
    "timing.max_actions", "control.tau", "control.epsilon", "control.p_c", "control.t_e",
    "control.k_n", "control.sigma_deg", "control.stop_secs", "control.goal_hold_secs",
    "control.veto_window_secs", "control.strategy", "control.goal_reward",
    "control.wrong_goal_reward", "control.discount", "tracker.rate_hz",
    "tracker.position_noise_cm", "tracker.heading_noise_deg", "detector.mode",
    "detector.smooth_windows", "detector.refractory_secs", "avoidance.enabled",
    "episode.0.start", "episode.0.goal", "arena.obstacle.0.center_cm",
    "arena.obstacle.0.size_cm", "arena.obstacle.0.radius_cm", "arena.obstacle.0.shape",
    "arena.obstacle.0.angle_deg", "colour",
]

EDGE_VALUES = [
    0, 1, -1, 2, 17, 1000, 20_001, 100_001, 10**9, 2**63 - 1, -(2**63),
    0.0, 0.5, 1.0, 1.5, -1.0, 60.5, 3600.5, 1e9, 1e12, 1e300, 1e-300,
    math.nan, math.inf, -math.inf,
    "", "x", "greedy", "thompson", "oracle", "bank", "literal", "Mexico", "box",
    "a" * 100_000, True,
    [], [1], [1, 2], [0, 0, 7], [300, 300], [60.0, math.nan], {},
]

# Flags of every command, with values a careless script might give.
FLAG_CASES = [
    ["calibrate", "--accuracy", v] for v in ["1.7", "0.5", "-3", "nan", "inf", "abc", "1", ""]
] + [
    ["calibrate", "--seed", v] for v in ["-1", "1.5", "1e3", "18446744073709551616", "x"]
] + [
    ["calibrate", "--subject", "S9"], ["calibrate", "--goals", "free"],
    ["calibrate", "--save", "OUT/x.txt"], ["calibrate", "--save", "OUT/missing/x.rrd"],
    ["calibrate", "--export", "OUT/x.rrd"], ["calibrate", "--export", "OUT"],
    ["run", "SCEN_GRID", "--runs", "2"], ["run", "SCEN_EPUCK", "--decoder", "oracle"],
    ["run", "SCEN_EPUCK", "--eeg", "bank"], ["run", "SCEN_EPUCK", "--runs", "0"],
    ["run", "SCEN_EPUCK", "--runs", "100001"], ["run", "SCEN_EPUCK", "--runs", "101", "--save", "OUT/x.rrd"],
    ["run", "SCEN_GRID", "--accuracy", "1"], ["run", "SCEN_EPUCK", "--accuracy", "1"],
    ["run", "SCEN_GRID", "--seed", "-1"], ["run", "OUT/nothing.toml"], ["run", "OUT"],
    ["run", "/dev/zero"], ["run", "SCEN_GRID", "--save", "/proc/x.rrd"],
    ["table1", "--episodes", "0"], ["table1", "--episodes", "1001"], ["table1", "--seed", "-5"],
] + [
    ["stream", "SCEN_GRID"] + extra for extra in [
        ["--speed", "0"], ["--speed", "nan"], ["--speed", "101"], ["--speed", "x"],
        ["--timeout", "-1"], ["--timeout", "inf"], ["--timeout", "3601"],
        ["--calibration-actions", "39"], ["--calibration-actions", "4001"],
        ["--calibration-actions", "-1"], ["--decisions", "x"], ["--decisions", "name="],
        ["--decisions", "host=a"], ["--runs", "0"], ["--accuracy", "0.4"],
        ["--liblsl", "/dev/zero"], ["--liblsl", "OUT/missing.so"],
        ["--save", "OUT/x.txt"], ["--save", "/proc/x.rrd"], ["--save", "OUT/missing/x.rrd"],
    ]
] + [
    ["stream", "OUT/nothing.toml"], ["stream", "/dev/zero"], ["stream", "OUT"],
] + [
    ["sweep", "--task", "grid", "--no-cache", "--out", "OUT/s"] + extra for extra in [
        ["--accuracy", "0.7,0.7"], ["--accuracy", "0.4"], ["--accuracy", "0.9:0.5:0.1"],
        ["--accuracy", "0.5:1:0.000001"], ["--param", "tau=0.3,0.3"],
        ["--param", "tau=0.3", "--param", "tau=0.5"], ["--param", "tau"],
        ["--param", "=1"], ["--param", "a.b.c.d.e=1"], ["--param", "tau=nan"],
        ["--param", "tau=1:1e12:1"], ["--param", "seed=1,2"], ["--param", "t_e=0.8"],
        ["--param", "tau=0.1:0.9:0.01", "--param", "epsilon=0:1:0.05"],
        ["--episodes", "0"], ["--episodes", "1e9"], ["--episodes", "1000001"],
        ["--threads", "0"], ["--threads", "100000"], ["--shard", "0/2"],
        ["--shard", "3/2"], ["--shard", "1/0"], ["--seed", "-1"], ["--eeg", "bank", "--task", "epuck"],
    ]
] + [
    ["merge", "OUT", "--out", "OUT/m"], ["merge", "OUT/none", "--out", "OUT/m"],
]


def toml_text(table, prefix=""):
    """A TOML document of `table` (scalars first, then tables)."""
    lines, subs, arrays = [], [], []
    for k, v in table.items():
        if isinstance(v, dict) and v:
            subs.append((k, v))
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            arrays.append((k, v))
        else:
            lines.append(f"{k} = {toml_value(v)}")
    out = "\n".join(lines) + "\n"
    for k, v in subs:
        name = f"{prefix}{k}"
        out += f"\n[{name}]\n" + toml_text(v, name + ".")
    for k, items in arrays:
        name = f"{prefix}{k}"
        for item in items:
            out += f"\n[[{name}]]\n" + toml_text(item, name + ".")
    return out


def set_field(table, field, value):
    parts = field.split(".")
    here = table
    i = 0
    while i < len(parts) - 1:
        nxt = here.setdefault(parts[i], {})
        if isinstance(nxt, list) and parts[i + 1].isdigit():
            if not nxt:
                nxt.append({})
            nxt = nxt[min(int(parts[i + 1]), len(nxt) - 1)]
            i += 1
        if not isinstance(nxt, dict):
            return
        here = nxt
        i += 1
    here[parts[-1]] = value


def scenario_cases():
    for path in SCENARIOS:
        base = tomllib.loads(path.read_text())
        epuck = base.get("task") == "epuck"
        for field in FIELDS:
            for value in EDGE_VALUES:
                table = tomllib.loads(path.read_text())
                if not epuck and field != "decoder":
                    table["decoder"] = "oracle"
                set_field(table, field, value)
                text = toml_text(table)
                label = f"{path.name}: {field} = {toml_value(value)[:40]}"
                run = ["run", "SCEN", "--save", "OUT/x.rrd", "--quiet"]
                if epuck:
                    run += ["--runs", "1"]
                yield label, text, run
                if field in ("control.tau", "control.t_e", "timing.max_actions", "runs",
                             "detector.smooth_windows", "bank_per_class", "seed"):
                    sweep = ["sweep", "--scenario", "SCEN", "--accuracy", "0.8", "--episodes",
                             "2", "--no-cache", "--quiet", "--out", "OUT/s"]
                    yield label + " (sweep)", text, sweep


def limit_memory(gib):
    def apply():
        size = gib << 30
        resource.setrlimit(resource.RLIMIT_AS, (size, size))
    return apply


def check(errp, label, text, args, gib, grid_file, epuck_file):
    work = Path(tempfile.mkdtemp(prefix="errp-fuzz-"))
    out = work / "out"
    out.mkdir()
    scen = work / "case.toml"
    if text is not None:
        scen.write_text(text)
    subst = {"SCEN": str(scen), "SCEN_GRID": str(grid_file), "SCEN_EPUCK": str(epuck_file)}
    argv = [errp] + [subst.get(a, a.replace("OUT", str(out))) for a in args]
    env = dict(os.environ, ERRP_CACHE_DIR=str(work / "cache"), RUST_BACKTRACE="0")
    try:
        p = subprocess.run(argv, capture_output=True, text=True, timeout=120,
                           preexec_fn=limit_memory(gib), env=env, cwd=ROOT)
    except subprocess.TimeoutExpired:
        shutil.rmtree(work, ignore_errors=True)
        return None, f"{label}: no answer within 120 s: {' '.join(args)}"
    left = sorted(str(f.relative_to(out)) for f in out.rglob("*"))
    shutil.rmtree(work, ignore_errors=True)
    why = None
    if p.returncode not in (0, 2):
        why = f"exit code {p.returncode}"
    elif p.returncode == 2:
        if not p.stderr.startswith("error:"):
            why = "exit 2 without `error:`"
        elif left:
            why = f"exit 2 left {left}"
    elif any(".partial-" in f or f.endswith("sweep.lock") for f in left):
        why = f"exit 0 left {left}"
    if why:
        return p.returncode, f"{label}: {why}: {' '.join(args)}\n{p.stderr[-600:]}"
    return p.returncode, None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("errp")
    ap.add_argument("--seconds", type=float, default=math.inf)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--memory-gib", type=int, default=4)
    ap.add_argument("--list", action="store_true")
    ap.add_argument("--python", default=sys.executable,
                    help="the Python with the errp package, for the python family")
    ap.add_argument("--only", choices=["input", "hostile", "signal", "recordings", "python",
                                       "realism", "edf", "lsl"],
                    help="run one family of cases")
    a = ap.parse_args()
    errp = str(Path(a.errp).resolve())
    cases = [("input", label, text, args) for label, text, args in scenario_cases()]
    cases += [("input", " ".join(f), None, f) for f in FLAG_CASES]
    cases += [("hostile", c.label, None, c) for c in hostile_cases()]
    cases += [("signal", c.label, at, c) for at, c in signal_cases(20, a.seed)]
    base_dir = tempfile.mkdtemp(prefix="errp-fuzz-base-")
    bases = None
    if a.only in (None, "recordings"):
        bases = make_bases(errp, base_dir)
        sizes = {kind: len(b) for kind, b in bases.items()}
        cases += [("recordings", c.label, None, c) for c in recording_cases(a.seed, sizes)]
    cases += [("python", c.label, None, c) for c in python_cases()]
    cases += [("realism", c.label, None, c) for c in realism_cases(a.seed)]
    edf_base = None
    if a.only in (None, "edf"):
        edf_base = make_edf_base(errp, base_dir)
        cases += [("edf", c.label, None, c)
                  for c in edf_cases(a.seed, len(edf_base)) + writer_cases()]
    cases += [("lsl", c.label, None, c) for c in lsl_cases(a.seed)]
    random.Random(a.seed).shuffle(cases)
    if a.list:
        for kind, label, _, args in cases:
            print(kind, "|", label, "|", " ".join(args) if kind == "input" else args.command())
        shutil.rmtree(base_dir, ignore_errors=True)
        return
    grid_file = ROOT / "scenarios" / "grid_fixed_goals.toml"
    epuck_file = ROOT / "scenarios" / "mexico_to_pisa.toml"
    if a.only:
        cases = [c for c in cases if c[0] == a.only]
    started = time.monotonic()
    ran, ran_ok, refused, stopped, failures = 0, 0, 0, 0, []
    base = None
    for kind, label, text, args in cases:
        if time.monotonic() - started > a.seconds:
            break
        if kind == "input":
            code, failure = check(errp, label, text, args, a.memory_gib, grid_file, epuck_file)
        elif kind == "python":
            failure, code = run_python_case(os.path.abspath(a.python), args, a.memory_gib,
                                            limit_memory)
        elif kind == "edf":
            failure, code = run_edf(errp, edf_base, args, os.path.abspath(a.python),
                                    a.memory_gib, limit_memory)
        elif kind == "lsl":
            failure, code = run_lsl(errp, args, os.path.abspath(a.python), a.memory_gib,
                                    limit_memory)
        elif kind == "realism":
            failure, code = run_realism(errp, args, a.memory_gib, limit_memory)
        elif kind == "recordings":
            failure, code = run_damage(errp, bases, args, a.memory_gib, limit_memory)
        else:
            if base is None:
                base = build_base(errp, base_dir)
            failure, code = run_case(errp, base, args, a.memory_gib, limit_memory,
                                     signal_at=text if kind == "signal" else None)
        ran += 1
        ran_ok += code == 0
        refused += code == 2
        stopped += code == 130
        if failure:
            failures.append(failure)
            print("FAIL", failure, file=sys.stderr, flush=True)
    shutil.rmtree(base_dir, ignore_errors=True)
    for f in failures:
        print(f, file=sys.stderr)
    print(f"fuzz_cli: {ran} of {len(cases)} cases in {time.monotonic() - started:.0f} s: "
          f"{ran_ok} ran (exit 0), {refused} refused (exit 2), {stopped} stopped by a signal "
          f"(exit 130), {len(failures)} failed "
          f"(seed {a.seed}, address space {a.memory_gib} GiB)")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
