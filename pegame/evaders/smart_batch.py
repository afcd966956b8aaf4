"""The paper's smart evader in many games at once: :class:`pegame.evaders.smart.SmartEvader`'s
decisions and commands for a batch of games in one kernel call per tick.

Per game the kernel does what the strategy does (Sec. "Smart Evader", Algorithm 2), by
the same kernels, so each game's commands are the strategy's, bit for bit:

- at a decision tick, the escape goal by :func:`pegame.evaders.escape.escape_goal` (the
  pursuer's region computed only where the argmin search looks; the strategy's search
  computes the whole region, with the same goal and cost);
- the goal followed, its path and the command at every tick by the kernels of
  :mod:`pegame.navigation.goals`, which the strategy calls for its batch of one.

The games are spread over as many threads as numba is set to use (its kernel releases
the GIL; at least MIN_GAMES_PER_THREAD games a thread), each thread with the escape
search's and A*'s scratch memory of its own; a game's commands do not depend on the
threads (a test plays one thread against two).

Not kept: the plan's info (the recorded candidates and the escape cost) and the INFO log
when no candidate exists, which a recorder and a log read; a batched game has neither.
Geodesic distances are not batched (:func:`batchable`).

Units and frames: metres, seconds and radians in the map frame of :mod:`pegame.grid`.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numba
import numpy as np
from numba import njit

from pegame.api import Context
from pegame.evaders.escape import escape_goal
from pegame.evaders.smart import SmartEvader
from pegame.navigation import PathFollower
from pegame.navigation.goals import GoalPaths, command, steer
from pegame.types import Pose

#: games a thread is given at least: below, starting a thread costs more than it saves
MIN_GAMES_PER_THREAD = 32


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
        self._search = (*search.view_inputs(), grid.kernel_frame, grid.width)
        self._scratch: tuple | None = None  # per thread, see _thread_scratch
        self._threads: tuple[ThreadPoolExecutor, int] | None = None

    def reset(self, game: int) -> None:
        """Game ``game`` starts: no goal, no path."""
        self.paths.reset(game)

    def command(
        self, poses: np.ndarray, commands: np.ndarray, games: np.ndarray, deciding: np.ndarray
    ) -> None:
        """Write the evader's (v, w) of ``games`` into commands[game, 1], deciding first
        where ``deciding``; poses, commands: (N, 2, 3) and (N, 2, 2), role 0 the
        pursuer. The games are spread over numba's threads, each with scratch memory of
        its own."""
        self._find_components(poses, games[deciding])
        threads = max(1, min(numba.get_num_threads(), games.size // MIN_GAMES_PER_THREAD))
        scratch = self._thread_scratch(threads)
        while games.size:
            unplayed = np.zeros(games.size, dtype=np.bool_)
            arguments = (games, deciding, poses, commands, self.component, self._pool)
            state = (self._search, self.paths.world, self.paths.state, scratch, unplayed)
            if threads == 1:
                _play(*arguments, *state, (0, 1))
            else:
                executor = self._executor(threads)
                chunks = [
                    executor.submit(_play, *arguments, *state, (c, threads)) for c in range(threads)
                ]
                for chunk in chunks:
                    chunk.result()
            # A new path longer than the room: grow it and play those games again.
            games, deciding = games[unplayed], deciding[unplayed]
            if games.size:
                self.paths.grow()

    def _executor(self, threads: int) -> ThreadPoolExecutor:
        """A pool of ``threads`` threads, kept while that many are asked for."""
        if self._threads is None or self._threads[1] != threads:
            if self._threads is not None:
                self._threads[0].shutdown()
            pool = ThreadPoolExecutor(threads, thread_name_prefix="smart-evader")
            self._threads = (pool, threads)
        return self._threads[0]

    def close(self) -> None:
        """Stop the threads, if any (a later command starts them again)."""
        if self._threads is not None:
            self._threads[0].shutdown()
            self._threads = None

    def _thread_scratch(self, threads: int) -> tuple:
        """The escape search's and A*'s scratch memory, one slice per thread (the first
        axis), made for the most threads asked so far."""
        if self._scratch is None or self._scratch[0].shape[0] < threads:
            search = self.strategy.search.scratch()
            astar = self.paths.world[2][2]
            self._scratch = (
                *(np.zeros((threads, *a.shape), dtype=a.dtype) for a in search),
                *(np.zeros((threads, *a.shape), dtype=a.dtype) for a in astar),
            )
        return self._scratch

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


@njit(cache=True, nogil=True)
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
    scratch: tuple,
    unplayed: np.ndarray,
    chunk: tuple[int, int],
) -> None:
    """:meth:`SmartEvaderBatch.command`'s kernel for the games at positions chunk[0],
    chunk[0] + chunk[1], ... of ``games``, with thread slice chunk[0] of the ``scratch``:
    each decided (where ``deciding``) and commanded; ``unplayed[k]`` set for a game whose
    new path did not fit the room (its goal and command untouched). world, state: the
    games' :class:`GoalPaths` kernel inputs. It releases the GIL, so chunks run on
    threads at once; a game's result does not depend on its chunk."""
    c, chunks = chunk
    starts, rows, cols, boxes, group_boxes, group_starts, members = pool[:7]
    cell_offsets, tile_offsets, group_offsets = pool[7:]
    sight, rays, half_widths, frame, width = search
    escape_scratch = (scratch[0][c], scratch[1][c], scratch[2][c])
    astar_scratch = (
        scratch[3][c],
        scratch[4][c],
        scratch[5][c],
        scratch[6][c],
        scratch[7][c],
        scratch[8][c],
        scratch[9][c],
        scratch[10][c],
    )
    lattice, heuristic, _, traversable, nearest = world[2]
    world = (
        world[0],
        world[1],
        (lattice, heuristic, astar_scratch, traversable, nearest),
        world[3],
    )
    for k in range(c, games.size, chunks):
        game = games[k]
        px, py, heading = poses[game, 0, 0], poses[game, 0, 1], poses[game, 0, 2]
        ex, ey, theta = poses[game, 1, 0], poses[game, 1, 1], poses[game, 1, 2]
        if deciding[k]:
            p = component[game]
            t0, t1 = tile_offsets[p], tile_offsets[p + 1]
            k0, k1 = cell_offsets[p], cell_offsets[p + 1]
            g0, g1 = group_offsets[p], group_offsets[p + 1]
            # A component's starts are its own (T + 1,), after p earlier ones' ends.
            cells = (starts[t0 + p : t1 + p + 1], rows[k0:k1], cols[k0:k1], frame, width)
            groups = (group_boxes[g0:g1], group_starts[g0 + p : g1 + p + 1], members[t0:t1])
            agents = (ex, ey, px, py, heading)
            tiles = (boxes[t0:t1], groups)
            cell, _ = escape_goal(cells, tiles, sight, rays, half_widths, agents, escape_scratch)
            if cell >= 0 and steer(game, cell, ex, ey, world, state) < 0:
                unplayed[k] = True
                continue
        commands[game, 1, 0], commands[game, 1, 1] = command(game, ex, ey, theta, world, state)
