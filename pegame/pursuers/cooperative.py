"""A cooperative team of smart pursuers: one tracker per seen evader, the others cover
where it would go next or split the belief about the lost evaders among themselves.

Every member runs the same deterministic assignment on the same team observation
(:class:`pegame.api.PursuerTeam`: every pursuer's pose and detections, the team's belief
about each evader, the union of the regions), so the members agree without messages: the
implicit coordination of a shared world model. Each decision tick (and at once when a
member loses the evader it tracked):

1. Trackers. A pursuer that detects an evader tracks it (the nearest it detects, by
   depth, and keeps it while it sees it), centred at the standoff with the paper's
   reactive controller (:class:`pegame.pursuers.smart.SmartPursuer`); while another
   evader is lost, only the nearest of an evader's trackers keeps it. The other pursuers
   are free: they do not all drive to the same estimate, as N independent copies of the
   smart pursuer do.
2. Tasks for the free pursuers. For a seen evader, its next hiding place: Algorithm 2 of
   the paper's smart evader (:class:`pegame.evaders.escape.EscapeSearch`) from its
   detected position against its tracker (the lowest-index one) and outside the union of the team's regions,
   the point a smart evader runs to; a pursuer there denies it. For a lost evader, the
   modes of the belief: its particles split into as many clusters as there are free
   pursuers by weighted k-means (Lloyd 1982, "Least squares quantization in PCM", IEEE
   Trans. Inf. Theory 28(2); centres seeded deterministically at the heaviest particle,
   then farthest-first), each cluster a task valued by its weight (a belief with a mean
   only, Kalman or last-seen, is one task at its mean).
3. Assignment by path cost: the free pursuers and the tasks are matched by the Hungarian
   method (Kuhn 1955; ``scipy.optimize.linear_sum_assignment``) on cost = geodesic path
   length (m, :meth:`pegame.navigation.Planner.distance_field`) / task value, a cover
   task valued ``cover_value``; pursuers left over after every task has one are matched
   again, so two can share a task. This is the multi-robot task allocation of Gerkey &
   Mataric (2004, "A formal analysis and taxonomy of task allocation in multi-robot
   systems", IJRR 23(9)), applied to the observation of several moving targets (Parker
   2002, "Distributed algorithms for multi-robot observation of multiple moving
   targets", Autonomous Robots 12(3)) and to splitting a moving target's belief among
   searchers (Hollinger, Singh, Djugash & Kehagias 2009, "Efficient multi-robot search
   for a moving target", IJRR 28(2)).

A free pursuer plans to its task, follows the path and scans in place there (the smart
pursuer's search and scan); a detection makes it a tracker at the next control tick. Units: m, s, rad, map frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import linear_sum_assignment

from pegame.api import Context, PursuerObservation, PursuerTeam
from pegame.errors import require
from pegame.evaders.escape import EscapeSearch
from pegame.navigation import Planner
from pegame.pursuers.smart import SCAN, SEARCH, TRACK, SmartPursuer
from pegame.types import Belief, Plan, Pose, Velocity

#: path cost (m) standing for "unreachable" in the assignment (finite, so the solver runs)
UNREACHABLE = 1e6


def weighted_kmeans(
    points: np.ndarray, weights: np.ndarray, k: int, iterations: int
) -> tuple[np.ndarray, np.ndarray]:
    """Weighted k-means (Lloyd) of the (N, 2) ``points`` with weights (N,) >= 0: (K, 2)
    centres and their (K,) total weights, K <= k (fewer when fewer distinct points carry
    weight). Seeds: the heaviest point, then each next the point maximising weight x
    squared distance to the nearest centre (deterministic farthest-first)."""
    order = weights > 0
    points, weights = points[order], weights[order]
    if points.shape[0] == 0:
        return np.zeros((0, 2)), np.zeros(0)
    centres = [points[int(np.argmax(weights))]]
    nearest = np.sum((points - centres[0]) ** 2, axis=1)
    for _ in range(1, k):
        score = weights * nearest
        if score.max() <= 0:
            break
        centres.append(points[int(np.argmax(score))])
        nearest = np.minimum(nearest, np.sum((points - centres[-1]) ** 2, axis=1))
    c = np.array(centres)
    for _ in range(iterations):
        label = np.argmin(((points[:, None, :] - c[None, :, :]) ** 2).sum(axis=2), axis=1)
        mass = np.bincount(label, weights, minlength=len(c))
        moved = np.column_stack(
            [np.bincount(label, weights * points[:, d], minlength=len(c)) for d in (0, 1)]
        )
        keep = mass > 0
        c = moved[keep] / mass[keep, None]
    label = np.argmin(((points[:, None, :] - c[None, :, :]) ** 2).sum(axis=2), axis=1)
    return c, np.bincount(label, weights, minlength=len(c))


def alone(observation: PursuerObservation) -> PursuerTeam:
    """The team of one of a 1v1 game's pursuer (whose observation has no team view)."""
    o = observation
    return PursuerTeam(0, 0, (o.pose,), ((o.detection,),), (o.belief,), (o.region,), o.region)


