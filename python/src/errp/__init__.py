"""The ErrP testbed from Python.

A synthetic user watches a simulated device (a cursor on a 5x5 grid, or an
e-puck robot in a 200 x 200 cm arena with 25 city goals), a synthetic EEG
generator turns each of the user's judgements into 34 EEG + 6 EOG channels,
a decoder turns that EEG into p(error), and shared control infers the
user's goal from it (Iturrate et al., MLIS'13). Everything runs in the Rust
crates of the testbed; this package is a thin binding over them.

Three uses:

- **Synthetic EEG** for MNE-Python: :func:`simulate_session` (a calibration
  session as an ``mne.io.RawArray`` with annotations) and the streaming
  :class:`EegGenerator`.
- **Your own decoder in the closed loop**: :class:`GridTask` and
  :class:`EpuckTask` call your callable with each epoch or window of
  preprocessed EEG; :func:`run` and :func:`sweep` give the testbed's own
  results as pandas DataFrames with the columns of ``episodes.csv``.
- **Your own agent**: Gymnasium environments in :mod:`errp.gym`
  (``errp/Grid-v0``, the 5x5 grid; ``errp/Epuck-v0``, the e-puck driven by
  motion primitives), whose feedback is the decoded ErrP;
  ``gym.make("errp/Grid-v0")`` works once the package is installed.

Units: EEG in microvolts (MNE objects in volts), time in seconds, sampling
rate in Hz. Seeds are explicit everywhere; the same seed gives the same
numbers as the ``errp`` program.
"""

from __future__ import annotations

import io
import numbers
import os
import shutil
import tempfile
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable, Dict, Mapping, Optional, Sequence, Union

import numpy as np

if TYPE_CHECKING:  # pragma: no cover - for the annotations only
    import pandas

from . import _args, _core, _gym_plugin, _own_eeg, _progress
from ._core import HAS_RERUN, __version__

__all__ = [
    "EegGenerator",
    "EpuckTask",
    "GridTask",
    "HAS_RERUN",
    "Session",
    "SweepResult",
    "SweepWarning",
    "episode_columns",
    "Recording",
    "read_recording",
    "run",
    "simulate_session",
    "sweep",
    "__version__",
]

PathLike = Union[str, "os.PathLike[str]"]
Scalar = Union[bool, int, float, str]


def _frame(csv: str):
    """Rows as the testbed writes them, read as ``episodes.csv`` is read."""
    import pandas as pd

    return pd.read_csv(io.StringIO(csv))


def _path(p: Optional[PathLike], name: str) -> Optional[str]:
    return _args.path(name, p)


def episode_columns(task: str) -> list:
    """The columns of one episode's row of ``task`` ("grid" or "epuck"),
    from ``success`` to ``online_accuracy``, as ``episodes.csv`` names
    them."""
    return list(_core.episode_columns(task))


class EegGenerator:
    """Streaming synthetic EEG: 34 EEG + 6 EOG channels at 256 Hz, in uV,
    the generator of the testbed's sessions and closed loops.

    Parameters
    ----------
    seed : int
        Seed of the background, the artifacts and the potentials' jitter
        (0 to 2^63 - 1).
    errp_to_noise : float
        Peak of the error-minus-correct difference at FCz over the SD of
        the background there (>= 0); a session's ``errp_to_noise`` gives
        its user.
    params : dict, optional
        Other fields of the EEG model by name (``background_uv``,
        ``blink_rate_hz``, ...), checked as a scenario's. ``realism`` is a
        dict of the effects that make the user less ideal (drifts, lapses,
        artifacts: a scenario's ``[realism]`` keys, all off by default;
        the guide's chapter "The simulated user as real users are").
    """

    def __init__(
        self, seed: int = 0, errp_to_noise: float = 1.0, params: Optional[Mapping[str, Any]] = None
    ) -> None:
        self._core = _core.EegGenerator(
            _args.seed("seed", seed),
            _args.real("errp_to_noise", errp_to_noise, what="an ErrP-to-noise ratio >= 0"),
            None if params is None else dict(params),
        )

    def schedule(self, onset_secs: float, kind: str) -> None:
        """Schedules the potential of an assessment, ``kind`` "error" or
        "correct", with its time zero at ``onset_secs`` on the generator's
        clock (s; it may lie in the past of the stream by up to the
        potential's length, or in the future)."""
        self._core.schedule(_args.real("onset_secs", onset_secs, what="a time >= 0 (s)"), kind)

    def generate(self, n_samples: int) -> np.ndarray:
        """The next ``n_samples`` samples, ``(n_channels, n_samples)``
        float64 in uV, rows in :attr:`ch_names` order (at most an hour per
        call)."""
        return self._core.generate(
            _args.whole("n_samples", n_samples, 0, _core.MAX_GENERATE_SAMPLES))

    @property
    def ch_names(self) -> list:
        """Channel names: the EEG channels, then the EOG ones."""
        return list(self._core.ch_names)

    @property
    def ch_types(self) -> list:
        """MNE channel types ("eeg", "eog")."""
        return list(self._core.ch_types)

    @property
    def sfreq(self) -> float:
        """Sampling rate (Hz)."""
        return self._core.sfreq

    @property
    def now_secs(self) -> float:
        """The generator's clock: seconds generated so far."""
        return self._core.now_secs

    @property
    def errp_to_noise(self) -> float:
        """The ErrP-to-noise ratio."""
        return self._core.errp_to_noise

    def __repr__(self) -> str:
        return f"EegGenerator(errp_to_noise={self.errp_to_noise}, now_secs={self.now_secs})"


