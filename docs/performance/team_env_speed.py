"""Game-steps per second of the batched team env against the PettingZoo env, one core.

``NUMBA_NUM_THREADS=1 python docs/performance/team_env_speed.py [GAMES] [PURSUERS] [EVADERS]``
(default 1024 2 2, the hall map, random actions): the median of 10 rounds of 5 batched
steps of every game, and of 5 rounds of 20 steps of one PettingZoo env (CPU time).
"""

from __future__ import annotations

import sys
import time

import numpy as np

from pegame.envs.parallel import parallel_env
from pegame.envs.vector import SelfPlayVectorEnv


def batched(overrides: list[str], games: int) -> float:
    env = SelfPlayVectorEnv(games, overrides=overrides)
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    rates = []
    for k in range(13):
        actions = {
            a: rng.uniform(-1, 1, (games, 2)).astype(np.float32) for a in env.possible_agents
        }
        start = time.process_time()
        for _ in range(5):
            env.step(actions)
        if k >= 3:  # three warm rounds
            rates.append(5 * games / (time.process_time() - start))
    return float(np.median(rates))


def single(overrides: list[str]) -> float:
    env = parallel_env(overrides=overrides)
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    rates = []
    for _ in range(5):
        start = time.process_time()
        for _ in range(20):
            env.step({a: rng.uniform(-1, 1, 2).astype(np.float32) for a in env.possible_agents})
            if not env.agents:
                env.reset()
        rates.append(20 / (time.process_time() - start))
    return float(np.median(rates))


def main() -> None:
    given = [int(a) for a in sys.argv[1:]]
    games, pursuers, evaders = given + [1024, 2, 2][len(given) :]
    overrides = ["env=hall", f"team.pursuers={pursuers}", f"team.evaders={evaders}"]
    fast, slow = batched(overrides, games), single(overrides)
    print(
        f"{pursuers}v{evaders} hall: batched {games} games {fast:,.0f} game-steps/s, "
        f"PettingZoo env {slow:,.0f} ({fast / slow:.1f}x)"
    )


if __name__ == "__main__":
    main()
