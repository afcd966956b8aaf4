"""A scripted keyboard player: plays ``evader=human`` games through the page's side of the
session, as a person at the page would, to make human-style recordings without a
person: ``python -m pegame.play.scripted --out DIR [--seconds S]``.

It is no model of people: it is a player that is limited as a person at a keyboard is.
It sees what the page shows (its own pose, the pursuer's pose and the view cone, without
occlusion, and the map), acts on it only every :data:`REACTION` s (a reaction time drawn
per look, seeded) and presses keys, so its commands are the keyboard's: full speed
forward or back or none, full turn left or right or none. Its styles (:data:`PLAYERS`):

- ``hide``: runs away from the pursuer while inside the cone, stops once out of it;
- ``run``: keeps running, heading away from the pursuer;
- ``wander``: walks to random points of the map, pausing now and then, ignoring the
  pursuer.

Each turns away from a wall ahead of it (a blocked cell within :data:`LOOK_AHEAD` m),
towards the side of the heading it wants, until the way ahead is clear; a heading with a
wall ahead is swapped for the nearest open one (in steps of 45 degrees).
Each game is played in real time (the human evader paces it) and its
``trajectory.csv`` becomes a recording for ``evader=replay``
(:mod:`pegame.evaders.replay`).
"""

from __future__ import annotations

import argparse
import math
import shutil
import sys
import tempfile
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from pegame.game import Scenario
from pegame.grid import OccupancyGrid
from pegame.job import run_job
from pegame.play.__main__ import composed
from pegame.play.session import Session, activate, now_ms
from pegame.types import wrap_angle

#: a look's reaction time (s): uniform in this range
REACTION = (0.18, 0.4)
#: how far ahead (m) the player checks for a wall
LOOK_AHEAD = 0.7


@dataclass(frozen=True)
class Player:
    """One recording: the player's name (the recording's), style and seed of its reaction
    times and choices."""

    name: str
    style: str
    seed: int


#: the committed recordings: all played on the default map and game seed (one start)
PLAYERS = (
    Player("hider", "hide", 1),
    Player("runner", "run", 2),
    Player("wanderer", "wander", 3),
    Player("hider_late", "hide", 4),
    Player("runner_zigzag", "run", 5),
)


