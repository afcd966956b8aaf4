"""Learning agents' actions: (v, w) scaled to [-1, 1] within the agent's limits.

An action is a float array of shape (2,): a[0] * v_max is the forward speed (m/s,
negative = backwards) and a[1] * w_max the turn rate (rad/s, CCW positive), with the
limits of the agent's :class:`pegame.api.Body`. An action outside [-1, 1], of another
shape or not finite is a ValueError; with ``clip=True`` finite out-of-range values are
clipped instead (NaN and infinities are always an error: there is no sensible command
to clip them to).
"""

from __future__ import annotations

import math

import numpy as np

from pegame.types import Body, Velocity


def to_velocity(action: object, body: Body, clip: bool = False, who: str = "action") -> Velocity:
    """The command for ``action`` (see the module docstring); ``who`` names it in errors."""
    try:
        a = action if isinstance(action, np.ndarray) else np.asarray(action, dtype=np.float64)
        shape = a.shape
        v, w = (float(value) for value in a.tolist()) if shape == (2,) else (math.nan, math.nan)
    except (TypeError, ValueError):
        raise ValueError(f"{who} must be 2 numbers (v, w) in [-1, 1], got {action!r}.") from None
    if shape != (2,):
        raise ValueError(
            f"{who} must have shape (2,) (v, w) in [-1, 1], got shape {shape}: {action!r}."
        )
    if not (math.isfinite(v) and math.isfinite(w)):
        raise ValueError(f"{who} must be finite, got {action!r}.")
    if not (-1.0 <= v <= 1.0 and -1.0 <= w <= 1.0):
        if not clip:
            raise ValueError(
                f"{who} must lie in [-1, 1] (scaled v, w), got {action!r}; "
                "pass clip_actions=True to clip instead."
            )
        v, w = min(1.0, max(-1.0, v)), min(1.0, max(-1.0, w))
    return Velocity(v * body.v_max, w * body.w_max)
