"""Cross-validating the testbed's decoder against pipelines of your own on
the same epochs, as MOABB does: the paper's decoder from errp.decoders,
scikit-learn's shrinkage LDA and a pyRiemann pipeline.

    python python/examples/cross_validate_decoders.py [--seed 1] [--draws 20]
    python python/examples/cross_validate_decoders.py --seeds 12 [--draws 10]

First the session's own cross-validation is repeated through scikit-learn
(its folds are session.cv_folds): the accuracy is the one the session
reports, for the discrete decoder and for the continuous one on its own
button-locked session. Then every decoder is scored on `--draws` draws of shuffled
stratified 10-fold cross-validation; the accuracy is the paper's, the mean
of the two classes' rates (scikit-learn's balanced accuracy).

With --seeds K, sessions of seeds 1 to K instead: for each, the accuracy
the session reports (one draw of folds, the one its accuracy targeting
used) against the mean over --draws other draws, for the testbed's decoder.
A targeting that picked favourable draws would show a positive mean
difference.
"""

import argparse

import numpy as np
from sklearn.discriminant_analysis import LinearDiscriminantAnalysis
from sklearn.metrics import balanced_accuracy_score
from sklearn.model_selection import PredefinedSplit, StratifiedKFold, cross_val_predict
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

import errp
from errp.decoders import ShrinkageLDA, TemporalFeatures, continuous_decoder, discrete_decoder


def draws(pipeline, x, y, n):
    """Balanced accuracy over `n` draws of shuffled stratified 10-fold CV."""
    return [
        balanced_accuracy_score(
            y,
            cross_val_predict(pipeline, x, y, cv=StratifiedKFold(10, shuffle=True, random_state=k)),
        )
        for k in range(n)
    ]


def across_seeds(seeds, n):
    print(f"seed  reported  mean of {n} draws  SD      reported - mean")
    diffs = []
    for seed in range(1, seeds + 1):
        session = errp.simulate_session(accuracy=0.7438, seed=seed)
        scores = draws(make_pipeline(TemporalFeatures(), ShrinkageLDA()), session.epochs,
                       session.y, n)
        diffs.append(session.cv_mean - np.mean(scores))
        print(f"{seed:4d}  {session.cv_mean:.4f}    {np.mean(scores):.4f}            "
              f"{np.std(scores, ddof=1):.4f}  {diffs[-1]:+.4f}")
    print(f"mean difference {np.mean(diffs):+.4f} (standard error "
          f"{np.std(diffs, ddof=1) / np.sqrt(len(diffs)):.4f}, {seeds} seeds)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1, help="seed of the session")
    ap.add_argument("--draws", type=int, default=20, help="draws of shuffled 10-fold CV")
    ap.add_argument("--seeds", type=int, default=0,
                    help="compare the reported accuracy with the draws over seeds 1..K")
    args = ap.parse_args()
    if args.seeds:
        across_seeds(args.seeds, args.draws)
        return

    session = errp.simulate_session(accuracy=0.7438, seed=args.seed)
    x, y = session.epochs, session.y
    same = cross_val_predict(discrete_decoder(), x, y, cv=PredefinedSplit(session.cv_folds))
    print(f"session (seed {args.seed}): {len(y)} actions, {y.sum()} errors")
    print(f"  the session's accuracy (cv_mean):                    {session.cv_mean:.4f}")
    print(
        "  errp.decoders on session.epochs, the session's folds: "
        f"{balanced_accuracy_score(y, same):.4f}"
    )
    # The continuous decoder (RBF SVM on 800 ms windows), on its own
    # button-locked session (sec. 5.1).
    cont = errp.simulate_session(accuracy=0.7438, seed=args.seed, protocol="continuous")
    same = cross_val_predict(
        continuous_decoder(), cont.epochs, cont.y, cv=PredefinedSplit(cont.cv_folds)
    )
    print(f"continuous session (seed {args.seed}): {len(cont.y)} windows, {cont.y.sum()} errors")
    print(f"  the session's accuracy (cv_mean):                    {cont.cv_mean:.4f}")
    print(
        "  errp.decoders on session.epochs, the session's folds: "
        f"{balanced_accuracy_score(cont.y, same):.4f}"
    )

    decoders = {
        "errp.decoders (z-score, PCA, shrinkage LDA)": make_pipeline(
            TemporalFeatures(), ShrinkageLDA()
        ),
        "scikit-learn (z-score, shrinkage LDA)": make_pipeline(
            TemporalFeatures(),
            StandardScaler(),
            LinearDiscriminantAnalysis(solver="lsqr", shrinkage="auto", priors=[0.5, 0.5]),
        ),
    }
    try:
        from pyriemann.estimation import XdawnCovariances
        from pyriemann.tangentspace import TangentSpace
        from sklearn.linear_model import LogisticRegression

        decoders["pyRiemann (Xdawn, tangent space, LR)"] = make_pipeline(
            XdawnCovariances(nfilter=2, estimator="oas"),
            TangentSpace(metric="riemann"),
            LogisticRegression(max_iter=1000, class_weight="balanced"),
        )
    except ImportError:
        print("(pyRiemann is not installed: pip install pyriemann)")

    print(f"\nshuffled stratified 10-fold CV, {args.draws} draws (mean, SD, range):")
    xf = x.astype(np.float64)
    for name, pipeline in decoders.items():
        scores = draws(pipeline, xf, y, args.draws)
        print(
            f"  {name:<45} {np.mean(scores):.4f}  {np.std(scores, ddof=1):.4f}  "
            f"[{min(scores):.4f}, {max(scores):.4f}]"
        )


if __name__ == "__main__":
    main()
