"""A recorded evader, played again: ``evader=replay evader.path=<recording>`` drives the
evader along a recorded trajectory, whatever the pursuer does, so recorded people (the
games of :mod:`pegame.play`) are opponents in any sweep.

A recording is a CSV file with a header row and one row per timed pose, times
increasing from 0 (s), positions in metres and headings in radians in the map frame:

- pegame's own ``trajectory.csv`` (a game's, a human game's): columns ``time``,
  ``evader_x``, ``evader_y``, ``evader_theta`` (a team game's: evader 0's,
  ``evader_0_x`` ...);
- any CSV of timed poses: columns ``time``, ``x``, ``y`` and optionally ``theta``.

``path`` is such a file (relative to the working directory), or the name of one of the
recordings shipped in ``pegame/evaders/recordings/`` (``evader.path=dodger``).

At the control tick of time t the evader commands the unicycle arc that starts at its
pose, tangent to its heading (backwards for a target behind it), and ends at the
recorded position at t + control_dt (linear between rows; the last row's position once
the recording ends); a target within 1 mm is a turn on the spot to the recorded heading.
The grid simulator moves along exactly that arc, so a recording made with the same
control rate, map and seed (the same start: its ``result.json`` names them) is played
again to within rounding, every tick re-aiming at the recording. The recording stays as
it was when the pursuer moves differently: the evader does not react to it, it passes
through the pursuer's body (agents do not collide in the grid simulator) and where the
recording would leave the map's free space it stops at the wall as any agent does. From
another start (another seed or map) it heads for the recorded path at its top speed
and follows it from where it gets to; commands beyond the body's limits (a recording
faster than ``evader.v_max``) are saturated by the simulator, and it catches up.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pegame.api import Context, Evader, EvaderObservation
from pegame.errors import ConfigError
from pegame.types import Plan, Pose, Velocity, wrap_angle

#: the recordings shipped with pegame, by name (``evader.path=<name>``)
RECORDINGS = Path(__file__).with_name("recordings")

#: the column names of each recording format, in lookup order: (time, x, y, theta)
FORMATS = (
    ("time", "evader_x", "evader_y", "evader_theta"),
    ("time", "evader_0_x", "evader_0_y", "evader_0_theta"),
    ("time", "x", "y", "theta"),
)

#: targets nearer than this (m) are reached by turning on the spot
ON_THE_SPOT = 1e-3


def recording_path(path: str) -> Path:
    """The file of ``path``: a shipped recording's name, or a CSV path."""
    if path and "/" not in path and not path.endswith(".csv"):
        return RECORDINGS / f"{path}.csv"
    return Path(path).expanduser()


def shipped() -> list[str]:
    """The names of the recordings shipped in ``pegame/evaders/recordings/``."""
    return sorted(p.stem for p in RECORDINGS.glob("*.csv"))


def load_recording(path: str) -> np.ndarray:
    """Float (K, 4) rows of (time s, x m, y m, theta rad) from the recording ``path``
    (module docstring); theta is 0 where the file has none. ConfigError naming
    ``evader.path`` for a missing, unreadable or malformed file."""
    file = recording_path(path)

    def bad(reason: str) -> ConfigError:
        names = ", ".join(shipped())
        return ConfigError(
            f"Invalid value for 'evader.path': {path!r} ({file}) {reason}. Allowed: a CSV of "
            f"timed poses with columns time, x, y[, theta] or a pegame trajectory.csv (time, "
            f"evader_x, evader_y, evader_theta), at least two rows, times increasing; or a "
            f"shipped recording: {names}."
        )

    try:
        with open(file, newline="") as handle:
            rows = list(csv.reader(handle))
    except (OSError, UnicodeDecodeError) as exc:
        raise bad(f"cannot be read ({getattr(exc, 'strerror', None) or exc})") from None
    if not rows:
        raise bad("is empty")
    header = [name.strip() for name in rows[0]]
    columns = next((f for f in FORMATS if set(f[:3]) <= set(header)), None)
    if columns is None:
        raise bad(f"has no time and position columns (its header: {', '.join(header)})")
    index = [header.index(name) if name in header else -1 for name in columns]
    try:
        poses = np.array(
            [[float(row[i]) if i >= 0 else 0.0 for i in index] for row in rows[1:] if row],
            dtype=float,
        )
    except (ValueError, IndexError):
        raise bad("has a row that is not numbers in every column") from None
    if len(poses) < 2:
        raise bad("has fewer than two poses")
    if not np.isfinite(poses).all():
        raise bad("has a value that is not finite")
    if not (np.diff(poses[:, 0]) > 0).all():
        raise bad("has times that do not increase")
    return poses


