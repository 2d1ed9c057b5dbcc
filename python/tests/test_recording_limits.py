"""Recordings under pressure: a disk that fills (a file-size limit here)
is an OSError that leaves nothing, two writers of one path are refused,
and a save= that records nothing says so."""

import os
import subprocess
import sys
import threading
import warnings
from pathlib import Path

import gymnasium as gym
import pytest

import errp
import errp.gym  # noqa: F401  (registers the environments)

ROOT = Path(__file__).resolve().parents[2]
GRID = str(ROOT / "scenarios" / "grid_fixed_goals.toml")

FULL = """
import resource, sys
import gymnasium as gym
import errp.gym
limit = int(sys.argv[1])
resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
env = gym.make("errp/Grid-v0", save="g.rrd")
for episode in range(5):
    env.reset(seed=episode)
    for _ in range(10):
        env.step(0)
try:
    env.close()
except OSError as e:
    print("OSError", e)
    sys.exit(3)
"""


@pytest.mark.parametrize("limit", [30_000, 70_000, 90_000, 100_000])
def test_a_full_disk_under_an_environment_is_an_oserror_that_leaves_nothing(tmp_path, limit):
    # 90 kB stops the writer at the recording's very end (its footer), which
    # the SDK only logs; 70 kB mid-way, where its flush used to wait forever.
    p = subprocess.run([sys.executable, "-c", FULL, str(limit)], cwd=tmp_path,
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 3, p.stdout + p.stderr
    assert "g.rrd" in p.stdout and ("File too large" in p.stdout or "end" in p.stdout), p.stdout
    assert os.listdir(tmp_path) == []


def test_two_environments_of_one_path_are_refused_naming_it(tmp_path):
    path = tmp_path / "same.rrd"
    first = gym.make("errp/Grid-v0", save=path)
    with pytest.raises(OSError, match="same.rrd"):
        gym.make("errp/Grid-v0", save=path)
    first.reset(seed=0)
    first.step(0)
    first.close()
    assert sorted(os.listdir(tmp_path)) == ["same.rrd"]


def test_two_threads_saving_one_path_one_is_refused(tmp_path):
    path = tmp_path / "t.rrd"
    errors, barrier = [], threading.Barrier(2)

    def run():
        barrier.wait()
        try:
            errp.run(GRID, overrides={"decoder": "oracle"}, save=path)
        except OSError as e:
            errors.append(str(e))

    threads = [threading.Thread(target=run) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    # Either the second is refused, or they did not overlap at all.
    assert len(errors) <= 1 and all("t.rrd" in e for e in errors), errors
    assert sorted(os.listdir(tmp_path)) == ["t.rrd"]


def test_a_save_that_records_nothing_warns_once_and_writes_nothing(tmp_path):
    env = gym.make("errp/Grid-v0", save=tmp_path / "z.rrd")
    env.reset(seed=0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        env.close()
        env.close()
    said = [str(w.message) for w in caught if "nothing was recorded" in str(w.message)]
    assert len(said) == 1 and "z.rrd" in said[0], said
    assert os.listdir(tmp_path) == []
