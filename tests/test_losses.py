"""Loss causes: constructed games name each cause, and real games' counts and times add up."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from pegame import registry
from pegame.api import Context, Tick
from pegame.config import compose
from pegame.detectors.oracle import OracleDetector
from pegame.game import Game
from pegame.loop import GamePlugins, TickLoop
from pegame.losses import (
    BEARING,
    BLOCKED,
    CAUSES,
    FAR,
    MISSED,
    NEAR,
    OCCLUDED,
    TURNING,
    LossCauses,
    chord,
    loss_cause,
)
from pegame.recorders.none import NullRecorder
from pegame.sims.grid import GridSimulator
from pegame.testing import small_context
from pegame.types import STOP, Body, Pose, Velocity


def _plugin(kind: str, name: str, context: Context, **options):
    cls = registry.load(kind, name)
    return cls(registry.make_config(kind, cls, options), context, np.random.default_rng(0))


def scripted(
    pursuer: Pose,
    evader: Pose,
    commands: tuple[Velocity, Velocity],
    ticks: int = 40,
    context: Context | None = None,
    **detector: float,
) -> tuple[list[Tick], TickLoop]:
    """A game on the small map (:func:`pegame.testing.small_map`, 10 Hz) of two external
    agents holding ``commands`` (pursuer's, evader's) from the given poses, seen by the
    oracle detector with ``detector`` options."""
    context = context or small_context()
    rng = np.random.default_rng(0)
    plugins = GamePlugins.one_on_one(
        GridSimulator(GridSimulator.Config(), context, rng),
        OracleDetector(OracleDetector.Config(**detector), context, rng),
        _plugin("estimator", "last_seen", context),
        _plugin("pursuer", "random", context),
        _plugin("evader", "random", context),
        NullRecorder(NullRecorder.Config(), context, rng),
    )
    loop = TickLoop(plugins, context, ticks, 10, external=("pursuer", "evader"), estimate=False)
    loop.start(pursuer, evader)
    played = [loop.advance({"pursuer": commands[0], "evader": commands[1]}) for _ in range(ticks)]
    return played, loop


def causes_of(ticks: list[Tick]) -> list[str]:
    return [loss.cause for tick in ticks for loss in tick.losses]


# The small map: a wall at x = 2.0-2.1 m from y = 0 to 2.0 m; east of it open floor to x = 4 m.
UP, DOWN, LEFT = math.pi / 2, -math.pi / 2, math.pi
WALK = Velocity(0.5, 0.0)


def test_an_evader_stepping_behind_a_wall_is_occluded():
    # seen over the wall's end, then walking down behind it
    ticks, _ = scripted(Pose(1.0, 1.5, 0.0), Pose(2.5, 2.3, DOWN), (STOP, WALK))
    assert ticks[0].detection is not None
    assert causes_of(ticks) == [OCCLUDED]


def test_an_evader_walking_out_of_the_side_of_the_view_left_by_the_bearing():
    ticks, _ = scripted(Pose(2.6, 0.5, 0.0), Pose(3.5, 0.6, UP), (STOP, WALK))
    assert causes_of(ticks) == [BEARING]


def test_an_evader_walking_away_goes_beyond_far_and_one_walking_close_inside_near():
    context = small_context()
    short = replace(context, camera=replace(context.camera, far=1.0))
    away, _ = scripted(Pose(2.6, 0.5, 0.0), Pose(3.2, 0.5, 0.0), (STOP, WALK), context=short)
    assert causes_of(away) == [FAR]
    close, _ = scripted(Pose(2.6, 0.5, 0.0), Pose(3.4, 0.5, LEFT), (STOP, WALK))
    assert causes_of(close) == [NEAR]


def test_a_pursuer_turning_away_on_the_spot_is_turning():
    ticks, _ = scripted(Pose(2.6, 0.5, 0.0), Pose(3.5, 0.5, 0.0), (Velocity(0.0, 1.0), STOP))
    assert causes_of(ticks) == [TURNING]


def test_a_pursuer_pushing_into_a_wall_while_the_evader_walks_off_is_blocked():
    heading = UP + 0.4  # up and to the left, into the wall at x = 2.1 m
    ticks, _ = scripted(
        Pose(2.35, 1.0, heading), Pose(2.15, 2.6, 0.0), (Velocity(0.5, 0.0), WALK), ticks=15
    )
    losses = [(tick, loss) for tick in ticks for loss in tick.losses]
    assert [loss.cause for _, loss in losses] == [BLOCKED]
    tick = losses[0][0]
    assert ticks[tick.step - 1].pursuer == tick.pursuer  # it did not move: the wall held it


def test_an_evader_in_view_that_the_detector_misses_is_missed():
    ticks, loop = scripted(
        Pose(2.6, 0.5, 0.0), Pose(3.5, 0.5, 0.0), (STOP, STOP), ticks=60, miss_probability=0.5
    )
    detected = [tick.detection is not None for tick in ticks]
    transitions = sum(a and not b for a, b in zip(detected, detected[1:]))
    assert transitions > 5
    assert causes_of(ticks) == [MISSED] * transitions
    missed = loop.metrics.summary()["loss_causes"][MISSED]
    assert missed["count"] == transitions


def test_the_causes_follow_their_precedence():
    """A pursuer turning in place, with the evader both sideways and behind a wall: the
    pursuer's state comes first, then the bearing, then the line of sight."""
    context = small_context()
    args = (context.grid, context.camera, context.pursuer, context.control_dt)
    before, after = Pose(1.0, 1.5, 0.0), Pose(1.0, 1.5, 1.2)
    behind = (2.5, 0.5)  # behind the wall, 45 degrees to the right of the start heading
    assert loss_cause(*args, before, after, Velocity(0.0, 1.0), behind) == TURNING
    assert loss_cause(*args, after, after, STOP, behind) == BEARING
    facing = Pose(1.0, 1.5, math.atan2(-1.0, 1.5))
    assert loss_cause(*args, facing, facing, STOP, behind) == OCCLUDED


