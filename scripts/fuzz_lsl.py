"""The hostile LSL decoder clients of fuzz_cli.py: `errp stream` beside a
client that reads the session's streams and then breaks the stream
contract of `docs/guide/online.md` one way at a time.

* shape: a decoder stream of 0, 1, 3 or 4 096 channels, of strings or
  8-bit integers, at a regular rate;
* values: p(error) NaN, infinite, negative, above 1, 1e308, or the edges
  0 and 1;
* ids: an action id or window timestamp that is NaN, infinite, negative,
  fractional, huge, past 2^53, of the next action, always 0, rounded
  through float32, moved by a millisecond, or random;
* floods: every decision sent 200 times, or a stream of random decisions
  as fast as the client can push them;
* silence: a decoder stream that never sends, one that stops after a few
  decisions, one that closes, a client that never opens the EEG, one that
  publishes before the calibration ends;
* ids of streams: a decoder named for another session, one naming no
  session, two decoder streams of this session at once, one found by
  another name than `--decisions` asks;
* a second session on the host: a bridge with the same scenario and seed
  but its own `--session` and no decoder, beside the first and its client.

Each case streams a grid scenario (20 actions a run, 200 where the
client falls silent) or Mexico to Pisa (a 10 s run; where the client
falls silent, a whole run at `--speed 4`) at `--speed 100` after 40
calibration actions, with `--save OUT/x.rrd`, the client being a
`--python` program with pylsl (the family is skipped without it). The
bridge must exit 0 (the contract lets the session go on: late and stray
decisions are counted) or 2 (with `error: ` naming the decoder's stream
or the EEG stream), as the case says; never panic, abort or hang past two
minutes, and leave nothing in OUT on exit 2. Every case runs in a
session id of its own, so no other stream on the host answers it.
"""

import itertools
import json
import os
import subprocess
import tempfile
import shutil
from pathlib import Path

from fuzz_common import verdict

ROOT = Path(__file__).resolve().parent.parent

#: The client: `python -c CLIENT SESSION SPEC` (SPEC is JSON, see LslCase).
CLIENT = r"""
import json, math, random, sys, time
import numpy as np
import pylsl

session, spec = sys.argv[1], json.loads(sys.argv[2])
rng = random.Random(spec.get("seed", 1))

def find(name):
    found = pylsl.resolve_byprop("source_id", f"{name}-{session}", 1, 30)
    if not found:
        sys.exit(f"client: no {name}-{session}")
    inlet = pylsl.StreamInlet(found[0], max_buflen=600, processing_flags=0)
    inlet.open_stream(10)
    return inlet

FORMATS = {"double64": pylsl.cf_double64, "float32": pylsl.cf_float32,
           "string": pylsl.cf_string, "int8": pylsl.cf_int8}
SOURCES = {"ours": f"errp-decoder-{session}", "other": f"errp-decoder-{session}x",
           "none": "errp-decoder"}

def outlet(o):
    info = pylsl.StreamInfo(o.get("name", "errp-decoder"), "Decisions", o.get("channels", 2),
                            o.get("rate", 0.0), FORMATS[o.get("format", "double64")],
                            SOURCES[o.get("source", "ours")])
    return pylsl.StreamOutlet(info), o.get("channels", 2), o.get("format", "double64")

def push(out, id_, p):
    o, n, fmt = out
    sample = ([id_, p] + [0.0] * n)[:n]
    if fmt == "string":
        sample = [repr(x) for x in sample]
    elif fmt == "int8":
        sample = [int(max(-128, min(127, x))) if math.isfinite(x) else 0 for x in sample]
    if n:
        o.push_sample(sample)

def ident(true_id):
    how = spec.get("id", "right")
    return {
        "right": lambda: true_id, "nan": lambda: math.nan, "inf": lambda: math.inf,
        "neg": lambda: -1.0 - true_id, "half": lambda: true_id + 0.5, "huge": lambda: 1e18,
        "past53": lambda: 2.0 ** 53 + 1, "next": lambda: true_id + 1, "zero": lambda: 0.0,
        "f32": lambda: float(np.float32(true_id)), "shift": lambda: true_id + 1e-3,
        "random": lambda: rng.uniform(-1e6, 1e6),
    }[how]()

def pvalue():
    p = spec.get("p", "random")
    return rng.random() if p == "random" else float(p)

markers = find("errp-markers")
eeg = None if spec.get("no_eeg") else find("errp-eeg")
outs, sent, ended = [], 0, None
if spec.get("early"):
    outs = [outlet(o) for o in spec.get("outlets", [{}])]
deadline = time.time() + 90
while time.time() < deadline and (ended is None or time.time() < ended + 1):
    if eeg is not None:
        _, stamps = eeg.pull_chunk(timeout=0.01)
    else:
        stamps = []
        time.sleep(0.01)
    msgs, _ = markers.pull_chunk(timeout=0.0)
    due = []
    for (m,) in msgs:
        event = json.loads(m)
        if event["event"] == "calibration_end" and not outs:
            outs = [outlet(o) for o in spec.get("outlets", [{}])]
        elif event["event"] == "action":
            due.append(event["action"])
        elif event["event"] == "end":
            ended = time.time()
    if spec.get("task") == "epuck" and stamps:
        due.append(stamps[-1])
    if not outs or spec.get("mode") == "silent":
        continue
    if spec.get("mode") == "flood":
        for o in outs:
            for _ in range(50):
                o[0].push_chunk([[rng.uniform(0, 1e4), rng.random()] for _ in range(200)])
        continue
    if spec.get("delay"):
        time.sleep(spec["delay"])
    for true_id in due:
        for _ in range(spec.get("repeat", 1)):
            for k in range(len(outs)):
                push(outs[k], ident(true_id), pvalue())
        sent += 1
        if sent == spec.get("stop_after"):
            spec["mode"] = "silent"
        if sent == spec.get("close_after"):
            outs = []  # the last reference: liblsl closes the outlet
            spec["mode"] = "silent"
"""