@dataclass(frozen=True)
class Session:
    """A simulated calibration session (the one ``errp calibrate`` makes).

    Attributes
    ----------
    data : ndarray, shape (n_channels, n_samples), float64
        The raw recording in uV: 34 EEG channels, then 6 EOG channels.
    ch_names, ch_types : list of str
        Channel names and MNE types ("eeg", "eog").
    sfreq : float
        Sampling rate (Hz): 256.
    onsets : ndarray, shape (n_actions,)
        Action onsets (s from the first sample).
    labels : ndarray of str, shape (n_actions,)
        "error" or "correct": the user's judgement of each action.
    epochs : ndarray, shape (n_actions, 8, n_epoch_samples), float32
        Each action's EEG from its onset (204 samples, 0-797 ms: the span
        of the paper's [200, 800] ms feature window), preprocessed as the
        closed loop preprocesses it (50 Hz notch, [1, 10] Hz band-pass,
        common average reference, EOG regression fitted on the session's
        EOG recording) on the paper's eight decoding channels: the arrays
        :class:`GridTask` gives a decoder of your own. For the continuous
        protocol, each example's 800 ms window from the button press (205
        samples), as :class:`EpuckTask` gives its windows.
    epoch_ch_names : list of str
        The channels of ``epochs``: Fz, FC1, FCz, FC2, C1, Cz, C2, CPz.
    errp_to_noise : float
        The ErrP-to-noise ratio that the targeting found.
    accuracy : float
        The requested mean accuracy.
    cv_correct, cv_error, cv_mean : float
        The testbed's decoder's cross-validated accuracy on this session
        (correct class, error class, their mean): the shrinkage LDA, or
        the SVM for the continuous protocol.
    cv_folds : ndarray of int, shape (n_actions,)
        The fold (0 to 9) each action was scored in by that
        cross-validation: ``sklearn.model_selection.PredefinedSplit(
        session.cv_folds)`` repeats it (see :mod:`errp.decoders`).
    seed : int
    protocol : str
        "discrete" or "continuous".
    window_starts : ndarray, shape (n_actions,), or None
        Continuous protocol: the start of each window, the button press
        (s; the onset plus a 50 ms SD reaction jitter).
    """

    data: np.ndarray
    ch_names: list
    ch_types: list
    sfreq: float
    onsets: np.ndarray
    labels: np.ndarray
    epochs: np.ndarray
    epoch_ch_names: list
    errp_to_noise: float
    accuracy: float
    cv_correct: float
    cv_error: float
    cv_mean: float
    cv_folds: np.ndarray
    seed: int
    protocol: str = "discrete"
    window_starts: Optional[np.ndarray] = None

    @property
    def y(self) -> np.ndarray:
        """``True`` where the action was an error, shape (n_actions,)."""
        return self.labels[: len(self.epochs)] == "error"

    @property
    def epoch_times(self) -> np.ndarray:
        """Time of each sample of an epoch from the onset (s)."""
        return np.arange(self.epochs.shape[-1]) / self.sfreq

    def to_mne(self):
        """The raw recording as an ``mne.io.RawArray`` (in volts) with one
        annotation per action ("error" or "correct") and the standard 10-05
        montage on the EEG channels (MNE's template head: ``colin27_1005``,
        ``standard_1005`` before MNE 1.12), so that topographic plots work.
        The EOG channels have no position. Needs MNE-Python."""
        try:
            import mne
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError(
                "Session.to_mne needs MNE-Python: pip install mne "
                "(the arrays are in Session.data without it)"
            ) from e
        info = mne.create_info(list(self.ch_names), self.sfreq, list(self.ch_types))
        raw = mne.io.RawArray(self.data * 1e-6, info, verbose="error")
        templates = mne.channels.get_builtin_montages()
        name = "colin27_1005" if "colin27_1005" in templates else "standard_1005"
        raw.set_montage(mne.channels.make_standard_montage(name), verbose="error")
        raw.set_annotations(
            mne.Annotations(
                onset=self.onsets,
                duration=np.zeros(len(self.onsets)),
                description=list(self.labels),
            )
        )
        return raw

    @property
    def raw(self):
        """Same as :meth:`to_mne`."""
        return self.to_mne()


