"""Gymnasium environments for learning from ErrP feedback.

``gym.make("errp/Grid-v0")`` needs no import of this module: installing
the package registers the environments with Gymnasium (its entry point for
Gymnasium 0.29, ``import errp`` for Gymnasium 1.x). They are:

- ``errp/Epuck-v0``: the e-puck of sec. 5, driven by motion primitives
  (see :class:`EpuckEnv`); its feedback is the p(error) of the
  sliding-window decoder every 62.5 ms.
- ``errp/Grid-v0``: the 5x5 grid of the paper's sec. 4. The agent moves the
  cursor (0 up, 1 down, 2 left, 3 right, 4 "goal reached"); the synthetic
  user judges each action against a goal the agent is not told (correct
  when it brings the cursor closer, or says "goal reached" on the goal);
  the EEG of that judgement is decoded by the testbed's calibrated decoder,
  and the agent observes the cursor and the decoded p(error). The reward is
  the feedback in [-1, 1], ``1 - 2 p(error)``: the agent learns from what
  the user's brain said, never from the goal. The episode ends when the
  agent says "goal reached" (``info["success"]`` says whether it was the
  goal) or after ``max_episode_steps`` actions (100).

``save="file.rrd"`` records every episode of an environment (each a run)
into one Rerun recording, written when the environment is closed (or
collected, or when Python exits); ``errp inspect file.rrd``, :func:`errp.read_recording` and the Rerun viewer read it.
``render_mode="rgb_array"`` draws a top-down frame (the arena or the grid)
for Gymnasium's ``RecordVideo``.

With ``observe_epoch=True`` the observation also holds the action's epoch of
preprocessed EEG, ``(n_channels, n_samples)`` float32 in uV, for agents that
decode the EEG themselves (the scenario's EEG must be streamed: the default
here).

    import gymnasium as gym

    env = gym.make("errp/Grid-v0", goal=(3, 1))
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(3)
"""

from __future__ import annotations

import numbers
import os
import warnings
import weakref
from typing import Any, Optional, Tuple

import numpy as np

try:
    import gymnasium as gym
    from gymnasium import spaces
except ImportError as e:  # pragma: no cover - depends on the environment
    raise ImportError(
        "errp.gym needs Gymnasium: pip install gymnasium (or pip install './python[gym]')"
    ) from e

from . import _args, _core, _gym_plugin, _progress

__all__ = ["ACTIONS", "EPUCK_ACTIONS", "EpuckEnv", "GridEnv"]

#: The grid's actions, by index.
ACTIONS = ("up", "down", "left", "right", "goal reached")
#: The e-puck's motion primitives, by index.
EPUCK_ACTIONS = ("forward", "turn left", "turn right", "stop")


