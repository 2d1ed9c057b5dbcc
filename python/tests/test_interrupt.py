"""Ctrl-C stops a long call that runs in Rust within a second, raises
KeyboardInterrupt, and leaves no partial file: the call is started in a
fresh interpreter, SIGINT is sent 3 s later (during the calibration or the
episodes), and the process must be gone, with KeyboardInterrupt, within a
second of the signal. Each call runs beside one busy process per core, as
on a machine that runs other work (a sweep uses every core itself, so its
users are always on a busy one)."""

import os
import signal
import subprocess
import sys
import time

import pytest

CALLS = {
    "run": "errp.run(runs=20000, seed=1)",
    "run-progress": "errp.run(runs=20000, seed=1, progress=True)",
    "run-save": "errp.run(runs=100, seed=1, save='run.rrd')",
    "sweep": "errp.sweep('sweep', task='grid', accuracy='0.6:0.9:0.05', episodes=200000, seed=1)",
    "GridTask.run": "errp.GridTask(overrides={'repeats': 10000, 'eeg': 'stream'}).run()",
    "simulate_session": "[errp.simulate_session(seed=s) for s in range(1, 100)]",
}


@pytest.fixture
def busy_machine():
    """One process spinning on each core until the test ends."""
    hogs = [
        subprocess.Popen([sys.executable, "-c", "while True: pass"])
        for _ in range(os.cpu_count() or 2)
    ]
    yield
    for hog in hogs:
        hog.kill()
        hog.wait()


@pytest.mark.parametrize("name", CALLS)
def test_ctrl_c_stops_a_long_call_within_a_second(name, tmp_path, busy_machine):
    code = f"import errp\nprint('ready', flush=True)\n{CALLS[name]}\n"
    # A shell that starts pytest in the background without job control
    # leaves SIGINT ignored, and Python then never raises
    # KeyboardInterrupt: the child gets the default disposition back, as a
    # terminal's process has.
    p = subprocess.Popen(
        [sys.executable, "-c", code], cwd=tmp_path,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    assert p.stdout.readline().strip() == "ready"
    time.sleep(3.0)
    assert p.poll() is None, f"{name} ended before the signal: {p.communicate()}"
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=60)
    elapsed = time.monotonic() - sent
    assert "KeyboardInterrupt" in err, err
    assert elapsed < 1.0, f"{name}: {elapsed:.2f} s from the signal to the exit"
    # No recording, no temporary; a sweep keeps the rows it wrote, whole.
    left = sorted(q.name for q in tmp_path.iterdir())
    if name == "sweep":
        assert left in ([], ["sweep"]), left
    else:
        assert left == [], left
