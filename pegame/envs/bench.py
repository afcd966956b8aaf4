"""The environments' speed: steps per second of the PettingZoo env with random actions."""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np

from pegame.envs.parallel import parallel_env


def bench_steps_per_second(
    seconds: float = 5.0, overrides: Sequence[str] = ("env=enclosed",), seed: int = 0, **settings
) -> dict[str, float]:
    """Run the two-agent env with uniformly random actions for about ``seconds`` s of
    wall time on one core (default options, a paper map) and measure it.

    Returns ``steps_per_s`` (step() calls per second, resets excluded), ``reset_ms``
    (mean reset time: spawn and plugin resets) and ``steps_per_s_with_resets``. The first
    reset and step (numba compilation or cache loading) are not timed.
    """
    env = parallel_env(overrides=overrides, **settings)
    rng = np.random.default_rng(seed)
    env.reset(seed=seed)
    env.step({agent: np.zeros(2, np.float32) for agent in env.possible_agents})
    stepping = resetting = 0.0
    steps = resets = 0
    while stepping + resetting < seconds:
        start = time.perf_counter()
        env.reset(seed=seed + resets)
        resetting += time.perf_counter() - start
        resets += 1
        actions = rng.uniform(-1.0, 1.0, (env.game.steps, 2, 2)).astype(np.float32)
        start = time.perf_counter()
        for pair in actions:
            env.step({"pursuer": pair[0], "evader": pair[1]})
            if not env.agents:
                break
        stepping += time.perf_counter() - start
        steps += len(actions)
    env.close()
    return {
        "steps_per_s": steps / stepping,
        "reset_ms": 1e3 * resetting / resets,
        "steps_per_s_with_resets": steps / (stepping + resetting),
    }
