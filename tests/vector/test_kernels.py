"""The batched game's kernels (pegame.vector) against the plain code they reproduce, bit for
bit: the crop, and the sensing kernels (pegame.visibility.sight, pegame.detectors) that
the scalar functions and the batched game both run, against plain Python references of
the tests (Python's hypot and angle wrap in numba: tests/test_numerics.py; the move is the
grid simulator's own kernel, tests/sims)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pegame.detectors.perception import hidden_fraction, silhouette_hidden
from pegame.envs.vector import vector_env
from pegame.grid import OccupancyGrid
from pegame.observe.crop import local_crop_reference
from pegame.types import Camera, Pose, wrap_angle
from pegame.vector.features import crop_into
from pegame.vector.game import _world
from pegame.visibility import SILHOUETTE, body_in_view, in_view
from pegame.visibility.sight import (
    _line_of_sight_reference,
    point_in_view,
    segment_clear,
    silhouette_in_view,
)


def reference_in_view(grid: OccupancyGrid, camera: Camera, pose: Pose, x: float, y: float) -> bool:
    """In view in plain Python: range (math.hypot), bearing (math.remainder's wrap), then
    the numpy line of sight at half a cell."""
    dx, dy = x - pose.x, y - pose.y
    if not camera.near <= math.hypot(dx, dy) <= camera.far:
        return False
    if abs(wrap_angle(math.atan2(dy, dx) - pose.theta)) > 0.5 * camera.fov:
        return False
    return _line_of_sight_reference(grid, (pose.x, pose.y), (x, y), 0.5 * grid.resolution)


def reference_silhouette(
    grid: OccupancyGrid, camera: Camera, pose: Pose, x: float, y: float, radius: float
) -> list[bool]:
    """Whether each SILHOUETTE point of the body at (x, y) is in view, in plain Python."""
    dx, dy = x - pose.x, y - pose.y
    distance = math.hypot(dx, dy)
    ax, ay = (-dy / distance, dx / distance) if distance > 0.0 else (0.0, 0.0)
    return [
        reference_in_view(grid, camera, pose, x + k * radius * ax, y + k * radius * ay)
        for k in SILHOUETTE
    ]


@pytest.fixture(scope="module")
def game():
    env = vector_env(1, overrides=["env=hall", "evader.model=action"], opponent="random")
    env.reset(seed=0)
    return env.game


def test_crop_is_the_reference_crop(game):
    world, grid = game.world, game.context.grid
    settings = game.settings
    rng = np.random.default_rng(2)
    x0, x1, y0, y1 = grid.extent
    out = np.empty(settings.crop_cells**2, np.float32)
    cells = np.empty(settings.crop_cells**2, np.int32)
    for x, y, theta in zip(
        rng.uniform(x0 - 2, x1 + 2, 200), rng.uniform(y0 - 2, y1 + 2, 200), rng.uniform(-4, 4, 200)
    ):
        crop_into(world, x, y, theta, out, 0, cells)
        want = local_crop_reference(
            grid, x, y, theta, settings.crop_cells, settings.crop_resolution
        ).ravel()
        np.testing.assert_array_equal(out, want)


def test_crop_on_cell_edges_is_the_reference_crop(game):
    """Poses whose crop cells fall on map cell edges (headings along the axes, positions on
    the map's lattice and one ulp off it) take the division route and still give the
    reference crop; random poses take the multiplication route."""
    world, grid = game.world, game.context.grid
    settings = game.settings
    res, (gx, gy, _) = grid.resolution, grid.origin
    out = np.empty(settings.crop_cells**2, np.float32)
    cells = np.empty(settings.crop_cells**2, np.int32)
    rng = np.random.default_rng(7)
    height, width = grid.blocked.shape
    slow = []
    headings = [0.0, math.pi / 2, math.pi, -math.pi / 2, -0.0, math.nextafter(0.0, 1.0)]
    for i in range(300):
        row, col = rng.integers(-5, height + 5), rng.integers(-5, width + 5)
        x, y = gx + col * res, gy + row * res
        if i % 3:
            x = math.nextafter(x, math.inf if i % 3 == 1 else -math.inf)
        theta = headings[i % len(headings)]
        slow.append(crop_into(world, x, y, theta, out, 0, cells))
        want = local_crop_reference(
            grid, x, y, theta, settings.crop_cells, settings.crop_resolution
        ).ravel()
        np.testing.assert_array_equal(out, want)
    assert np.mean(slow) > 0.9
    x0, x1, y0, y1 = grid.extent
    fast = [
        not crop_into(world, x, y, theta, out, 0, cells)
        for x, y, theta in zip(
            rng.uniform(x0, x1, 100), rng.uniform(y0, y1, 100), rng.uniform(-4, 4, 100)
        )
    ]
    assert np.mean(fast) > 0.9


def test_crop_on_a_rotated_far_off_grid_is_the_reference_crop(game):
    """The lattice route with the grid's own rotation and an origin far from 0 (the size
    its error bound counts), on random poses, poses on the lattice of the grid's cells,
    and poses off the map whose crop leaves the table's border (the division route)."""
    grid = game.context.grid
    settings = game.settings
    data = np.where(grid.blocked, 100, 0).astype(np.int8)
    rotated = OccupancyGrid(data, grid.resolution, origin=(-731.3, 402.7, 0.7), name="r")
    world = _world(rotated, game.context, settings)
    rng = np.random.default_rng(9)
    res, (gx, gy, yaw) = rotated.resolution, rotated.origin
    height, width = rotated.blocked.shape
    out = np.empty(settings.crop_cells**2, np.float32)
    cells = np.empty(settings.crop_cells**2, np.int32)
    slow = []
    for i in range(600):
        u, v = rng.uniform(-40, width + 40) * res, rng.uniform(-40, height + 40) * res
        if i % 2:
            u, v = round(u / res) * res, round(v / res) * res  # on the cells' corners
        x = gx + math.cos(yaw) * u - math.sin(yaw) * v
        y = gy + math.sin(yaw) * u + math.cos(yaw) * v
        theta = rng.uniform(-4, 4) if i % 4 < 2 else yaw + (i % 3) * math.pi / 2
        slow.append(crop_into(world, x, y, theta, out, 0, cells))
        want = local_crop_reference(
            rotated, x, y, theta, settings.crop_cells, settings.crop_resolution
        ).ravel()
        np.testing.assert_array_equal(out, want)
    assert 0.02 < np.mean(slow) < 0.98  # both routes were taken


def test_in_view_tests_are_the_plain_references(game):
    """The point and body in view and the hidden fraction, called for one pose (the
    scalar functions) and as the batched game inlines them (the kernels on the World's
    arrays), are the plain references."""
    world, grid, camera = game.world, game.context.grid, game.context.camera
    sight = world.frame, world.blocked, world.sight_values
    lens = camera.near, camera.far, camera.fov
    rng = np.random.default_rng(3)
    free = np.argwhere(~grid.blocked)
    seen = partly = 0
    for _ in range(3000):
        (r, c), (r2, c2) = free[rng.integers(len(free), size=2)]
        px, py = grid.cell_to_world(r, c)
        ex, ey = grid.cell_to_world(r2, c2)
        ex, ey = ex + rng.uniform(-0.5, 0.5), ey + rng.uniform(-0.5, 0.5)
        theta = math.atan2(ey - py, ex - px) + rng.uniform(-0.7, 0.7)
        pose = Pose(px, py, theta)
        points = reference_silhouette(grid, camera, pose, ex, ey, 0.25)
        centre = reference_in_view(grid, camera, pose, ex, ey)
        assert in_view(grid, camera, pose, (ex, ey)) == centre
        assert point_in_view(*sight, *lens, px, py, theta, ex, ey) == centre
        assert body_in_view(grid, camera, pose, (ex, ey), 0.25) == any(points)
        assert silhouette_in_view(*sight, *lens, px, py, theta, ex, ey, 0.25, 1) == any(points[1:])
        hidden = points.count(False) / len(SILHOUETTE)
        assert hidden_fraction(grid, camera, pose, (ex, ey), 0.25) == hidden
        assert silhouette_hidden(*sight, *lens, px, py, theta, ex, ey, 0.25) == hidden
        seen += centre
        partly += 0 < hidden < 1
    assert 100 < seen < 2900  # both outcomes were tested
    assert partly > 30  # and bodies partly hidden


def test_segment_clear_on_cell_edges_is_the_reference(game):
    """Segments along the map's lattice lines (their samples on cell edges: the division
    route) and random ones (the product route) give the numpy reference's answer."""
    world, grid = game.world, game.context.grid
    res, (gx, gy, _) = grid.resolution, grid.origin
    height, width = grid.blocked.shape
    rng = np.random.default_rng(8)
    clear = []
    for i in range(2000):
        (r, c), (r2, c2) = rng.integers(-3, [height + 3, width + 3], (2, 2))
        if i % 2:
            r2 = r  # along a lattice line
        ax, ay, bx, by = gx + c * res, gy + r * res, gx + c2 * res, gy + r2 * res
        if i % 4 == 3:
            ax, ay = ax + rng.uniform(0, res), ay + rng.uniform(0, res)
        want = _line_of_sight_reference(grid, (ax, ay), (bx, by), 0.5 * res)
        sight = world.frame, world.blocked, world.sight_values
        assert segment_clear(*sight, ax, ay, bx, by, 0.5 * res) == want
        clear.append(want)
    assert 0.05 < np.mean(clear) < 0.95  # both outcomes were tested
