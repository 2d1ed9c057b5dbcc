"""Type stubs of the compiled core (``errp._core``). The documented API is
the package's (``errp``, ``errp.gym``); these are what it calls."""

from typing import Any, Callable, Dict, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

HAS_RERUN: bool
__version__: str
#: Most e-puck runs in one call (``errp run --runs``).
MAX_RUNS: int
#: Most episodes per sweep level (``errp sweep --episodes``).
MAX_EPISODES: int
#: Most worker threads.
MAX_THREADS: int
#: Most samples per :meth:`EegGenerator.generate` call (an hour at 256 Hz).
MAX_GENERATE_SAMPLES: int
#: What long calls report their progress to: ``progress(stage, done,
#: total)``, ``total`` 0 when not known beforehand.
Progress = Callable[[str, int, int], None]
#: Most trials and features :func:`lda_fit` takes; most trials of :func:`svm_fit`.
MAX_LDA_TRIALS: int
MAX_LDA_FEATURES: int
MAX_SVM_TRIALS: int

def simulate_session(
    accuracy: float = 0.7438,
    seed: int = 1,
    continuous: bool = False,
    progress: Optional[Progress] = None,
) -> Dict[str, Any]:
    """The calibration session of ``errp calibrate``: ``data`` (n_channels,
    n_samples) uV, ``ch_names``, ``ch_types``, ``sfreq``, ``onsets`` (s),
    ``labels``, ``epochs`` (n_actions, n_eeg, n_samples) float32,
    ``epoch_ch_names``, ``errp_to_noise``, ``accuracy``, ``cv_correct``,
    ``cv_error``, ``cv_mean``, ``seed``, ``cv_folds`` (n_actions,). With
    ``continuous``, the continuous decoder's session (sec. 5.1): 800 ms
    windows from the button presses as ``epochs``, and ``window_starts``
    (s)."""

def temporal_features(x: npt.NDArray[np.float64], sfreq: float) -> npt.NDArray[np.float64]:
    """The discrete decoder's features of C-ordered epochs (n, channels,
    samples): (n, 39 x channels)."""

def continuous_features(x: npt.NDArray[np.float64], sfreq: float) -> npt.NDArray[np.float64]:
    """The continuous decoder's features of C-ordered windows: (n, 64 x
    channels)."""

def lda_fit(
    x: npt.NDArray[np.float64],
    y: npt.NDArray[np.bool_],
    pca_variance: float,
    shrinkage: Optional[float],
    platt_folds: Optional[int],
    seed: int,
) -> Dict[str, Any]:
    """``coef``, ``intercept``, ``n_components``, ``shrinkage``, ``platt_a``,
    ``platt_b``."""

def svm_fit(
    x: npt.NDArray[np.float64],
    y: npt.NDArray[np.bool_],
    c: float,
    gamma: Optional[float],
    tolerance: float,
    seed: int,
) -> Dict[str, Any]:
    """``mean``, ``inv_sd``, ``gamma``, ``support`` (float32), ``dual_coef``,
    ``intercept``, ``platt_a``, ``platt_b``, ``n_iter``."""

