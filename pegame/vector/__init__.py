"""Batched games: thousands of pegame games stepped together by numba kernels.

- :mod:`pegame.vector.game`: :class:`BatchedGame`, many games of one scenario (1v1, or
  teams in self-play), each the game the single env plays with the same seed, in the
  tick loop's order;
- :mod:`pegame.vector.kernels`: the tick of every game (the grid simulator's own move
  kernel, the measures) as numba kernels, parallel over games; :mod:`pegame.vector.camera`
  (detector, ground truth: the visibility and detector plugins' own kernels) and
  :mod:`pegame.vector.features` (observations: :mod:`pegame.observe.features`' own
  kernels) per game; :mod:`pegame.vector.state` the
  arrays and numbers they take;
- :mod:`pegame.vector.opponents`: the scripted opponent of a learner;
- :mod:`pegame.vector.estimation`: the estimator per game in Python, for a pursuer
  strategy or a belief observation;
- :mod:`pegame.vector.metrics`: the measures kept as running sums.

The Gymnasium vector envs on it are in :mod:`pegame.envs.vector`.
"""

from pegame.vector.game import BatchedGame

__all__ = ["BatchedGame"]
