"""Every whole-number and real argument of the public functions, given a
bad value, raises ValueError or TypeError naming the argument; none raises
OverflowError or speaks in the command line's syntax (``--seed``). The bad
values are drawn for each argument's kind: negative, too large for 64 bits,
of the wrong type, not finite."""

import math
import re

import gymnasium as gym
import numpy as np
import pytest

import errp
import errp.gym  # noqa: F401  (registers the environments)

WHOLE = [-1, -(2**70), 2**64, 2**200, 1.5, 2.0, "3", True, None, float("nan"), [1], np.float64(1.0),
         1 + 0j]
REAL = [float("nan"), float("inf"), -float("inf"), "0.8", True, [0.8], object(), 10**400, 1 + 0j,
        b"0.8"]
#: Bad actions of an environment: fractions, non-finite, out of range,
#: arrays of several, complex, None.
ACTIONS = [3.7, float("nan"), float("inf"), -1, 7, 2**70, np.array([1, 2]), 1 + 0j, None, True,
           "1"]
CELLS = [(3.9, 1.2), (float("inf"), 1), (5, 0), (1,), (1, 2, 3), "ab", 7, (1 + 0j, 0)]
SWEEP_TEXT = ["2.0", "0.4:0.9:0.1", "abc", "0.9:0.6:0.1", ""]


def calls():
    """(label, argument name, bad value, call) for every case."""
    cases = []

    def add(label, name, values, f, optional=False):
        for v in values:
            if optional and v is None:
                continue
            cases.append((label, name, v, f))

    add("simulate_session", "seed", WHOLE, lambda v: errp.simulate_session(seed=v))
    add("simulate_session", "accuracy", REAL + [None], lambda v: errp.simulate_session(accuracy=v))
    add("run", "seed", WHOLE, lambda v: errp.run(seed=v), optional=True)
    add("run", "runs", WHOLE + [0, 10**6], lambda v: errp.run(runs=v), optional=True)
    add("run", "accuracy", REAL, lambda v: errp.run(accuracy=v))
    sweep = dict(task="grid", accuracy=0.7, episodes=2)
    add("sweep", "episodes", WHOLE + [0, 10**7],
        lambda v: errp.sweep(**{**sweep, "episodes": v}))
    add("sweep", "seed", WHOLE, lambda v: errp.sweep(**{**sweep, "seed": v}))
    add("sweep", "threads", WHOLE + [0, 5000],
        lambda v: errp.sweep(**{**sweep, "threads": v}), optional=True)
    # A sweep's accuracy may be text: a range or a list ("0.6:0.9:0.05").
    numbers = [v for v in REAL if not isinstance(v, (str, list))]
    add("sweep", "accuracy", numbers + SWEEP_TEXT + [[], [0.7, "x"], [0.7, 2.0]],
        lambda v: errp.sweep(**{**sweep, "accuracy": v}))
    add("GridTask", "seed", WHOLE, lambda v: errp.GridTask(seed=v), optional=True)
    add("GridTask", "accuracy", REAL, lambda v: errp.GridTask(accuracy=v))
    add("EpuckTask", "seed", WHOLE, lambda v: errp.EpuckTask(seed=v), optional=True)
    add("EpuckTask", "accuracy", REAL, lambda v: errp.EpuckTask(accuracy=v))
    add("EegGenerator", "seed", WHOLE, lambda v: errp.EegGenerator(seed=v))
    add("EegGenerator", "errp_to_noise", REAL + [-1.0, None],
        lambda v: errp.EegGenerator(errp_to_noise=v))
    gen = errp.EegGenerator(seed=1)
    add("EegGenerator.generate", "n_samples", WHOLE + [10**9], gen.generate)
    add("EegGenerator.schedule", "onset_secs", REAL + [-1.0, None],
        lambda v: gen.schedule(v, "error"))
    # Paths: bytes and other types are refused, naming the argument.
    for bad in [b"x.toml", 3, 2.5]:
        cases.append(("run", "scenario", bad, lambda v: errp.run(v)))
        cases.append(("read_recording", "path", bad, lambda v: errp.read_recording(v)))
    cases.append(("sweep", "out", b"d", lambda v: errp.sweep(v, task="grid", accuracy=0.7)))
    # A sweep's values may not hold the list separators.
    for bad in ["0.3,0.5", "0.3:0.5:0.1"]:
        cases.append(("sweep", "params", bad,
                      lambda v: errp.sweep(task="grid", accuracy=0.7, params={"tau": [v]})))
    # The environments: actions, goals and starts.
    grid = gym.make("errp/Grid-v0")
    grid.reset(seed=0)
    add("Grid-v0.step", "action", ACTIONS, lambda v: grid.step(v))
    add("Grid-v0.reset", "goal", CELLS, lambda v: grid.reset(options={"goal": v}))
    add("Grid-v0.reset", "start", CELLS, lambda v: grid.reset(options={"start": v}))
    add("Grid-v0", "goal", CELLS, lambda v: gym.make("errp/Grid-v0", goal=v))
    epuck = gym.make("errp/Epuck-v0")
    epuck.reset(seed=0)
    add("Epuck-v0.step", "action", ACTIONS, lambda v: epuck.step(v))
    add("Epuck-v0", "goal", [2.5, float("inf"), 25, -1, "Atlantis", 1 + 0j],
        lambda v: gym.make("errp/Epuck-v0", goal=v))
    # errp.decoders: scikit-learn's habit, parameters checked at fit.
    try:
        from errp import decoders as d
    except ImportError:  # pragma: no cover - scikit-learn missing
        return cases
    rng = np.random.default_rng(0)
    y = np.arange(40) % 2
    x = rng.normal(size=(40, 4)) + y[:, None]
    epochs = rng.normal(size=(4, 2, 210))
    fit = lambda make: (lambda v: make(v).fit(x, y))  # noqa: E731
    add("ShrinkageLDA", "pca_variance", REAL + [0.0, 1.5, -0.1, None],
        fit(lambda v: d.ShrinkageLDA(pca_variance=v)))
    add("ShrinkageLDA", "shrinkage", REAL + [-0.5, 1.5, None],
        fit(lambda v: d.ShrinkageLDA(shrinkage=v)))
    add("ShrinkageLDA", "cv", WHOLE + [1, 10**4],
        fit(lambda v: d.ShrinkageLDA(probability="platt", cv=v)))
    add("ShrinkageLDA", "random_state", WHOLE, fit(lambda v: d.ShrinkageLDA(random_state=v)),
        optional=True)
    add("RbfSVC", "C", REAL + [0.0, -1.0, None], fit(lambda v: d.RbfSVC(C=v)))
    add("RbfSVC", "gamma", REAL + [0.0, -1.0, None], fit(lambda v: d.RbfSVC(gamma=v)))
    add("RbfSVC", "tol", REAL + [0.0, -1.0, None], fit(lambda v: d.RbfSVC(tol=v)))
    add("RbfSVC", "random_state", WHOLE, fit(lambda v: d.RbfSVC(random_state=v)), optional=True)
    for cls in (d.TemporalFeatures, d.ContinuousFeatures):
        add(cls.__name__, "sfreq", REAL + [0.0, 250.0, 2.0**70, None],
            lambda v, cls=cls: cls(sfreq=v).fit_transform(epochs))
    # Input that is not finite, overflows the features or is complex: X.
    def spoilt(a, v):
        a = a.astype(complex) if isinstance(v, complex) else a.copy()
        a.flat[3] = v
        return a

    bad_x = [float("nan"), float("inf"), 1e300, 1j]
    for cls in (d.TemporalFeatures, d.ContinuousFeatures):
        add(cls.__name__, "X", bad_x,
            lambda v, cls=cls: cls().fit_transform(spoilt(rng.normal(size=(4, 8, 256)), v)))
    for cls in (d.ShrinkageLDA, d.RbfSVC):
        add(cls.__name__, "X", bad_x, lambda v, cls=cls: cls().fit(spoilt(x, v), y))
    return cases


