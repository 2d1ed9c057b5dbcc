"""Decoders of the user's own in the closed loop: a scikit-learn LDA trained
on the simulated calibration session runs the grid as the testbed's own
decoder does at the same accuracy; callables are called as documented, and
their mistakes are reported by name."""

import numpy as np
import pytest

import errp

CHANNELS = ["Fz", "FC1", "FCz", "FC2", "C1", "Cz", "C2", "CPz"]


def features(x, ch_names):
    """The paper's features: 8 fronto-central channels, [200, 800] ms at
    64 Hz. `x`: (n_channels, n_samples) or (n_epochs, n_channels,
    n_samples), from the onset at 256 Hz."""
    rows = [ch_names.index(c) for c in CHANNELS]
    x = np.asarray(x)[..., rows, 51::4]
    return x.reshape(*x.shape[:-2], -1)


class PlattLda:
    """scikit-learn's shrinkage LDA with Platt scaling fitted by
    cross-validation and the session's 20 % error prior removed: a
    calibrated p(error), as the testbed's own decoder gives."""

    def __init__(self, session):
        from scipy.special import logit
        from sklearn.calibration import CalibratedClassifierCV
        from sklearn.discriminant_analysis import LinearDiscriminantAnalysis
        from sklearn.pipeline import make_pipeline
        from sklearn.preprocessing import StandardScaler

        lda = make_pipeline(
            StandardScaler(), LinearDiscriminantAnalysis(solver="lsqr", shrinkage="auto")
        )
        x, y = features(session.epochs, session.epoch_ch_names), session.y
        self.names = session.epoch_ch_names
        self.model = CalibratedClassifierCV(lda, method="sigmoid", cv=5).fit(x, y)
        self.prior_logit = logit(y.mean())

    def __call__(self, x):
        """p(error) of epochs (n, n_channels, n_samples) or of one epoch."""
        from scipy.special import expit, logit

        one = np.ndim(x) == 2
        f = features(x[None] if one else x, self.names)
        p = np.clip(self.model.predict_proba(f)[:, 1], 1e-9, 1 - 1e-9)
        p = expit(logit(p) - self.prior_logit)
        return float(p[0]) if one else p


@pytest.fixture(scope="module")
def lda(session):
    pytest.importorskip("sklearn")
    return PlattLda(session)


def summary(df):
    ok = df[df.success == 1]
    return {
        "success": df.success.mean(),
        "actions": ok.actions.mean(),
        "accuracy": (df.acc_correct.mean() + df.acc_error.mean()) / 2,
    }


REPEATS = {"repeats": 20, "eeg": "bank"}


def test_an_sklearn_lda_in_the_loop_matches_the_builtin_decoder(lda, session, root):
    # The idealised user, as the session's (errp.simulate_session simulates
    # it unless given a realism table).
    scenario = root / "scenarios/variants/grid_fixed_goals_ideal.toml"
    builtin = errp.GridTask(scenario, overrides=REPEATS)
    # The same user: the session and the task's calibration share the seed
    # and target the same accuracy, the session by cross-validation and the
    # grid task online (held-out epochs), which reads a little higher at a
    # ratio: the ratios differ by a few hundredths.
    assert abs(builtin.calibration["errp_to_noise"] - session.errp_to_noise) < 0.1
    names = builtin.ch_names
    assert names == session.epoch_ch_names and builtin.n_samples == session.epochs.shape[2]

    def batch(x):
        assert x.ndim == 3 and x.shape[1:] == (8, builtin.n_samples)
        return lda(x)

    mine = errp.GridTask(scenario, batch_decoder=batch, overrides=REPEATS)
    a, b = summary(builtin.run()), summary(mine.run())
    assert len(mine.run()) == 100
    # At a matched accuracy, the same success and about the same effort.
    assert abs(a["accuracy"] - b["accuracy"]) < 0.05, (a, b)
    assert a["success"] > 0.9 and b["success"] > 0.9, (a, b)
    assert abs(a["actions"] - b["actions"]) < 0.3 * a["actions"], (a, b)

    # A decoder that knows nothing converges rarely and slowly: the
    # tolerances above tell a working decoder from a broken one.
    blind = errp.GridTask(scenario, batch_decoder=lambda x: np.full(len(x), 0.5),
                          overrides=REPEATS)
    c = summary(blind.run())
    assert c["success"] < 0.5 or c["actions"] > 2 * a["actions"], c


def test_a_per_epoch_decoder_sees_every_action(lda, root):
    calls = []

    def f(x):
        calls.append(x.shape)
        assert task.ch_names == lda.names
        return lda(x)

    task = errp.GridTask(root / "scenarios/variants/grid_fixed_goals_ideal.toml", decoder=f)
    df = task.run()
    assert len(calls) == df.actions.sum() == task.decoder_calls
    assert set(calls) == {(8, task.n_samples)}
    assert task.sfreq == 256.0
    assert df.success.mean() >= 0.6
    # Same seed, same decoder: the same episodes.
    calls.clear()
    again = task.run()
    assert again.equals(df)


def test_decoder_mistakes_are_reported(root):
    scenario = root / "scenarios/grid_fixed_goals.toml"
    with pytest.raises(ValueError, match=r"decoder: returned p\(error\) = 2"):
        errp.GridTask(scenario, decoder=lambda x: 2.0).run()
    with pytest.raises(ValueError, match="decoder: returned 'no'"):
        errp.GridTask(scenario, decoder=lambda x: "no").run()

    class Oops(RuntimeError):
        pass

    def raising(x):
        raise Oops("from the decoder")

    with pytest.raises(Oops, match="from the decoder"):
        errp.GridTask(scenario, decoder=raising).run()
    with pytest.raises(ValueError, match="batch_decoder.*one per epoch"):
        errp.GridTask(scenario, batch_decoder=lambda x: np.zeros(3))
    with pytest.raises(ValueError, match="batch_decoder: p\\(error\\) of epoch 0"):
        errp.GridTask(scenario, batch_decoder=lambda x: np.full(len(x), -1.0))
    with pytest.raises(ValueError, match="decoder: expected a callable"):
        errp.GridTask(scenario, decoder=3)
    with pytest.raises(ValueError, match="oracle"):
        errp.GridTask(scenario, decoder=lambda x: 0.5, overrides={"decoder": "oracle"})
    with pytest.raises(ValueError, match="e-puck scenario; errp.GridTask needs a grid scenario"):
        errp.GridTask(root / "scenarios/mexico_to_pisa.toml")


def test_an_epuck_decoder_is_called_every_window(root):
    seen = []

    def f(x):
        seen.append(x.shape)
        return 0.0

    task = errp.EpuckTask(root / "scenarios/mexico_to_pisa.toml", decoder=f,
                          overrides={"max_secs": 30.0})
    df = task.run(runs=2)
    assert len(df) == 2
    windows = np.round(df.time_secs / 0.0625).sum()
    assert len(seen) == windows == task.decoder_calls
    assert set(seen) == {(8, task.n_samples)} and task.n_samples == 205
    # It never reports an error: the robot never stops for one.
    assert df.detected.sum() == 0
    assert task.t_e == 0.8
    with pytest.raises(ValueError, match="runs"):
        task.run(runs=0)
