"""Reinforcement-learning environments on pegame's games.

- :func:`parallel_env` - PettingZoo Parallel env, agents ``pursuer`` and ``evader``
  (:mod:`pegame.envs.parallel`);
- ``gymnasium.make("pegame/Pursuit-v0")`` and ``"pegame/Evasion-v0"`` - one learner
  against a pegame strategy (:mod:`pegame.envs.single`), registered when this package is
  imported (or ``gymnasium.make("pegame.envs:pegame/Pursuit-v0")``);
- :func:`vector_env` - ``num_envs`` games stepped together by numba kernels, a
  ``gymnasium.vector.VectorEnv`` for a learning pursuer or evader, or both for self-play
  (:mod:`pegame.envs.vector`);
- :func:`bench_steps_per_second` - the env's speed, for ``python -m pegame.bench``.

Every env takes the app's config (``config=`` a composed DictConfig, or ``overrides=``
the command-line overrides: any map, simulator, detector, estimator, opponent) and the
options of :class:`pegame.observe.settings.EnvSettings` (validated by
:func:`pegame.envs.config.env_settings`). Observations and actions live in
:mod:`pegame.observe`, shared with the ``policy`` pursuer and evader, which play a
trained policy in ordinary games without importing this package.

The env classes need gymnasium and pettingzoo (``pip install pegame[rl]``); importing
this package registers the Gymnasium ids when gymnasium is installed. The PettingZoo env
is imported on first use.
"""

from __future__ import annotations

import importlib
from importlib.util import find_spec
from typing import Any

_LAZY = {
    "parallel_env": "pegame.envs.parallel",
    "PursuitEvasionParallelEnv": "pegame.envs.parallel",
    "PursuitEnv": "pegame.envs.single",
    "EvasionEnv": "pegame.envs.single",
    "register_envs": "pegame.envs.single",
    "bench_steps_per_second": "pegame.envs.bench",
    "vector_env": "pegame.envs.vector",
    "PursuitVectorEnv": "pegame.envs.vector",
    "EvasionVectorEnv": "pegame.envs.vector",
    "SelfPlayVectorEnv": "pegame.envs.vector",
}

__all__ = sorted(_LAZY)


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'pegame.envs' has no attribute '{name}'")


# Gymnasium 1.x has no plugin entry points: env ids exist once their package is imported.
if find_spec("gymnasium") is not None:
    importlib.import_module("pegame.envs.single").register_envs()
