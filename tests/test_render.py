"""Frames from above (pegame.render): bodies, regions and the map where they are, looked
at pixel by pixel."""

from __future__ import annotations

import math

import numpy as np

from pegame.grid import OCCUPIED, OccupancyGrid
from pegame.render import EVADER, PURSUER, FrameRenderer, FrameState
from pegame.testing import walled_room


def renderer(grid: OccupancyGrid) -> FrameRenderer:
    return FrameRenderer(
        grid, fov=math.pi / 3, near=0.3, far=2.0, pursuer_radius=0.2, evader_radius=0.25, size=400
    )


def at(image: np.ndarray, draw: FrameRenderer, x: float, y: float) -> tuple[int, ...]:
    col, row = draw.pixel([x], [y])[0]
    return tuple(int(v) for v in image[int(row), int(col)])


def test_bodies_walls_and_free_cells_are_drawn_where_they_are():
    grid = walled_room()  # 4 m x 3 m, a pillar at x 1.75-2.25, y 1.25-1.75
    draw = renderer(grid)
    image = draw.frame(
        FrameState(np.array([[0.6, 0.6, 0.0]]), np.array([[3.4, 2.4, math.pi]]), [False])
    )
    assert image.shape == (300, 400, 3) and image.dtype == np.uint8
    assert at(image, draw, 0.6, 0.5) == PURSUER  # beside the heading line, inside the disc
    assert at(image, draw, 3.4, 2.3) == EVADER
    assert max(at(image, draw, 2.0, 1.5)) < 100  # the pillar is dark
    assert at(image, draw, 3.4, 0.6) == (255, 255, 255)  # a free cell far from everything


def test_the_region_is_tinted_inside_the_wedge_and_not_behind_it():
    grid = walled_room()
    draw = renderer(grid)
    pose = np.array([[0.6, 1.5, 0.0]])
    seen = draw.frame(FrameState(pose, np.array([[3.5, 2.5, 0.0]]), [True]))
    unseen = draw.frame(FrameState(pose, np.array([[3.5, 2.5, 0.0]]), [False]))
    inside, behind = (1.4, 1.5), (0.3, 1.5)
    green, yellow = at(seen, draw, *inside), at(unseen, draw, *inside)
    assert green[1] > green[0] and green[1] > green[2]  # green: the pursuer detects
    assert yellow[0] > yellow[2] and yellow[1] > yellow[2]  # yellow: it does not
    assert at(seen, draw, *behind) == (255, 255, 255)
    # a given outline replaces the wedge: a region that stops at x = 1.0
    square = np.array([[0.6, 1.3], [1.0, 1.3], [1.0, 1.7], [0.6, 1.7]])
    clipped = draw.frame(FrameState(pose, np.array([[3.5, 2.5, 0.0]]), [True], [[square]]))
    assert at(clipped, draw, *inside) == (255, 255, 255)
    assert at(clipped, draw, 0.9, 1.4) != (255, 255, 255)


def test_a_rotated_map_is_drawn_in_its_own_cell_frame():
    data = np.zeros((40, 60), dtype=np.int8)
    data[10:14, 20:24] = OCCUPIED
    grid = OccupancyGrid(data, 0.05, (1.0, -2.0, 0.7))
    draw = renderer(grid)
    x, y = grid.cell_to_world(30, 45)
    image = draw.frame(FrameState(np.array([[x, y, 0.0]]), np.empty((0, 3)), [False]))
    assert at(image, draw, x, y - 0.1) == PURSUER
    bx, by = grid.cell_to_world(12, 22)
    assert max(at(image, draw, bx, by)) < 100