def simulate_session(
    accuracy: float = 0.7438,
    seed: int = 1,
    *,
    protocol: str = "discrete",
    progress: Optional[bool] = None,
) -> Session:
    """Simulates the discrete calibration session of ``errp calibrate
    --accuracy ACCURACY --seed SEED``: the ErrP-to-noise ratio is targeted
    so that the paper's decoder reaches ``accuracy`` (mean of the two
    classes, cross-validated), then 400 actions, 20 % of them erroneous, are
    simulated at that ratio.

    Parameters
    ----------
    accuracy : float
        Requested mean accuracy, strictly between 0.5 and 1 (Table 1:
        0.7438 fixed goals, 0.7767 free goals).
    seed : int
        Seed of the synthetic user and the session (>= 0).
    protocol : {"discrete", "continuous"}
        ``"continuous"``: the continuous decoder's calibration instead
        (sec. 5.1, as the e-puck task calibrates it): the ratio targeted for
        the RBF SVM on the 512 features of an 800 ms window, then 70
        erroneous and 70 correct assessments 1 to 2 s apart, each example
        window starting at the user's button press. (The e-puck
        scenarios ask the continuous decoder for 0.9; the paper gives no
        accuracy for it.)
    progress : bool, optional
        Show progress on stderr (a tqdm bar if tqdm is installed, else a
        line per tenth): by default when stderr is a terminal.

    Returns
    -------
    Session
        The recording, its events, the preprocessed epochs and the
        targeting; ``session.to_mne()`` gives an ``mne.io.RawArray``.
    """
    accuracy = _args.accuracy("accuracy", accuracy, oracle=False)
    seed = _args.seed("seed", seed)
    if protocol not in ("discrete", "continuous"):
        raise ValueError(
            f'protocol = {protocol!r} is invalid: expected "discrete" (400 actions, the '
            'shrinkage LDA) or "continuous" (70 + 70 button-locked windows, the SVM)'
        )
    with _progress.shown(progress, "simulate_session") as report:
        d = _core.simulate_session(
            accuracy, seed, continuous=protocol == "continuous", progress=report
        )
    d["protocol"] = protocol
    d["labels"] = np.asarray(d["labels"])
    return Session(**d)


def run(
    scenario: Optional[PathLike] = None,
    *,
    seed: Optional[int] = None,
    runs: Optional[int] = None,
    accuracy: Optional[float] = None,
    overrides: Optional[Mapping[str, Any]] = None,
    save: Optional[PathLike] = None,
    progress: Optional[bool] = None,
) -> "pandas.DataFrame":
    """Runs a scenario as ``errp run`` does and returns one row per episode.

    Parameters
    ----------
    scenario : path, optional
        A scenario file (``scenarios/*.toml``); by default the built-in
        Mexico-to-Pisa e-puck run.
    seed : int, optional
        Replaces the scenario's seed.
    runs : int, optional
        E-puck runs (1 to 100 000); a grid scenario lists its episodes.
    accuracy : float, optional
        Replaces ``user.accuracy`` (as ``errp run --accuracy``).
    overrides : dict, optional
        Scenario fields by dotted key, e.g. ``{"control.tau": 0.5}``; they
        are checked as the file's own.
    save : path, optional
        Records the run to this ``.rrd`` file, as ``errp run --save``.
    progress : bool, optional
        Show progress on stderr (a tqdm bar if tqdm is installed, else a
        line per tenth): by default when stderr is a terminal.

    Returns
    -------
    pandas.DataFrame
        The columns of ``episodes.csv`` (``level``, ``accuracy``,
        ``episode``, ``seed``, ``success``, the task's columns and the
        online accuracy); ``df.attrs["decoder"]`` holds the calibration.
    """
    keywords = dict(
        seed=_args.seed("seed", seed, optional=True),
        runs=_args.whole("runs", runs, 1, _core.MAX_RUNS, optional=True),
        accuracy=_args.accuracy("accuracy", accuracy, optional=True),
        overrides=None if overrides is None else dict(overrides),
        save=_path(save, "save"),
    )
    with _progress.shown(progress, "errp.run") as report:
        d = _core.run(_path(scenario, "scenario"), progress=report, **keywords)
    df = _frame(d["csv"])
    df.attrs["task"] = d["task"]
    df.attrs["decoder"] = dict(d["decoder"])
    return df


