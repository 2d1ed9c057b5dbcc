"""The surroundings cases of fuzz_cli.py: the program's input is fine, what
is around it is not (see fuzz_cli.py's docstring).

A case copies a prepared base directory (scenarios, the three shards of an
oracle sweep, a complete oracle sweep, a complete grid EEG sweep with its
cache, e-puck and grid cache entries), changes something in the copy, runs
one command in it and checks what it did.
"""

import hashlib
import json
import os
import random
import shutil
import signal
import socket
import subprocess
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

ORACLE = (
    'task = "grid"\nseed = 1\ndecoder = "oracle"\n[user]\naccuracy = 0.75\n'
    "[[episode]]\nstart = [0, 0]\ngoal = [4, 4]\n[[episode]]\nstart = [4, 0]\ngoal = [0, 4]\n"
)

SHARD = ["sweep", "--scenario", "go.toml", "--accuracy", "0.6,0.8", "--episodes", "10",
         "--quiet", "--no-cache"]
FULL = ["sweep", "--scenario", "go.toml", "--accuracy", "0.6,0.8", "--episodes", "30",
        "--quiet", "--no-cache", "--out", "full"]
EEG = ["sweep", "--task", "grid", "--accuracy", "0.8", "--episodes", "2", "--quiet",
       "--cache", "cache", "--out", "eeg"]
PREP_GRID = ["sweep", "--task", "grid", "--accuracy", "0.8", "--prepare-only", "--cache", "cache"]
PREP_EPUCK = ["sweep", "--task", "epuck", "--accuracy", "0.9", "--prepare-only", "--cache",
              "cache"]
MERGE = ["merge", "s1", "s2", "s3", "--out", "OUT/m"]
SIGNALLED = ["sweep", "--scenario", "go.toml", "--accuracy", "0.6,0.7", "--episodes", "40000",
             "--quiet", "--no-cache", "--out", "OUT/s"]