class LslCase:
    """One session: `task` (grid or epuck), the client's `spec` (its
    outlets, what it sends), `expect` (the exit codes the bridge may give),
    `bridge` (extra flags), `second` (a second bridge in another session
    beside it), `long` (runs long enough for a silence of 3 s)."""

    def __init__(self, task, how, spec, expect, bridge=(), second=False, long=False):
        self.task, self.how, self.spec = task, how, dict(spec, task=task)
        self.expect, self.bridge, self.second = expect, list(bridge), second
        self.long = long
        # An e-puck run reaches Pisa in about 3 s of wall time at 10.
        self.speed = 4 if long and task == "epuck" else 100
        self.label = f"LSL client {task}: {how}"

    def command(self):
        return (f"errp stream {self.task} --speed {self.speed} --calibration-actions 40 "
                f"{' '.join(self.bridge)} beside a client that {self.how}")


EITHER, RUNS, STOPS = (0, 2), (0,), (2,)


def lsl_cases(seed):
    cases = []
    for task in ("grid", "epuck"):
        for n in (0, 1, 3, 4096):
            cases.append(LslCase(task, f"publishes {n} channels", {"outlets": [{"channels": n}]},
                                 STOPS))
        for fmt in ("string", "int8"):
            cases.append(LslCase(task, f"publishes {fmt} channels",
                                 {"outlets": [{"format": fmt}]}, STOPS if fmt == "string"
                                 else EITHER))
        cases.append(LslCase(task, "publishes at 100 Hz", {"outlets": [{"rate": 100.0}]}, STOPS))
        for p in ("nan", "inf", "-inf", "-0.1", "1.5", "1e308"):
            cases.append(LslCase(task, f"sends p(error) {p}", {"p": p}, STOPS))
        for p in ("0", "1"):
            cases.append(LslCase(task, f"sends p(error) {p}", {"p": p}, RUNS))
        for how in ("nan", "inf", "neg", "half", "huge", "past53", "next", "zero", "f32",
                    "shift", "random"):
            cases.append(LslCase(task, f"sends ids {how}", {"id": how}, RUNS))
        cases.append(LslCase(task, "sends each decision 200 times", {"repeat": 200}, EITHER))
        cases.append(LslCase(task, "floods random decisions", {"mode": "flood"}, EITHER))
        cases.append(LslCase(task, "never sends", {"mode": "silent"}, STOPS, ["--timeout", "3"],
                             long=True))
        cases.append(LslCase(task, "stops after 3 decisions", {"stop_after": 3}, STOPS,
                             ["--timeout", "3"], long=True))
        cases.append(LslCase(task, "closes its stream after 3 decisions", {"close_after": 3},
                             STOPS, ["--timeout", "3"], long=True))
        cases.append(LslCase(task, "never opens the EEG", {"no_eeg": True}, STOPS,
                             ["--timeout", "3"]))
        cases.append(LslCase(task, "publishes before the calibration ends", {"early": True},
                             RUNS))
        cases.append(LslCase(task, "answers 0.2 s late", {"delay": 0.2}, RUNS))
        cases.append(LslCase(task, "publishes for another session",
                             {"outlets": [{"source": "other"}]}, STOPS, ["--timeout", "3"]))
        cases.append(LslCase(task, "publishes naming no session",
                             {"outlets": [{"source": "none"}]}, STOPS, ["--timeout", "3"]))
        cases.append(LslCase(task, "publishes two decoder streams", {"outlets": [{}, {}]},
                             EITHER))
        cases.append(LslCase(task, "publishes another name than --decisions asks",
                             {"outlets": [{"name": "mine"}]}, STOPS, ["--timeout", "3"]))
        cases.append(LslCase(task, "is found by --decisions name=mine",
                             {"outlets": [{"name": "mine"}]}, RUNS,
                             ["--decisions", "name=mine"]))
        cases.append(LslCase(task, "answers one of two sessions with the same seed", {}, RUNS,
                             second=True))
    for k, c in enumerate(cases):
        c.spec["seed"] = seed * 1000 + k
    return cases


