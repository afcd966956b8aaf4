"""The loop's estimation in a batched game, game by game in Python: the pursuer's belief
about the evader, for a pursuer strategy opponent
(:class:`pegame.vector.opponents.PursuerStrategyOpponent`) and for a learning pursuer's
``belief`` observation (:class:`pegame.observe.observations.PursuerFeatures`).

Per game, as :class:`pegame.loop.TickLoop` runs it with ``estimate=True`` in a 1v1 game:
the estimator built from the game's 'estimator' stream (as :class:`pegame.game.Game`
builds it), reset at tick 0 and updated at every later tick from the detection and the
visibility region at the pursuer's pose (:meth:`Estimation.sensed`, after the tick is
sensed); and the game's measures kept by :class:`pegame.metrics.TrackingMetrics` itself,
with the belief's (:meth:`Estimation.measure`, before the tick's move). It costs the
estimator and the region per game and tick, as in a single game.
"""

from __future__ import annotations

import numpy as np

from pegame.api import Estimator
from pegame.game import Scenario
from pegame.metrics import TrackingMetrics
from pegame.types import Belief, BoundingBox, Detection, Pose
from pegame.vector.state import (
    BOX_H,
    BOX_W,
    BOX_X,
    BOX_Y,
    DEPTH,
    EVADER,
    PURSUER,
    SEEN_X,
    SEEN_Y,
    BatchState,
)
from pegame.visibility import VisibilityRegion


def detection_of(state: BatchState, game: int) -> Detection | None:
    """Game ``game``'s current detection (state.detected, state.detection) as the
    detector's :class:`Detection`, None without one."""
    if not state.detected[game]:
        return None
    row = state.detection[game]
    box = BoundingBox(float(row[BOX_X]), float(row[BOX_Y]), float(row[BOX_W]), float(row[BOX_H]))
    position = (float(row[SEEN_X]), float(row[SEEN_Y]))
    return Detection(box=box, depth=float(row[DEPTH]), position=position)


class Estimation:
    """The scenario's estimator and measures for each of ``num_games`` 1v1 games."""

    def __init__(self, scenario: Scenario, num_games: int) -> None:
        cls = scenario.classes["estimator"]
        assert issubclass(cls, Estimator)  # the scenario's classes implement their kinds
        self.cls, self.config, self.context = cls, scenario.configs["estimator"], scenario.context
        self.estimators: list = [None] * num_games
        self.metrics: list[TrackingMetrics | None] = [None] * num_games
        #: (detection, region, belief) of each game's current tick
        self.seen: list = [None] * num_games

    def reset(self, game: int, streams: dict) -> None:
        """A new estimator for ``game`` from its 'estimator' stream of ``streams``, and
        new measures."""
        rng = np.random.default_rng(streams["estimator"])
        self.estimators[game] = self.cls(self.config, self.context, rng)
        self.metrics[game] = TrackingMetrics(self.context.control_dt)

    def sensed(self, state: BatchState, games: np.ndarray) -> None:
        """The loop's estimation after a tick is sensed (``_sense``): each game's region at
        the pursuer's pose and its estimator's belief from the detection (a reset at tick
        0)."""
        grid, camera, dt = self.context.grid, self.context.camera, self.context.control_dt
        for game in games.tolist():
            pose = Pose(*state.poses[game, PURSUER].tolist())
            detection = detection_of(state, game)
            region = VisibilityRegion(grid, pose, camera)
            estimator = self.estimators[game]
            if state.steps[game] == 0:
                belief = estimator.reset((pose,), (detection,), region)
            else:
                belief = estimator.update(dt, (pose,), (detection,), region)
            self.seen[game] = (detection, region, belief)

    def measure(self, state: BatchState, games: np.ndarray) -> None:
        """The current tick's measures of ``games`` (the loop's ``metrics.add``)."""
        poses = state.poses
        for game in games.tolist():
            pursuer = Pose(*poses[game, PURSUER].tolist())
            evader = Pose(*poses[game, EVADER].tolist())
            detected, in_view = bool(state.detected[game]), bool(state.in_view[game])
            self.metrics[game].add(pursuer, evader, detected, in_view, self.belief(game))

    def belief(self, game: int) -> Belief:
        """Game ``game``'s belief at its current tick."""
        return self.seen[game][2]
