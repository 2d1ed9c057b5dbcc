"""Registers the Gymnasium environments without importing them (the
environments themselves are in :mod:`errp.gym`, which imports Gymnasium).

Gymnasium 0.26 to 0.29 call :func:`register_envs` from the package's entry
point (``gymnasium.envs``) when ``gymnasium`` is imported, inside the
``errp`` namespace; Gymnasium 1.x dropped entry points, so ``import errp``
calls :func:`register` when Gymnasium is installed. Either way
``gym.make("errp/Grid-v0")`` works without ``import errp.gym``.
"""

from __future__ import annotations

#: (name, entry point, max_episode_steps) of each environment.
ENVS = (
    ("Grid-v0", "errp.gym:GridEnv", 100),
    ("Epuck-v0", "errp.gym:EpuckEnv", 1200),
)


def register_envs() -> None:
    """The entry point's function: Gymnasium calls it inside the ``errp``
    namespace, so the ids are given without it."""
    from gymnasium.envs.registration import register as gym_register
    from gymnasium.envs.registration import registry

    for name, entry_point, steps in ENVS:
        if f"errp/{name}" not in registry:
            gym_register(id=name, entry_point=entry_point, max_episode_steps=steps)


def register() -> None:
    """Registers ``errp/Grid-v0`` and ``errp/Epuck-v0`` if Gymnasium is
    installed and they are not registered yet; imports nothing else."""
    import importlib.util

    if importlib.util.find_spec("gymnasium") is None:
        return
    from gymnasium.envs.registration import register as gym_register
    from gymnasium.envs.registration import registry

    for name, entry_point, steps in ENVS:
        if f"errp/{name}" not in registry:
            gym_register(id=f"errp/{name}", entry_point=entry_point, max_episode_steps=steps)
