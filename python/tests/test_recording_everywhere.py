"""Every way of running the testbed records: `GridTask.run`, `EpuckTask.run`
and the Gymnasium environments take `save=`; their recordings are read back
by `errp inspect` and `errp.read_recording` with each run as it happened,
and `render_mode="rgb_array"` feeds Gymnasium's `RecordVideo`."""

import numpy as np
import pytest

import errp
from conftest import cli

pytestmark = pytest.mark.skipif(not errp.HAS_RERUN, reason="built without Rerun")
gym = pytest.importorskip("gymnasium")
import errp.gym  # noqa: E402  (registers the environments)


def _cell(c):
    """A cell of the runs table, "(x, y)", or None for no commitment."""
    if not isinstance(c, str) or c in ("", "-"):
        return None
    return tuple(int(v) for v in c.strip("()").split(","))


def test_grid_env_records_each_episode_as_a_run(tmp_path):
    rrd = tmp_path / "grid_env.rrd"
    env = gym.make("errp/Grid-v0", goal=(3, 1), save=rrd)
    rng = np.random.default_rng(0)
    seen = []
    for ep in range(4):
        obs, info = env.reset(seed=ep)
        start = tuple(int(v) for v in obs["cursor"])
        n, errors, decoded = 0, 0, 0
        while True:
            # Random moves, then "goal reached"; episode 3 is cut short by
            # the reset after 5 moves (no commitment).
            a = 4 if (n >= 12 and ep != 3) else int(rng.integers(0, 4))
            obs, _, term, trunc, info = env.step(a)
            n += 1
            errors += info["error"]
            decoded += info["decoded_error"]
            if term or trunc or (ep == 3 and n == 5):
                break
        committed = tuple(int(v) for v in obs["cursor"]) if term else None
        seen.append((start, n, committed, info["success"], errors))
    assert not rrd.exists()  # written on close, not before
    env.close()
    rec = errp.read_recording(rrd)
    assert rec.provenance["runs"] == 4
    assert "errp.gym.GridEnv" in rec.provenance["agent"]
    runs = rec.runs
    assert [_cell(c) for c in runs.start] == [s[0] for s in seen]
    assert list(runs.actions) == [s[1] for s in seen]
    assert [_cell(c) for c in runs.committed] == [s[2] for s in seen]
    assert list(runs.reached) == [s[3] for s in seen]
    # The user's judgements are recorded action by action.
    assert rec.actions.groupby("run").error.sum().tolist() == [s[4] for s in seen]
    # The program reads it too, and says who drove.
    out = cli("inspect", str(rrd))
    assert "driven by: an agent" in out and "4 run(s)" in out


def test_epuck_env_records_each_episode_as_a_run(tmp_path):
    rrd = tmp_path / "epuck_env.rrd"
    env = gym.make("errp/Epuck-v0", goal="Pisa", save=rrd, max_episode_steps=40)
    rng = np.random.default_rng(3)
    seen = []
    for ep in range(3):
        env.reset(seed=10 + ep)
        detected = 0
        while True:
            obs, _, term, trunc, info = env.step(int(rng.integers(0, 3)))
            detected += int(obs["detected"])
            if term or trunc:
                break
        seen.append((info["time_secs"], term, detected))
    env.close()
    rec = errp.read_recording(rrd)
    assert rec.provenance["runs"] == 3 and "EpuckEnv" in rec.provenance["agent"]
    runs = rec.runs
    # Each truncated episode is a run of its length, without a commitment.
    assert np.allclose(runs.time_s, [s[0] for s in seen], atol=1 / 64)
    assert all(t == pytest.approx(40 * 0.25) for t, _, _ in seen)
    assert list(runs.reached) == [False] * 3
    # Actions with a detection (each action is 4 windows) against the
    # windows the recording says were detected.
    per_run = rec.detections.groupby("run").size().reindex([1, 2, 3], fill_value=0)
    for (_, _, actions_with), windows in zip(seen, per_run):
        assert actions_with <= windows <= 4 * actions_with
    # One trajectory row per physics step, the whole episode long.
    assert rec.trajectory.groupby("run").size().tolist() == [640, 640, 640]
    out = cli("inspect", str(rrd), "--figure", str(tmp_path / "f.png"))
    assert "driven by: an agent" in out
    assert (tmp_path / "f.png").stat().st_size > 10_000


def test_epuck_env_stopping_on_a_goal_commits(tmp_path):
    rrd = tmp_path / "commit.rrd"
    env = errp.gym.EpuckEnv(goal="Pisa", save=rrd, windows_per_action=2)
    env.reset(seed=0)
    # The robot starts on Mexico (the scenario's start): stopping at once
    # commits to it, a wrong goal.
    _, _, term, _, info = env.step(3)
    assert term and info["committed"] == "Mexico" and not info["success"]
    env.close()
    rec = errp.read_recording(rrd)
    assert rec.runs.converged_on.tolist() == ["Mexico"]
    assert rec.runs.time_s.tolist() == [pytest.approx(0.125)]
    assert "stopped on Mexico (a wrong goal)" in rec.events.text.tolist()


