"""An example third-party pegame pursuer: turns in place until it sees the evader, then
drives at it, steering to keep its bounding box centred."""

from __future__ import annotations

from dataclasses import dataclass

from pegame.api import Plan, Pursuer, PursuerObservation, Velocity
from pegame.errors import require


class Spinner(Pursuer):
    """Spins in place (turn_rate rad/s) until it detects the evader, then drives at it."""

    description = "Example plugin: spins until it sees the evader, then drives at it."

    @dataclass
    class Config(Pursuer.Config):
        turn_rate: float = 0.8  # rad/s while searching

        def __post_init__(self) -> None:
            super().__post_init__()
            require(self.turn_rate > 0, "turn_rate", "a positive rate in rad/s", self.turn_rate)

    def reset(self, pose) -> None:
        pass

    def decide(self, observation: PursuerObservation) -> Plan:
        return Plan(info={"mode": "track" if observation.detection else "spin"})

    def control(self, observation: PursuerObservation) -> Velocity:
        if observation.detection is None:
            return Velocity(0.0, self.config.turn_rate)
        width = self.context.camera.image_width
        offset = (observation.detection.box.center_x - 0.5 * width) / width  # -1/2 .. 1/2
        return Velocity(0.5 * self.context.pursuer.v_max, -3.0 * offset)