@dataclass
class Recording:
    """A recording read back by :func:`read_recording`.

    Attributes
    ----------
    task : str
        ``"epuck"`` or ``"grid"``.
    provenance : dict
        How it was made: ``scenario_text`` (the scenario as run, TOML),
        ``seed``, ``runs``, ``command``, ``errp_version``, ``commit``,
        ``decoder_summary`` and, when an agent of your own chose the
        actions (``errp.gym``), ``agent``.
    tables : dict of pandas.DataFrame
        The tidy tables, each with a ``run`` column (from 1), identical to
        the CSV files of ``errp inspect --csv``. E-puck: ``runs`` (one row
        per run, recomputed from the recording: ``converged_on``,
        ``time_s``, ``detected``, ``false``, ``missed``, ``errps``,
        accuracies, ``path_m``, ``turning_s``, ``driving_s``,
        ``stopped_s``), ``trajectory`` (one row per 1/64 s physics step:
        ``t_s``, ``x_cm``, ``y_cm``, ``heading_deg``, the tracked position,
        ``phase``, ``current_goal``, ``p_error``, ``evidence``),
        ``detections``, ``belief`` (``goal``, ``p``), ``errps``,
        ``events``. Grid: ``runs``, ``actions``, ``belief`` (per cell),
        ``visits``.
    path : str
        The file.
    cities : dict
        E-puck: each city's position (x, y in cm).
    arena_cm : float
        E-puck: the side of the arena (cm).
    """

    task: str
    provenance: Dict[str, Any]
    tables: Dict[str, Any]
    path: str
    cities: Dict[str, Any] = field(default_factory=dict)
    arena_cm: float = 200.0

    def __getattr__(self, name: str):
        tables = self.__dict__.get("tables", {})
        if name in tables:
            return tables[name]
        raise AttributeError(name)

    def __repr__(self) -> str:
        p = self.provenance
        return (
            f"Recording({self.path!r}: {self.task}, {p['scenario_name']!r}, "
            f"{p['runs']} run(s), seed {p['seed']}; tables "
            f"{', '.join(self.tables)})"
        )

    def plot(self, run: int = 1, ax=None):
        """Draws the paper's Fig. 5 (e-puck: the cities, every run's path
        faint, run ``run`` in blue with a red cross at each detection) or
        Fig. 4 (grid: visit frequencies, with the paths) with matplotlib;
        returns the axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 6))
        n = len(self.tables["runs"])
        if not 1 <= run <= n:
            raise ValueError(f"run = {run} is invalid: expected 1 to {n}")
        if self.task == "epuck":
            size = self.arena_cm
            ax.plot([0, size, size, 0, 0], [0, 0, size, size, 0], color="0.3")
            traj = self.tables["trajectory"]
            for k, part in traj.groupby("run"):
                if k != run:
                    ax.plot(part.x_cm, part.y_cm, color="C0", alpha=0.15, lw=0.8)
            part = traj[traj.run == run]
            ax.plot(part.x_cm, part.y_cm, color="C0", lw=2)
            det = self.tables["detections"]
            det = det[det.run == run]
            ax.plot(det.x_cm, det.y_cm, "x", color="red", ms=9, mew=2.5)
            goal = self.tables["runs"].goal.iloc[0]
            for name, (x, y) in self.cities.items():
                ax.plot(x, y, "o", color="green" if name == goal else "0.6",
                        ms=11 if name == goal else 8)
                ax.annotate(name, (x, y - 0.045 * size), ha="center", fontsize=7)
            if len(part):
                ax.plot(part.x_cm.iloc[0], part.y_cm.iloc[0], "k^", ms=9)
            ax.set_xlim(0, size)
            ax.set_ylim(0, size)
            ax.set_xlabel("cm")
        else:
            visits = self.tables["visits"].groupby(["x", "y"]).visits.sum()
            w = int(self.tables["visits"].x.max()) + 1
            h = int(self.tables["visits"].y.max()) + 1
            grid = np.zeros((h, w))
            for (x, y), v in visits.items():
                grid[y, x] = v
            ax.imshow(grid / max(grid.max(), 1), cmap="Blues", origin="upper",
                      extent=(0, w, h, 0))
            actions = self.tables["actions"]
            runs = self.tables["runs"]
            for k, r in runs.iterrows():
                a = actions[actions.run == r.run]
                sx, sy = (int(v) for v in r.start.strip("()").split(","))
                xs = [sx + 0.5] + list(a.to_x + 0.5)
                ys = [sy + 0.5] + list(a.to_y + 0.5)
                if r.run == run:
                    ax.plot(xs, ys, color="C0", lw=2.5)
                    gx, gy = (int(v) for v in r.goal.strip("()").split(","))
                    ax.annotate("S", (sx + 0.8, sy + 0.2), color="green")
                    ax.annotate("G", (gx + 0.8, gy + 0.2), color="red")
                else:
                    ax.plot(xs, ys, color="C0", alpha=0.15)
            ax.set_xlim(0, w)
            ax.set_ylim(h, 0)
        ax.set_aspect("equal")
        ax.set_title(f"{self.provenance['scenario_name']}, run {run} of {n}")
        return ax


def read_recording(path: PathLike) -> Recording:
    """Reads a recording made by ``errp run --save`` or :func:`run`
    (``save=``): its provenance and its tidy tables as DataFrames, each run
    recomputed from the recording as ``errp inspect`` recomputes it. No
    Rerun SDK and no knowledge of entity paths is needed.

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    ValueError
        If it is empty, truncated, corrupt, not a recording of errp, or of
        a newer format (the message names the file and what is wrong).
    """
    import json

    import pandas as pd

    if not HAS_RERUN:
        raise RuntimeError("this errp was built without Rerun; read_recording needs it")
    d = _core.read_recording(_path(path, "path"))

    def column(values):
        # Integers with some missing come as (values, mask): pandas' Int64.
        if isinstance(values, tuple):
            return pd.arrays.IntegerArray(*values)
        return values

    tables = {
        name: pd.DataFrame({c: column(cols[c]) for c in d["order"][name]})
        for name, cols in d["tables"].items()
    }
    return Recording(
        task=d["task"],
        provenance=json.loads(d["provenance"]),
        tables=tables,
        path=str(path),
        cities={name: (x, y) for name, x, y in d.get("cities", [])},
        arena_cm=float(d.get("arena_cm", 200.0)),
    )


@dataclass
class SweepResult:
    """A finished sweep: its episodes and per-level summary as DataFrames
    (the columns of ``episodes.csv`` and ``summary.csv``), and where its
    files are (``None`` when it ran in a temporary directory)."""

    episodes: Any
    summary: Any
    out: Optional[str]
    task: str
    ran: int = 0
    files: Dict[str, str] = field(default_factory=dict)


class SweepWarning(UserWarning):
    """Something a sweep found wrong and worked around: a targeting cache
    that cannot be written (or an entry of it that could not be stored), or
    a cached targeting whose figures did not come back when checked
    (searched again and replaced). The sweep's results are right either
    way; it, or the next one, may only be slower."""


def sweep(
    out: Optional[PathLike] = None,
    *,
    accuracy: Union[str, float, Sequence[float], None] = None,
    task: Optional[str] = None,
    scenario: Optional[PathLike] = None,
    episodes: int = 100,
    seed: int = 1,
    params: Optional[Mapping[str, Sequence[Scalar]]] = None,
    per_action: Optional[bool] = None,
    cache: Optional[PathLike] = None,
    threads: Optional[int] = None,
    progress: Optional[bool] = None,
    stream: Optional[bool] = None,
) -> SweepResult:
    """Runs a Monte Carlo sweep as ``errp sweep`` does.

    Parameters
    ----------
    out : path, optional
        The sweep directory (``episodes.csv``, ``summary.csv``, plots,
        ``sweep.json``); running the same sweep into it again resumes it.
        By default a temporary directory, removed once read.
    accuracy : str, float or list of float
        Decoder accuracies: ``"0.6:0.9:0.05"`` (a range), ``[0.7, 0.8]``.
        Required, but for a sweep over recordings
        (``params={"eeg.recording": ["s01.edf", "s02.edf"]}``, paths relative
        to the scenario's directory, or a scenario with an ``[eeg]``
        table), which has none: each level's decoder has the accuracy its
        recording gives (the ``accuracy`` column).
    task : {"grid", "epuck"}, optional
        The task, for its built-in scenario when ``scenario`` is not given.
    scenario : path, optional
        A scenario file.
    episodes : int
        Episodes per level (1 to 1 000 000).
    seed : int
        The sweep's seed; episode seeds derive from it.
    params : dict, optional
        Swept parameters: ``{"strategy": ["greedy", "info_gain"]}``, by the
        short names of ``errp sweep --param`` or dotted scenario keys.
    per_action : bool, optional
        Grid: synthesise the EEG of every action when it happens instead of
        drawing epochs from a bank synthesised in advance (the sweep's
        default; about 200 times faster).
    cache : path, optional
        A directory for the accuracy targeting, shared across sweeps. Each
        cached entry is checked before use; one that does not verify, or a
        directory that cannot be written, gives a :class:`SweepWarning`.
    threads : int, optional
        Worker threads (all cores by default); results do not depend on it.
    progress : bool, optional
        Show progress on stderr (the decoders calibrated, then the
        episodes: tqdm bars if tqdm is installed, else a line per tenth): by default when stderr is a terminal.
    stream : bool, optional
        Deprecated: the former name of ``per_action``.
    """
    if stream is not None:
        if per_action is not None:
            raise TypeError("per_action and stream: give per_action only (stream is its former name)")
        warnings.warn(
            "errp.sweep(stream=...) is deprecated: use per_action=...",
            DeprecationWarning,
            stacklevel=2,
        )
    episodes = _args.whole("episodes", episodes, 1, _core.MAX_EPISODES)
    seed = _args.seed("seed", seed)
    threads = _args.whole("threads", threads, 1, _core.MAX_THREADS, optional=True)
    if accuracy is None:
        acc = None
    elif isinstance(accuracy, str):
        acc = accuracy
    elif isinstance(accuracy, numbers.Real) and not isinstance(accuracy, bool):
        acc = repr(_args.accuracy("accuracy", accuracy))
    elif isinstance(accuracy, (list, tuple, np.ndarray)) and len(accuracy) > 0:
        acc = ",".join(repr(_args.accuracy(f"accuracy[{i}]", a)) for i, a in enumerate(accuracy))
    else:
        raise TypeError(
            "accuracy must be a range such as \"0.6:0.9:0.05\", a number or a non-empty "
            f"list of numbers, not {type(accuracy).__name__} {accuracy!r}"
        )
    axes = None
    if params is not None:
        axes = []
        for name, values in params.items():
            if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
                values = [values]
            texts = [_value_text(v) for v in values]
            for i, t in enumerate(texts):
                if "," in t or ":" in t:
                    raise ValueError(
                        f"params[{name!r}][{i}] = {t!r} is invalid: one value may not hold ',' "
                        "or ':', which separate values and ranges; give the values as a list")
            axes.append(f"{name}=" + ",".join(texts))
    tmp = None
    if out is None:
        tmp = tempfile.mkdtemp(prefix="errp-sweep-")
        target = os.path.join(tmp, "sweep")
    else:
        target = _args.path("out", out)
    try:
        with _progress.shown(progress, "errp.sweep") as report:
            d = _core.sweep(
                target,
                dict(
                    accuracy=acc,
                    task=task,
                    scenario=_path(scenario, "scenario"),
                    episodes=episodes,
                    seed=seed,
                    params=axes,
                    per_action=per_action,
                    stream=stream,
                    cache=_path(cache, "cache"),
                    threads=threads,
                ),
                progress=report,
            )
        for text in d["warnings"]:
            warnings.warn(text, SweepWarning, stacklevel=2)
        import pandas as pd

        result = SweepResult(
            episodes=pd.read_csv(d["episodes_csv"]),
            summary=pd.read_csv(d["summary_csv"]),
            out=None if tmp else target,
            task=d["task"],
            ran=d["ran"],
            files={} if tmp else {
                "episodes": d["episodes_csv"],
                "summary": d["summary_csv"],
                "manifest": d["manifest"],
            },
        )
    finally:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
    return result


def _value_text(v: Scalar) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    return str(v)


Decoder = Callable[[np.ndarray], float]
BatchDecoder = Callable[[np.ndarray], np.ndarray]


class _Task:
    """What both tasks' wrappers share: the calibration and the shape of
    what a decoder of your own is given."""

    _core: Any

    @property
    def calibration(self) -> dict:
        """What the calibration of the testbed's decoder found."""
        return dict(self._core.calibration)

    @property
    def ch_names(self) -> list:
        """Channels of each epoch or window given to your decoder."""
        return list(self._core.ch_names)

    @property
    def sfreq(self) -> float:
        """Sampling rate (Hz)."""
        return self._core.sfreq

    @property
    def n_samples(self) -> int:
        """Samples per epoch (from the onset) or window (800 ms)."""
        return self._core.n_samples

    @property
    def decoder_calls(self) -> int:
        """How often your per-epoch or per-window decoder has been called."""
        return self._core.decoder_calls

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._core.name!r}, seed={self._core.seed})"


