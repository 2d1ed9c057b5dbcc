"""Synthetic EEG: the calibration session as MNE reads it, and the
streaming generator."""

import numpy as np
import pytest

import errp


def test_mne_reads_the_session(session):
    mne = pytest.importorskip("mne")
    raw = session.to_mne()
    assert isinstance(raw, mne.io.RawArray)
    assert raw.info["sfreq"] == 256.0
    assert len(raw.ch_names) == 40
    assert raw.ch_names == session.ch_names
    types = raw.get_channel_types()
    assert types.count("eeg") == 34 and types.count("eog") == 6
    assert "FCz" in raw.ch_names and "C1" in raw.ch_names and "C2" in raw.ch_names
    # One annotation per action: 400, about 20 % errors.
    assert len(raw.annotations) == 400
    n_err = sum(d == "error" for d in raw.annotations.description)
    assert 50 <= n_err <= 110
    # Volts in MNE, microvolts in the arrays.
    np.testing.assert_allclose(raw.get_data(picks=[0])[0] * 1e6, session.data[0])
    events, ids = mne.events_from_annotations(raw, verbose="error")
    assert len(events) == 400 and set(ids) == {"error", "correct"}


def test_the_epochs_hold_the_errp(session):
    x, y = session.epochs, session.y
    assert x.dtype == np.float32 and x.ndim == 3
    assert x.shape[1] == len(session.epoch_ch_names) == 8
    assert x.shape[0] == len(y) == 400
    assert x.shape[2] == len(session.epoch_times)
    # The error-minus-correct average at FCz has its negativity near 250 ms
    # and its positivity near 350 ms (Fig. 1), both clear of the noise.
    fcz = session.epoch_ch_names.index("FCz")
    t = session.epoch_times
    diff = x[y, fcz].mean(0) - x[~y, fcz].mean(0)
    neg = t[np.argmin(diff[(t > 0.15) & (t < 0.32)]) + np.argmax(t > 0.15)]
    pos = t[np.argmax(diff[(t > 0.28) & (t < 0.45)]) + np.argmax(t > 0.28)]
    assert 0.18 < neg < 0.32 and 0.28 < pos < 0.45
    noise = x[~y, fcz].std(0).mean() / np.sqrt((~y).sum())
    assert diff.max() - diff.min() > 6 * noise


def test_without_mne_the_arrays_are_there(session):
    assert session.data.shape == (40, session.data.shape[1])
    assert session.data.shape[1] / session.sfreq > 400 * 3.0
    assert np.all(np.diff(session.onsets) >= 3.0 - 1e-9)
    assert 0.5 < session.cv_mean < 1 and abs(session.cv_mean - 0.7438) < 0.02


def test_same_seed_same_session():
    a = errp.simulate_session(accuracy=0.8, seed=5)
    b = errp.simulate_session(accuracy=0.8, seed=5)
    np.testing.assert_array_equal(a.data, b.data)
    assert a.errp_to_noise == b.errp_to_noise


@pytest.mark.parametrize("accuracy", [0.5, 1.0, 1.2, float("nan")])
def test_a_bad_accuracy_names_the_field(accuracy):
    with pytest.raises(ValueError, match="accuracy.*strictly between 0.5"):
        errp.simulate_session(accuracy=accuracy)


def test_the_generator_carries_its_state_across_blocks():
    g1 = errp.EegGenerator(seed=3, errp_to_noise=2.0)
    g2 = errp.EegGenerator(seed=3, errp_to_noise=2.0)
    for g in (g1, g2):
        g.schedule(1.5, "error")
        g.schedule(6.0, "correct")
    whole = g1.generate(2560)
    parts = np.concatenate([g2.generate(256) for _ in range(10)], axis=1)
    np.testing.assert_array_equal(whole, parts)
    assert whole.shape == (40, 2560) and g1.now_secs == 10.0
    assert g1.ch_types == ["eeg"] * 34 + ["eog"] * 6 and g1.sfreq == 256.0


def test_the_generator_puts_the_errp_where_it_is_scheduled():
    fcz = errp.EegGenerator().ch_names.index("FCz")
    n = 256 * 3
    avg = {}
    for kind in ("error", "correct"):
        trials = []
        for seed in range(40):
            g = errp.EegGenerator(seed=seed, errp_to_noise=3.0, params={"blink_rate_hz": 0.0})
            g.schedule(1.0, kind)
            trials.append(g.generate(n)[fcz, 256:512])
        avg[kind] = np.mean(trials, axis=0)
    diff = avg["error"] - avg["correct"]
    t = np.arange(256) / 256
    assert 0.18 < t[np.argmin(diff[:90])] < 0.34


def test_generator_errors_name_the_field():
    g = errp.EegGenerator()
    with pytest.raises(ValueError, match="kind"):
        g.schedule(1.0, "wrong")
    with pytest.raises(ValueError, match="onset_secs"):
        g.schedule(-1.0, "error")
    with pytest.raises(ValueError, match="n_samples"):
        g.generate(10**9)
    with pytest.raises(ValueError, match="errp_to_noise"):
        errp.EegGenerator(errp_to_noise=-1.0)
    with pytest.raises(ValueError, match="params"):
        errp.EegGenerator(params={"no_such_field": 1.0})