@dataclass(frozen=True)
class Task:
    """A place for a free pursuer: ``goal`` (x, y) m, its ``value`` (> 0), the evader it
    serves and why (``cover`` a seen evader's escape, ``search`` a lost one's cluster)."""

    goal: tuple[float, float]
    value: float
    evader: int
    kind: str


class CooperativePursuer(SmartPursuer):
    """A team member: tracks an evader it is the nearest seer of; otherwise goes where
    the team's assignment sends it (module docstring)."""

    description = (
        "Team: one tracker per seen evader; the rest cover its escape or split the belief."
    )

    @dataclass
    class Config(SmartPursuer.Config):
        cover_value: float = (
            0.5  # task value of covering a seen evader's escape (a cluster's is its weight)
        )
        kmeans_iterations: int = 8  # Lloyd iterations splitting a lost evader's particles
        escape_stride: int = 2  # candidate stride of the predicted escape (cells, >= 1)
        escape_margin: float = 0.3  # m, hide margin of the predicted escape (the evader's)

        def __post_init__(self) -> None:
            super().__post_init__()
            require(self.cover_value > 0, "cover_value", "a value > 0", self.cover_value)
            require(
                self.kmeans_iterations >= 1,
                "kmeans_iterations",
                "a whole number >= 1",
                self.kmeans_iterations,
            )
            require(
                self.escape_stride >= 1,
                "escape_stride",
                "a whole number >= 1",
                self.escape_stride,
            )
            require(
                self.escape_margin >= 0,
                "escape_margin",
                "a distance >= 0 m",
                self.escape_margin,
            )

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        grid = context.grid
        self.escape = EscapeSearch(
            grid,
            context.camera,
            Planner.shared(grid, context.evader.radius),
            None,
            "euclidean",
            config.escape_stride,
            config.escape_margin,
        )
        self.task: Task | None = None
        self.tracking: int | None = None  # the evader this pursuer tracks, if any

    #: the last tick's assignment, shared by the members: (detections, beliefs, tasks),
    #: the tick's own tuples as its key (the loop builds new ones every tick)
    _assignment: tuple | None = None

    def reset(self, pose: Pose) -> None:
        super().reset(pose)
        self.task, self.tracking = None, None

    # -- the team's roles, the same for every member

    @staticmethod
    def trackers(team: PursuerTeam) -> dict[int, int]:
        """Pursuer -> the evader it tracks: for every pursuer that detects some evader, the
        one it detects nearest (smallest depth; lowest index among ties). While some
        evader is seen by nobody, an evader tracked by several keeps only its nearest
        tracker: the others are released to search."""
        out: dict[int, tuple[float, int]] = {}
        for i, row in enumerate(team.detections):
            seen = [(d.depth, j) for j, d in enumerate(row) if d is not None]
            if seen:
                out[i] = min(seen)
        tracked = {j for _, j in out.values()}
        if len(tracked) < len(team.beliefs):
            nearest: dict[int, tuple[float, int]] = {}
            for i, (depth, j) in out.items():
                nearest[j] = min(nearest.get(j, (depth, i)), (depth, i))
            out = {i: (d, j) for i, (d, j) in out.items() if nearest[j][1] == i}
        return {i: j for i, (_, j) in out.items()}

    def tasks(self, team: PursuerTeam, free: int) -> list[Task]:
        """The free pursuers' tasks (module docstring, step 2), in evader order."""
        tasks: list[Task] = []
        for j, belief in enumerate(team.beliefs):
            seers = [(i, d) for i, row in enumerate(team.detections) if (d := row[j]) is not None]
            if seers:
                tracker, detection = seers[0]
                me = Pose(*detection.position)
                found = self.escape.escape(me, team.pursuers[tracker], team.union)
                if found.count:
                    x, y = self.escape.centres(found.cell)
                    tasks.append(Task((float(x), float(y)), self.config.cover_value, j, "cover"))
                continue
            tasks.extend(self._search_tasks(belief, j, free))
        return tasks

    def _search_tasks(self, belief: Belief, j: int, free: int) -> list[Task]:
        """A lost evader's belief as tasks: its particle clusters, or its mean."""
        if belief.particles is not None and belief.weights is not None:
            centres, mass = weighted_kmeans(
                belief.particles[:, :2], belief.weights, free, self.config.kmeans_iterations
            )
            total = float(mass.sum()) or 1.0
            return [
                Task((float(c[0]), float(c[1])), float(m) / total, j, "search")
                for c, m in zip(centres, mass)
                if m > 0
            ]
        if belief.mean is not None:
            return [Task((float(belief.mean[0]), float(belief.mean[1])), 1.0, j, "search")]
        return []

    def assign(self, team: PursuerTeam) -> dict[int, Task]:
        """Free pursuer -> task for the whole team (step 3); the same for every member
        of one tick, so it is computed once per tick and shared."""
        shared = CooperativePursuer._assignment
        if shared is not None and shared[0] is team.detections and shared[1] is team.beliefs:
            return shared[2]
        assigned = self._assign(team)
        CooperativePursuer._assignment = (team.detections, team.beliefs, assigned)
        return assigned

    def _assign(self, team: PursuerTeam) -> dict[int, Task]:
        busy = self.trackers(team)
        free = [i for i in range(len(team.pursuers)) if i not in busy]
        tasks = self.tasks(team, len(free)) if free else []
        if not tasks:
            return {}
        goals = [self.planner.nearest_traversable(t.goal) or t.goal for t in tasks]
        cells = [self.context.grid.world_to_cell(*g) for g in goals]
        cost = np.empty((len(free), len(tasks)))
        for row, i in enumerate(free):
            field = self.planner.distance_field((team.pursuers[i].x, team.pursuers[i].y))
            for col, (cell, task) in enumerate(zip(cells, tasks)):
                length = field[cell] if self.context.grid.contains(*cell) else math.inf
                cost[row, col] = min(length, UNREACHABLE) / task.value
        assigned: dict[int, Task] = {}
        left = list(range(len(free)))
        while left:  # every pursuer gets a task; once each task has one, they share
            rows, cols = linear_sum_assignment(cost[left])
            for r, c in zip(rows, cols):
                assigned[free[left[r]]] = tasks[c]
            left = [k for k in left if free[k] not in assigned]
        return assigned

    # -- the strategy

    def decide(self, observation: PursuerObservation) -> Plan:
        team = observation.team or alone(observation)
        tracked = self.trackers(team).get(team.member)
        if tracked is not None:
            self.tracking, self.task = tracked, None
            self.mode = TRACK
            detection = team.detections[team.member][tracked]
            assert detection is not None  # a tracker detects its evader
            return Plan(goal=detection.position, info={"mode": TRACK, "evader": tracked})
        self.tracking = None
        return self._go(observation, self.assign(team).get(team.member))

    def _go(self, observation: PursuerObservation, task: Task | None) -> Plan:
        """Plan to ``task`` and follow it (mode SEARCH), or scan when there is none."""
        self.task = task
        if task is None:
            self._start_scan(observation)
            return Plan(info={"mode": SCAN, "reason": "no task"})
        pose = observation.pose
        result = self.planner.plan((pose.x, pose.y), task.goal)
        if not result.reachable:
            self._start_scan(observation)
            return Plan(info={"mode": SCAN, "reason": result.reason})
        self.mode = SEARCH
        self.follower.set_path(result.path)
        info = {"mode": SEARCH, "task": task.kind, "evader": task.evader}
        return Plan(goal=task.goal, path=result.path, info=info)

    def control(self, observation: PursuerObservation) -> Velocity:
        team = observation.team or alone(observation)
        row = team.detections[team.member]
        tracked = self.trackers(team).get(team.member)
        if tracked is not None:
            # Keep the evader being tracked while it is seen, else take the assigned one.
            if self.tracking is None or row[self.tracking] is None:
                self.tracking = tracked
            self.mode = TRACK
            return self._track(replace(observation, detection=row[self.tracking]))
        if self.tracking is not None or self.mode == TRACK:
            self.decide(observation)  # just lost it (or handed it over): a task now
        return self._search_or_scan(observation)