class GridTask(_Task):
    """The grid task of a scenario with its decoder calibrated once.

    Without ``decoder``, episodes are decoded by the testbed's decoder (the
    paper's shrinkage LDA). With ``decoder``, your callable decodes every
    action: it is called with the action's epoch of preprocessed EEG, an
    ndarray ``(n_channels, n_samples)`` float64 in uV (channels
    :attr:`ch_names`, :attr:`sfreq` Hz, :attr:`n_samples` samples from the
    onset), and returns p(error) in [0, 1]; p >= 0.5 counts as its
    "error" class. Everything else (the user, the EEG, the shared control)
    is the scenario's. With ``batch_decoder``, your callable is called once
    with a bank of epochs, ``(n_epochs, n_channels, n_samples)`` float32,
    ``bank_per_class`` of each class in a shuffled order it is not told, and
    returns their p(error), shape ``(n_epochs,)``; each action then draws
    one of them, as the testbed's sweeps draw from their epoch bank. The
    same user at the same seed is behind all three, so their results
    compare at the same accuracy.

    With ``eeg``, a person's own EEG replaces the synthetic user's
    EEG: the testbed's decoder is calibrated on the file's first part
    (the same preprocessing, features, LDA, cross-validation and Platt
    scaling as on a synthetic session) and each action decodes an epoch of
    its class drawn from the part after it, never from the part it was
    trained on. No accuracy is targeted: :attr:`calibration` reports the
    one the recording gives (``cv_mean`` cross-validated on the
    calibration part, which the shared control assumes, and
    ``held_out_mean``). See the guide's chapter "Your own EEG in the loop".

    Parameters
    ----------
    scenario : path, optional
        A grid scenario file; by default the built-in fixed-goals one
        (``scenarios/grid_fixed_goals.toml``, 74.38 %).
    decoder, batch_decoder : callable, optional
    seed, accuracy, overrides, progress :
        As for :func:`run` (``progress`` shows the calibration's search).
    eeg : mne.io.Raw, mne.Epochs or path, optional
        A recording with annotations (or epochs with events) naming each
        action "error" or "correct", or a file MNE reads (EDF, BDF, FIF,
        BrainVision, EEGLAB, GDF, ...). Its channels are matched by name to
        the decoder's eight (Fz FC1 FCz FC2 C1 Cz C2 CPz) and the EOG
        regression's six (EOG LA, EOG LB, EOG RA, EOG RB, EOG LO, EOG RO);
        another sampling rate than 256 Hz is resampled with MNE. Epochs are
        laid end to end into one recording (the filters then see a jump at
        each boundary). Not with ``accuracy``, ``decoder`` or
        ``batch_decoder``.
    eeg_options : dict, optional
        The keys of a scenario's ``[eeg]`` table: ``calibration`` (the
        fraction of the events that calibrates, default 0.5) or
        ``calibration_events`` (a count), ``error`` and ``correct`` (the
        annotations, default "error" and "correct"), ``draw``
        ("with_replacement", the default, or "without_replacement": each
        epoch of a class once in an episode before any repeats).
    """

    def __init__(
        self,
        scenario: Optional[PathLike] = None,
        *,
        decoder: Optional[Decoder] = None,
        batch_decoder: Optional[BatchDecoder] = None,
        seed: Optional[int] = None,
        accuracy: Optional[float] = None,
        overrides: Optional[Mapping[str, Any]] = None,
        progress: Optional[bool] = None,
        eeg: Any = None,
        eeg_options: Optional[Mapping[str, Any]] = None,
    ) -> None:
        if eeg is None and eeg_options is not None:
            raise ValueError("eeg_options: set with eeg=..., a recording to split and draw from")
        keywords = dict(
            decoder=decoder,
            batch_decoder=batch_decoder,
            seed=_args.seed("seed", seed, optional=True),
            accuracy=_args.accuracy("accuracy", accuracy, optional=True),
            overrides=None if overrides is None else dict(overrides),
        )
        if eeg is not None:
            keywords["eeg"] = _own_eeg.read(eeg, eeg_options)
        with _progress.shown(progress, "errp.GridTask") as report:
            self._core = _core.GridTask(_path(scenario, "scenario"), progress=report, **keywords)

    def run(
        self, *, save: Optional[PathLike] = None, progress: Optional[bool] = None
    ) -> "pandas.DataFrame":
        """Runs every episode of the scenario and returns one row per
        episode (the columns of :func:`run`). With ``save``, the episodes
        (at most 5000) are recorded into that ``.rrd`` as ``errp run
        --save`` records them, with the decoder in the loop (yours, if
        given). ``progress`` as for :func:`run`."""
        with _progress.shown(progress, "GridTask.run") as report:
            csv = self._core.run(_path(save, "save"), progress=report)
        df = _frame(csv)
        df.attrs["task"] = "grid"
        df.attrs["decoder"] = self.calibration
        return df