class GridEnv(gym.Env):
    """The grid task with the device's actions chosen by an agent.

    Parameters
    ----------
    scenario : path, optional
        A grid scenario; by default the built-in fixed-goals one, with its
        EEG streamed (each action's EEG synthesised and decoded live).
    accuracy : float, optional
        The decoder's mean accuracy (the scenario's, 74.38 %, by default).
    overrides : dict, optional
        Scenario fields by dotted key.
    goal, start : (x, y), optional
        The user's goal and the cursor's start; drawn from the reset seed
        when not given (``reset(options={"goal": ..., "start": ...})`` sets
        them for one episode).
    observe_epoch : bool
        Add the action's preprocessed EEG epoch to the observation.
    render_mode : {"ansi", "rgb_array"}, optional
        ``render()`` returns the grid as text, or as an RGB frame
        ``(340, 320, 3)`` uint8: the cells shaded by this episode's visits,
        the goal outlined in red, the cursor in black, p(error) as a bar.
    save : path, optional
        Record every episode (up to 5000) into this ``.rrd``, written by
        :meth:`close`: the actions, p(error) and the user's judgements, as
        ``errp run --save`` records the grid (no belief: the agent's is its
        own).
    progress : bool, optional
        Show the decoder's calibration on stderr (a tqdm bar if tqdm is
        installed, else a line per tenth): by default when stderr is a
        terminal. A decoder of the same scenario and accuracy is calibrated
        once per process, so later environments show nothing.
    """

    metadata = {"render_modes": ["ansi", "rgb_array"], "render_fps": 2}

    def __init__(
        self,
        scenario: Optional[str] = None,
        *,
        accuracy: Optional[float] = None,
        overrides: Optional[dict] = None,
        goal: Optional[Tuple[int, int]] = None,
        start: Optional[Tuple[int, int]] = None,
        observe_epoch: bool = False,
        render_mode: Optional[str] = None,
        save: Optional[str] = None,
        progress: Optional[bool] = None,
    ) -> None:
        _check_render_mode(render_mode, self.metadata["render_modes"])
        fields = {"eeg": "per_action"}
        if overrides:
            fields.update(overrides)
        accuracy = _args.accuracy("accuracy", accuracy, optional=True)
        with _progress.shown(progress, "errp/Grid-v0") as report:
            self._core = _core.GridEnvCore(
                _args.path("scenario", scenario),
                accuracy=accuracy,
                overrides=fields,
                save=_args.path("save", save),
                progress=report,
            )
        self.save = save
        self._full_warned = False
        # The recording is written by close(), or when the environment is
        # collected or the interpreter exits without it.
        self._finalizer = weakref.finalize(self, self._core.close)
        self.goal = _cell("goal", goal)
        self.start = _cell("start", start)
        self.observe_epoch = bool(observe_epoch)
        self.render_mode = render_mode
        self.action_space = spaces.Discrete(5)
        obs = {
            "cursor": spaces.MultiDiscrete([5, 5]),
            "p_error": spaces.Box(0.0, 1.0, shape=(1,), dtype=np.float32),
        }
        if self.observe_epoch:
            if not self._core.per_action:
                raise ValueError(
                    "observe_epoch: the scenario's decoder does not synthesise each "
                    "action's EEG; set eeg = \"per_action\" and decoder = \"eeg\""
                )
            names, n_samples, _ = self._core.epoch_shape
            obs["epoch"] = spaces.Box(
                -np.inf, np.inf, shape=(len(names), n_samples), dtype=np.float32
            )
        self.observation_space = spaces.Dict(obs)
        self._cursor = (0, 0)
        self._goal = (0, 0)
        self._last: dict = {}
        self._visits = np.zeros((5, 5), dtype=np.int64)

    @property
    def ch_names(self) -> list:
        """Channels of an epoch."""
        return list(self._core.epoch_shape[0])

    @property
    def sfreq(self) -> float:
        """Sampling rate of an epoch (Hz)."""
        return self._core.epoch_shape[2]

    def _obs(self, p_error: float, epoch: Optional[np.ndarray]) -> dict:
        obs = {
            "cursor": np.array(self._cursor, dtype=np.int64),
            "p_error": np.array([p_error], dtype=np.float32),
        }
        if self.observe_epoch:
            shape = self.observation_space["epoch"].shape
            obs["epoch"] = (
                np.zeros(shape, dtype=np.float32)
                if epoch is None
                else np.asarray(epoch, dtype=np.float32)
            )
        return obs

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict] = None):
        """Starts an episode. The observation's p_error is 0.5 (no feedback
        yet) and its epoch zeros; ``info["goal"]`` is the user's goal, for
        evaluation only."""
        super().reset(seed=seed)
        options = options or {}
        unknown = set(options) - {"goal", "start"}
        if unknown:
            raise ValueError(
                f"options: unknown key(s) {sorted(unknown)}; accepted: 'goal', 'start'"
            )
        goal = _cell("goal", options.get("goal", self.goal))
        start = _cell("start", options.get("start", self.start))
        core_seed = int(self.np_random.integers(0, 2**63 - 1))
        self._cursor, self._goal = self._core.reset(core_seed, start, goal)
        self._last = {}
        self._visits[:] = 0
        self._visits[self._cursor] += 1
        _warn_full(self, 5000)
        return self._obs(0.5, None), {"goal": self._goal, "actions": 0}

    def step(self, action: Any):
        """Takes an action (0-4) and returns the observation, the reward
        ``1 - 2 p(error)``, whether the agent said "goal reached", False
        (the time limit is the wrapper's), and info: ``success``, the
        user's true judgement ``error``, the decoder's ``decoded_error``,
        ``p_error``, ``interval_secs`` and the goal."""
        a = _action(action, "0 (up), 1 (down), 2 (left), 3 (right) or 4 (goal reached)", 5)
        d = self._core.step(a, self.observe_epoch)
        self._cursor = tuple(d["cursor"])
        self._visits[self._cursor] += 1
        p = float(d["p_error"])
        self._last = d
        terminated = a == 4
        info = {
            "success": bool(d["reached"]),
            "error": bool(d["error"]),
            "decoded_error": bool(d["decoded_error"]),
            "p_error": p,
            "interval_secs": float(d["interval_secs"]),
            "goal": self._goal,
        }
        return self._obs(p, d.get("epoch")), 1.0 - 2.0 * p, terminated, False, info

    def close(self) -> None:
        """Writes the recording (``save=``); the environment records no more.
        With ``save=`` and no episode that took an action, nothing is
        written, and a warning says so."""
        _close_recording(self)
        super().close()

    def render(self):
        """The grid as text (row 4 on top: C the cursor, G the goal) or as
        an RGB frame, by ``render_mode``."""
        if self.render_mode == "rgb_array":
            return _grid_frame(self._cursor, self._goal, self._visits, self._last.get("p_error"))
        if self.render_mode != "ansi":
            return None
        rows = []
        for y in reversed(range(5)):
            row = ""
            for x in range(5):
                c = "C" if (x, y) == tuple(self._cursor) else "."
                if (x, y) == tuple(self._goal):
                    c = "*" if c == "C" else "G"
                row += c
            rows.append(row)
        p = self._last.get("p_error")
        tail = "" if p is None else f"\np(error) = {p:.2f}"
        return "\n".join(rows) + tail


