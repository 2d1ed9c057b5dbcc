"""A person's recording in the closed loop from Python: an exported session
read by MNE gives the grid's decoder the accuracy it was made at, resampled
and reordered too; the e-puck runs on a hybrid of it; and what cannot be
used is refused naming it."""

import hashlib

import numpy as np
import pytest

import errp

from conftest import cli

mne = pytest.importorskip("mne")

#: Episodes per run: enough for the goals-reached claim, a few seconds.
EPISODES = {"free_goals": {"count": 10}}


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """`errp calibrate --accuracy 0.78 --seed 1 --export s.edf`."""
    path = tmp_path_factory.mktemp("recorded") / "s.edf"
    cli("calibrate", "--quiet", "--accuracy", "0.78", "--seed", "1", "--export", str(path))
    return path


def _task(eeg, **kw):
    return errp.GridTask(eeg=eeg, overrides=EPISODES, progress=False, **kw)


def _check(task):
    cv = task.calibration["cv_mean"]
    assert abs(cv - 0.78) <= 0.03, task.calibration
    df = task.run(progress=False)
    assert df["success"].sum() >= 9, df
    return cv


def test_an_exported_file_read_by_mne_gives_the_accuracy_it_was_made_at(exported):
    task = _task(exported)
    cv = _check(task)
    # The same data through MNE's Raw: the same split, the same decoder.
    raw = mne.io.read_raw_edf(exported, preload=True, verbose="error")
    assert _task(raw).calibration["cv_mean"] == cv
    # Resampled to 512 Hz (and back, by the package) with its channels
    # reordered: the same recording to within resampling.
    moved = raw.copy().resample(512, verbose="error")
    moved.reorder_channels(moved.ch_names[::-1])
    _check(_task(moved))


def test_the_recording_is_named_with_its_digest_in_the_recording(exported, tmp_path):
    if not errp.HAS_RERUN:
        pytest.skip("the package was built without Rerun")
    task = _task(exported)
    task.run(save=tmp_path / "r.rrd", progress=False)
    rec = errp.read_recording(tmp_path / "r.rrd")
    digest = rec.provenance["eeg_recording"]
    want = hashlib.sha256(exported.read_bytes()).hexdigest()
    assert digest == {"name": "s.edf", "bytes": exported.stat().st_size, "sha256": want}


def test_the_epuck_reaches_pisa_on_a_hybrid_read_by_mne(exported, tmp_path):
    task = errp.EpuckTask(eeg=exported, progress=False)
    info = task.calibration
    # T_e set on the held-out hybrid for the paper-fitted user's rate; the
    # control assumes the recording's own cross-validated accuracy.
    assert abs(info["online_false_alarms_per_min"] - 5.37) < 0.3, info
    assert info["accuracy"] == info["cv_mean"] and 0.6 < info["cv_mean"] < 0.8, info
    df = task.run(50, progress=False)
    # As `errp run scenarios/recorded/own_eeg_epuck.toml` on the same file:
    # the data are the file's, so the hybrid and its runs are the same.
    assert df["success"].sum() >= 25, df["success"].sum()
    if errp.HAS_RERUN:
        task.run(1, save=tmp_path / "h.rrd", progress=False)
        digest = errp.read_recording(tmp_path / "h.rrd").provenance["eeg_recording"]
        assert digest["name"] == "s.edf" and digest["bytes"] == exported.stat().st_size
    raw = mne.io.read_raw_edf(exported, preload=True, verbose="error")
    with pytest.raises(ValueError, match="accuracy"):
        errp.EpuckTask(eeg=raw, accuracy=0.9, progress=False)
    with pytest.raises(ValueError, match="eeg_options"):
        errp.EpuckTask(eeg=raw, eeg_options={"draw": "with_replacement"}, progress=False)
    with pytest.raises(ValueError, match="false_alarms_per_min"):
        errp.EpuckTask(eeg=raw, eeg_options={"false_alarms_per_min": 0}, progress=False)


def test_a_sweep_over_recordings_has_one_level_per_file(exported, tmp_path):
    scenario = exported.parent / "own.toml"
    scenario.write_text(
        'task = "grid"\n[free_goals]\ncount = 3\n[eeg]\nrecording = "s.edf"\n'
    )
    result = errp.sweep(
        scenario=scenario, params={"eeg.recording": ["s.edf"]}, episodes=3, progress=False
    )
    assert len(result.summary) == 1
    # The level's accuracy is the one the recording gives.
    assert abs(result.summary["accuracy"][0] - 0.78) <= 0.03, result.summary
    assert set(result.episodes["accuracy"]) == {result.summary["accuracy"][0]}
    with pytest.raises(ValueError, match="accuracy"):
        errp.sweep(scenario=scenario, accuracy=0.8, episodes=3, progress=False)
    with pytest.raises(ValueError, match="accuracy"):
        errp.sweep(task="grid", episodes=3, progress=False)


def test_an_in_memory_session_and_its_epochs_run():
    session = errp.simulate_session(accuracy=0.78, seed=2)
    raw = session.to_mne()
    task = _task(raw, eeg_options={"calibration": 0.6, "draw": "without_replacement"})
    assert task.calibration["cv_mean"] > 0.7, task.calibration
    events, ids = mne.events_from_annotations(raw, verbose="error")
    epochs = mne.Epochs(
        raw, events, ids, tmin=-1.0, tmax=2.0, baseline=None, preload=True, verbose="error"
    )
    task = _task(epochs)
    assert task.calibration["cv_mean"] > 0.65, task.calibration


def test_a_recording_without_eog_channels_runs_without_the_regression(exported):
    raw = mne.io.read_raw_edf(exported, preload=True, verbose="error")
    raw.drop_channels([c for c in raw.ch_names if c.startswith("EOG")])
    task = _task(raw)
    assert task.calibration["cv_mean"] > 0.7, task.calibration
    with pytest.raises(ValueError, match="EOG LA"):
        _task(mne.io.read_raw_edf(exported, preload=True, verbose="error").drop_channels(["EOG LA"]))


def test_what_cannot_be_used_is_refused_naming_it(exported, tmp_path):
    raw = mne.io.read_raw_edf(exported, preload=True, verbose="error")
    no_fcz = raw.copy().drop_channels(["FCz"])
    with pytest.raises(ValueError, match="FCz"):
        _task(no_fcz)
    with pytest.raises(ValueError, match="no events of class error"):
        _task(raw, eeg_options={"error": "S 96"})
    with pytest.raises(ValueError, match="at least 5 of each"):
        _task(raw, eeg_options={"calibration_events": 8})
    short = raw.copy().crop(tmax=60.0)
    with pytest.raises(ValueError, match="calibration part"):
        _task(short)
    text = tmp_path / "text.edf"
    text.write_text("subject 1, session 2\n")
    with pytest.raises(ValueError, match="text.edf"):
        _task(text)
    cut = tmp_path / "cut.edf"
    cut.write_bytes(exported.read_bytes()[: exported.stat().st_size // 2])
    with pytest.raises(ValueError, match="cut.edf: truncated"):
        _task(cut)
    with pytest.raises(ValueError, match="no accuracy is targeted"):
        _task(raw, accuracy=0.7)
    with pytest.raises(ValueError, match="eeg.calibration"):
        _task(raw, eeg_options={"calibration": 1.5})
    with pytest.raises(TypeError, match="mne.io.Raw"):
        _task(np.zeros((8, 100)))
    with pytest.raises(ValueError, match="recording"):
        errp.GridTask(eeg=raw, decoder=lambda x: 0.5, progress=False)