class EpuckTask(_Task):
    """The e-puck task of a scenario with its continuous decoder calibrated
    once.

    With ``decoder``, your callable replaces the testbed's sliding-window
    SVM: every 62.5 ms it is called with the last 800 ms of preprocessed
    EEG, an ndarray ``(n_channels, n_samples)`` float64 in uV (channels
    :attr:`ch_names`, :attr:`sfreq` Hz), and returns p(error) in [0, 1].
    Its output goes through the scenario's detector at the scenario's
    ``control.t_e`` (:attr:`t_e`), and is scored over the response spans
    measured for the testbed's decoder.

    With ``eeg``, the runs stream a labelled hybrid of a person's own
    recording ("hybrid: recorded background, recorded ErrP template"): the
    recording's continuous EEG as the background (its first part for the
    calibration, the rest online, looped) and the subject's
    error-minus-correct response from the first part, added at the
    simulated user's assessments with the generator's single-trial
    variability. The SVM is calibrated on it with no accuracy targeted, and
    T_e is set on the held-out hybrid for the false alarms a minute of the
    paper-fitted user (5.37). See the guide's chapter "Your own EEG in the
    loop".

    Parameters
    ----------
    scenario : path, optional
        An e-puck scenario; by default the built-in Mexico-to-Pisa run.
    decoder : callable, optional
    seed, accuracy, overrides, progress :
        As for :func:`run` (``progress`` shows the calibration's search).
    eeg : mne.io.Raw, mne.Epochs or path, optional
        A recording, as for :class:`GridTask`. Not with ``accuracy`` or
        ``decoder``.
    eeg_options : dict, optional
        The keys of an e-puck scenario's ``[eeg]`` table: ``calibration``
        (default 0.5) or ``calibration_events``, ``error`` and ``correct``,
        and ``false_alarms_per_min`` (the rate T_e is set for, in (0, 60],
        default 5.37).
    """

    def __init__(
        self,
        scenario: Optional[PathLike] = None,
        *,
        decoder: Optional[Decoder] = None,
        seed: Optional[int] = None,
        accuracy: Optional[float] = None,
        overrides: Optional[Mapping[str, Any]] = None,
        progress: Optional[bool] = None,
        eeg: Any = None,
        eeg_options: Optional[Mapping[str, Any]] = None,
    ) -> None:
        if eeg is None and eeg_options is not None:
            raise ValueError("eeg_options: set with eeg=..., a recording to run a hybrid of")
        keywords = dict(
            decoder=decoder,
            seed=_args.seed("seed", seed, optional=True),
            accuracy=_args.accuracy("accuracy", accuracy, optional=True),
            overrides=None if overrides is None else dict(overrides),
        )
        if eeg is not None:
            keywords["eeg"] = _own_eeg.read(eeg, eeg_options)
        with _progress.shown(progress, "errp.EpuckTask") as report:
            self._core = _core.EpuckTask(_path(scenario, "scenario"), progress=report, **keywords)

    def run(
        self,
        runs: Optional[int] = None,
        *,
        save: Optional[PathLike] = None,
        progress: Optional[bool] = None,
    ) -> "pandas.DataFrame":
        """Runs ``runs`` runs (the scenario's by default) and returns one row
        per run (the columns of :func:`run`). With ``save``, the runs (at
        most 100) are recorded into that ``.rrd`` as ``errp run --save``
        records them, with the decoder in the loop (yours, if given).
        ``progress`` as for :func:`run`."""
        runs = _args.whole("runs", runs, 1, _core.MAX_RUNS, optional=True)
        with _progress.shown(progress, "EpuckTask.run") as report:
            csv = self._core.run(runs, save=_path(save, "save"), progress=report)
        df = _frame(csv)
        df.attrs["task"] = "epuck"
        df.attrs["decoder"] = self.calibration
        return df

    @property
    def t_e(self) -> float:
        """The detection threshold your decoder's p(error) is compared with."""
        return self._core.t_e


# Gymnasium 1.x has no entry points: register errp/Grid-v0 and errp/Epuck-v0
# here (a no-op without Gymnasium; errp.gym is imported only by gym.make).
_gym_plugin.register()