def test_tasks_record_with_the_callers_decoder(tmp_path):
    calls = []

    def decoder(epoch):
        calls.append(1)
        return 0.9 if epoch[:, -10:].mean() > 0 else 0.1

    task = errp.GridTask(overrides={"decoder": "eeg", "repeats": 1}, decoder=decoder, seed=2)
    rrd = tmp_path / "task_grid.rrd"
    df = task.run(save=rrd)
    rec = errp.read_recording(rrd)
    assert list(rec.runs.actions) == list(df.actions)
    assert list(rec.runs.reached) == list(df.success.astype(bool))
    assert "decoder of the caller's own" in " ".join(rec.provenance["command"])
    assert task.decoder_calls == int(df.actions.sum())

    etask = errp.EpuckTask(seed=3)
    rrd = tmp_path / "task_epuck.rrd"
    df = etask.run(2, save=rrd)
    rec = errp.read_recording(rrd)
    assert np.allclose(rec.runs.time_s, df.time_secs, atol=1 / 64)
    assert list(rec.runs.detected) == list(df.detected)
    # The same runs as without a recording.
    again = etask.run(2)
    assert list(again.time_secs) == list(df.time_secs)
    # Too many runs for one file: refused before anything is run or written.
    big = tmp_path / "big.rrd"
    with pytest.raises(ValueError, match=r"save with 101 runs: a recording holds at most 100"):
        etask.run(101, save=big)
    assert not big.exists()


def test_save_refuses_what_errp_did_not_write(tmp_path):
    foreign = tmp_path / "notes.rrd"
    foreign.write_text("my notes")
    with pytest.raises(ValueError, match="not a Rerun recording"):
        errp.gym.GridEnv(save=foreign)
    with pytest.raises(ValueError, match="ending in .rrd"):
        errp.gym.GridEnv(save=tmp_path / "x.txt")
    assert foreign.read_text() == "my notes"
    assert not (tmp_path / "x.txt").exists()
    # An environment closed before any step writes nothing.
    env = errp.gym.GridEnv(save=tmp_path / "empty.rrd")
    env.reset(seed=0)
    env.close()
    assert not (tmp_path / "empty.rrd").exists()


def test_record_video_of_an_episode(tmp_path):
    pytest.importorskip("moviepy")
    from gymnasium.wrappers import RecordVideo

    env = gym.make("errp/Epuck-v0", render_mode="rgb_array", max_episode_steps=24)
    assert env.metadata["render_fps"] == 4
    env = RecordVideo(env, str(tmp_path / "videos"), episode_trigger=lambda e: True)
    env.reset(seed=0)
    frames = [env.render()]
    while True:
        _, _, term, trunc, _ = env.step(0)
        if term or trunc:
            break
    env.close()
    videos = list((tmp_path / "videos").glob("*.mp4"))
    assert len(videos) == 1 and videos[0].stat().st_size > 5_000
    frame = frames[0]
    assert frame.shape == (400, 400, 3) and frame.dtype == np.uint8
    # The arena is drawn: cities (grey), the goal ring (red), the robot.
    assert (frame == [150, 150, 150]).all(axis=2).sum() > 25 * 50
    assert (frame == [220, 40, 40]).all(axis=2).sum() > 50
    assert (frame == [30, 30, 30]).all(axis=2).sum() > 100

    grid = errp.gym.GridEnv(render_mode="rgb_array", goal=(3, 1), start=(0, 0))
    grid.reset(seed=0)
    for a in (3, 3, 0):
        grid.step(a)
    g = grid.render()
    assert g.shape == (340, 320, 3)
    # Four cells visited (start included) are shaded; the cursor at (2, 1).
    shaded = [(x, y) for x in range(5) for y in range(5) if g[(4 - y) * 64 + 10, x * 64 + 10, 0] < 250]
    assert sorted(shaded) == [(0, 0), (1, 0), (2, 0), (2, 1)]
    assert (g[(4 - 1) * 64 + 32, 2 * 64 + 32] == [30, 30, 30]).all()


def test_an_environment_never_closed_still_writes_its_recording(tmp_path):
    import gc

    rrd = tmp_path / "forgotten.rrd"
    env = errp.gym.GridEnv(save=rrd, goal=(1, 1), start=(0, 0))
    env.reset(seed=0)
    env.step(3)
    env.step(0)
    env.step(4)
    del env
    gc.collect()
    rec = errp.read_recording(rrd)
    assert list(rec.runs.actions) == [3] and list(rec.runs.reached) == [True]
