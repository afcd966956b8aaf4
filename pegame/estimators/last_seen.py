"""Baseline estimator: the evader is believed to be where it was last detected."""

from __future__ import annotations

from pegame.api import Estimator
from pegame.types import EMPTY_BELIEF, Belief, Detection, Pose, Region


class LastSeen(Estimator):
    """The last detected map position, held until the next detection."""

    description = "Baseline: the evader's last detected map position."

    def reset(self, pursuer: Pose, detection: Detection | None, visible: Region) -> Belief:
        self.belief = EMPTY_BELIEF
        return self.update(0.0, pursuer, detection, visible)

    def update(
        self, dt: float, pursuer: Pose, detection: Detection | None, visible: Region
    ) -> Belief:
        if detection is not None:
            self.belief = Belief(mean=detection.position)
        return self.belief
