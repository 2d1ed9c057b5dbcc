"""The Gymnasium environments: Gymnasium's own checker, seeded resets, and
feedback that carries the user's judgement."""

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")
from gymnasium.utils.env_checker import check_env  # noqa: E402

import errp.gym  # noqa: E402,F401  (registers the environments)


@pytest.mark.parametrize(
    "env_id, kwargs",
    [
        ("errp/Grid-v0", {}),
        ("errp/Grid-v0", {"observe_epoch": True, "goal": (3, 1)}),
        ("errp/Epuck-v0", {}),
        ("errp/Epuck-v0", {"observe_window": True, "goal": "Tokyo"}),
        ("errp/Grid-v0", {"render_mode": "rgb_array"}),
        ("errp/Epuck-v0", {"render_mode": "rgb_array"}),
    ],
)
def test_check_env(env_id, kwargs):
    env = gym.make(env_id, **kwargs)
    # The render check only where there is something to render with.
    check_env(env.unwrapped, skip_render_check="render_mode" not in kwargs)
    obs, _ = env.reset(seed=0)
    assert env.observation_space.contains(obs)


def rollout(env, seed, actions):
    obs, info = env.reset(seed=seed)
    out = [obs]
    for a in actions:
        obs, reward, terminated, truncated, info = env.step(a)
        out.append((obs, reward, info))
        if terminated:
            break
    return out, info


def same(a, b):
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, (tuple, list)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray):
        return np.array_equal(a, b)
    return a == b


@pytest.mark.parametrize("env_id, actions", [
    ("errp/Grid-v0", [3, 3, 0, 1, 2, 0, 0, 4]),
    ("errp/Epuck-v0", [1, 1, 0, 0, 0, 2, 0, 3]),
])
def test_a_seeded_reset_is_reproducible(env_id, actions):
    env = gym.make(env_id)
    first, _ = rollout(env, 11, actions)
    second, _ = rollout(env, 11, actions)
    other, _ = rollout(env, 12, actions)
    assert same(first, second)
    assert not same(first, other)


def test_grid_feedback_follows_the_users_judgement():
    """Over many actions, p(error) is higher after the actions the user
    judged erroneous, and about as accurate as the decoder's calibration."""
    env = gym.make("errp/Grid-v0", goal=(2, 2))
    rng = np.random.default_rng(0)
    p_err, p_ok = [], []
    for ep in range(6):
        env.reset(seed=ep)
        for _ in range(40):
            _, reward, terminated, truncated, info = env.step(int(rng.integers(0, 4)))
            assert reward == pytest.approx(1 - 2 * info["p_error"])
            (p_err if info["error"] else p_ok).append(info["p_error"])
    acc = (np.mean(np.array(p_err) >= 0.5) + np.mean(np.array(p_ok) < 0.5)) / 2
    assert np.mean(p_err) > np.mean(p_ok) + 0.1
    assert 0.64 < acc < 0.86, acc


def test_saying_goal_reached_on_the_goal_succeeds():
    env = gym.make("errp/Grid-v0", goal=(1, 0), start=(0, 0))
    env.reset(seed=3)
    _, _, terminated, _, info = env.step(3)
    assert not terminated and tuple(env.unwrapped._cursor) == (1, 0)
    _, _, terminated, _, info = env.step(4)
    assert terminated and info["success"]
    env.reset(seed=3)
    _, _, terminated, _, info = env.step(4)
    assert terminated and not info["success"]


def test_the_time_limit_truncates():
    env = gym.make("errp/Grid-v0", max_episode_steps=5)
    env.reset(seed=0)
    for k in range(5):
        *_, truncated, _ = env.step(0)
    assert truncated


def test_epuck_driving_to_the_goal_commits_to_it():
    env = gym.make("errp/Epuck-v0", windows_per_action=2, max_episode_steps=2000)
    obs, info = env.reset(seed=1)
    assert info["goal"] == "Pisa"
    core = env.unwrapped
    # Steer towards Pisa with the pose the camera gives.
    name, gx, gy = core.goals[core.goal_names.index("Pisa")]
    goal = np.array([gx, gy])
    for _ in range(2000):
        x, y, h = obs["pose"]
        bearing = np.arctan2(goal[1] - y, goal[0] - x) - h
        bearing = np.arctan2(np.sin(bearing), np.cos(bearing))
        near = np.hypot(*(goal - (x, y))) < 0.5 * core.goal_radius_m
        a = 3 if near else (0 if abs(bearing) < 0.12 else (1 if bearing > 0 else 2))
        obs, reward, terminated, truncated, info = env.step(a)
        if terminated:
            break
    assert terminated and info["success"] and info["committed"] == "Pisa"


def test_bad_arguments_name_the_field():
    with pytest.raises(ValueError, match="goal"):
        gym.make("errp/Grid-v0", goal=(7, 0))
    with pytest.raises(ValueError, match="goal"):
        gym.make("errp/Epuck-v0", goal="Atlantis")
    with pytest.raises(ValueError, match="windows_per_action"):
        gym.make("errp/Epuck-v0", windows_per_action=0)
    env = gym.make("errp/Grid-v0")
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action"):
        env.step(9)
    with pytest.raises(ValueError, match="options"):
        env.reset(seed=0, options={"gaol": (1, 1)})
    with pytest.raises(ValueError, match="render_mode = 'human' is invalid"):
        errp.gym.GridEnv(render_mode="human")
    with pytest.raises(ValueError, match="'ansi' or 'rgb_array'"):
        errp.gym.EpuckEnv(render_mode="rgb")


def test_the_environments_are_registered_without_importing_errp_gym(tmp_path):
    # Gymnasium 1.x has no entry points: `import errp` registers both ids
    # (by name only: errp.gym, which imports Gymnasium's spaces, is loaded
    # by gym.make).
    import subprocess
    import sys

    code = (
        "import sys, gymnasium as gym, errp\n"
        "assert 'errp.gym' not in sys.modules\n"
        "assert 'errp/Grid-v0' in gym.registry and 'errp/Epuck-v0' in gym.registry\n"
        "env = gym.make('errp/Grid-v0')\n"
        "print(type(env.unwrapped).__name__, env.spec.max_episode_steps,\n"
        "      env.metadata['render_fps'])\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=tmp_path, timeout=600)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["GridEnv", "100", "2"]
