"""A person as the evader: the commands come from a browser page, in real time (paper,
Sec. V-B: a human evader, told the pursuer's pose through a HoloLens, tries to escape
the TurtleBot).

``evader=human`` plays only under ``python -m pegame.play``, which serves the page and
the :class:`pegame.play.session.Session` this strategy reads. The game is an ordinary
pegame game (the same tick loop, results and recording); this strategy only

- paces the loop in real time: each control tick's command waits until the tick's
  wall-clock time, ``reset`` time + the tick's time (s), so a tick of ``control_dt`` s
  lasts ``control_dt`` s of the person's time; a tick computed late is not waited for
  (its lag, in ms, is measured), and no tick is ever skipped;
- returns the person's latest (v m/s, w rad/s) command, STOP before the first input
  (the simulator saturates it to the body's limits, as for every strategy);
- says what the page may show the person (``show``): the pursuer's pose
  (``pursuer``, as the paper's HoloLens relayed it), its view cone (``cone``), the
  pursuer's belief about the evader (``belief``, more than the paper's person knew).

A closed page during a game fails that game (:class:`pegame.play.session.PageClosed`),
recorded like any failed game.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from pegame.api import Context, Evader, EvaderObservation
from pegame.errors import ConfigError, require
from pegame.play.session import active
from pegame.types import Plan, Pose, Velocity

#: what the page may draw besides the map, the evader and the clock (``show``; by
#: default the first two, what the paper's HoloLens relayed)
SHOWN = ("pursuer", "cone", "belief")


class HumanEvader(Evader):
    """A person at ``python -m pegame.play``'s page: keyboard or gamepad, in real time."""

    description = "A person at a browser page (python -m pegame.play): keyboard or gamepad."

    @dataclass
    class Config(Evader.Config):
        show: list[str] = field(default_factory=lambda: list(SHOWN[:2]))  # drawn: see SHOWN

        def __post_init__(self) -> None:
            super().__post_init__()
            for item in self.show:
                require(item in SHOWN, "show", f"a list of {', '.join(SHOWN)}", self.show)

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        self.session = active("evader")
        if self.session.evader_taken:
            raise ConfigError(
                "Invalid value for 'team.evaders': one person plays one evader. Allowed: "
                "team.evaders=1, or team members of another plugin after the first."
            )
        self.session.evader_taken = True
        self.session.show = tuple(config.show)
        self.start = time.monotonic()

    def reset(self, pose: Pose) -> None:
        self.start = time.monotonic()

    def decide(self, observation: EvaderObservation) -> Plan:
        return Plan()

    def control(self, observation: EvaderObservation) -> Velocity:
        """The person's command for this tick, given at the tick's wall-clock time."""
        wait = self.start + observation.time - time.monotonic()
        self.session.latencies.tick_lag.append(max(-wait, 0.0) * 1000.0)
        self.session.wait(wait)
        return self.session.command()
