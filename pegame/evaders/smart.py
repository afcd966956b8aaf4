"""The paper's smart evader (Sec. "Smart Evader", Algorithms 1 and 2).

At every decision the evader is told the pursuer's pose (the paper's assumption) and:

1. takes the pursuer's visibility region V (Algorithm 1, with occlusion:
   :class:`pegame.visibility.VisibilityRegion` for ``context.camera``) as the game computed
   it this tick (``EvaderObservation.pursuer_region``), or computes it when not given;
2. takes as candidate goals the cells of F \\ V it can reach: traversable for its radius
   and connected to its own cell (:meth:`pegame.navigation.Planner.reachable`), minus V;
3. scores each candidate i with Algorithm 2's
   ``cost_escape[i] = cost_effort[i] / cost_dist[i]``, where cost_effort is the distance
   (m) from the evader to the candidate and cost_dist the distance (m) from the pursuer to
   it; a candidate at distance 0 from the pursuer costs +inf (no division by zero);
4. navigates to the argmin: a path as :meth:`Planner.plan` finds it, and
   :class:`PathFollower`'s pure pursuit for the (v, w) commands at control ticks (both
   by :class:`pegame.navigation.goals.GoalPaths`, which the batched smart evader shares).

Distances (``Config.distance``): ``euclidean`` is the paper's straight-line distance
between the agents' positions and the candidate cell centres; ``geodesic`` is the
shortest 8-connected path on the grid (:meth:`Planner.distance_field`, unweighted), the
evader's over the cells traversable for its radius and the pursuer's over the cells
traversable for the pursuer's radius (``context.pursuer.radius``). A candidate the
pursuer cannot reach has cost_dist = +inf and so cost 0: an ideal hiding place.

Hidden means the whole body: with ``hide_margin`` > 0 (default 0.3 m, about the evader's
radius) a candidate must lie more than that distance (cell centre to cell centre) from
every cell of V. With the paper's bare cell test (``hide_margin=0``) the argmin is the
free cell right next to V's edge; an evader whose centre stands in V arrives there within
the follower's tolerance while still seen, and stays: measured on the enclosed map this
froze every smart-vs-smart game at 100% tracking.

Ties go to the lowest cost, then to the lowest row-major cell index (row * width + col),
so the same inputs always give the same goal.

An evader already out of sight stays put. cost_effort, and cost_escape with it, is
smallest at the evader's own position, so whenever the evader's own cell is outside V the
argmin is at or next to that cell (with euclidean distances the cell centres sit up to
half a cell from the evader): the evader waits where it is until V reaches it and only
then runs. That is Algorithm 2 as printed, kept on purpose. With geodesic distances the
own cell costs exactly 0 and ties with every cell the pursuer cannot reach; a tied cell
of lower row-major index then wins, so the evader moves into such a region.

When no candidate exists (V covers all the free space the evader can reach) the evader
logs it at INFO and keeps following its current plan (it stands still when it has none).

Cost control: the argmin is recomputed at every decision (V too, when not given), but
the path is replanned only when the chosen goal moves by more than one cell (Chebyshev
distance) from the goal being followed. ``candidate_stride`` k > 1 scores only the cells whose row and
column are both multiples of k (about 1/k^2 of them).

Units and frames: metres, seconds and radians in the map frame of :mod:`pegame.grid`
(x right, y up, row 0 = lowest y). Candidates are cell centres.

The argmin is :class:`pegame.evaders.escape.EscapeSearch`'s: numba kernels that skip
most of the candidates, held bit for bit to a plain numpy reference.

Against a team of pursuers (``EvaderObservation.pursuers`` holds more than one pose) V is
the union of their regions (``pursuer_region``) and cost_dist the distance from each
candidate to its nearest pursuer, ``min_k dist(p_k, c)``: a hiding place next to another
pursuer is no escape. That argmin is :meth:`SmartEvader.team_escape`, in plain numpy over
every candidate (it is the 1v1 reference with the minimum over the pursuers).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import distance_transform_edt

from pegame.api import Context, Evader, EvaderObservation
from pegame.errors import require
from pegame.evaders.escape import (
    DISTANCES,
    MAX_RECORDED_CANDIDATES,
    Escape,
    EscapeSearch,
    escape_costs,
    subsample,
)
from pegame.navigation import PathFollower, Planner
from pegame.navigation.goals import GoalPaths
from pegame.types import Plan, Pose, Region, Velocity
from pegame.visibility import UnionRegion, VisibilityRegion

log = logging.getLogger(__name__)


class SmartEvader(Evader):
    """Runs to the reachable cell outside the pursuer's view minimising effort / distance."""

    description = (
        "Paper's smart evader: escapes to the out-of-view cell minimising effort/distance."
    )

    @dataclass
    class Config(Evader.Config):
        distance: str = "euclidean"  # 'euclidean' (the paper) or 'geodesic' (grid paths)
        candidate_stride: int = 1  # score every k-th cell in rows and columns (k >= 1)
        hide_margin: float = 0.3  # m; candidates lie at least this far outside V (the body hidden)

        def __post_init__(self) -> None:
            super().__post_init__()
            require(self.distance in DISTANCES, "distance", ", ".join(DISTANCES), self.distance)
            require(self.hide_margin >= 0, "hide_margin", "a distance >= 0 m", self.hide_margin)
            require(
                self.candidate_stride >= 1,
                "candidate_stride",
                "an integer >= 1",
                self.candidate_stride,
            )

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        grid = context.grid
        self.planner = Planner.shared(grid, context.evader.radius)
        # The pursuer's planner only serves its geodesic distance field.
        pursuer_planner = (
            Planner.shared(grid, context.pursuer.radius) if config.distance == "geodesic" else None
        )
        self.search = EscapeSearch(
            grid,
            context.camera,
            self.planner,
            pursuer_planner,
            config.distance,
            config.candidate_stride,
            config.hide_margin,
        )
        #: the goal followed and its path: a batch of one (pegame.navigation.goals)
        self.paths = GoalPaths(grid, self.planner, PathFollower(context.evader), 1)
        self.plan = Plan()

    def reset(self, pose: Pose) -> None:
        self.plan = Plan()
        self.paths.reset(0)

    def decide(self, observation: EvaderObservation) -> Plan:
        """Find the escape goal for this tick's V; replan when it moved by more than a cell.

        The returned plan's goal and path are those being followed; its info holds
        "candidates", float (K, 2) candidate cell centres (m, map frame, at most
        escape.MAX_RECORDED_CANDIDATES of them, evenly subsampled), and "escape_cost", the
        cost of this decision's argmin (+inf when there is no candidate).
        """
        me, pursuer = observation.pose, observation.pursuer
        if len(observation.pursuers) > 1:
            found = self.team_escape(me, observation.pursuers, observation.pursuer_region)
        else:
            found = self.search.escape(me, pursuer, observation.pursuer_region)
        if found.count == 0:
            log.info(
                "t=%.2f s: the pursuer's view covers all free space the evader can reach; "
                "keeping the current plan.",
                observation.time,
            )
            self.plan = Plan(
                self.plan.goal,
                self.plan.path,
                {"candidates": np.zeros((0, 2)), "escape_cost": math.inf},
            )
            return self.plan
        goal, path = self.plan.goal, self.plan.path
        if self.paths.steer(0, found.cell, me.x, me.y):
            x, y = self.search.centres(found.cell)
            goal, path = (float(x), float(y)), self.paths.path(0)
        info = {
            "candidates": self.search.centres(found.sample),
            "escape_cost": found.cost,
        }
        self.plan = Plan(goal, path, info)
        return self.plan

    def team_escape(
        self, me: Pose, pursuers: Sequence[Pose], visible: Region | None = None
    ) -> Escape:
        """Algorithm 2 against a team (module docstring): the candidates outside the union
        ``visible`` of the pursuers' regions (computed from ``pursuers`` when not given)
        grown by the hide margin, cost_dist the distance to the nearest pursuer. Plain
        numpy over every candidate, as :meth:`EscapeSearch.escape_reference`; with every
        pursuer at one pose it is that pose's 1v1 argmin."""
        search, grid = self.search, self.context.grid
        if visible is None:
            visible = UnionRegion(
                [VisibilityRegion(grid, pose, self.context.camera) for pose in pursuers]
            )
        exposed = self._grown(visible)
        stride = self.config.candidate_stride
        mask = self.planner.reachable((me.x, me.y)) & ~exposed
        mask[np.arange(grid.height) % stride != 0, :] = False
        mask[:, np.arange(grid.width) % stride != 0] = False
        cells = np.flatnonzero(mask)
        if cells.size == 0:
            return Escape(-1, math.inf, 0, cells)
        if self.config.distance == "euclidean":
            x, y = search.centres(cells).T
            effort = np.sqrt((x - me.x) ** 2 + (y - me.y) ** 2)
            dist = np.min([np.sqrt((x - p.x) ** 2 + (y - p.y) ** 2) for p in pursuers], axis=0)
        else:
            effort = self.planner.distance_field((me.x, me.y)).ravel()[cells]
            fields = [search.pursuer_distances(p) for p in pursuers]
            dist = np.min([f[cells] for f in fields], axis=0)
        cost = escape_costs(effort, dist)
        best = int(np.argmin(cost))  # first minimum: the lowest row-major index among ties
        return Escape(
            int(cells[best]),
            float(cost[best]),
            cells.size,
            subsample(cells, MAX_RECORDED_CANDIDATES),
        )

    def _grown(self, visible: Region) -> np.ndarray:
        """Bool (H, W): the cells within the hide margin (m) of ``visible``, by the
        Euclidean distance transform (as the 1v1 reference grows V), computed over V's
        bounds padded by the margin: no cell farther out can be that close."""
        mask, margin = visible.mask, self.config.hide_margin
        r0, r1, c0, c1 = visible.bounds
        if margin <= 0 or r1 <= r0:
            return mask
        grid = self.context.grid
        pad = math.ceil(margin / grid.resolution) + 1
        r0, c0 = max(r0 - pad, 0), max(c0 - pad, 0)
        r1, c1 = min(r1 + pad, grid.height), min(c1 + pad, grid.width)
        grown = np.zeros(mask.shape, dtype=bool)
        window = distance_transform_edt(~mask[r0:r1, c0:c1]) * grid.resolution <= margin
        grown[r0:r1, c0:c1] = window
        return grown

    def control(self, observation: EvaderObservation) -> Velocity:
        pose = observation.pose
        return Velocity(*self.paths.command(0, pose.x, pose.y, pose.theta))
