"""The other members of a team game in a recording: every pursuer with its FOV, every
evader, each evader's belief and every detection.

Member 0 of each role (pursuer 0, evader 0 and the belief about evader 0) keeps the 1v1
game's entities (:mod:`.scene`); the others are buffered each tick under their own paths:
``world/pursuer_<i>/pose`` and ``/fov``, ``world/evader_<j>/pose``,
``world/belief_<j>/mean`` and ``/particles``, and ``world/team/detections`` (every
pursuer's detection but pursuer 0's of evader 0, which is ``world/detection``).
Positions are in the map frame (m).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import rerun as rr
from numpy.typing import ArrayLike

from pegame.api import Context, Tick
from pegame.recorders.rerun.columns import points_at
from pegame.recorders.rerun.scene import (
    DETECTION,
    ESTIMATE,
    EVADER,
    HEAVY_PARTICLE,
    PURSUER,
    Z_AGENT,
    Z_MARKER,
    Z_PARTICLES,
    Z_REGION,
    Buffers,
    fov_template,
)
from pegame.types import Pose


def placed(points: np.ndarray, pose: Pose) -> np.ndarray:
    """(K, 2) points (m) given in the frame of ``pose`` (x forward), in the map frame."""
    c, s = math.cos(pose.theta), math.sin(pose.theta)
    x, y = points[:, 0], points[:, 1]
    return np.column_stack((pose.x + c * x - s * y, pose.y + s * x + c * y))


def _discs(positions: ArrayLike, radius: float, color: ArrayLike) -> dict[str, Any]:
    xy = np.asarray(positions, dtype=float).reshape(-1, 2)
    n = len(xy)
    return {
        "positions": points_at(xy, Z_AGENT),
        "radii": np.full(n, radius, dtype=np.float32),
        "colors": np.tile(np.asarray(color, dtype=np.uint8), (n, 1)),
    }


def buffer_team(buffers: Buffers, tick: Tick, context: Context, max_particles: int) -> None:
    """Buffer the tick's team members past member 0 (module docstring), with at most
    ``max_particles`` particles per belief (0: none this tick); nothing in 1v1."""
    if tick.solo:
        return
    step, time = tick.step, tick.time
    wedge = fov_template(context.camera)
    for i, pose in enumerate(tick.pursuers[1:], start=1):
        body = _discs([(pose.x, pose.y)], context.pursuer.radius, PURSUER)
        buffers.add(f"world/pursuer_{i}/pose", rr.Points3D, step, time, **body)
        strip = [points_at(placed(wedge, pose), Z_REGION)]
        buffers.add(f"world/pursuer_{i}/fov", rr.LineStrips3D, step, time, strips=strip)
    for j, pose in enumerate(tick.evaders[1:], start=1):
        body = _discs([(pose.x, pose.y)], context.evader.radius, EVADER)
        buffers.add(f"world/evader_{j}/pose", rr.Points3D, step, time, **body)
    for j, belief in enumerate(tick.beliefs[1:], start=1):
        mean = [] if belief.mean is None else [belief.mean]
        marker = _discs(mean, 0.12, ESTIMATE)
        marker["positions"] = points_at(mean, Z_MARKER)
        buffers.add(f"world/belief_{j}/mean", rr.Points3D, step, time, **marker)
        if max_particles and belief.particles is not None:
            xy = belief.particles[:: max(1, math.ceil(len(belief.particles) / max_particles)), :2]
            cloud = _discs(xy, 0.04, HEAVY_PARTICLE.astype(np.uint8))
            cloud["positions"] = points_at(xy, Z_PARTICLES)
            buffers.add(f"world/belief_{j}/particles", rr.Points3D, step, time, **cloud)
    seen = [
        d.position
        for i, row in enumerate(tick.detections)
        for j, d in enumerate(row)
        if d is not None and (i, j) != (0, 0)
    ]
    marker = _discs(seen, 0.12, DETECTION)
    marker["positions"] = points_at(seen, Z_MARKER)
    buffers.add("world/team/detections", rr.Points3D, step, time, **marker)