class EpuckEnv(gym.Env):
    """The e-puck task with the robot driven by an agent.

    Every action is a motion primitive held for ``windows_per_action``
    decoder windows of 62.5 ms (0.25 s by default): 0 forward (the
    scenario's drive speed), 1 turn left, 2 turn right (in place, the
    scenario's turn speed), 3 stop. The synthetic user watches the robot
    through the ceiling camera and judges its motion against a goal the
    agent is not told; the testbed's sliding-window SVM turns the EEG into
    p(error) every window. The observation is the pose the camera sees
    ``(x_m, y_m, heading_rad)``, the p(error) of each window of the action
    and whether the scenario's detector reported an error; the reward is
    the mean of ``1 - 2 p(error)`` over the action's windows. Stopping on
    a goal (within the scenario's goal radius) commits to it and ends the
    episode (``info["success"]``: it was the user's); the time limit is
    ``max_episode_steps`` actions (1200: 5 minutes at 0.25 s).

    Parameters
    ----------
    scenario : path, optional
        An e-puck scenario; by default the built-in Mexico-to-Pisa run.
    accuracy, overrides :
        As for :class:`GridEnv`.
    goal : int or str, optional
        The user's goal: an index into :attr:`goal_names` or a city name
        (the scenario's by default; ``reset(options={"goal": ...})`` sets
        it for one episode).
    windows_per_action : int
        Windows of 62.5 ms each action lasts, 1 to 64.
    observe_window : bool
        Add the last window of preprocessed EEG, ``(n_channels,
        n_samples)`` float32 in uV, to the observation.
    render_mode : {"ansi", "rgb_array"}, optional
        ``render()`` returns the pose as text, or a top-down RGB frame of
        the arena ``(400, 400, 3)`` uint8, 0.5 cm per pixel: the cities in
        grey with the user's goal ringed in red, the path in blue, red
        marks where the detector reported an error, the e-puck in black with
        its heading in orange. ``metadata["render_fps"]`` is real time (4
        frames a second at 4 windows per action).
    save : path, optional
        Record every episode (up to 100, each a run) into this ``.rrd`` as
        ``errp run --save`` records the e-puck, written by :meth:`close`;
        an episode cut short (a time limit, a reset) is a run without a
        commitment.
    progress : bool, optional
        Show the continuous decoder's calibration on stderr (a tqdm bar if
        tqdm is installed, else a line per tenth): by default when stderr is
        a terminal. A decoder of the same scenario and accuracy is
        calibrated once per process, so later environments show nothing.
    """

    metadata = {"render_modes": ["ansi", "rgb_array"], "render_fps": 4}

    def __init__(
        self,
        scenario: Optional[str] = None,
        *,
        accuracy: Optional[float] = None,
        overrides: Optional[dict] = None,
        goal: Any = None,
        windows_per_action: int = 4,
        observe_window: bool = False,
        render_mode: Optional[str] = None,
        save: Optional[str] = None,
        progress: Optional[bool] = None,
    ) -> None:
        _check_render_mode(render_mode, self.metadata["render_modes"])
        if not (isinstance(windows_per_action, int) and 1 <= windows_per_action <= 64):
            raise ValueError(
                f"windows_per_action = {windows_per_action!r} is invalid: expected a "
                "whole number from 1 to 64 (windows of 62.5 ms)"
            )
        accuracy = _args.accuracy("accuracy", accuracy, optional=True)
        with _progress.shown(progress, "errp/Epuck-v0") as report:
            self._core = _core.EpuckEnvCore(
                _args.path("scenario", scenario),
                accuracy=accuracy,
                overrides=None if overrides is None else dict(overrides),
                save=_args.path("save", save),
                progress=report,
            )
        self.save = save
        self._full_warned = False
        # The recording is written by close(), or when the environment is
        # collected or the interpreter exits without it.
        self._finalizer = weakref.finalize(self, self._core.close)
        self.metadata = {
            **type(self).metadata,
            "render_fps": 1.0 / (0.0625 * windows_per_action),
        }
        self.goal_names = list(self._core.goal_names)
        #: The goals as (name, x_m, y_m): where the cities are is no secret;
        #: which one the user wants is.
        self.goals = [tuple(g) for g in self._core.goals]
        #: How near a goal's centre the robot must stop to commit to it (m).
        self.goal_radius_m = float(self._core.goal_radius_m)
        self.goal = self._goal_index(goal)
        self.windows_per_action = windows_per_action
        self.observe_window = bool(observe_window)
        self.render_mode = render_mode
        size = float(self._core.arena_size_m)
        self.action_space = spaces.Discrete(4)
        obs = {
            "pose": spaces.Box(
                np.array([0.0, 0.0, -np.pi], dtype=np.float32),
                np.array([size, size, np.pi], dtype=np.float32),
                dtype=np.float32,
            ),
            "p_error": spaces.Box(0.0, 1.0, shape=(windows_per_action,), dtype=np.float32),
            "detected": spaces.Discrete(2),
        }
        if self.observe_window:
            names, n_samples, _ = self._core.window_shape
            obs["window"] = spaces.Box(
                -np.inf, np.inf, shape=(len(names), n_samples), dtype=np.float32
            )
        self.observation_space = spaces.Dict(obs)
        self._size = size
        self._pose = (0.0, 0.0, 0.0)
        self._goal = 0
        self._time = 0.0
        self._path: list = []
        self._detections: list = []
        self._obstacles = [np.asarray(o, dtype=np.float64) for o in self._core.obstacles]

    @property
    def ch_names(self) -> list:
        """Channels of a window."""
        return list(self._core.window_shape[0])

    @property
    def sfreq(self) -> float:
        """Sampling rate (Hz)."""
        return self._core.window_shape[2]

    def _goal_index(self, goal: Any) -> Optional[int]:
        if goal is None:
            return None
        if isinstance(goal, str):
            if goal not in self.goal_names:
                raise ValueError(
                    f"goal = {goal!r} is invalid: expected one of the 25 cities "
                    f"({', '.join(self.goal_names)}) or an index 0-24"
                )
            return self.goal_names.index(goal)
        g = _whole(goal)
        if g is None:
            raise TypeError(
                f"goal must be a city name or a whole index from 0 to "
                f"{len(self.goal_names) - 1}, not {type(goal).__name__} {goal!r}")
        if not 0 <= g < len(self.goal_names):
            raise ValueError(
                f"goal = {goal!r} is invalid: expected an index from 0 to "
                f"{len(self.goal_names) - 1} or a city name"
            )
        return g

    def _obs(self, p_error, detected: bool, window) -> dict:
        x, y, h = self._pose
        obs = {
            "pose": np.array(
                [
                    min(max(x, 0.0), self._size),
                    min(max(y, 0.0), self._size),
                    np.arctan2(np.sin(h), np.cos(h)),
                ],
                dtype=np.float32,
            ),
            "p_error": np.asarray(p_error, dtype=np.float32),
            "detected": int(detected),
        }
        if self.observe_window:
            shape = self.observation_space["window"].shape
            obs["window"] = (
                np.zeros(shape, dtype=np.float32)
                if window is None
                else np.asarray(window, dtype=np.float32)
            )
        return obs

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict] = None):
        """Starts an episode at the scenario's start pose; p_error is 0.5 (no
        feedback yet). ``info["goal"]`` names the user's goal, for
        evaluation only."""
        super().reset(seed=seed)
        options = options or {}
        unknown = set(options) - {"goal"}
        if unknown:
            raise ValueError(f"options: unknown key(s) {sorted(unknown)}; accepted: 'goal'")
        goal = self._goal_index(options.get("goal", self.goal))
        core_seed = int(self.np_random.integers(0, 2**63 - 1))
        self._pose, self._goal = self._core.reset(core_seed, goal)
        self._time = 0.0
        self._path = [self._pose[:2]]
        self._detections = []
        _warn_full(self, 100)
        p = np.full(self.windows_per_action, 0.5, dtype=np.float32)
        return self._obs(p, False, None), {"goal": self.goal_names[self._goal], "time_secs": 0.0}

    def step(self, action: Any):
        """Runs a motion primitive (0-3) and returns the observation, the
        mean of ``1 - 2 p(error)``, whether the robot stopped on a goal,
        False, and info: ``success``, ``committed`` (the city stopped on),
        ``errps`` (the user's ErrPs during the action, for scoring),
        ``time_secs`` and the goal."""
        a = _action(action, "0 (forward), 1 (turn left), 2 (turn right) or 3 (stop)", 4)
        d = self._core.step(a, self.windows_per_action, self.observe_window)
        self._pose = tuple(d["pose"])
        self._time = float(d["time_secs"])
        self._path.append(self._pose[:2])
        if d["detected"]:
            self._detections.append(self._pose[:2])
        p = np.asarray(d["p_error"], dtype=np.float64)
        on_goal = d["on_goal"]
        terminated = a == 3 and on_goal is not None
        info = {
            "success": terminated and on_goal == self._goal,
            "committed": self.goal_names[on_goal] if terminated else None,
            "errps": int(d["errps"]),
            "time_secs": self._time,
            "goal": self.goal_names[self._goal],
        }
        reward = float(np.mean(1.0 - 2.0 * p))
        return self._obs(p, d["detected"], d.get("window")), reward, terminated, False, info

    def close(self) -> None:
        """Writes the recording (``save=``); the episode in progress ends
        without a commitment, and the environment records no more. With
        ``save=`` and no episode that took an action, nothing is written,
        and a warning says so."""
        _close_recording(self)
        super().close()

    def render(self):
        """The pose and time as text, or a top-down RGB frame of the arena,
        by ``render_mode``."""
        if self.render_mode == "rgb_array":
            return _arena_frame(self)
        if self.render_mode != "ansi":
            return None
        x, y, h = self._pose
        return (
            f"t = {self._time:.2f} s: e-puck at ({100 * x:.1f}, {100 * y:.1f}) cm, "
            f"heading {np.degrees(h):.0f} deg; the user wants {self.goal_names[self._goal]}"
        )