class KeyboardPlayer:
    """Reads the session's frames and sets keyboard commands (module docstring)."""

    def __init__(self, session: Session, grid: OccupancyGrid, style: str, seed: int) -> None:
        self.session, self.grid, self.style = session, grid, style
        self.rng = np.random.default_rng(seed)
        self.game: dict[str, Any] | None = None
        self.frame: dict[str, Any] | None = None
        self.goal: tuple[float, float] | None = None
        self.dodge = 0  # the turn (+1 left, -1 right) away from a wall ahead, 0 when clear
        self.stop = threading.Event()

    def run(self) -> None:
        """Look, wait a reaction time, press keys; until :attr:`stop` is set."""
        while not self.stop.is_set():
            for message in self.session.take():
                if message["type"] == "game":
                    self.game = message
                elif message["type"] == "frame":
                    self.frame = message
            if self.game is not None and self.frame is not None:
                v, w = self.keys(self.frame)
                self.stop.wait(float(self.rng.uniform(*REACTION)))
                evader = self.game["evader"]
                self.session.set_command(v * evader["v_max"], w * evader["w_max"], now_ms())
            else:
                self.stop.wait(0.02)

    def keys(self, frame: dict[str, Any]) -> tuple[int, int]:
        """(forward, turn) keys in {-1, 0, 1} for this frame."""
        x, y, theta = frame["evader"]
        px, py, ptheta = frame["pursuers"][0]
        away = math.atan2(y - py, x - px)
        if self.style == "wander":
            heading, go = self.wander(x, y)
        elif self.style == "hide":
            heading, go = away, self.in_cone(x, y, px, py, ptheta)
        else:
            heading, go = away + float(self.rng.normal(0.0, 0.5)), True
        if not go:
            return 0, 0
        heading = self.open_heading(x, y, heading)
        error = wrap_angle(heading - theta)
        if self.wall_ahead(x, y, theta):
            if self.dodge == 0:  # the side of the wanted heading, kept until the way is clear
                self.dodge = 1 if error > 0 else -1
            return 0, self.dodge
        self.dodge = 0
        turn = 0 if abs(error) < 0.35 else (1 if error > 0 else -1)
        return (1 if abs(error) < 1.2 else 0), turn

    def in_cone(self, x: float, y: float, px: float, py: float, ptheta: float) -> bool:
        """Whether (x, y) lies in the pursuer's cone as drawn (no occlusion), with a
        margin of one body radius in range."""
        assert self.game is not None
        camera, distance = self.game["camera"], math.hypot(x - px, y - py)
        bearing = abs(wrap_angle(math.atan2(y - py, x - px) - ptheta))
        margin = self.game["evader"]["radius"]
        return bearing <= camera["fov"] / 2 + 0.2 and distance <= camera["far"] + margin

    def wander(self, x: float, y: float) -> tuple[float, bool]:
        """The heading to the current random goal, and whether to walk (not pausing)."""
        if self.goal is None or math.hypot(self.goal[0] - x, self.goal[1] - y) < 0.5:
            rows, cols = np.nonzero(~self.grid.blocked)
            k = int(self.rng.integers(rows.size))
            self.goal = self.grid.cell_to_world(int(rows[k]), int(cols[k]))
        pausing = self.rng.random() < 0.15
        return math.atan2(self.goal[1] - y, self.goal[0] - x), not pausing

    def open_heading(self, x: float, y: float, heading: float) -> float:
        """``heading`` (rad), or the nearest heading to it in steps of 45 degrees that has
        no wall ahead (a cornered player looks for a way out); ``heading`` if none has."""
        for turn in (0.0, 0.785, -0.785, 1.571, -1.571, 2.356, -2.356):
            if not self.wall_ahead(x, y, heading + turn):
                return heading + turn
        return heading

    def wall_ahead(self, x: float, y: float, theta: float) -> bool:
        """Whether the strip ahead, up to LOOK_AHEAD m long and as wide as the body
        plus 5 cm on each side, leaves the free space."""
        assert self.game is not None
        side = self.game["evader"]["radius"] + 0.05
        c, s = math.cos(theta), math.sin(theta)
        for d in (0.3, 0.5, LOOK_AHEAD):
            for lateral in (-side, 0.0, side):
                if not self.grid.is_free(x + d * c - lateral * s, y + d * s + lateral * c):
                    return True
        return False


def record(player: Player, overrides: Sequence[str], out_dir: Path) -> Path:
    """Play ``player``'s game with ``overrides`` into ``out_dir``; its trajectory.csv."""
    cfg = composed([*overrides, "recorder=none"])
    grid = Scenario(cfg).context.grid
    session = Session()
    session.connect()
    keyboard = KeyboardPlayer(session, grid, player.style, player.seed)
    thread = threading.Thread(target=keyboard.run, daemon=True)
    activate(session)
    thread.start()
    try:
        run = run_job(cfg, out_dir, overrides=list(overrides))
    finally:
        keyboard.stop.set()
        thread.join()
        activate(None)
    if run.failed:
        raise RuntimeError(f"{player.name}'s game failed: see {out_dir}")
    return out_dir / "trajectory.csv"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m pegame.play.scripted", description=__doc__)
    parser.add_argument("--out", type=Path, required=True, help="where the recordings go")
    parser.add_argument("--seconds", type=float, default=45.0, help="game length (s)")
    parser.add_argument("overrides", nargs="*", help="Hydra overrides, e.g. pursuer=random")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for player in PLAYERS:
        games = Path(tempfile.mkdtemp(prefix="pegame-scripted-"))
        try:
            started = time.monotonic()
            overrides = [f"game.t_max={args.seconds}", *args.overrides]
            trajectory = record(player, overrides, games)
            shutil.copyfile(trajectory, args.out / f"{player.name}.csv")
            print(f"{player.name}: {time.monotonic() - started:.0f} s", flush=True)
        finally:
            shutil.rmtree(games, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
