"""Baseline estimator: the evader is believed to be where it was last detected."""

from __future__ import annotations

from pegame.api import OneOnOneEstimator
from pegame.types import EMPTY_BELIEF, Belief, Detection, Pose, Region


class LastSeen(OneOnOneEstimator):
    """The last detected map position, held until the next detection."""

    description = "Baseline: the evader's last detected map position."

    def reset_1v1(self, pursuer: Pose, detection: Detection | None, visible: Region) -> Belief:
        self.belief = EMPTY_BELIEF
        return self.update_1v1(0.0, pursuer, detection, visible)

    def update_1v1(
        self, dt: float, pursuer: Pose, detection: Detection | None, visible: Region
    ) -> Belief:
        if detection is not None:
            self.belief = Belief(mean=detection.position)
        return self.belief
