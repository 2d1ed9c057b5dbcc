"""How fast the closed loop runs with a decoder in Python.

    python python/examples/throughput.py [--quick]

Grid: episodes per second of the fixed-goals scenario with the testbed's
decoder and with a scikit-learn LDA (Platt-scaled) called from the loop,
per epoch (EEG per action: one Python call per action) and once over an
epoch bank (the `batch_decoder`); a callable that returns a constant shows
the cost of the binding itself. E-puck: the real-time factor (simulated
seconds per second of wall time) of the Mexico-to-Pisa run with the
testbed's SVM and with a Python callable of the same size called every
62.5 ms window. Everything on one thread of this machine.
"""

import argparse
import os
import time

os.environ.setdefault("RAYON_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from scipy.special import expit, logit  # noqa: E402
from sklearn.calibration import CalibratedClassifierCV  # noqa: E402
from sklearn.discriminant_analysis import LinearDiscriminantAnalysis  # noqa: E402
from sklearn.pipeline import make_pipeline  # noqa: E402
from sklearn.preprocessing import StandardScaler  # noqa: E402

import errp  # noqa: E402

CH = ["Fz", "FC1", "FCz", "FC2", "C1", "Cz", "C2", "CPz"]


def lda_decoder(session):
    rows = [session.epoch_ch_names.index(c) for c in CH]

    def feats(x):
        x = np.asarray(x)[..., rows, 51:204:4]
        return x.reshape(*x.shape[:-2], -1)

    lda = make_pipeline(StandardScaler(),
                        LinearDiscriminantAnalysis(solver="lsqr", shrinkage="auto"))
    model = CalibratedClassifierCV(lda, method="sigmoid", cv=5)
    model.fit(feats(session.epochs), session.y)
    prior = logit(session.y.mean())

    def p_error(x):
        one = np.ndim(x) == 2
        f = feats(x[None] if one else x)
        p = expit(logit(np.clip(model.predict_proba(f)[:, 1], 1e-9, 1 - 1e-9)) - prior)
        return float(p[0]) if one else p

    return p_error


def timed(f):
    t = time.perf_counter()
    out = f()
    return out, time.perf_counter() - t


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a few episodes only (for CI)")
    args = ap.parse_args()
    repeats, runs = (2, 1) if args.quick else (40, 4)

    session = errp.simulate_session(accuracy=0.7438, seed=1)
    f = lda_decoder(session)
    s = "scenarios/grid_fixed_goals.toml"
    print(f"Grid, fixed goals x {repeats} ({5 * repeats} episodes), one thread:")
    rows = [
        ("testbed LDA, epoch bank", dict(overrides={"repeats": repeats, "eeg": "bank"})),
        ("testbed LDA, EEG per action", dict(overrides={"repeats": repeats, "eeg": "per_action"})),
        ("Python constant per epoch", dict(decoder=lambda x: 0.3,
                                           overrides={"repeats": repeats})),
        ("Python LDA per epoch, streamed", dict(decoder=f, overrides={"repeats": repeats})),
        ("Python LDA batch over the bank", dict(batch_decoder=f,
                                                overrides={"repeats": repeats, "eeg": "bank"})),
    ]
    for name, kw in rows:
        task, prep = timed(lambda: errp.GridTask(s, **kw))
        df, secs = timed(task.run)
        print(f"  {name:<32} {len(df) / secs:9.1f} episodes/s  "
              f"({df.actions.sum() / secs:8.0f} actions/s; preparing {prep:.1f} s)")

    print(f"E-puck, Mexico to Pisa, {runs} run(s), one thread:")
    window_rows = [CH.index(c) for c in CH]

    def per_window(x):
        return f(np.asarray(x)[window_rows, 1:])

    for name, kw in [("testbed SVM", {}), ("Python constant per window", {"decoder": lambda x: 0.1}),
                     ("Python LDA per window", {"decoder": per_window})]:
        task = errp.EpuckTask(**kw)
        df, secs = timed(lambda: task.run(runs))
        sim = df.time_secs.sum()
        print(f"  {name:<32} {sim / secs:9.1f} x real time  "
              f"({sim / 0.0625 / secs:8.0f} windows/s)")


if __name__ == "__main__":
    main()