def _check_render_mode(mode: Optional[str], modes: list) -> None:
    if mode is not None and mode not in modes:
        raise ValueError(
            f"render_mode = {mode!r} is invalid: expected None, "
            + " or ".join(repr(m) for m in modes)
        )


def _warn_full(env, cap: int) -> None:
    if env.save is not None and env._core.recording_full and not env._full_warned:
        env._full_warned = True
        warnings.warn(
            f"save={os.fspath(env.save)!r}: the recording holds its first {cap} episodes; "
            "later ones are not recorded",
            RuntimeWarning,
            stacklevel=3,
        )


class _Canvas:
    """An RGB frame drawn with numpy: discs, rings and thick lines."""

    def __init__(self, height: int, width: int, background=(250, 250, 248)) -> None:
        self.img = np.empty((height, width, 3), dtype=np.uint8)
        self.img[:] = background
        self.yy, self.xx = np.mgrid[0:height, 0:width]

    def disc(self, x: float, y: float, r: float, colour, inner: float = -1.0) -> None:
        h, w, _ = self.img.shape
        x0, x1 = max(int(x - r - 1), 0), min(int(x + r + 2), w)
        y0, y1 = max(int(y - r - 1), 0), min(int(y + r + 2), h)
        if x0 >= x1 or y0 >= y1:
            return
        d2 = (self.xx[y0:y1, x0:x1] - x) ** 2 + (self.yy[y0:y1, x0:x1] - y) ** 2
        mask = (d2 <= r * r) & (d2 >= inner * inner if inner > 0 else True)
        self.img[y0:y1, x0:x1][mask] = colour

    def line(self, p0, p1, colour, width: float = 1.0) -> None:
        n = int(max(abs(p1[0] - p0[0]), abs(p1[1] - p0[1]))) + 1
        for t in np.linspace(0.0, 1.0, n + 1):
            self.disc(p0[0] + t * (p1[0] - p0[0]), p0[1] + t * (p1[1] - p0[1]), width / 2, colour)


