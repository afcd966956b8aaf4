"""The paper's smart evader in many games at once: :class:`pegame.evaders.smart.SmartEvader`'s
decisions and commands for a batch of games in one kernel call per tick.

Per game the kernel does what the strategy does (Sec. "Smart Evader", Algorithm 2), by
the same kernels, so each game's commands are the strategy's, bit for bit:

- at a decision tick, the escape goal by :func:`pegame.evaders.escape.escape_goal` (the
  pursuer's region computed only where the argmin search looks; the strategy's search
  computes the whole region, with the same goal and cost);
- the goal followed, its path and the command at every tick by the kernels of
  :mod:`pegame.navigation.goals`, which the strategy calls for its batch of one.

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
from pegame.evaders.escape import escape_goal
from pegame.evaders.smart import SmartEvader
from pegame.navigation import PathFollower
from pegame.navigation.goals import GoalPaths, command, steer
from pegame.types import Pose


def batchable(config: Any) -> bool:
    """Whether :class:`SmartEvaderBatch` plays the smart evader with ``config``."""
    return config.distance == "euclidean"


class SmartEvaderBatch:
    """The smart evader with ``config`` in ``context``, in ``num_games`` games: their
    goals and paths (:class:`pegame.navigation.goals.GoalPaths`) and the candidate cells
    of each connected component the evaders stand in, kept in one pool where a
    component's tiles are found by their offsets."""

    def __init__(self, config: Any, context: Context, num_games: int) -> None:
        # The strategy itself holds the search, the planner and the follower's gains.
        self.strategy = SmartEvader(config, context, np.random.default_rng(0))
        self.grid = context.grid
        self.paths = GoalPaths(
            context.grid, self.strategy.planner, PathFollower(context.evader), num_games
        )
        self.component = np.zeros(num_games, dtype=np.int64)
        self._labels: dict[int, int] = {}  # planner label -> component index
        self._components: list[tuple] = []  # their (cells, tiles) kernel inputs
        self._pool: tuple = ()
        search, grid = self.strategy.search, context.grid
        self._search = (*search.view_inputs(), grid.kernel_frame, grid.width, search.scratch())

    def reset(self, game: int) -> None:
        """Game ``game`` starts: no goal, no path."""
        self.paths.reset(game)

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
                self.paths.world,
                self.paths.state,
            )
            if stop < 0:
                return
            # A path longer than the room: grow it and decide that game again.
            start += int(stop)
            self.paths.grow()

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
        nearest = self.paths.world[2][4]  # the planner's start cells
        rows, cols = nearest[0, rows, cols], nearest[1, rows, cols]
        labels = strategy.planner.labels[rows, cols]
        for k, label in enumerate(labels.tolist()):
            if label not in self._labels:
                pose = Pose(float(x[k]), float(y[k]), 0.0)
                self._add(label, strategy.search.component_at(pose))
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
    world: tuple,
    state: tuple,
) -> int:
    """:meth:`SmartEvaderBatch.command`'s kernel: -1 when every game is commanded, else
    the position in ``games`` of the first game whose new path did not fit the room (its
    goal and command untouched, those after it too). world, state: the games'
    :class:`GoalPaths` kernel inputs."""
    starts, rows, cols, boxes, group_boxes, group_starts, members = pool[:7]
    cell_offsets, tile_offsets, group_offsets = pool[7:]
    sight, rays, half_widths, frame, width, scratch = search
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
            if cell >= 0 and steer(game, cell, ex, ey, world, state) < 0:
                return k
        commands[game, 1, 0], commands[game, 1, 1] = command(game, ex, ey, theta, world, state)
    return -1