def arc_command(pose: Pose, target: tuple[float, float], theta: float, dt: float) -> Velocity:
    """The (v m/s, w rad/s) command whose unicycle arc, held for ``dt`` s, takes ``pose``
    to the point ``target`` (m, map frame), leaving tangent to the heading (backwards
    when the target is behind); a target within :data:`ON_THE_SPOT` turns on the spot to
    the heading ``theta`` (rad).

    The arc tangent to the heading through a point at distance d and bearing a (rad,
    from the heading) turns by 2a over an arc length d a / sin a."""
    dx, dy = target[0] - pose.x, target[1] - pose.y
    distance = math.hypot(dx, dy)
    if distance < ON_THE_SPOT:
        return Velocity(0.0, wrap_angle(theta - pose.theta) / dt)
    forward = dx * math.cos(pose.theta) + dy * math.sin(pose.theta)
    lateral = -dx * math.sin(pose.theta) + dy * math.cos(pose.theta)
    sign = 1.0 if forward >= 0 else -1.0  # backwards: the same arc for the reversed heading
    bearing = math.atan2(sign * lateral, sign * forward)
    length = distance if abs(bearing) < 1e-12 else distance * bearing / math.sin(bearing)
    return Velocity(sign * length / dt, 2.0 * bearing / dt)


class ReplayEvader(Evader):
    """Plays a recorded evader trajectory, whatever the pursuer does (module docstring)."""

    description = (
        "Plays a recorded evader trajectory (a human game, a trajectory.csv, timed poses)."
    )

    @dataclass
    class Config(Evader.Config):
        path: str = (
            ""  # a recording: a CSV (time, x, y[, theta]), a trajectory.csv or a shipped name
        )

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        if not config.path:
            raise ConfigError(
                "Missing value for 'evader.path': give evader.path=<recording.csv> or the "
                f"name of a shipped recording: {', '.join(shipped())}."
            )
        self.recording = load_recording(config.path)

    def reset(self, pose: Pose) -> None:
        pass

    def decide(self, observation: EvaderObservation) -> Plan:
        """The recorded position at the next decision as the plan's goal."""
        x, y, _ = self.recorded(observation.time + self.context.decision_dt)
        return Plan((x, y))

    def recorded(self, time: float) -> tuple[float, float, float]:
        """The recorded (x m, y m, theta rad) at ``time`` (s): positions linear between
        rows, the heading of the row at or after ``time``; the last row after the end."""
        times = self.recording[:, 0]
        k = int(np.searchsorted(times, time, side="left"))
        if k >= len(times):
            _, x, y, theta = self.recording[-1]
            return float(x), float(y), float(theta)
        if k == 0 or times[k] == time:
            _, x, y, theta = self.recording[k]
            return float(x), float(y), float(theta)
        (t0, x0, y0, _), (t1, x1, y1, theta) = self.recording[k - 1], self.recording[k]
        f = (time - t0) / (t1 - t0)
        return float(x0 + f * (x1 - x0)), float(y0 + f * (y1 - y0)), float(theta)

    def control(self, observation: EvaderObservation) -> Velocity:
        dt = self.context.control_dt
        x, y, theta = self.recorded(observation.time + dt)
        return arc_command(observation.pose, (x, y), theta, dt)