def _grid_frame(cursor, goal, visits, p_error) -> np.ndarray:
    cell = 64
    c = _Canvas(5 * cell + 20, 5 * cell, background=(190, 190, 190))
    most = max(int(visits.max()), 1)
    for x in range(5):
        for y in range(5):
            top = (4 - y) * cell
            v = visits[x, y] / most
            shade = (255 - v * np.array([235, 195, 115])).astype(np.uint8)
            c.img[top + 1 : top + cell - 1, x * cell + 1 : (x + 1) * cell - 1] = shade
    gx, gy = goal
    top = (4 - gy) * cell
    for k in range(3):
        c.img[top + k, gx * cell : (gx + 1) * cell] = (220, 40, 40)
        c.img[top + cell - 1 - k, gx * cell : (gx + 1) * cell] = (220, 40, 40)
        c.img[top : top + cell, gx * cell + k] = (220, 40, 40)
        c.img[top : top + cell, (gx + 1) * cell - 1 - k] = (220, 40, 40)
    cx, cy = cursor
    c.disc(cx * cell + cell / 2, (4 - cy) * cell + cell / 2, cell * 0.22, (30, 30, 30))
    c.img[5 * cell :] = (250, 250, 248)
    if p_error is not None:
        c.img[5 * cell + 4 : 5 * cell + 16, : int(round(p_error * 5 * cell))] = (220, 40, 40)
    return c.img


