"""Whole games of the batched pursuit env against the smart evader: the evader batched in
the kernels (``batch``) or played game by game in Python as any strategy (``strategy``);
env steps per second over every step of one game (enclosed, random actions for the
pursuer), and per block of 100 steps (the first, with most evaders in view and every game
planning, is the slowest). On one numba thread (the default) the rates are per second of
CPU time, on more (a third argument) per second of wall time.

    python docs/performance/smart_evader_games.py 1024 batch
    python docs/performance/smart_evader_games.py 256 strategy
    python docs/performance/smart_evader_games.py 1024 batch 2
"""

import sys
import time

import numba
import numpy as np

from pegame.envs.vector import vector_env
from pegame.evaders.smart import SmartEvader
from pegame.vector.opponents import StrategyOpponent

n = int(sys.argv[1])
which = sys.argv[2]
threads = int(sys.argv[3]) if len(sys.argv) > 3 else 1
numba.set_num_threads(threads)
clock = time.process_time if threads == 1 else time.perf_counter
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
t0 = t = clock()
for i, actions in enumerate(acts):
    env.step(actions)
    if i % 100 == 99:
        now = clock()
        phase.append(100 * n / (now - t))
        t = now
total = clock() - t0
blocks = " ".join(f"{p / 1e3:.0f}k" for p in phase)
rate = f"{steps * n / total:.0f} steps/s over a whole game on {threads} thread(s)"
print(f"{which}, {n} games: {rate}; per 100: {blocks}")
