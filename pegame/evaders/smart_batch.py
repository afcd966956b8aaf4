"""The paper's smart evader in many games at once: :class:`pegame.evaders.smart.SmartEvader`'s
decisions and commands for a batch of games in one kernel call per tick.

Per game the kernel does what the strategy does (Sec. "Smart Evader", Algorithm 2), by
the same kernels, so each game's commands are the strategy's, bit for bit:

- at a decision tick, the escape goal by :func:`pegame.evaders.escape.escape_goal` (the
  pursuer's region computed only where the argmin search looks; the strategy's search
  computes the whole region, with the same goal and cost);
- a new path when the goal moved by more than one cell (Chebyshev) from the goal being
  followed, or there is no path: A* (:func:`pegame.navigation.search.astar`, the
  planner's tables) from the cell :meth:`pegame.navigation.Planner.plan` starts from to
  the goal cell, the cells' centres then the goal point (a candidate cell is traversable
  and in the evader's component, so the goal is never snapped and always reached);
- at every tick the pure-pursuit command (:func:`pegame.navigation.follower.follow_command`),
  or a stop before the first goal.

Not kept: the plan's info (the recorded candidates and the escape cost) and the INFO log
when no candidate exists, which a recorder and a log read; a batched game has neither.
Geodesic distances are not batched (:func:`batchable`).

Units and frames: metres, seconds and radians in the map frame of :mod:`pegame.grid`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit

from pegame.api import Context
from pegame.evaders.escape import _cell_centre, escape_goal
from pegame.evaders.smart import SmartEvader
from pegame.grid.cells import point_cell
from pegame.navigation.follower import follow_command
from pegame.navigation.search import astar
from pegame.types import Pose

#: waypoints a game's path holds at first; a longer path grows every game's room
FIRST_CAPACITY = 256


def batchable(config: Any) -> bool:
    """Whether :class:`SmartEvaderBatch` plays the smart evader with ``config``."""
    return config.distance == "euclidean"


class SmartEvaderBatch:
    """The smart evader with ``config`` in ``context``, in ``num_games`` games.

    Per game (first axis): the goal cell being followed (flat row-major, -1 before the
    first), whether a goal was set, the path (waypoints, segment lengths, arc lengths,
    count) and the follower's progress (m) and done flag. The candidate cells of each
    connected component the evaders stand in are kept in one pool, a component's tiles
    found by their offsets.
    """

    def __init__(self, config: Any, context: Context, num_games: int) -> None:
        # The strategy itself holds the search, the planner and the follower's gains.
        self.strategy = SmartEvader(config, context, np.random.default_rng(0))
        self.grid = context.grid
        self.goal_cell = np.full(num_games, -1, dtype=np.int64)
        self.has_goal = np.zeros(num_games, dtype=np.bool_)
        self.path_length = np.zeros(num_games, dtype=np.int64)
        self.progress = np.zeros(num_games)
        self.done = np.ones(num_games, dtype=np.bool_)
        self.waypoints = np.zeros((num_games, FIRST_CAPACITY, 2))
        self.seg_len = np.zeros((num_games, FIRST_CAPACITY))
        self.arc = np.zeros((num_games, FIRST_CAPACITY))
        self.component = np.zeros(num_games, dtype=np.int64)
        self._labels: dict[int, int] = {}  # planner label -> component index
        self._components: list[tuple] = []  # their (cells, tiles) kernel inputs
        self._pool: tuple = ()
        search, planner, follower = (
            self.strategy.search,
            self.strategy.planner,
            self.strategy.follower,
        )
        sight, rays, half_widths = search.view_inputs()
        grid = context.grid
        self._search = (sight, rays, half_widths, grid.kernel_frame, grid.width, search.scratch())
        self._planner = planner.search_tables()
        self._follower = (
            (
                follower.lookahead,
                follower.goal_tolerance,
                follower.rotate_threshold,
                follower.turn_gain,
            ),
            (follower.body.v_max, follower.body.w_max),
        )

    def _grow(self) -> None:
        """Twice the room for waypoints per game, keeping the paths held."""
        held = self.waypoints.shape[1]
        games = self.goal_cell.size
        waypoints, seg_len, arc = (
            np.zeros((games, 2 * held, 2)),
            np.zeros((games, 2 * held)),
            np.zeros((games, 2 * held)),
        )
        waypoints[:, :held], seg_len[:, :held], arc[:, :held] = (
            self.waypoints,
            self.seg_len,
            self.arc,
        )
        self.waypoints, self.seg_len, self.arc = waypoints, seg_len, arc

    def reset(self, game: int) -> None:
        """Game ``game`` starts: no goal, no path."""
        self.goal_cell[game], self.has_goal[game] = -1, False
        self.path_length[game], self.progress[game], self.done[game] = 0, 0.0, True

    def command(
        self, poses: np.ndarray, commands: np.ndarray, games: np.ndarray, deciding: np.ndarray
    ) -> None:
        """Write the evader's (v, w) of ``games`` into commands[game, 1], deciding first
        where ``deciding``; poses, commands: (N, 2, 3) and (N, 2, 2), role 0 the
        pursuer."""
        self._find_components(poses, games[deciding])
        start = 0
        while start < games.size:
            stop = _play(
                games[start:],
                deciding[start:],
                poses,
                commands,
                self.component,
                self._pool,
                self._search,
                self._planner,
                self._follower,
                (self.goal_cell, self.has_goal, self.path_length, self.progress, self.done),
                (self.waypoints, self.seg_len, self.arc),
            )
            if stop < 0:
                return
            # A path longer than the room: grow it and decide that game again.
            start += int(stop)
            self._grow()

    def _find_components(self, poses: np.ndarray, games: np.ndarray) -> None:
        """Point each game of ``games`` at the component of the cell its evader's plan
        starts from (:meth:`pegame.navigation.Planner.plan`), building the component's
        candidate cells at its first evader (EscapeSearch's, shared per map)."""
        if games.size == 0:
            return
        strategy, grid = self.strategy, self.grid
        x, y = poses[games, 1, 0], poses[games, 1, 1]
        rows, cols = grid.world_to_cell(x, y)
        rows, cols = np.clip(rows, 0, grid.height - 1), np.clip(cols, 0, grid.width - 1)
        nearest = self._planner[4]
        rows, cols = nearest[0, rows, cols], nearest[1, rows, cols]
        labels = strategy.planner.labels[rows, cols]
        for k, label in enumerate(labels.tolist()):
            if label not in self._labels:
                pose = Pose(float(x[k]), float(y[k]), 0.0)
                self._add(label, strategy.search._component_at(pose))
            self.component[games[k]] = self._labels[label]

    def _add(self, label: int, component: Any) -> None:
        """Add ``component`` (of planner label ``label``) to the pool: its tile starts,
        cell rows and columns, tile boxes, group boxes, group starts and group members
        after the earlier components', with the offsets of every component's cells, tiles
        and groups (starts hold one entry more per component)."""
        self._labels[label] = len(self._components)
        cells, tiles = self.strategy.search.kernel_inputs(component)[:2]
        self._components.append((cells, tiles))
        parts = self._components
        self._pool = (
            np.concatenate([c[0] for c, _ in parts]),
            np.concatenate([c[1] for c, _ in parts]),
            np.concatenate([c[2] for c, _ in parts]),
            np.concatenate([t[0] for _, t in parts]),
            np.concatenate([t[1][0] for _, t in parts]),
            np.concatenate([t[1][1] for _, t in parts]),
            np.concatenate([t[1][2] for _, t in parts]),
            np.cumsum([0] + [c[1].size for c, _ in parts]),
            np.cumsum([0] + [t[0].shape[0] for _, t in parts]),
            np.cumsum([0] + [t[1][0].shape[0] for _, t in parts]),
        )


@njit(cache=True)
def _play(
    games: np.ndarray,
    deciding: np.ndarray,
    poses: np.ndarray,
    commands: np.ndarray,
    component: np.ndarray,
    pool: tuple,
    search: tuple,
    planner: tuple,
    follower: tuple,
    plans: tuple,
    paths: tuple,
) -> int:
    """:meth:`SmartEvaderBatch.command`'s kernel: -1 when every game is commanded, else
    the position in ``games`` of the first game whose new path did not fit (its state
    and command untouched, those after it too)."""
    starts, rows, cols, boxes, group_boxes, group_starts, members = pool[:7]
    cell_offsets, tile_offsets, group_offsets = pool[7:]
    sight, rays, half_widths, frame, width, scratch = search
    lattice, heuristic, astar_scratch, traversable, nearest = planner
    gains, limits = follower
    goal_cell, has_goal, path_length, progress, done = plans
    waypoints, seg_len, arc = paths
    height = traversable.shape[0]
    padded_width = lattice[3]
    for k in range(games.size):
        game = games[k]
        px, py, heading = poses[game, 0, 0], poses[game, 0, 1], poses[game, 0, 2]
        ex, ey, theta = poses[game, 1, 0], poses[game, 1, 1], poses[game, 1, 2]
        if deciding[k]:
            c = component[game]
            t0, t1 = tile_offsets[c], tile_offsets[c + 1]
            k0, k1 = cell_offsets[c], cell_offsets[c + 1]
            g0, g1 = group_offsets[c], group_offsets[c + 1]
            # A component's starts are its own (T + 1,), after c earlier ones' ends.
            cells = (starts[t0 + c : t1 + c + 1], rows[k0:k1], cols[k0:k1], frame, width)
            groups = (group_boxes[g0:g1], group_starts[g0 + c : g1 + c + 1], members[t0:t1])
            agents = (ex, ey, px, py, heading)
            tiles = (boxes[t0:t1], groups)
            cell, _ = escape_goal(cells, tiles, sight, rays, half_widths, agents, scratch)
            if cell >= 0 and _needs_path(cell, goal_cell[game], path_length[game], width):
                row, col = point_cell(ex, ey, frame)
                row, col = min(max(row, 0), height - 1), min(max(col, 0), width - 1)
                start_row, start_col = nearest[0, row, col], nearest[1, row, col]
                goal_row, goal_col = cell // width, cell % width
                _, route, _ = astar(
                    lattice,
                    (start_row + 1) * padded_width + start_col + 1,
                    (goal_row + 1) * padded_width + goal_col + 1,
                    heuristic,
                    astar_scratch,
                )
                count = route.size + 1
                if count > waypoints.shape[1]:
                    return k
                for i in range(route.size):
                    r, q = route[i] // padded_width, route[i] % padded_width
                    waypoints[game, i, 0], waypoints[game, i, 1] = _cell_centre(r - 1, q - 1, frame)
                gx, gy = _cell_centre(goal_row, goal_col, frame)
                waypoints[game, route.size, 0], waypoints[game, route.size, 1] = gx, gy
                arc[game, 0] = 0.0
                for i in range(count - 1):
                    dx = waypoints[game, i + 1, 0] - waypoints[game, i, 0]
                    dy = waypoints[game, i + 1, 1] - waypoints[game, i, 1]
                    seg_len[game, i] = np.hypot(dx, dy)
                    arc[game, i + 1] = arc[game, i] + seg_len[game, i]
                path_length[game], progress[game], done[game] = count, 0.0, False
                goal_cell[game], has_goal[game] = cell, True
        v, w = 0.0, 0.0
        if has_goal[game] and not done[game]:
            n = path_length[game]
            path = (waypoints[game, :n], seg_len[game, : n - 1], arc[game, :n])
            v, w, progress[game], done[game] = follow_command(
                path, progress[game], gains, limits, (ex, ey, theta)
            )
        commands[game, 1, 0], commands[game, 1, 1] = v, w
    return -1


@njit(cache=True, inline="always")
def _needs_path(cell: int, goal: int, length: int, width: int) -> bool:
    """SmartEvader._needs_replan: no path, or ``cell`` more than one cell (Chebyshev) from
    the ``goal`` cell being followed (flat indices on a grid ``width`` cells wide)."""
    if goal < 0 or length == 0:
        return True
    return max(abs(cell // width - goal // width), abs(cell % width - goal % width)) > 1