def _arena_frame(env) -> np.ndarray:
    px = 400 / env._size  # pixels per metre
    c = _Canvas(400, 400)

    def at(x, y):
        return (x * px, (env._size - y) * px)

    for o in env._obstacles:
        pts = [at(x, y) for x, y in o]
        for p0, p1 in zip(pts, pts[1:]):
            c.line(p0, p1, (110, 80, 50), 2)
    for i, (_, gx, gy) in enumerate(env.goals):
        x, y = at(gx, gy)
        c.disc(x, y, 5, (150, 150, 150))
        if i == env._goal:
            r = max(env.goal_radius_m * px, 9.0)
            c.disc(x, y, r, (220, 40, 40), inner=r - 2)
    pts = [at(x, y) for x, y in env._path]
    for p0, p1 in zip(pts, pts[1:]):
        c.line(p0, p1, (40, 90, 200), 2)
    for x, y in env._detections:
        c.disc(*at(x, y), 4, (220, 30, 30))
    x, y, h = env._pose
    rx, ry = at(x, y)
    c.disc(rx, ry, 0.037 * px, (30, 30, 30))
    c.line((rx, ry), (rx + 0.08 * px * np.cos(h), ry - 0.08 * px * np.sin(h)), (230, 120, 20), 2)
    c.img[[0, -1], :] = (60, 60, 60)
    c.img[:, [0, -1]] = (60, 60, 60)
    return c.img


