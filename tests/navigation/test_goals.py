"""GoalPaths (pegame.navigation.goals), the smart evaders' goal following, plans the
paths Planner.plan plans and gives PathFollower's commands along them, bit for bit, and
keeps a goal within a cell of the one followed."""

from __future__ import annotations

import math
from importlib.resources import files
from pathlib import Path

import numpy as np
import pytest

from pegame.grid import load_map
from pegame.navigation import PathFollower, Planner
from pegame.navigation.goals import GoalPaths
from pegame.types import Body, Pose

BODY = Body(0.25, 0.5, 1.8)
MAPS_DIR = Path(str(files("pegame.maps")))


@pytest.mark.parametrize("name", ["enclosed", "office"])
def test_paths_and_commands_are_the_planners_and_the_followers(name):
    grid = load_map(MAPS_DIR / f"{name}.yaml")
    planner = Planner.shared(grid, BODY.radius)
    largest = np.bincount(planner.labels.ravel())[1:].argmax() + 1
    rows, cols = np.nonzero(planner.labels == largest)
    rng = np.random.default_rng(2)
    paths = GoalPaths(grid, planner, PathFollower(BODY), 3)
    for _ in range(12):
        game = int(rng.integers(3))
        i, j = rng.integers(rows.size, size=2)
        start = grid.cell_to_world(rows[i], cols[i])
        x, y = start[0] + rng.uniform(-0.02, 0.02), start[1] + rng.uniform(-0.02, 0.02)
        theta = rng.uniform(-math.pi, math.pi)
        goal = int(rows[j] * grid.width + cols[j])
        paths.reset(game)
        assert paths.steer(game, goal, x, y)
        centre = grid.cell_to_world(rows[j], cols[j])
        planned = planner.plan((x, y), (float(centre[0]), float(centre[1]))).path
        np.testing.assert_array_equal(paths.path(game), planned)
        follower = PathFollower(BODY)
        follower.set_path(planned)
        for _ in range(40):  # drive along: the same commands from the same poses
            want = follower.command(Pose(x, y, theta))
            assert paths.command(game, x, y, theta) == (want.v, want.w)
            x, y = x + 0.1 * want.v * math.cos(theta), y + 0.1 * want.v * math.sin(theta)
            theta += 0.1 * want.w


def test_a_goal_within_a_cell_of_the_one_followed_keeps_its_path():
    grid = load_map(MAPS_DIR / "hall.yaml")
    planner = Planner.shared(grid, BODY.radius)
    labels = planner.labels.ravel()
    largest = np.bincount(labels)[1:].argmax() + 1
    cells = np.flatnonzero(labels == largest)
    # a goal whose neighbours one and two cells on (and a row down) are in its component
    goal = next(
        int(c) for c in cells[::-1] if (labels[[c + 1, c + 2, c - grid.width - 1]] == largest).all()
    )
    paths = GoalPaths(grid, planner, PathFollower(BODY), 1)
    x, y = grid.cell_to_world(*divmod(int(cells[0]), grid.width))
    assert paths.steer(0, goal, x, y)
    kept = paths.path(0)
    for moved, planned in ((1, False), (-grid.width - 1, False), (2, True)):
        assert paths.steer(0, goal + moved, x, y) == planned
        if not planned:
            np.testing.assert_array_equal(paths.path(0), kept)
