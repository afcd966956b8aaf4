"""The smart evader's decision on game states: the escape argmin with the pursuer's region
computed only where the search looks (``escape_goal``, what the batched evader runs)
against the whole region then the search (``EscapeSearch.escape`` with no region given,
what the strategy computes without one), per decision, one core, best of 3 passes over
the states of ``num_games`` batched games (enclosed, random pursuer actions) at env step
``step``; both give the same goal and cost (the tests hold them to the reference).

    python docs/performance/escape_decisions.py 1024 20
"""

import sys
import time

import numba
import numpy as np

from pegame.envs.vector import vector_env
from pegame.evaders.escape import escape_goal
from pegame.types import Pose

numba.set_num_threads(1)
n, step = int(sys.argv[1]), int(sys.argv[2])
env = vector_env(n, overrides=["env=enclosed"], opponent="smart")
env.reset(seed=0)
rng = np.random.default_rng(0)
for _ in range(step):
    env.step(rng.uniform(-1.0, 1.0, (n, 2)).astype(np.float32))
poses = env.game.state.poses
search = env.game.opponent.batch.strategy.search
pairs = [(Pose(*poses[k, 1]), Pose(*poses[k, 0])) for k in range(n)]
inputs = [search.kernel_inputs(search.component_at(me)) for me, _ in pairs]
scratch = search.scratch()


def lazy() -> None:
    for (me, p), arguments in zip(pairs, inputs):
        escape_goal(*arguments, (me.x, me.y, p.x, p.y, p.theta), scratch)


def whole() -> None:
    for me, p in pairs:
        search.escape(me, p)


for name, decide in (("escape_goal", lazy), ("whole region + escape", whole)):
    best = np.inf
    for _ in range(3):
        start = time.process_time()
        decide()
        best = min(best, time.process_time() - start)
    print(f"{name}: {1e6 * best / n:.0f} us per decision")