def svm_decision(
    model: Dict[str, Any], x: npt.NDArray[np.float64]
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """The decision and Platt-scaled p(error) of each row."""

def run(
    scenario: Optional[str] = None,
    *,
    seed: Optional[int] = None,
    runs: Optional[int] = None,
    accuracy: Optional[float] = None,
    overrides: Optional[Dict[str, Any]] = None,
    save: Optional[str] = None,
    progress: Optional[Progress] = None,
) -> Dict[str, Any]:
    """``task``, ``csv`` (one row per episode) and ``decoder``."""

def sweep(
    out: str, keywords: Dict[str, Any], progress: Optional[Progress] = None
) -> Dict[str, Any]:
    """Paths of the sweep's files, ``ran``, ``total``, ``task`` and
    ``warnings`` (what the sweep found wrong and worked around).

    ``keywords`` holds every keyword of :func:`errp.sweep` (``accuracy``,
    ``task``, ``scenario``, ``episodes``, ``seed``, ``params``,
    ``per_action`` (or its former name ``stream``), ``cache``, ``threads``),
    as that function passes them."""

def episode_columns(task: str) -> List[str]: ...

class EegGenerator:
    """Streaming synthetic EEG, 34 EEG + 6 EOG channels, 256 Hz, uV."""

    def __init__(
        self, seed: int = 0, errp_to_noise: float = 1.0, params: Optional[Dict[str, Any]] = None
    ) -> None: ...
    def schedule(self, onset_secs: float, kind: str) -> None:
        """Schedules the potential of an assessment ("error" or "correct")
        with its time zero at ``onset_secs`` on the generator's clock."""
    def generate(self, n_samples: int) -> npt.NDArray[np.float64]:
        """The next samples, (n_channels, n_samples) in uV."""
    @property
    def ch_names(self) -> List[str]: ...
    @property
    def ch_types(self) -> List[str]: ...
    @property
    def sfreq(self) -> float: ...
    @property
    def now_secs(self) -> float: ...
    @property
    def errp_to_noise(self) -> float: ...

class GridTask:
    def __init__(
        self,
        scenario: Optional[str] = None,
        *,
        decoder: Optional[Callable[[npt.NDArray[np.float64]], float]] = None,
        batch_decoder: Optional[Callable[[npt.NDArray[np.float32]], Any]] = None,
        seed: Optional[int] = None,
        accuracy: Optional[float] = None,
        overrides: Optional[Dict[str, Any]] = None,
        progress: Optional[Progress] = None,
        eeg: Optional[Dict[str, Any]] = None,
    ) -> None: ...
    def run(self, save: Optional[str] = None, progress: Optional[Progress] = None) -> str: ...
    @property
    def calibration(self) -> Dict[str, float]: ...
    @property
    def ch_names(self) -> List[str]: ...
    @property
    def sfreq(self) -> float: ...
    @property
    def n_samples(self) -> int: ...
    @property
    def decoder_calls(self) -> int: ...
    @property
    def name(self) -> str: ...
    @property
    def seed(self) -> int: ...

class EpuckTask:
    def __init__(
        self,
        scenario: Optional[str] = None,
        *,
        decoder: Optional[Callable[[npt.NDArray[np.float64]], float]] = None,
        seed: Optional[int] = None,
        accuracy: Optional[float] = None,
        overrides: Optional[Dict[str, Any]] = None,
        progress: Optional[Progress] = None,
        eeg: Optional[Dict[str, Any]] = None,
    ) -> None: ...
    def run(
        self,
        runs: Optional[int] = None,
        *,
        save: Optional[str] = None,
        progress: Optional[Progress] = None,
    ) -> str: ...
    @property
    def calibration(self) -> Dict[str, float]: ...
    @property
    def ch_names(self) -> List[str]: ...
    @property
    def sfreq(self) -> float: ...
    @property
    def n_samples(self) -> int: ...
    @property
    def t_e(self) -> float: ...
    @property
    def decoder_calls(self) -> int: ...
    @property
    def name(self) -> str: ...
    @property
    def seed(self) -> int: ...

class GridEnvCore:
    def __init__(
        self,
        scenario: Optional[str] = None,
        *,
        accuracy: Optional[float] = None,
        overrides: Optional[Dict[str, Any]] = None,
        save: Optional[str] = None,
        progress: Optional[Progress] = None,
    ) -> None: ...
    def close(self) -> Optional[str]: ...
    @property
    def recording_full(self) -> bool: ...
    def reset(
        self,
        seed: int,
        start: Optional[Tuple[int, int]] = None,
        goal: Optional[Tuple[int, int]] = None,
    ) -> Tuple[Tuple[int, int], Tuple[int, int]]: ...
    def step(self, action: int, keep_epoch: bool = False) -> Dict[str, Any]: ...
    @property
    def per_action(self) -> bool: ...
    @property
    def epoch_shape(self) -> Tuple[List[str], int, float]: ...
    @property
    def max_actions(self) -> int: ...
    @property
    def name(self) -> str: ...

class EpuckEnvCore:
    def __init__(
        self,
        scenario: Optional[str] = None,
        *,
        accuracy: Optional[float] = None,
        overrides: Optional[Dict[str, Any]] = None,
        save: Optional[str] = None,
        progress: Optional[Progress] = None,
    ) -> None: ...
    def close(self) -> Optional[str]: ...
    @property
    def recording_full(self) -> bool: ...
    @property
    def obstacles(self) -> List[List[Tuple[float, float]]]: ...
    def reset(
        self, seed: int, goal: Optional[int] = None
    ) -> Tuple[Tuple[float, float, float], int]: ...
    def step(self, action: int, windows: int, keep_window: bool = False) -> Dict[str, Any]: ...
    @property
    def window_shape(self) -> Tuple[List[str], int, float]: ...
    @property
    def goal_names(self) -> List[str]: ...
    @property
    def arena_size_m(self) -> float: ...
    @property
    def max_secs(self) -> float: ...
    @property
    def scenario_goal(self) -> int: ...
    @property
    def name(self) -> str: ...

def read_recording(path: str) -> Dict[str, Any]: ...
