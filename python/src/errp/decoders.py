"""The paper's two decoders as scikit-learn estimators, by the code the
closed loop runs (the Rust crates), for cross-validating them against a
pipeline of your own on the same epochs (the MOABB habit).

- :class:`TemporalFeatures` turns epochs ``(n_epochs, n_channels,
  n_samples)`` that start at the onset into the discrete decoder's
  features: each channel at [200, 800] ms, downsampled to 64 Hz (39 samples;
  312 features for the paper's eight channels), sec. 2.2.1.
- :class:`ShrinkageLDA` is the discrete decoder on those features: z-score,
  PCA keeping 95 % of the variance, LDA with Ledoit-Wolf shrinkage and
  equal class priors; ``probability="platt"`` adds the Platt scaling the
  testbed fits on the calibration's out-of-fold decisions.
- :class:`ContinuousFeatures` turns 800 ms windows into the continuous
  decoder's 512 features: the temporal ones and the log power spectral
  density at 3 to 9 Hz every 0.25 Hz (sec. 2.2.2).
- :class:`RbfSVC` is the continuous decoder on those features: an
  RBF-kernel SVM on z-scored features, with libsvm's Platt scaling when
  ``probability=True``.
- :func:`discrete_decoder` and :func:`continuous_decoder` chain them as the
  closed loop does.

For the paper's accuracy (the mean of the two classes' rates) score with
``scoring="balanced_accuracy"``; the second of the sorted classes is the
error class (``True``, ``1`` or ``"error"``). Needs scikit-learn (``pip
install scikit-learn``).

Example: the session's own cross-validation, by scikit-learn::

    import errp
    from errp.decoders import discrete_decoder
    from sklearn.metrics import balanced_accuracy_score
    from sklearn.model_selection import PredefinedSplit, cross_val_predict

    session = errp.simulate_session(accuracy=0.7438, seed=1)
    folds = PredefinedSplit(session.cv_folds)
    y_hat = cross_val_predict(discrete_decoder(), session.epochs, session.y, cv=folds)
    print(round(balanced_accuracy_score(session.y, y_hat), 4), round(session.cv_mean, 4))
"""

from __future__ import annotations

import contextlib

import numpy as np

try:
    from sklearn.base import BaseEstimator, ClassifierMixin, TransformerMixin
    from sklearn.pipeline import Pipeline, make_pipeline
    from sklearn.utils.metaestimators import available_if
    from sklearn.utils.multiclass import check_classification_targets
    from sklearn.utils.validation import check_is_fitted
except ImportError as e:  # pragma: no cover - depends on the environment
    raise ImportError(
        "errp.decoders needs scikit-learn: pip install scikit-learn "
        '(or pip install "./python[examples]")'
    ) from e

try:  # scikit-learn >= 1.6
    from sklearn.utils.validation import validate_data as _validate_data
except ImportError:  # pragma: no cover - older scikit-learn

    def _validate_data(estimator, *args, **kwargs):
        return estimator._validate_data(*args, **kwargs)


from . import _args, _core

__all__ = [
    "ContinuousFeatures",
    "RbfSVC",
    "ShrinkageLDA",
    "TemporalFeatures",
    "continuous_decoder",
    "discrete_decoder",
]


#: The largest magnitude of an input value: beyond it a power or a squared
#: distance would overflow a float and the result would be invented.
MAX_MAGNITUDE = 1e100


def _bounded(name: str, X: np.ndarray) -> np.ndarray:
    """Refuses an ``X`` that holds NaN, infinities or values beyond
    :data:`MAX_MAGNITUDE`, naming where."""
    bad = ~np.isfinite(X) | (np.abs(np.nan_to_num(X)) > MAX_MAGNITUDE)
    if bad.any():
        at = tuple(int(i) for i in np.argwhere(bad)[0])
        raise ValueError(
            f"{name}: X[{', '.join(map(str, at))}] = {float(X[at])!r} is invalid: expected finite "
            f"values (no NaN or inf) of magnitude at most {MAX_MAGNITUDE:g} "
            f"({int(bad.sum())} value(s) are not)"
        )
    return X