CASES = calls()


def shown(value) -> str:
    """A value as a test id: its repr, but the same in every process (a
    bare object's repr holds its address, and pytest-xdist's workers must
    collect the same ids)."""
    return "object()" if type(value) is object else repr(value)


@pytest.mark.parametrize(
    "label,name,value,call", CASES, ids=[f"{c[0]}-{c[1]}-{shown(c[2])}"[:60] for c in CASES]
)
def test_a_bad_argument_is_named(label, name, value, call):
    with pytest.raises((ValueError, TypeError)) as info:
        call(value)
    assert not isinstance(info.value, OverflowError)
    message = str(info.value)
    assert re.search(rf"\b{re.escape(name)}\b", message), f"{label}: {message}"
    assert not re.search(r"(^|\s)--[a-z]", message), f"{label} speaks CLI: {message}"


def test_the_bad_values_cover_every_kind():
    # Negative, beyond 64 bits, fractional, text, bool and non-finite all
    # appear for the whole-number arguments; a wrong implementation that
    # let any through to the core would raise OverflowError above.
    kinds = {type(v).__name__ for v in WHOLE}
    assert {"int", "float", "str", "bool"} <= kinds
    assert any(isinstance(v, int) and v >= 2**64 for v in WHOLE)
    assert any(isinstance(v, float) and math.isnan(v) for v in REAL)
