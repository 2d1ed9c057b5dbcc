"""Bad input raises a ValueError (an OSError for files) that names the
field, the value and what is accepted, and leaves no file behind."""

import pytest

import errp


def test_scenario_fields_are_named(root, tmp_path):
    s = str(root / "scenarios/grid_fixed_goals.toml")
    with pytest.raises(ValueError, match=r"control\.tau.*abc.*expected a number"):
        errp.run(s, overrides={"control.tau": "abc"})
    with pytest.raises(ValueError, match="accuracy"):
        errp.run(s, accuracy=1.5)
    with pytest.raises(ValueError, match="runs: applies to e-puck"):
        errp.run(s, runs=3)
    with pytest.raises(ValueError, match="runs = 0"):
        errp.run(runs=0)
    with pytest.raises(ValueError, match="overrides.*set twice"):
        errp.run(s, accuracy=0.8, overrides={"user.accuracy": 0.7})
    with pytest.raises(ValueError, match=r"overrides\[\"control.tau\"\]"):
        errp.run(s, overrides={"control.tau": object()})


def test_files_are_named(tmp_path):
    missing = tmp_path / "nope.toml"
    with pytest.raises(OSError, match="nope.toml"):
        errp.run(missing)
    with pytest.raises(ValueError, match=r"save = .*expected a file name ending in \.rrd"):
        errp.run(save=tmp_path / "run.txt")
    assert list(tmp_path.iterdir()) == []


def test_sweep_arguments_are_named(tmp_path):
    out = tmp_path / "s"
    with pytest.raises(ValueError, match="accuracy"):
        errp.sweep(out, task="grid", accuracy="abc")
    with pytest.raises(ValueError, match="task"):
        errp.sweep(out, task="maze", accuracy=0.7)
    with pytest.raises(ValueError, match="episodes"):
        errp.sweep(out, task="grid", accuracy=0.7, episodes=0)
    with pytest.raises(ValueError, match="params"):
        errp.sweep(out, task="grid", accuracy=0.7, params={"no_such": [1]})
    with pytest.raises(ValueError, match="stream= applies to the grid"):
        errp.sweep(out, task="epuck", accuracy=0.8, stream=True)
    with pytest.raises(ValueError, match="give scenario= FILE.toml, or task="):
        errp.sweep(out, accuracy=0.7)
    assert not out.exists()


def test_episode_columns_name_the_task():
    assert errp.episode_columns("grid")[:2] == ["success", "start_x"]
    with pytest.raises(ValueError, match="task"):
        errp.episode_columns("maze")


def test_a_recording_is_written_when_asked(tmp_path, root):
    if not errp.HAS_RERUN:
        pytest.skip("built without Rerun")
    rrd = tmp_path / "grid.rrd"
    df = errp.run(root / "scenarios/grid_fixed_goals.toml", seed=1, save=rrd)
    assert len(df) == 5 and rrd.stat().st_size > 10_000
    rr = pytest.importorskip("rerun")
    assert rr is not None
