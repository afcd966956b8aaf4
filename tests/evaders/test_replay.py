"""evader=replay: the arc command, the recording formats, and a recorded game played
again to within rounding, whatever the pursuer does."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pegame.config import compose
from pegame.errors import ConfigError
from pegame.evaders.replay import arc_command, load_recording, recording_path, shipped
from pegame.game import Game, write_outcome
from pegame.sims.grid import unicycle
from pegame.testing import EvaderConformance
from pegame.types import Pose, Velocity


@settings(max_examples=200, deadline=None)
@given(
    theta=st.floats(-3.1, 3.1),
    v=st.floats(-0.5, 0.5),
    w=st.floats(-1.8, 1.8),
)
def test_the_arc_command_takes_the_pose_to_where_the_unicycle_went(theta, v, w):
    dt, start = 0.1, Pose(2.0, 3.0, theta)
    end = unicycle(start, Velocity(v, w), dt)
    if math.hypot(end.x - start.x, end.y - start.y) < 1e-3:
        return  # a turn on the spot: aimed at the heading instead
    command = arc_command(start, (end.x, end.y), end.theta, dt)
    reached = unicycle(start, command, dt)
    assert math.hypot(reached.x - end.x, reached.y - end.y) < 1e-9
    assert abs(command.v - v) < 1e-6 and abs(command.w - w) < 1e-6


def test_a_target_on_the_spot_is_a_turn_to_the_recorded_heading():
    command = arc_command(Pose(1.0, 1.0, 0.0), (1.0, 1.0), 0.5, 0.1)
    assert command == Velocity(0.0, 5.0)


def test_recordings_are_trajectory_csvs_or_timed_poses(tmp_path):
    poses = tmp_path / "poses.csv"
    poses.write_text("time,x,y\n0,1,2\n0.5,1.5,2\n")
    assert load_recording(str(poses)).tolist() == [[0, 1, 2, 0], [0.5, 1.5, 2, 0]]
    assert {"hider", "runner", "wanderer"} <= set(shipped())
    shipped_rows = load_recording("hider")
    assert shipped_rows.shape[1] == 4 and shipped_rows[0, 0] == 0.0
    assert recording_path("hider").parent.name == "recordings"


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("", "is empty"),
        ("t,a,b\n0,1,2\n1,2,3\n", "no time and position columns"),
        ("time,x,y\n0,1,2\n", "fewer than two poses"),
        ("time,x,y\n0,1,2\n0,1,3\n", "do not increase"),
        ("time,x,y\n0,1,2\n1,one,3\n", "not numbers"),
        ("time,x,y\n0,1,2\n1,nan,3\n", "not finite"),
    ],
)
def test_a_malformed_recording_is_refused_naming_the_key_and_the_formats(tmp_path, text, reason):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(ConfigError, match=reason) as info:
        load_recording(str(path))
    assert "evader.path" in str(info.value) and "time, x, y" in str(info.value)
    with pytest.raises(ConfigError, match="cannot be read"):
        load_recording(str(tmp_path / "missing.csv"))


def play(overrides, out_dir):
    """A short game's trajectory (float rows) and its columns, written to ``out_dir``."""
    game = Game(compose(["recorder=none", "game.t_max=6", *overrides]))
    out_dir.mkdir()
    outcome = game.play(out_dir)
    write_outcome(outcome, out_dir)
    return np.array(outcome.trajectory, dtype=float), outcome.header


@pytest.mark.slow
def test_a_recorded_game_is_played_again_and_stays_as_recorded_against_another_pursuer(tmp_path):
    recorded, columns = play(["evader=random"], tmp_path / "recorded")
    path = tmp_path / "recorded" / "trajectory.csv"
    ex, ey, px = columns.index("evader_x"), columns.index("evader_y"), columns.index("pursuer_x")
    again, _ = play(["evader=replay", f"evader.path={path}"], tmp_path / "again")
    assert np.abs(again[:, [ex, ey]] - recorded[:, [ex, ey]]).max() < 1e-9
    other, _ = play(["evader=replay", f"evader.path={path}", "pursuer=random"], tmp_path / "other")
    assert np.abs(other[:, px] - recorded[:, px]).max() > 0.1  # the pursuer moved otherwise
    assert np.abs(other[:, [ex, ey]] - recorded[:, [ex, ey]]).max() < 1e-9


def test_a_replay_without_a_path_names_the_shipped_recordings():
    with pytest.raises(ConfigError, match="evader.path.*hider"):
        Game(compose(["recorder=none", "evader=replay"]))


class TestConformance(EvaderConformance):
    plugin = "replay"
    overrides = ("evader.path=hider",)
    bad_values = {"v_max": -1.0}