def _real(name: str, X) -> None:
    """Refuses complex input, naming ``X`` (NumPy would drop the imaginary
    part with only a warning)."""
    if np.iscomplexobj(X):
        raise ValueError(f"{name}: X must be real, not complex (Complex data not supported)")


@contextlib.contextmanager
def _naming_complex(name: str):
    """scikit-learn's refusal of complex input, with the estimator and ``X``
    named."""
    try:
        yield
    except ValueError as e:
        if "Complex data not supported" in str(e):
            raise ValueError(
                f"{name}: X must be real, not complex (Complex data not supported)") from None
        raise


def _epochs(name: str, X) -> np.ndarray:
    """``X`` as a C-ordered float64 array of shape (n_epochs, n_channels,
    n_samples), finite and bounded."""
    _real(name, X)
    X = np.ascontiguousarray(X, dtype=np.float64)
    if X.ndim != 3:
        raise ValueError(
            f"{name}: X must be 3-D (n_epochs, n_channels, n_samples), got shape {X.shape}"
        )
    return _bounded(name, X)


def _sfreq(value) -> float:
    return _args.real("sfreq", value, what="a multiple of 64 Hz from 64 to 4096")


def _random_state(value) -> int:
    """A seed from scikit-learn's ``random_state``: an int >= 0, ``None``
    (0: the fits are deterministic), or a NumPy ``RandomState`` or
    ``Generator`` (one draw)."""
    if value is None:
        return 0
    if isinstance(value, np.random.RandomState):
        return int(value.randint(0, 2**31 - 1))
    if isinstance(value, np.random.Generator):
        return int(value.integers(0, 2**31 - 1))
    return _args.seed("random_state", value)


def _positive(name: str, value, what: str) -> float:
    """A finite real > 0, checked here because the core names it otherwise
    (``c``, ``tolerance``)."""
    v = _args.real(name, value, what=what)
    if not v > 0:
        raise ValueError(f"{name} = {v!r} is invalid: expected {what}")
    return v


class _Features(TransformerMixin, BaseEstimator):
    """Common part of the two feature extractors: stateless, 3-D input."""

    _core_function = None

    def __init__(self, sfreq: float = 256.0):
        self.sfreq = sfreq

    def fit(self, X, y=None):
        """Checks ``X`` and records its channels and samples; learns nothing."""
        X = _epochs(type(self).__name__, X)
        self.transform(X)
        self.n_channels_, self.n_samples_ = X.shape[1:]
        return self

    def transform(self, X) -> np.ndarray:
        """The features of every epoch of ``X``, shape (n_epochs, n_features)."""
        X = _epochs(type(self).__name__, X)
        return type(self)._core_function(X, _sfreq(self.sfreq))

    def __sklearn_tags__(self):  # scikit-learn >= 1.6
        tags = super().__sklearn_tags__()
        tags.input_tags.two_d_array = False
        tags.input_tags.three_d_array = True
        tags.requires_fit = False
        return tags

    def _more_tags(self):  # scikit-learn < 1.6
        return {"X_types": ["3darray"], "stateless": True, "requires_fit": False}


class TemporalFeatures(_Features):
    """The discrete decoder's features (sec. 2.2.1): each channel of an
    epoch at [200, 800] ms after the onset, downsampled to 64 Hz (39
    samples), channel by channel.

    Parameters
    ----------
    sfreq : float
        Sampling rate of the epochs (Hz): a multiple of 64 (256 for the
        testbed's). The epochs start at the onset and hold at least
        ``round(0.2 sfreq) + 38 sfreq / 64 + 1`` samples (204 at 256 Hz, as
        ``Session.epochs`` and the epochs :class:`errp.GridTask` gives).

    The epochs are expected preprocessed as the testbed preprocesses them
    (the low-pass at 10 Hz makes plain decimation safe).
    """

    _core_function = staticmethod(_core.temporal_features)


