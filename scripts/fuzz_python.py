"""The Python cases of fuzz_cli.py: the `errp` package's public calls, each
given a bad value for one argument, in a process of its own (see
fuzz_cli.py's docstring).

Each case runs `python -c SNIPPET` (the interpreter of `--python`, with the
package installed) in an empty directory, under the address-space limit and
a two-minute time-out. The call must either succeed (a value that is in
fact valid) or raise TypeError, ValueError or OSError whose message names
the argument; any other exception (OverflowError, a panic's
PanicException, an unnamed error), a crash, a hang, or a file left in the
directory by a refused call is a failure.
"""

import shutil
import subprocess
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
GRID = str(ROOT / "scenarios" / "grid_fixed_goals.toml")

#: Bad values, as Python source.
VALUES = ["float('nan')", "float('inf')", "-float('inf')", "10**400", "1+0j", "3.7", "-1",
          "2**70", "None", "'x'", "b'x'", "[1]", "True"]

#: (label, argument named in the message (alternatives split by |), setup,
#: call with V for the value).
CALLS = [
    ("run seed", "seed", "", f"errp.run({GRID!r}, overrides={{'decoder': 'oracle'}}, seed=V)"),
    ("run runs", "runs", "", f"errp.run({GRID!r}, overrides={{'decoder': 'oracle'}}, runs=V)"),
    ("run accuracy", "accuracy", "", f"errp.run({GRID!r}, accuracy=V)"),
    ("run save", "save", "", f"errp.run({GRID!r}, overrides={{'decoder': 'oracle'}}, save=V)"),
    ("sweep episodes", "episodes", "", "errp.sweep('s', task='grid', accuracy=0.7, episodes=V)"),
    ("sweep seed", "seed", "", "errp.sweep('s', task='grid', accuracy=0.7, episodes=2, seed=V)"),
    ("sweep threads", "threads", "",
     "errp.sweep('s', task='grid', accuracy=0.7, episodes=2, threads=V)"),
    ("sweep params", "params", "",
     "errp.sweep('s', task='grid', accuracy=0.7, episodes=2, params={'tau': [V, '0.3,0.5']})"),
    ("EegGenerator errp_to_noise", "errp_to_noise", "", "errp.EegGenerator(errp_to_noise=V)"),
    ("EegGenerator.generate", "n_samples", "g = errp.EegGenerator()", "g.generate(V)"),
    ("EegGenerator.schedule", "onset_secs", "g = errp.EegGenerator()", "g.schedule(V, 'error')"),
    ("Grid-v0 step", "action", "e = gym.make('errp/Grid-v0'); e.reset(seed=0)", "e.step(V)"),
    ("Grid-v0 goal", "goal", "e = gym.make('errp/Grid-v0')",
     "e.reset(options={'goal': (V, 1)})"),
    ("Epuck-v0 step", "action", "e = gym.make('errp/Epuck-v0'); e.reset(seed=0)", "e.step(V)"),
    ("Epuck-v0 goal", "goal", "", "gym.make('errp/Epuck-v0', goal=V)"),
    ("read_recording", "path|x", "", "errp.read_recording(V)"),
    ("ShrinkageLDA X", "X",
     "from errp.decoders import ShrinkageLDA; X = np.random.default_rng(0).normal(size=(20, 3))"
     "; y = [0, 1] * 10",
     "X = X.astype(complex) if isinstance(V, complex) else X; X[0, 0] = V; "
     "ShrinkageLDA().fit(X, y)"),
]

SNIPPET = """
import sys
import numpy as np
import gymnasium as gym
import errp, errp.gym
{setup}
V = {value}
try:
    {call}
except (TypeError, ValueError, OSError) as e:
    print("REFUSED", type(e).__name__, str(e).replace(chr(10), " ")[:400])
    sys.exit(2)
"""


class PyCase:
    """One call with one bad value."""

    def __init__(self, label, name, setup, call, value):
        self.label = f"python {label} = {value}"
        self.name = name
        self.source = SNIPPET.format(setup=setup, value=value, call=call)

    def command(self):
        return self.label


def python_cases():
    """Every call with every bad value (except the ones a call's value
    slot cannot hold)."""
    cases = []
    for label, name, setup, call in CALLS:
        for value in VALUES:
            if label == "ShrinkageLDA X" and value in ("None", "'x'", "b'x'", "[1]", "10**400",
                                                      "True"):
                continue
            cases.append(PyCase(label, name, setup, call, value))
    return cases


def run_python_case(python, case, gib, limit_memory):
    """Runs one case; returns (failure or None, exit code)."""
    work = Path(tempfile.mkdtemp(prefix="errp-fuzz-py-"))
    try:
        try:
            p = subprocess.run([python, "-c", case.source], capture_output=True, text=True,
                               timeout=120, preexec_fn=limit_memory(gib), cwd=work)
        except subprocess.TimeoutExpired:
            return f"{case.label}: no answer within 120 s", None
        left = sorted(str(x.relative_to(work)) for x in work.rglob("*"))
        why = None
        if p.returncode == 2:
            words = p.stdout.split()
            if not (len(words) > 2 and words[0] == "REFUSED"
                    and any(n in p.stdout.split(" ", 2)[2] for n in case.name.split("|"))):
                why = f"refused without naming {case.name}: {p.stdout.strip()[:300]}"
            elif left:
                why = f"refused, but left {left}"
        elif p.returncode != 0:
            why = f"exit code {p.returncode}: {p.stderr.strip()[-400:]}"
        elif any(".partial-" in x for x in left):
            why = f"left {left}"
        return (f"{case.label}: {why}" if why else None), (2 if p.returncode == 2 else
                                                           p.returncode)
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    # A module of fuzz_cli.py: it runs nothing by itself.
    from fuzz_common import module_help

    module_help(__doc__)

