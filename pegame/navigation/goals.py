"""Goal cells followed, for one agent or a batch: a new path when the goal moves, pure
pursuit along it at every tick, as the paper's smart evader drives to its escape point.

:class:`GoalPaths` keeps per game (first axis) the goal cell being followed (flat
row-major index, -1 before the first), the path to it (waypoints, segment lengths, arc
lengths, count) and the follower's progress (m) and done flag. Its kernels:

- :func:`steer` takes a new goal cell: when there is no path, or the cell lies more than
  one cell (Chebyshev) from the goal followed, it plans a new path as
  :meth:`pegame.navigation.Planner.plan` does between traversable cells: A*
  (:func:`pegame.navigation.search.astar`, the planner's own tables) from the cell the
  planner starts from (the agent's, or the nearest traversable one) to the goal cell, the
  cells' centres then the goal cell's centre, the goal point;
- :func:`command` gives the pure-pursuit command along it
  (:func:`pegame.navigation.follower.follow_command`, :class:`PathFollower`'s step), or a
  stop before the first goal and once the path is done.

Goal cells must be traversable and reachable from the agent (the smart evader's
candidates are its component's cells): the goal is then never snapped and always
reached. The single smart evader is a batch of one; the batched one calls the kernels
for every game of a tick inside its own kernel.

Units and frames: metres, seconds and radians in the map frame of :mod:`pegame.grid`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from pegame.grid import OccupancyGrid
from pegame.grid.cells import cell_centre, point_cell
from pegame.navigation.follower import PathFollower, follow_command
from pegame.navigation.planner import Planner
from pegame.navigation.search import astar

#: waypoints a game's path holds at first; a longer path doubles every game's room
FIRST_CAPACITY = 256


class GoalPaths:
    """The goals and paths of ``num_games`` agents planned by ``planner`` on ``grid`` and
    followed with ``follower``'s gains and body (module docstring)."""

    def __init__(
        self, grid: OccupancyGrid, planner: Planner, follower: PathFollower, num_games: int
    ) -> None:
        self.goal_cell = np.full(num_games, -1, dtype=np.int64)
        self.path_length = np.zeros(num_games, dtype=np.int64)
        self.progress = np.zeros(num_games)
        self.done = np.ones(num_games, dtype=np.bool_)
        self.waypoints = np.zeros((num_games, FIRST_CAPACITY, 2))
        self.seg_len = np.zeros((num_games, FIRST_CAPACITY))
        self.arc = np.zeros((num_games, FIRST_CAPACITY))
        gains = (
            follower.lookahead,
            follower.goal_tolerance,
            follower.rotate_threshold,
            follower.turn_gain,
        )
        #: the kernels' fixed inputs: the grid, the planner's tables, the follower's
        self.world = (
            grid.kernel_frame,
            grid.width,
            planner.search_tables(),
            (gains, (follower.body.v_max, follower.body.w_max)),
        )

    def reset(self, game: int) -> None:
        """Game ``game`` starts: no goal, no path."""
        self.goal_cell[game], self.path_length[game] = -1, 0
        self.progress[game], self.done[game] = 0.0, True

    @property
    def state(self) -> tuple:
        """The kernels' per-game arrays: (goal cells, path lengths, progress, done) and
        (waypoints, segment lengths, arc lengths)."""
        plans = (self.goal_cell, self.path_length, self.progress, self.done)
        return plans, (self.waypoints, self.seg_len, self.arc)

    def grow(self) -> None:
        """Twice the room for waypoints per game, keeping the paths held."""
        held = self.waypoints.shape[1]
        games = self.goal_cell.size
        waypoints = np.zeros((games, 2 * held, 2))
        seg_len, arc = np.zeros((games, 2 * held)), np.zeros((games, 2 * held))
        waypoints[:, :held], seg_len[:, :held], arc[:, :held] = (
            self.waypoints,
            self.seg_len,
            self.arc,
        )
        self.waypoints, self.seg_len, self.arc = waypoints, seg_len, arc

    def steer(self, game: int, cell: int, x: float, y: float) -> bool:
        """:func:`steer` for game ``game``'s agent at (x, y) (m) and goal ``cell``, growing
        the room when the new path needs it; whether a new path was planned."""
        while True:
            planned = steer(game, cell, x, y, self.world, self.state)
            if planned >= 0:
                return bool(planned)
            self.grow()

    def path(self, game: int) -> np.ndarray:
        """Float (K, 2): game ``game``'s path (m), a copy."""
        return self.waypoints[game, : self.path_length[game]].copy()

    def command(self, game: int, x: float, y: float, theta: float) -> tuple[float, float]:
        """:func:`command` for game ``game``'s agent at pose (x, y, theta)."""
        return command(game, x, y, theta, self.world, self.state)