class ContinuousFeatures(_Features):
    """The continuous decoder's features (sec. 2.2.2) of windows that start
    at their first sample: the :class:`TemporalFeatures` of the window, then
    the log10 power spectral density of each channel over its 800 ms at 3 to
    9 Hz every 0.25 Hz (25 bins): 512 features for eight channels.

    Parameters
    ----------
    sfreq : float
        Sampling rate of the windows (Hz): a multiple of 64. The windows
        hold at least ``round(0.8 sfreq) + 1`` samples (205 at 256 Hz, as
        the windows :class:`errp.EpuckTask` gives).
    """

    _core_function = staticmethod(_core.continuous_features)


class _Binary(ClassifierMixin, BaseEstimator):
    """Common part of the two classifiers: binary labels, 2-D features."""

    def _classes(self, X, y):
        with _naming_complex(type(self).__name__):
            X, y = _validate_data(self, X, y, dtype=np.float64, order="C")
        _bounded(type(self).__name__, X)
        check_classification_targets(y)
        self.classes_, index = np.unique(y, return_inverse=True)
        k = len(self.classes_)
        if k != 2:
            raise ValueError(
                f"Only binary classification is supported: {type(self).__name__} needs two "
                f"classes (correct, then error), got {k} class{'es' if k != 1 else ''}: "
                f"{list(self.classes_)}"
            )
        return X, index.astype(bool)

    def _features(self, X):
        check_is_fitted(self)
        with _naming_complex(type(self).__name__):
            X = _validate_data(self, X, dtype=np.float64, order="C", reset=False)
        return _bounded(type(self).__name__, X)

    def predict(self, X) -> np.ndarray:
        """The class of each row: the error class where the decision is
        ``>= 0`` (the paper's rule, and the one the session's accuracy
        counts)."""
        error = self.decision_function(X) >= 0
        return self.classes_[error.astype(int)]

    def __sklearn_tags__(self):  # scikit-learn >= 1.6
        tags = super().__sklearn_tags__()
        tags.classifier_tags.multi_class = False
        return tags

    def _more_tags(self):  # scikit-learn < 1.6
        return {"binary_only": True}


def _p_error(decision: np.ndarray, a: float, b: float) -> np.ndarray:
    """p(error) = 1 / (1 + e^-(a y + b)), without overflow."""
    return np.exp(-np.logaddexp(0.0, -(a * decision + b)))


