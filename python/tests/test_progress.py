"""progress=: what long calls report, and how it is shown."""

import re
import subprocess
import sys

import pytest

import errp
from errp import _core


class Calls:
    """A progress callable that keeps what it was given."""

    def __init__(self):
        self.seen = []

    def __call__(self, stage, done, total):
        self.seen.append((stage, done, total))

    def stages(self):
        return [s for i, (s, _, _) in enumerate(self.seen) if i == 0 or self.seen[i - 1][0] != s]


def check_counts(seen):
    """Within a stage, done never goes back and never passes total."""
    for (s0, d0, _), (s1, d1, t1) in zip(seen, seen[1:]):
        if s0 == s1:
            assert d1 >= d0, seen
        assert t1 == 0 or d1 <= t1, seen


def test_a_run_reports_the_calibration_then_every_run():
    calls = Calls()
    d = _core.run(None, runs=12, seed=1, progress=calls)
    assert calls.stages() == ["calibrating", "runs"]
    assert calls.seen[-1] == ("runs", 12, 12)
    assert all(t == 0 for s, _, t in calls.seen if s == "calibrating")
    check_counts(calls.seen)
    # The same rows as without progress.
    assert d["csv"] == _core.run(None, runs=12, seed=1)["csv"]


def test_a_grid_task_and_a_sweep_report_their_episodes(tmp_path):
    calls = Calls()
    task = _core.GridTask(None, overrides={"repeats": 2}, progress=calls)
    assert calls.stages() == ["calibrating"]
    calls.seen.clear()
    task.run(progress=calls)
    assert calls.seen[-1] == ("episodes", 10, 10)
    check_counts(calls.seen)

    calls = Calls()
    keywords = dict(accuracy="0.7,0.8", task="grid", scenario=None, episodes=6, seed=1,
                    params=None, stream=None, cache=None, threads=1)
    _core.sweep(str(tmp_path / "s"), keywords, progress=calls)
    assert calls.stages() == ["calibrating", "episodes"], calls.seen
    assert calls.seen[-1] == ("episodes", 12, 12)
    check_counts(calls.seen)


@pytest.mark.parametrize("core, accuracy", [("GridEnvCore", 0.7123), ("EpuckEnvCore", 0.8765)])
def test_an_environment_reports_its_calibration_once_per_decoder(core, accuracy):
    # An accuracy no other test asks for: the process keeps decoders by key.
    make = getattr(_core, core)
    calls = Calls()
    make(None, accuracy=accuracy, progress=calls).close()
    assert calls.stages() == ["calibrating"], calls.seen
    check_counts(calls.seen)
    again = Calls()
    make(None, accuracy=accuracy, progress=again).close()
    assert again.seen == [], "a kept decoder is not calibrated again"


def test_the_gymnasium_environments_take_progress():
    from errp.gym import EpuckEnv, GridEnv

    for env in (GridEnv, EpuckEnv):
        with pytest.raises(TypeError, match="progress must be True, False or None"):
            env(progress="yes")


def test_an_exception_in_the_progress_callable_stops_the_work():
    def fail(stage, done, total):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        _core.run(None, runs=50_000, seed=1, progress=fail)


@pytest.mark.parametrize("value", ["yes", 1, 0.5])
def test_progress_takes_a_bool_or_none(value):
    with pytest.raises(TypeError, match="progress must be True, False or None"):
        errp.run(runs=1, progress=value)


def run_python(code):
    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=600
    )


def test_without_tqdm_a_line_per_tenth_goes_to_stderr():
    out = run_python(
        "import sys; sys.modules['tqdm'] = None\n"
        "import errp\n"
        "errp.run(runs=20, seed=1, progress=True)\n"
    )
    assert out.returncode == 0, out.stderr
    lines = out.stderr.splitlines()
    # The core is polled every 50 ms, so which steps of the search show
    # depends on the machine's speed; that some do, with their count, does not.
    assert any(re.match(r"errp\.run: calibrating, step \d+ \[", line) for line in lines), lines
    runs = [line for line in lines if line.startswith("errp.run: runs ")]
    assert 2 <= len(runs) <= 11 and runs[-1].startswith("errp.run: runs 20/20 ["), lines
    assert out.stdout == ""


def test_progress_is_off_by_default_when_stderr_is_not_a_terminal():
    out = run_python("import errp\nerrp.run(runs=5, seed=1)\nerrp.simulate_session(seed=2)\n")
    assert out.returncode == 0, out.stderr
    assert out.stderr == ""


def test_tqdm_bars_when_asked():
    pytest.importorskip("tqdm")
    out = run_python("import errp\nerrp.run(runs=8, seed=1, progress=True)\n")
    assert out.returncode == 0, out.stderr
    assert "errp.run: runs: 100%" in out.stderr and "8/8" in out.stderr, out.stderr
