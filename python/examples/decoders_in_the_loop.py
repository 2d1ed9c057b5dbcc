"""Your own decoder in the closed loop: scikit-learn's shrinkage LDA and a
pyRiemann pipeline, trained on a simulated calibration session, then run the
grid task, compared with the testbed's own decoder at the same accuracy,
built in and fitted from Python (errp.decoders).

    python python/examples/decoders_in_the_loop.py [--repeats 20] [--seed 1]

Every decoder sees the same synthetic user (ErrP-to-noise ratio targeted for
74.38 %, seed 1) and the same epochs of preprocessed EEG. The closed loop
needs a calibrated p(error): each classifier's probabilities are Platt-scaled
by cross-validation and the session's 20 % error prior is taken out, as the
testbed does for its own decoder (an uncalibrated LDA is overconfident, and
the belief then converges fast on wrong goals).
"""

import argparse
import time

import numpy as np
from scipy.special import expit, logit
from sklearn.calibration import CalibratedClassifierCV
from sklearn.discriminant_analysis import LinearDiscriminantAnalysis
from sklearn.linear_model import LogisticRegression
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

import errp
from errp.decoders import TemporalFeatures, discrete_decoder


class Calibrated:
    """A classifier's p(error), Platt-scaled by 5-fold cross-validation, with
    the training prior removed."""

    def __init__(self, estimator, x, y, transform=None):
        self.transform = transform or (lambda e: e)
        self.model = CalibratedClassifierCV(estimator, method="sigmoid", cv=5)
        self.model.fit(self.transform(x), y)
        self.prior = logit(y.mean())

    def __call__(self, epochs):
        p = self.model.predict_proba(self.transform(epochs))[:, 1]
        return expit(logit(np.clip(p, 1e-9, 1 - 1e-9)) - self.prior)


def summary(name, df, secs):
    ok = df[df.success == 1]
    acc = (df.acc_correct.mean() + df.acc_error.mean()) / 2
    print(
        f"{name:<38} reached {df.success.mean():6.1%}  actions {ok.actions.mean():5.1f} "
        f"+- {ok.actions.std():4.1f}  online accuracy {acc:6.2%}  ({secs:.1f} s)"
    )


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=20, help="repeats of the 5 start/goal pairs")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()

    session = errp.simulate_session(accuracy=0.7438, seed=args.seed)
    x, y = session.epochs, session.y
    print(
        f"Calibration session: {len(y)} actions ({y.sum()} errors), {x.shape[1]} channels x "
        f"{x.shape[2]} samples per epoch; the testbed's LDA: {session.cv_mean:.2%} "
        f"(cross-validated)"
    )

    # The testbed's decoder fitted from Python: the paper's features, z-score,
    # PCA, shrinkage LDA, and the loop's Platt scaling (prior removed).
    ours = discrete_decoder(random_state=args.seed).fit(x, y)
    decoders = {
        "errp.decoders (LDA, Platt) from Python": lambda e: ours.predict_proba(e)[:, 1],
        "scikit-learn shrinkage LDA": Calibrated(
            make_pipeline(TemporalFeatures(), StandardScaler(),
                          LinearDiscriminantAnalysis(solver="lsqr", shrinkage="auto")),
            x, y,
        ),
    }
    try:
        from pyriemann.estimation import XdawnCovariances
        from pyriemann.tangentspace import TangentSpace

        decoders["pyRiemann Xdawn + tangent space + LR"] = Calibrated(
            make_pipeline(XdawnCovariances(nfilter=2, estimator="oas"),
                          TangentSpace(metric="riemann"),
                          LogisticRegression(max_iter=1000)),
            x.astype(np.float64), y,
            transform=lambda e: np.asarray(e, dtype=np.float64),
        )
    except ImportError:
        print("(pyRiemann is not installed: pip install pyriemann)")

    # The idealised user, the session's (errp.simulate_session simulates it),
    # so that every decoder is trained and used on one user.
    scenario = "scenarios/variants/grid_fixed_goals_ideal.toml"
    overrides = {"repeats": args.repeats, "eeg": "bank"}
    t = time.perf_counter()
    builtin = errp.GridTask(scenario, overrides=overrides, seed=args.seed)
    summary("the testbed's decoder (LDA, Platt)", builtin.run(), time.perf_counter() - t)
    for name, decode in decoders.items():
        t = time.perf_counter()
        task = errp.GridTask(scenario, batch_decoder=decode, overrides=overrides, seed=args.seed)
        summary(name, task.run(), time.perf_counter() - t)


if __name__ == "__main__":
    main()
