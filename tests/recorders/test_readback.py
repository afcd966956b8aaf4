"""A recording read back (pegame.recorders.rerun.readback) holds what the game played:
the map, every pose, the detections, the series the recorder logs, for 1v1 and teams."""

from __future__ import annotations

import numpy as np
import pytest

from pegame.config import compose
from pegame.game import Game
from pegame.recorders.rerun.readback import read_game

SHORT = ["recorder=rerun", "game.t_max=4", "env=hall"]


@pytest.fixture(scope="module")
def played(tmp_path_factory):
    """A recorded 1v1 game: (its outcome, the game read back)."""
    out_dir = tmp_path_factory.mktemp("run")
    game = Game(compose(SHORT))
    outcome = game.play(out_dir)
    return game, outcome, read_game(out_dir / "game.rrd")


def test_poses_and_detections_are_those_of_the_trajectory(played):
    _, outcome, recorded = played
    rows = np.asarray(outcome.trajectory, dtype=float)
    column = {name: rows[:, i] for i, name in enumerate(outcome.header)}
    assert recorded.steps.tolist() == column["step"].astype(int).tolist()
    assert np.allclose(recorded.time, column["time"])
    for role, poses in (("pursuer", recorded.pursuers), ("evader", recorded.evaders)):
        expected = np.column_stack([column[f"{role}_{a}"] for a in ("x", "y", "theta")])
        assert poses.shape == (1, len(rows), 3)
        assert np.allclose(poses[0], expected, atol=1e-5)  # recorded as float32
    assert np.array_equal(recorded.detected, column["detected"])
    distance = np.hypot(
        column["pursuer_x"] - column["evader_x"], column["pursuer_y"] - column["evader_y"]
    )
    assert np.allclose(recorded.distance, distance, atol=1e-5)


def test_the_map_camera_and_belief_come_back(played):
    game, _, recorded = played
    grid = game.scenario.context.grid
    assert np.array_equal(recorded.grid.data, grid.data)
    assert recorded.grid.resolution == pytest.approx(grid.resolution)
    assert recorded.setting("camera.fov", 0.0) == pytest.approx(game.scenario.context.camera.fov)
    assert np.all(recorded.n_eff[np.isfinite(recorded.n_eff)] > 0)
    assert all(len(p) > 0 for p in recorded.particles)  # the particle subsample of every tick
    assert all(outline and outline[0].shape[1] == 2 for outline in recorded.outlines)


def test_a_team_game_reads_every_member(tmp_path):
    out_dir = tmp_path / "team"
    Game(compose([*SHORT, "team.pursuers=2", "team.evaders=2"])).play(out_dir)
    recorded = read_game(out_dir / "game.rrd")
    assert recorded.pursuers.shape[0] == 2 and recorded.evaders.shape[0] == 2
    assert np.isfinite(recorded.pursuers).all() and np.isfinite(recorded.evaders).all()


def test_a_file_that_is_no_game_recording_is_a_value_error(tmp_path):
    import rerun as rr

    path = tmp_path / "other.rrd"
    rec = rr.RecordingStream("other")
    rec.save(str(path))
    rec.log("points", rr.Points2D([[0.0, 0.0]]))
    rec.disconnect()
    with pytest.raises(ValueError, match="holds no game"):
        read_game(path)