def build_base(errp, into):
    """The base directory every case copies."""
    base = Path(into) / "base"
    base.mkdir()
    (base / "go.toml").write_text(ORACLE)
    shutil.copy(ROOT / "scenarios" / "mexico_to_pisa.toml", base / "ep.toml")
    env = dict(os.environ, ERRP_CACHE_DIR=str(base / "cache"))
    runs = [SHARD + ["--shard", f"{k}/3", "--out", f"s{k}"] for k in (1, 2, 3)]
    runs += [FULL, EEG, PREP_EPUCK, SIGNALLED[:-1] + ["ref"]]
    for args in runs:
        subprocess.run([errp] + args, cwd=base, env=env, check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return base


def files(root):
    return sorted(p for p in root.rglob("*") if p.is_file() or p.is_symlink())


def digest(path):
    if path.is_symlink() or not path.is_file():
        return "special"
    return hashlib.sha256(path.read_bytes()).hexdigest()


def cache_entry(work, kind):
    return next((work / "cache").glob(f"{kind}-*.json"))


def fifo(path):
    path.unlink(missing_ok=True)
    os.mkfifo(path)


def sock(path):
    path.unlink(missing_ok=True)
    s = socket.socket(socket.AF_UNIX)
    s.bind(str(path))
    s.close()


def devnull(path):
    path.unlink(missing_ok=True)
    path.symlink_to("/dev/null")


def directory(path):
    path.unlink(missing_ok=True)
    path.mkdir()


SPECIAL = {"fifo": fifo, "socket": sock, "device": devnull, "directory": directory}


def edit_json(path, change):
    value = json.loads(path.read_text())
    change(value)
    path.write_text(json.dumps(value, indent=2))


def set_ratio(factor=None, value=None):
    def change(entry):
        r = entry["result"]["ratio"]
        entry["result"]["ratio"] = r * factor if factor is not None else value
    return change


class Case:
    def __init__(self, label, args, prep=None, stdout="pipe", stderr="pipe", expect=(0, 2),
                 may_change=(), after=None):
        self.label, self.args, self.prep = label, args, prep
        self.stdout, self.stderr, self.expect = stdout, stderr, set(expect)
        self.may_change, self.after = may_change, after

    def command(self):
        return " ".join(self.args)


def outputs_exist(*names):
    def check(work, out, p):
        missing = [n for n in names if not (work / n.replace("OUT", "out")).is_file()]
        return f"exit 0 without {missing}" if p.returncode == 0 and missing else None
    return check


def restored(kind):
    """The cache entry of `kind` is back to what the search finds."""
    def check(work, out, p):
        if p.returncode != 0:
            return None
        if "searched now" not in p.stdout or "1 searched now" not in p.stdout:
            return "the damaged entry was not searched again"
        if digest(cache_entry(work, kind)) != digest(cache_entry(work.parent / "base", kind)):
            return "the cache entry was not restored"
        return None
    return check


def hostile_cases():
    cases = []
    # Standard output and error: closed early, or on a full disk.
    commands = [
        ["run", "go.toml", "--quiet"],
        ["run", "go.toml", "--save", "OUT/x.rrd"],
        ["run", "ep.toml", "--runs", "1", "--save", "OUT/x.rrd"],
        ["calibrate", "--save", "OUT/c.rrd", "--export", "OUT/c.edf"],
        ["table1", "--decoder", "oracle", "--episodes", "1"],
        ["subjects"],
        ["sweep", "--scenario", "go.toml", "--accuracy", "0.7", "--episodes", "20",
         "--out", "OUT/s"],
        PREP_GRID,
        MERGE,
        ["--help"],
        ["sweep", "--accuracy", "2"],
    ]
    for args in commands:
        made = [a for a in args if a.startswith("OUT/") and "." in a]
        for out_mode, err_mode in [("head", "pipe"), ("full", "pipe"), ("pipe", "full"),
                                   ("full", "full"), ("head", "head"), ("pipe", "head")]:
            after = outputs_exist(*made) if out_mode in ("head", "pipe") and made else None
            cases.append(Case(f"stdout {out_mode}, stderr {err_mode}: {' '.join(args)}", args,
                              stdout=out_mode, stderr=err_mode, after=after,
                              may_change=("cache",)))
    # Special files where a regular file belongs.
    places = [
        ("scenario", "go.toml", ["run", "go.toml", "--quiet"]),
        ("scenario (sweep)", "go.toml",
         ["sweep", "--scenario", "go.toml", "--accuracy", "0.7", "--out", "OUT/s"]),
        ("--save", "OUT/x.rrd", ["run", "ep.toml", "--runs", "1", "--save", "OUT/x.rrd"]),
        ("--export", "OUT/c.edf", ["calibrate", "--export", "OUT/c.edf", "--quiet"]),
        ("episodes.csv", "full/episodes.csv", FULL),
        ("sweep.json", "full/sweep.json", FULL),
        ("sweep.lock", "full/sweep.lock", FULL),
        ("summary.csv", "full/summary.csv", FULL),
        ("shard episodes.csv", "s1/episodes.csv", MERGE),
        ("shard sweep.json", "s1/sweep.json", MERGE),
        ("shard sweep.lock", "s2/sweep.lock", MERGE),
        ("merge output", "OUT/m", MERGE),
        ("cache entry (grid)", "CACHE:grid-lda-online", PREP_GRID),
        ("cache entry (e-puck)", "CACHE:epuck-svm", PREP_EPUCK),
    ]
    for what, rel, args in places:
        for kind, make in SPECIAL.items():
            def prep(work, rel=rel, make=make):
                if rel.startswith("CACHE:"):
                    path = cache_entry(work, rel[6:])
                else:
                    path = work / rel.replace("OUT", "out")
                path.parent.mkdir(parents=True, exist_ok=True)
                make(path)
            cases.append(Case(f"a {kind} as the {what}", args, prep=prep,
                              may_change=("full", "cache")))
    # Cache entries edited or damaged: searched again and restored.
    edits = {
        "ratio x3": set_ratio(factor=3.0), "ratio 0": set_ratio(value=0.0),
        "ratio 1e308": set_ratio(value=1e308), "ratio -1": set_ratio(value=-1.0),
        "ratio x1.5": set_ratio(factor=1.5), "ratio 1e-300": set_ratio(value=1e-300),
        "ratio a string": set_ratio(value="nan"),
        "accuracy edited": lambda e: e["result"]["accuracy"].update(correct=0.99),
        "no steps": lambda e: e["result"].update(steps=[]),
        "another request": lambda e: e.update(request=e["request"] + " x"),
    }
    for kind, prep_args in [("grid-lda-online", PREP_GRID), ("epuck-svm", PREP_EPUCK)]:
        for name, change in edits.items():
            def prep(work, kind=kind, change=change):
                edit_json(cache_entry(work, kind), change)
            expect_restore = name not in ("no steps",)
            cases.append(Case(f"cache {kind}: {name}", prep_args, prep=prep, expect=(0,),
                              may_change=("cache",),
                              after=restored(kind) if expect_restore else None))
        for name, data in [("empty", b""), ("cut short", None), ("binary", os.urandom(512)),
                           ("20 MB", b"{" + b" " * (20 << 20))]:
            def prep(work, kind=kind, data=data):
                path = cache_entry(work, kind)
                path.write_bytes(path.read_bytes()[:40] if data is None else data)
            cases.append(Case(f"cache {kind}: {name}", prep_args, prep=prep, expect=(0,),
                              may_change=("cache",), after=restored(kind)))
    # Sweep metadata edited: resume (FULL, EEG) and merge refuse, or go on.
    meta = {
        "version 9.9.9": lambda m: m.update(errp_version="9.9.9"),
        "format 3": lambda m: m.update(format=3),
        "seed changed": lambda m: m["spec"].update(seed=m["spec"]["seed"] + 1),
        "episodes changed": lambda m: m["spec"].update(episodes=m["spec"]["episodes"] + 1),
        "scenario text changed": lambda m: m["spec"].update(
            scenario_toml=m["spec"]["scenario_toml"] + "\n# edited\n"),
        "scenario path changed": lambda m: m["spec"].update(scenario_path="elsewhere/go.toml"),
        "decoders dropped": lambda m: m.update(decoders=[]),
        "shard index": lambda m: m.update(shard={"index": 2, "count": 3}),
        "ratio of a decoder": lambda m: [d.update(errp_to_noise=(d.get("errp_to_noise") or 1) * 2)
                                         for d in m["decoders"]],
    }
    for name, change in meta.items():
        for where, args in [("full", FULL), ("eeg", EEG), ("s1", MERGE)]:
            def prep(work, where=where, change=change):
                edit_json(work / where / "sweep.json", change)
            cases.append(Case(f"{where}/sweep.json: {name}", args, prep=prep,
                              may_change=(where, "cache")))
    for name, data in [("empty", b""), ("garbage", b"\x00\xff" * 100), ("cut", None),
                       ("20 MB", b"{" + b" " * (20 << 20))]:
        for where, args in [("full", FULL), ("s1", MERGE)]:
            def prep(work, where=where, data=data):
                path = work / where / "sweep.json"
                path.write_bytes(path.read_bytes()[:50] if data is None else data)
            cases.append(Case(f"{where}/sweep.json {name}", args, prep=prep,
                              may_change=(where,)))
    # The same sweep through another spelling of its scenario's path.
    cases.append(Case("the scenario by its absolute path", FULL[:2] + ["ABS/go.toml"] + FULL[3:],
                      expect=(0,), may_change=("full",)))
    # Rows edited.
    rows = {
        "last row twice": lambda t: t + t.splitlines(keepends=True)[-1],
        "a garbage row": lambda t: t + "1,2,3\n",
        "NUL bytes": lambda t: t[:-40] + "\x00" * 39 + "\n",
        "a 2 MB line": lambda t: t + "x" * (2 << 20) + "\n",
        "header changed": lambda t: "a," + t,
        "cut in a row": lambda t: t[:-7],
        "empty": lambda t: "",
        "rows swapped": lambda t: "".join(
            (lambda ls: [ls[0], ls[2], ls[1]] + ls[3:])(t.splitlines(keepends=True))),
    }
    for name, change in rows.items():
        for where, args in [("full", FULL), ("full", FULL + ["--repair"]), ("s1", MERGE)]:
            def prep(work, where=where, change=change):
                path = work / where / "episodes.csv"
                path.write_text(change(path.read_text(errors="replace")))
            label = f"{where}/episodes.csv: {name}" + (" (--repair)" if "--repair" in args else "")
            cases.append(Case(label, args, prep=prep, may_change=(where,)))
    # Locks.
    record = ("host = {host}\npid = {pid}\ntoken = 00000000000000ab\ncommand = errp sweep\n")
    locks = [
        ("another host, fresh", "elsewhere", 5, 0, (2,)),
        ("another host, 10 years ahead", "elsewhere", 5, 10 * 365 * 86400, (0,)),
        ("another host, an hour old", "elsewhere", 5, -3600, (0,)),
        ("this host, a dead pid", socket.gethostname(), 999_999, 0, (0,)),
        ("garbage", None, 0, 0, (0,)),
    ]
    for name, host, pid, shift, expect in locks:
        def prep(work, host=host, pid=pid, shift=shift):
            lock = work / "full" / "sweep.lock"
            lock.write_text(record.format(host=host, pid=pid) if host else "\x00" * 5000)
            t = time.time() + shift
            os.utime(lock, (t, t))
        cases.append(Case(f"lock: {name}", FULL, prep=prep, expect=expect,
                          may_change=("full",)))
    # Outputs that cannot be written.
    def immutable(rel):
        def prep(work):
            path = work / rel
            path.parent.mkdir(parents=True, exist_ok=True)
            if not path.exists():
                path.write_bytes(b"RRF2" if rel.endswith(".rrd") else b"0       ")
            if os.geteuid() == 0:
                subprocess.run(["chattr", "+i", str(path)], stderr=subprocess.DEVNULL)
            else:
                path.chmod(0o444)
        return prep
    for rel, args in [("out/x.rrd", ["run", "go.toml", "--save", "OUT/x.rrd", "--quiet"]),
                      ("out/c.edf", ["calibrate", "--export", "OUT/c.edf", "--quiet"]),
                      ("out/m/a.txt", MERGE)]:
        cases.append(Case(f"unwritable {rel}", args, prep=immutable(rel), expect=(2,)))
    for rel, args in [("out/notes.rrd", ["run", "go.toml", "--save", "OUT/notes.rrd"]),
                      ("out/notes.edf", ["calibrate", "--export", "OUT/notes.edf"])]:
        def prep(work, rel=rel):
            (work / rel).parent.mkdir(parents=True, exist_ok=True)
            (work / rel).write_text("a user's own notes\n")
        cases.append(Case(f"a user's file as {rel}", args, prep=prep, expect=(2,)))
    return cases


def run_case(errp, base, case, gib, limit_memory, signal_at=None):
    """Runs `case` in a copy of `base`; the failure, or None, and the exit code."""
    work = Path(tempfile.mkdtemp(prefix="errp-hostile-"))
    try:
        shutil.copytree(base, work / "base", symlinks=True)
        shutil.copytree(base, work / "w", symlinks=True)
        w = work / "w"
        out = w / "out"
        out.mkdir()
        if case.prep:
            case.prep(w)
        before = {p.relative_to(w): digest(p) for p in files(w)}
        argv = [errp] + [a.replace("OUT", "out").replace("ABS", str(w)) for a in case.args]
        env = dict(os.environ, ERRP_CACHE_DIR=str(w / "cache"), RUST_BACKTRACE="0")
        err_path = work / "stderr.txt"
        full = lambda: open("/dev/full", "w")  # noqa: E731
        err = full() if case.stderr == "full" else (
            subprocess.PIPE if case.stderr == "head" else open(err_path, "w"))
        stdout = full() if case.stdout == "full" else subprocess.PIPE
        p = subprocess.Popen(argv, cwd=w, env=env, stdout=stdout, stderr=err, text=True,
                             preexec_fn=limit_memory(gib))
        text = ""
        try:
            if case.stderr == "head":
                p.stderr.readline()
                p.stderr.close()
            if signal_at is not None:
                time.sleep(signal_at)
                p.send_signal(signal.SIGTERM)
            if case.stdout == "head":
                text = p.stdout.readline()
                p.stdout.close()
                p.wait(timeout=120)
            elif case.stdout == "pipe":
                text, _ = p.communicate(timeout=120)
            else:
                p.wait(timeout=120)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()
            return f"{case.label}: no answer within 120 s: {case.command()}", None
        stderr_text = err_path.read_text() if err_path.exists() else ""
        p.stdout = text  # for the checks
        why = None
        if p.returncode not in case.expect and not (signal_at is not None
                                                    and p.returncode == 130):
            why = f"exit code {p.returncode} (expected {sorted(case.expect)})"
        elif p.returncode == 2 and case.stderr == "pipe" and not any(
                line.startswith("error:") for line in stderr_text.splitlines()):
            why = "exit 2 without `error:`"
        if why is None:
            left = [str(f.relative_to(w)) for f in files(w)
                    if ".partial-" in f.name or (f.name == "sweep.lock"
                                                 and digest(f) != before.get(f.relative_to(w)))]
            if left:
                why = f"left {left}"
        if why is None:
            changed = [str(k) for k, d in before.items()
                       if not any(str(k).startswith(m) for m in case.may_change + ("out",))
                       and (not (w / k).exists() and not (w / k).is_symlink()
                            or digest(w / k) != d)]
            if changed:
                why = f"changed what it did not write: {changed}"
        if why is None and case.after:
            why = case.after(w, out, p)
        if why is None and signal_at is not None:
            # The same command resumes to the files of a run left alone.
            again = subprocess.run(argv, cwd=w, env=env, capture_output=True, text=True,
                                   timeout=300)
            if again.returncode != 0:
                why = f"the resume exits {again.returncode}"
                stderr_text = again.stderr
            else:
                for name in ("episodes.csv", "summary.csv"):
                    if digest(out / "s" / name) != digest(w / "ref" / name):
                        why = f"resumed, {name} differs from an uninterrupted run"
        if why:
            return f"{case.label}: {why}: {case.command()}\n{stderr_text[-600:]}", p.returncode
        return None, p.returncode
    finally:
        if os.geteuid() == 0:
            subprocess.run(["chattr", "-R", "-i", str(work)], stderr=subprocess.DEVNULL)
        else:
            subprocess.run(["chmod", "-R", "u+w", str(work)], stderr=subprocess.DEVNULL)
        shutil.rmtree(work, ignore_errors=True)


def signal_cases(n, seed):
    """`n` sweeps stopped by SIGTERM at seeded random moments: each exits 0
    or 130 and leaves nothing being written, and the same command resumes
    to the files of an uninterrupted run."""
    rng = random.Random(seed)
    out = []
    for _ in range(n):
        at = round(rng.uniform(0.05, 2.5), 2)
        out.append((at, Case(f"SIGTERM {at} s into a sweep, then resumed", SIGNALLED,
                             expect=(0, 130), may_change=("ref",))))
    return out


if __name__ == "__main__":
    # A module of fuzz_cli.py: it runs nothing by itself.
    from fuzz_common import module_help

    module_help(__doc__)
