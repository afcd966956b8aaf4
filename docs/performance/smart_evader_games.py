"""Whole games of the batched pursuit env against the smart evader, one core: the evader
batched in the kernels (``batch``) or played game by game in Python as any strategy
(``strategy``); env steps per second of CPU time over every step of one game (enclosed,
random actions for the pursuer), and per block of 100 steps (the first, with most evaders
in view and every game planning, is the slowest).

    python docs/performance/smart_evader_games.py 1024 batch
    python docs/performance/smart_evader_games.py 256 strategy
"""

import sys
import time

import numba
import numpy as np

from pegame.envs.vector import vector_env
from pegame.evaders.smart import SmartEvader
from pegame.vector.opponents import StrategyOpponent

numba.set_num_threads(1)
n = int(sys.argv[1])
which = sys.argv[2]
env = vector_env(n, overrides=["env=enclosed"], opponent="smart")
if which == "strategy":
    game = env.game
    config = game.scenario.configs["evader"]
    game.opponent = StrategyOpponent(SmartEvader, config, game.context, n)
env.reset(seed=0)
env.step(np.zeros((n, 2), np.float32))
rng = np.random.default_rng(0)
steps = env.game.steps - 1
acts = rng.uniform(-1, 1, (steps, n, 2)).astype(np.float32)
phase = []
t0 = t = time.process_time()
for i, actions in enumerate(acts):
    env.step(actions)
    if i % 100 == 99:
        now = time.process_time()
        phase.append(100 * n / (now - t))
        t = now
total = time.process_time() - t0
blocks = " ".join(f"{p / 1e3:.0f}k" for p in phase)
print(f"{which}, {n} games: {steps * n / total:.0f} steps/s over a whole game; per 100: {blocks}")