def _close_recording(env) -> None:
    """Closes ``env``'s core once (writing its recording); warns when
    ``save=`` was given and no episode was recorded, so nothing was
    written."""
    if not env._finalizer.alive:
        return
    written = env._finalizer()
    if env.save is not None and written is None:
        warnings.warn(
            f"save={os.fspath(env.save)!r}: no episode took an action, so nothing was recorded "
            "and no file was written",
            UserWarning,
            stacklevel=3,
        )


def _whole(v) -> Optional[int]:
    """``v`` as an ``int`` if it is a Python or NumPy integer (a 0-d
    integer array too), else ``None``: no float, fraction, bool, complex,
    string or None is taken for one."""
    if isinstance(v, np.ndarray) and v.ndim == 0 and v.dtype.kind in "iu":
        v = v.item()
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Integral):
        return None
    return int(v)


def _action(action, expected: str, n: int) -> int:
    """An environment's action: a whole number from 0 to ``n - 1``."""
    a = _whole(action)
    if a is None:
        raise TypeError(
            f"action must be a whole number: {expected}, not {type(action).__name__} {action!r}")
    if not 0 <= a < n:
        raise ValueError(f"action = {a} is invalid: expected {expected}")
    return a


def _cell(name: str, c) -> Optional[Tuple[int, int]]:
    if c is None:
        return None
    expected = "a cell (x, y) of the 5x5 grid, x and y whole numbers from 0 to 4"
    try:
        parts = list(c)
    except TypeError:
        raise TypeError(f"{name} must be {expected}, not {type(c).__name__} {c!r}") from None
    whole = [_whole(v) for v in parts]
    if len(parts) != 2 or any(v is None for v in whole):
        raise TypeError(f"{name} must be {expected}, not {c!r}")
    x, y = whole
    if not (0 <= x < 5 and 0 <= y < 5):
        raise ValueError(
            f"{name} = ({x}, {y}) is invalid: expected a cell (x, y) of the 5x5 grid, "
            "x and y from 0 to 4"
        )
    return (x, y)


_gym_plugin.register()