def scenario(task, long, work):
    """A copy of the task's scenario with short runs (0.6 s of wall time at
    speed 100), or long ones (6 s)."""
    if task == "grid":
        text = (ROOT / "scenarios" / "grid_fixed_goals.toml").read_text()
        actions = 200 if long else 20
        text = text.replace("[timing]\n", f"[timing]\nmax_actions = {actions}\n")
    else:
        text = (ROOT / "scenarios" / "mexico_to_pisa.toml").read_text()
        text = text.replace("max_secs = 600", "max_secs = 600" if long else "max_secs = 10")
    path = work / f"{task}.toml"
    path.write_text(text)
    return path


_count = itertools.count()


def run_lsl(errp, case, python, gib, limit_memory):
    """Runs one case; returns (failure or None, exit code)."""
    has = subprocess.run([python, "-c", "import pylsl, numpy"], capture_output=True)
    if has.returncode != 0:
        return None, 0
    work = Path(tempfile.mkdtemp(prefix="errp-fuzz-lsl-"))
    session = f"fz{os.getpid() % 100000}_{next(_count)}"
    env = dict(os.environ, RUST_BACKTRACE="0")
    lib = subprocess.run([python, "-c", "import pylsl, os; print(os.path.join(os.path.dirname("
                          "pylsl.__file__), 'lib', 'liblsl.so'))"], capture_output=True,
                         text=True).stdout.strip()
    env["ERRP_LIBLSL"] = lib
    try:
        scen = scenario(case.task, case.long, work)
        procs = []

        def bridge(name, extra):
            out = work / name
            out.mkdir()
            timeout = [] if "--timeout" in extra else ["--timeout", "20"]
            argv = [errp, "stream", str(scen), "--speed", str(case.speed),
                    "--calibration-actions", "40", "--runs", "1", "--quiet", "--save",
                    str(out / "x.rrd"), *timeout, *extra]
            p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                 text=True, env=env, preexec_fn=limit_memory(gib))
            procs.append(p)
            return p, out

        main, out = bridge("out", ["--session", session, *case.bridge])
        second = None
        clients = [(session, case.spec)]
        if case.second:
            # Its EEG read by a client that publishes no decoder.
            second = bridge("out2", ["--session", session + "b", "--timeout", "3"])
            clients.append((session + "b", dict(case.spec, outlets=[])))
        for who, spec in clients:
            procs.append(subprocess.Popen([python, "-c", CLIENT, who, json.dumps(spec)],
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        failures, code = [], None
        for p, o, who in [(main, out, "the bridge")] + (
                [(second[0], second[1], "the second session's bridge")] if second else []):
            try:
                stdout, stderr = p.communicate(timeout=120)
            except subprocess.TimeoutExpired:
                failures.append(f"{who}: no answer within 120 s")
                continue
            done = subprocess.CompletedProcess(p.args, p.returncode, stdout, stderr)
            why = verdict(done, o, ("errp-decoder", "errp-eeg", "EEG stream", "--decisions"),
                          "a stream")
            if who == "the bridge":
                code = p.returncode
                if not why and p.returncode not in case.expect:
                    why = f"exit {p.returncode}, expected {' or '.join(map(str, case.expect))}"
            elif not why and p.returncode != 2:
                why = f"exit {p.returncode}: took the other session's decoder"
            elif not why and f"errp-decoder-{session}" not in stderr:
                why = "exit 2 without naming the other session's decoder it passed over"
            if why:
                failures.append(f"{who}: {why}\n{stderr[-600:]}")
        if failures:
            return f"{case.label}: " + "; ".join(failures) + f": {case.command()}", code
        return None, code
    finally:
        for p in procs:
            if p.poll() is None:
                p.kill()
            p.communicate()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    # A module of fuzz_cli.py: it runs nothing by itself.
    from fuzz_common import module_help

    module_help(__doc__)