def _platt_folds(cv: int, labels: np.ndarray) -> int:
    """Checks that every fold of the Platt scaling's ``cv``-fold
    cross-validation trains on at least two samples of each class."""
    smallest = int(min(labels.sum(), (~labels).sum()))
    if smallest - -(-smallest // cv) < 2:
        need = 4 if cv == 2 else 3
        raise ValueError(
            f'probability="platt" with cv = {cv} needs at least {need} samples of each '
            f"class, got {smallest} in the smaller class"
        )
    return cv


class ShrinkageLDA(_Binary):
    """The discrete decoder of sec. 2.2.1 on 2-D features (for instance
    from :class:`TemporalFeatures`): z-score, PCA keeping ``pca_variance``
    of the variance, LDA with shrinkage and equal class priors. The
    decision y is the log-likelihood ratio of the two classes; the paper's
    p(error) is 1 / (1 + e^-y).

    Parameters
    ----------
    pca_variance : float
        Fraction of the variance the PCA keeps, in (0, 1] (the paper: 0.95).
    shrinkage : "ledoit_wolf" or float
        Covariance shrinkage: Ledoit-Wolf's analytic intensity, or a fixed
        one in [0, 1].
    probability : "logistic" or "platt"
        ``predict_proba``: the paper's 1 / (1 + e^-y) (consistent with
        ``predict``), or the closed loop's Platt scaling, fitted on the
        out-of-fold decisions of a stratified ``cv``-fold cross-validation
        with the training set's class prior removed. Its 0.5 point is near
        y = 0 but not exactly there, as with libsvm.
    cv : int
        Folds of that cross-validation (the calibration's: 10).
    random_state : int, RandomState or None
        Seed of those folds (``None``: 0). With the features of
        ``Session.epochs`` and the session's ``seed``, ``probability="platt"``
        gives the closed loop's own decoder.

    It trains on at most 100 000 samples of at most 4096 features (its PCA
    decomposes a features x features covariance).

    Attributes
    ----------
    classes_ : ndarray of shape (2,)
        The classes; the second is the error class.
    coef_ : ndarray of shape (1, n_features)
        Weights of the decision on the raw features (z-score and PCA folded
        in): ``y = X @ coef_.T + intercept_``.
    intercept_ : ndarray of shape (1,)
    n_components_ : int
        Principal components kept.
    shrinkage_ : float
        Shrinkage intensity used.
    platt_ : tuple of float
        ``(a, b)`` of p(error) = 1 / (1 + e^-(a y + b)); ``(1, 0)`` for the
        logistic mapping.
    """

    def __init__(
        self,
        pca_variance: float = 0.95,
        shrinkage="ledoit_wolf",
        probability: str = "logistic",
        cv: int = 10,
        random_state=None,
    ):
        self.pca_variance = pca_variance
        self.shrinkage = shrinkage
        self.probability = probability
        self.cv = cv
        self.random_state = random_state

    def fit(self, X, y):
        """Fits on features ``X`` (n_samples, n_features) and labels ``y``."""
        X, labels = self._classes(X, y)
        if self.probability not in ("logistic", "platt"):
            raise ValueError(
                f"probability = {self.probability!r} is invalid: expected \"logistic\" "
                "(the paper's 1 / (1 + e^-y)) or \"platt\" (the closed loop's)"
            )
        if isinstance(self.shrinkage, str):
            if self.shrinkage != "ledoit_wolf":
                raise ValueError(
                    f"shrinkage = {self.shrinkage!r} is invalid: expected \"ledoit_wolf\" "
                    "or an intensity in [0, 1]"
                )
            shrinkage = None
        else:
            shrinkage = _args.real(
                "shrinkage", self.shrinkage, what='"ledoit_wolf" or an intensity in [0, 1]'
            )
        folds = None
        if self.probability == "platt":
            folds = _platt_folds(_args.whole("cv", self.cv, 2, 1000), labels)
        r = _core.lda_fit(
            X,
            labels,
            _args.real("pca_variance", self.pca_variance, what="a fraction in (0, 1]"),
            shrinkage,
            folds,
            _random_state(self.random_state),
        )
        self.coef_ = r["coef"].reshape(1, -1)
        self.intercept_ = np.array([r["intercept"]])
        self.n_components_ = r["n_components"]
        self.shrinkage_ = r["shrinkage"]
        self.platt_ = (r["platt_a"], r["platt_b"])
        return self

    def decision_function(self, X) -> np.ndarray:
        """The decision y of each row, shape (n_samples,): > 0 leans to
        error."""
        X = self._features(X)
        return X @ self.coef_[0] + self.intercept_[0]

    def predict_proba(self, X) -> np.ndarray:
        """(p(correct), p(error)) of each row, shape (n_samples, 2)."""
        p = _p_error(self.decision_function(X), *self.platt_)
        return np.column_stack([1.0 - p, p])


class RbfSVC(_Binary):
    """The continuous decoder's classifier of sec. 2.2.2 on 2-D features
    (for instance from :class:`ContinuousFeatures`): a C-SVC with the
    kernel exp(-gamma |u - v|^2) on z-scored features, trained by the
    testbed's libsvm-style SMO solver.

    Parameters
    ----------
    C : float
        Penalty on margin violations (> 0; libsvm's default, 1).
    gamma : "scale" or float
        Kernel width on the z-scored features; ``"scale"`` is
        1 / n_features (scikit-learn's ``"scale"`` after z-scoring).
    tol : float
        Stopping tolerance on the largest KKT violation (libsvm: 1e-3).
    probability : bool
        Whether ``predict_proba`` is available: libsvm's Platt scaling,
        fitted on an internal stratified 5-fold cross-validation (always
        fitted; the closed loop's p(error)). As with scikit-learn's
        ``SVC(probability=True)``, its 0.5 point is not exactly at decision
        0, so ``predict`` and the larger probability can disagree near the
        boundary.
    random_state : int, RandomState or None
        Seed of that internal cross-validation (``None``: 0).

    It trains on at most 10 000 samples (its kernel matrix is samples x
    samples: 800 MB at that size).

    Attributes
    ----------
    classes_ : ndarray of shape (2,)
    support_vectors_ : ndarray of shape (n_support, n_features), float32
        The support vectors, z-scored.
    dual_coef_ : ndarray of shape (1, n_support)
        ``alpha_i y_i`` of each (y = +1 for the error class).
    intercept_ : ndarray of shape (1,)
    gamma_ : float
        Kernel width used.
    platt_ : tuple of float
        ``(a, b)`` of p(error) = 1 / (1 + e^-(a y + b)).
    n_iter_ : int
        SMO iterations of the final fit.
    """

    def __init__(
        self,
        C: float = 1.0,
        gamma="scale",
        tol: float = 1e-3,
        probability: bool = False,
        random_state=None,
    ):
        self.C = C
        self.gamma = gamma
        self.tol = tol
        self.probability = probability
        self.random_state = random_state

    def fit(self, X, y):
        """Fits on features ``X`` (n_samples, n_features) and labels ``y``."""
        X, labels = self._classes(X, y)
        if isinstance(self.gamma, str):
            if self.gamma != "scale":
                raise ValueError(
                    f"gamma = {self.gamma!r} is invalid: expected \"scale\" or a width > 0"
                )
            gamma = None
        else:
            gamma = _args.real("gamma", self.gamma, what='"scale" or a finite width > 0')
        if not isinstance(self.probability, (bool, np.bool_)):
            raise TypeError(f"probability must be True or False, not {self.probability!r}")
        self._model = _core.svm_fit(
            X,
            labels,
            _positive("C", self.C, "a finite penalty > 0"),
            gamma,
            _positive("tol", self.tol, "a finite tolerance > 0, e.g. 1e-3"),
            _random_state(self.random_state),
        )
        m = self._model
        self.support_vectors_ = m["support"]
        self.dual_coef_ = m["dual_coef"].reshape(1, -1)
        self.intercept_ = np.array([m["intercept"]])
        self.gamma_ = m["gamma"]
        self.platt_ = (m["platt_a"], m["platt_b"])
        self.n_iter_ = m["n_iter"]
        return self

    def _decide(self, X):
        X = self._features(X)
        return _core.svm_decision(self._model, X)

    def decision_function(self, X) -> np.ndarray:
        """The decision of each row, shape (n_samples,): >= 0 is error."""
        return self._decide(X)[0]

    @available_if(lambda self: bool(self.probability))
    def predict_proba(self, X) -> np.ndarray:
        """(p(correct), p(error)) of each row, Platt-scaled, shape
        (n_samples, 2)."""
        p = self._decide(X)[1]
        return np.column_stack([1.0 - p, p])


def discrete_decoder(sfreq: float = 256.0, **lda) -> Pipeline:
    """The closed loop's discrete decoder as a pipeline:
    :class:`TemporalFeatures` then :class:`ShrinkageLDA` with
    ``probability="platt"`` (``lda`` sets its parameters). Fits on epochs
    such as ``Session.epochs``."""
    lda.setdefault("probability", "platt")
    return make_pipeline(TemporalFeatures(sfreq=sfreq), ShrinkageLDA(**lda))


def continuous_decoder(sfreq: float = 256.0, **svm) -> Pipeline:
    """The closed loop's continuous decoder as a pipeline:
    :class:`ContinuousFeatures` then :class:`RbfSVC` with
    ``probability=True`` (``svm`` sets its parameters). Fits on 800 ms
    windows such as those :class:`errp.EpuckTask` gives."""
    svm.setdefault("probability", True)
    return make_pipeline(ContinuousFeatures(sfreq=sfreq), RbfSVC(**svm))