@njit(cache=True)
def steer(game: int, cell: int, x: float, y: float, world: tuple, state: tuple) -> int:
    """Follow goal ``cell`` (flat row-major) in game ``game`` from the agent at (x, y)
    (m): 1 when a new path was planned, 0 when the goal followed is kept, -1 when the new
    path does not fit the room (nothing changed)."""
    frame, width, planner, _ = world
    (goal_cell, path_length, progress, done), (waypoints, seg_len, arc) = state
    goal = goal_cell[game]
    if goal >= 0 and path_length[game] > 0:
        moved = max(abs(cell // width - goal // width), abs(cell % width - goal % width))
        if moved <= 1:
            return 0
    lattice, heuristic, scratch, traversable, nearest = planner
    padded_width = lattice[3]
    row, col = point_cell(x, y, frame)
    row = min(max(row, 0), traversable.shape[0] - 1)
    col = min(max(col, 0), width - 1)
    start_row, start_col = nearest[0, row, col], nearest[1, row, col]
    goal_row, goal_col = cell // width, cell % width
    start = (start_row + 1) * padded_width + start_col + 1
    _, route, _ = astar(
        lattice, start, (goal_row + 1) * padded_width + goal_col + 1, heuristic, scratch
    )
    count = route.size + 1
    if count > waypoints.shape[1]:
        return -1
    for i in range(route.size):
        r, q = route[i] // padded_width, route[i] % padded_width
        waypoints[game, i, 0], waypoints[game, i, 1] = cell_centre(r - 1, q - 1, frame)
    waypoints[game, route.size, 0], waypoints[game, route.size, 1] = cell_centre(
        goal_row, goal_col, frame
    )
    arc[game, 0] = 0.0
    for i in range(count - 1):  # as PathFollower.set_path: numpy's hypot, a running sum
        dx = waypoints[game, i + 1, 0] - waypoints[game, i, 0]
        dy = waypoints[game, i + 1, 1] - waypoints[game, i, 1]
        seg_len[game, i] = np.hypot(dx, dy)
        arc[game, i + 1] = arc[game, i] + seg_len[game, i]
    path_length[game], progress[game], done[game] = count, 0.0, False
    goal_cell[game] = cell
    return 1


@njit(cache=True)
def command(
    game: int, x: float, y: float, theta: float, world: tuple, state: tuple
) -> tuple[float, float]:
    """(v, w) (m/s, rad/s) of game ``game``'s agent at pose (x, y, theta) along its
    path: :class:`PathFollower`'s command, (0, 0) without a path or once it is done."""
    gains, limits = world[3]
    (goal_cell, path_length, progress, done), (waypoints, seg_len, arc) = state
    if goal_cell[game] < 0 or done[game]:
        return 0.0, 0.0
    n = path_length[game]
    path = (waypoints[game, :n], seg_len[game, : n - 1], arc[game, :n])
    v, w, progress[game], done[game] = follow_command(
        path, progress[game], gains, limits, (x, y, theta)
    )
    return v, w