def test_a_chord_is_the_saturated_arc_end_to_end():
    body = Body(0.2, 0.5, 1.8)
    assert chord(Velocity(2.0, 0.0), body, 0.1) == pytest.approx(0.05)  # v saturated
    # a half circle (w dt = pi) of radius v / w ends a diameter away
    assert chord(Velocity(0.5, math.pi), Body(0.2, 0.5, 4.0), 1.0) == pytest.approx(
        2 * 0.5 / math.pi
    )


def _transitions(flags: list[bool]) -> int:
    return sum(a and not b for a, b in zip(flags, flags[1:]))


RR = ["pursuer=random", "evader=random"]


@pytest.mark.parametrize(
    "overrides",
    [
        [*RR, "env=brick", "game.seed=3", "game.t_max=40"],
        ["env=hall", "detector.miss_probability=0.2", "game.seed=3", "game.t_max=40"],
        # the 3D plugins' detectors, on the images of sim=pybullet
        *(
            pytest.param(
                [*RR, "sim=pybullet", f"detector={name}", "game.seed=0", "game.t_max=15"],
                marks=pytest.mark.slow,
                id=name,
            )
            for name in ("segmentation", "vision")
        ),
    ],
)
def test_a_games_losses_count_every_loss_once_and_its_time_lost(overrides):
    game = Game(compose(["recorder=none", *overrides]))
    loop = game.start()
    ticks = [loop.advance() for _ in range(loop.ticks)]
    detected = [tick.detection is not None for tick in ticks]
    causes = loop.metrics.summary()["loss_causes"]
    assert list(causes) == list(CAUSES)
    assert sum(c["count"] for c in causes.values()) == _transitions(detected) > 0
    assert sum(len(tick.losses) for tick in ticks) == _transitions(detected)
    # the time lost: every undetected tick after the first detection
    first = detected.index(True)
    unseen = detected[first:].count(False) * loop.context.control_dt
    assert sum(c["time_lost_s"] for c in causes.values()) == pytest.approx(unseen)
    reacquired = sum(c["reacquired"] for c in causes.values())
    assert reacquired == _transitions([not d for d in detected[first:]])
    for c in causes.values():
        assert (c["mean_reacquire_s"] is None) == (c["reacquired"] == 0)


def test_a_team_counts_every_pairs_losses():
    game = Game(
        compose(["recorder=none", "game.t_max=30", "team.pursuers=2", "team.evaders=2", "env=hall"])
    )
    loop = game.start()
    ticks = [loop.advance() for _ in range(loop.ticks)]
    pairs = {
        (i, j): [tick.detections[i][j] is not None for tick in ticks]
        for i in range(2)
        for j in range(2)
    }
    expected = sum(_transitions(flags) for flags in pairs.values())
    causes = loop.metrics.summary()["loss_causes"]
    assert sum(c["count"] for c in causes.values()) == expected > 0
    for tick in ticks:
        for loss in tick.losses:
            flags = pairs[(loss.pursuer, loss.evader)]
            assert flags[loss.step - 1] and not flags[loss.step]


def test_a_summary_without_losses_has_every_cause_at_zero():
    summary = LossCauses(small_context()).summary()
    assert summary == {
        cause: {"count": 0, "reacquired": 0, "time_lost_s": 0.0, "mean_reacquire_s": None}
        for cause in CAUSES
    }
