"""Constant-velocity Kalman filter on the detected evader positions.

A baseline to compare with the paper's particle filter (Sec. "Particle Filter based
Tracking"): a linear Kalman filter (filterpy.kalman.KalmanFilter) with state
[x, y, vx, vy] (m, m, m/s, m/s) in the map frame and measurement z = the detection's map
position (x, y) (m) with isotropic noise ``measurement_std``. Between ticks the evader is
assumed to move at constant velocity, disturbed by white acceleration noise of std
``accel_std`` (m/s^2), the discrete white-noise model: for a tick of dt seconds,

    F = [[I, dt I], [0, I]],   Q = accel_std^2 [[dt^4/4 I, dt^3/2 I], [dt^3/2 I, dt^2 I]].

It predicts at every tick (F and Q rebuilt for that tick's dt) and updates only when the
evader is detected, so through a gap of misses the estimate coasts along the last
velocity while its covariance grows. The visibility region is not used (a Kalman filter
cannot express "not here" without becoming non-Gaussian).

Speed clamp: the evader cannot move faster than ``context.evader.v_max``, so after every
predict and update a velocity estimate faster than that is scaled back to v_max (same
direction). This is a projection onto the feasible set, not a Bayesian update; the
covariance is left as the filter computed it.

The filter starts at the first detection (position = detection, velocity 0 with std
v_max); before it the belief's mean is None. In a team every pursuer's detection of the
evader corrects the filter in turn (:meth:`KalmanEstimator.update`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from filterpy.common import Q_discrete_white_noise
from filterpy.kalman import KalmanFilter

from pegame.api import Context, Estimator
from pegame.errors import require
from pegame.types import EMPTY_BELIEF, Belief, Detection, Pose, Region


class KalmanEstimator(Estimator):
    """Constant-velocity Kalman filter on the detections, coasting through misses."""

    description = "Constant-velocity Kalman filter on the detected positions (baseline)."

    @dataclass
    class Config:
        measurement_std: float = 0.2  # m, std of the detected position's noise, per axis
        accel_std: float = 1.0  # m/s^2, std of the white acceleration (process) noise

        def __post_init__(self) -> None:
            for key in ("measurement_std", "accel_std"):
                value = getattr(self, key)
                require(0.0 < value < math.inf, key, "a finite std > 0", value)

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        self._kf: KalmanFilter | None = None

    def reset(
        self, pursuers: Sequence[Pose], detections: Sequence[Detection | None], region: Region
    ) -> Belief:
        """Forget the track; start one at the first detection and correct it with the others."""
        self._kf = None
        seen = [d for d in detections if d is not None]
        if seen:
            self._correct(self._start(seen[0].position), seen[1:])
        return self._belief()

    def update(
        self,
        dt: float,
        pursuers: Sequence[Pose],
        detections: Sequence[Detection | None],
        region: Region,
    ) -> Belief:
        """Predict ``dt`` s ahead, then correct with every pursuer's detection in turn
        (independent measurements of one position: sequential updates are the batch
        update); before the first detection, start at it."""
        kf = self._kf
        if kf is None:
            return self.reset(pursuers, detections, region)
        kf.F = transition(dt)
        kf.Q = Q_discrete_white_noise(
            dim=2, dt=dt, var=self.config.accel_std**2, block_size=2, order_by_dim=False
        )
        kf.predict()
        _clamp_speed(kf, self.context.evader.v_max)
        self._correct(kf, [d for d in detections if d is not None])
        return self._belief()

    def _correct(self, kf: KalmanFilter, detections: Sequence[Detection]) -> None:
        """Kalman updates of ``kf`` with each of ``detections``' map positions, speed
        clamped."""
        for detection in detections:
            kf.update(np.asarray(detection.position, dtype=float))
            _clamp_speed(kf, self.context.evader.v_max)

    def _start(self, position: tuple[float, float]) -> KalmanFilter:
        """A filter at ``position`` (m), at rest, with the velocity's std v_max (m/s)."""
        kf = KalmanFilter(dim_x=4, dim_z=2)
        kf.x = np.array([position[0], position[1], 0.0, 0.0])
        kf.H = np.hstack((np.eye(2), np.zeros((2, 2))))
        kf.R = self.config.measurement_std**2 * np.eye(2)
        v_max = self.context.evader.v_max
        kf.P = np.diag([self.config.measurement_std**2] * 2 + [v_max**2] * 2)
        self._kf = kf
        return kf

    def _belief(self) -> Belief:
        if self._kf is None:
            return EMPTY_BELIEF
        x = self._kf.x
        return Belief(mean=(float(x[0]), float(x[1])), covariance=self._kf.P[:2, :2].copy())


def transition(dt: float) -> np.ndarray:
    """The constant-velocity transition matrix F (4, 4) for a step of dt seconds."""
    f = np.eye(4)
    f[0, 2] = f[1, 3] = dt
    return f


def _clamp_speed(kf: KalmanFilter, v_max: float) -> None:
    """Scale ``kf``'s velocity estimate down to ``v_max`` (m/s) if it exceeds it."""
    velocity = kf.x[2:4]
    speed = float(np.hypot(*velocity))
    if speed > v_max:
        kf.x[2:4] = velocity * (v_max / speed)
