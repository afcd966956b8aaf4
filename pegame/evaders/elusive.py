"""An evader that hides from where the pursuer could look, not only from where it looks,
and keeps moving away once hidden (same information as the paper's smart evader: the
pursuer's pose, its camera and the map).

The paper's smart evader (Algorithm 2) runs to the out-of-view cell of least
effort / distance and parks there. Against a pursuer that turns at 1.8 rad/s that cell,
just outside the camera's 60 degree wedge, is found again by a turn. This evader scores
every cell c it can reach within ``horizon`` m (geodesic) by a time (s):

    cost(c) = d_e(c) / v_e - weight * min(d_p(c), horizon_p) / v_p
              + [c in O] * (exposed_penalty - turn_weight * t_turn(c))

with d_e the evader's and d_p the pursuer's shortest 8-connected grid paths (m,
:meth:`pegame.navigation.Planner.distance_field`, each over the cells traversable for its
radius), v_e and v_p their top speeds (m/s), and O the cells the pursuer sees from its
position when it turns all the way round: Algorithm 1 with occlusion for the pursuer's
camera with a full-turn field of view (:func:`pegame.visibility.visibility_region`),
grown by ``hide_margin`` so the whole body is hidden. Cells in the camera's current
region V (grown the same way) are not candidates. So the evader prefers cells the
pursuer cannot see without moving (behind an obstacle or beyond its range) and, among
those, the ones it reaches soon and the pursuer late. Walking straight away from the
pursuer lowers the cost when v_p / v_e < weight, so the weight sets whether the evader
flees or hides: ``flee_weight`` when it is faster than the pursuer (it can leave the
camera's range, and keeps moving on rather than parking), ``hide_weight`` otherwise (it
takes the nearest cell out of the pursuer's line of sight, and stays there until that
cell is seen). The pursuer's distance counts up to ``horizon_p`` m so that cells it
cannot reach at all do not outweigh everything else. It is the escape-time idea of
visibility-based tracking seen from the target's side (the target maximises the time
the observer needs to see it again: Gonzalez-Banos, Lee and Latombe, "Real-time
combinatorial tracking of a target moving unpredictably among obstacles", ICRA 2002;
Bandyopadhyay et al., "Stealth tracking of an unpredictable target among obstacles",
WAFR 2004), with the pursuer's geodesic distance in place of its reachable set, and for
the cells it sees by turning the time it needs to turn its field of view onto them:
moving behind the pursuer, along the edge of what it senses, is the optimal evasion of
a pursuer with limited sensing (Maity, Von Moll, Shishika and Dorothy, "Optimal evasion
from a sensing-limited pursuer", arXiv:2401.12848, 2024).

A cell of O is seen again as soon as the pursuer turns to it: its time to visibility is
the turn t_turn(c) = max(0, |bearing of c from the pursuer's heading| - fov / 2) / w_max
(s), from 0 at the edge of the camera's wedge to (pi - fov / 2) / w_max behind the
pursuer (1.45 s for the paper's pi/3 and 1.8 rad/s). Where nothing hides the evader
(the open hall: every cell within range is in O) that term alone says where to go:
behind the pursuer, across its heading, where a pursuer that lost it must turn longest
to see it again, rather than just beside the wedge, where the next turn of a pursuer
re-centring on its last detection finds it (measured against the smart pursuer in the
hall, dev seeds 1000-1007, ``+experiment=paper_conditions``: 66.3% tracked at v_p/v_e
= 1 without the term, 32.6% with turn_weight = 2; the smart evader 59.1%).

When no cell within the horizon lies outside V, every reachable cell outside V is a
candidate; when V covers every reachable cell, every reachable cell is (the evader then
runs from the pursuer). Ties go to the lowest row-major cell index (np.argmin). The
evader replans when the chosen cell moves by more than one cell (Chebyshev) from the one
it follows, and follows the path by pure pursuit (both by
:class:`pegame.navigation.goals.GoalPaths`, as the smart evader does).

Units and frames: metres and radians in the map frame of :mod:`pegame.grid` (x right, y
up, row 0 = lowest y). Candidates are cell centres. Everything is vectorised numpy over
the grid; the ray march and the distance fields are the numba kernels of
:mod:`pegame.visibility` and :mod:`pegame.navigation`, each with its plain reference there.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import maximum_filter

from pegame.api import Context, Evader, EvaderObservation
from pegame.errors import require
from pegame.navigation import PathFollower, Planner
from pegame.navigation.goals import GoalPaths
from pegame.types import Plan, Pose, Region, Velocity
from pegame.visibility.region import whole_region


class ElusiveEvader(Evader):
    """Walks to the cell, out of the pursuer's view and line of sight, that the pursuer
    needs longest to reach, and keeps walking."""

    description = (
        "Hides out of the pursuer's line of sight, as far from it as it can, and moves on."
    )

    @dataclass
    class Config(Evader.Config):
        horizon: float = 3.0  # m; candidate cells lie within this path length of the evader
        flee_weight: float = 1.0  # s of walking worth one s of the pursuer's, when faster than it
        hide_weight: float = 0.25  # the same when the pursuer is at least as fast
        horizon_p: float = 10.0  # m; the pursuer's path length to a cell counts up to this
        exposed_penalty: float = 4.0  # s; cost of a cell the pursuer sees by turning round
        turn_weight: float = 2.0  # s of cost off per s the pursuer must turn to see such a cell
        hide_margin: float = 0.3  # m; a hidden cell lies this far outside the seen cells
        sight_angle_step: float = 0.005  # rad between rays of the full-turn region

        def __post_init__(self) -> None:
            super().__post_init__()
            require(self.horizon > 0, "horizon", "a positive distance in m", self.horizon)
            require(self.horizon_p > 0, "horizon_p", "a positive distance in m", self.horizon_p)
            for key in ("flee_weight", "hide_weight"):
                value = getattr(self, key)
                require(value >= 0, key, "a weight >= 0 (s per s)", value)
            require(
                self.turn_weight >= 0,
                "turn_weight",
                "a weight >= 0 (s per s)",
                self.turn_weight,
            )
            require(
                self.exposed_penalty >= 0,
                "exposed_penalty",
                "a cost >= 0 s",
                self.exposed_penalty,
            )
            require(self.hide_margin >= 0, "hide_margin", "a distance >= 0 m", self.hide_margin)
            require(
                0 < self.sight_angle_step <= 0.1,
                "sight_angle_step",
                "an angle in (0, 0.1] rad",
                self.sight_angle_step,
            )

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        grid = context.grid
        self.planner = Planner.shared(grid, context.evader.radius)
        self.pursuer_planner = Planner.shared(grid, context.pursuer.radius)
        #: the goal followed and its path (pegame.navigation.goals); goals are reachable
        #: cells (finite evader distances), as GoalPaths needs
        self.paths = GoalPaths(grid, self.planner, PathFollower(context.evader), 1)
        # The pursuer's camera turned all the way round: what it sees without moving.
        self._all_round = dataclasses.replace(
            context.camera, fov=2 * math.pi, angle_step=config.sight_angle_step
        )
        rows, cols = np.indices(grid.data.shape)
        # Every cell centre (m), flat row-major, for the bearings of the turn times.
        self._centres = grid.cell_to_world(rows.ravel(), cols.ravel())
        self.reset(Pose(0.0, 0.0))

    def reset(self, pose: Pose) -> None:
        self.plan = Plan()
        self.paths.reset(0)

    def decide(self, observation: EvaderObservation) -> Plan:
        """Choose the goal cell for this tick (module docstring); replan when it moved by
        more than a cell. The plan's info holds "cost", the goal's cost (s)."""
        me, pursuer = observation.pose, observation.pursuer
        cost = self.costs(me, pursuer, observation.pursuer_region)
        if not np.isfinite(cost).any():
            return self.plan  # nowhere to go: keep the current plan
        cell = int(np.argmin(cost))
        goal, path = self.plan.goal, self.plan.path
        if self.paths.steer(0, cell, me.x, me.y):
            x, y = self.context.grid.cell_to_world(*divmod(cell, self.context.grid.width))
            goal, path = (float(x), float(y)), self.paths.path(0)
        self.plan = Plan(goal, path, {"cost": float(cost.flat[cell])})
        return self.plan

    def control(self, observation: EvaderObservation) -> Velocity:
        pose = observation.pose
        return Velocity(*self.paths.command(0, pose.x, pose.y, pose.theta))

    def costs(self, me: Pose, pursuer: Pose, region: Region | None = None) -> np.ndarray:
        """Float (H * W,): each cell's cost (s, module docstring) by flat row-major index,
        +inf for the cells that are not candidates. ``region``: the pursuer camera's
        visibility region this tick when the game computed it, else computed here."""
        grid, config, context = self.context.grid, self.config, self.context
        if region is None:
            seen, bounds = whole_region(grid, pursuer, context.camera)
        else:
            seen, bounds = region.mask, region.bounds
        d_e = self.planner.distance_field((me.x, me.y)).ravel()
        d_p = self.pursuer_planner.distance_field((pursuer.x, pursuer.y)).ravel()
        faster = context.evader.v_max > context.pursuer.v_max
        weight = config.flee_weight if faster else config.hide_weight
        reachable = np.isfinite(d_e)
        in_view = self._grown(seen, bounds).ravel()
        exposed = self._grown(*whole_region(grid, pursuer, self._all_round)).ravel()
        score = (
            np.where(reachable, d_e, 0.0) / context.evader.v_max
            - weight * np.minimum(d_p, config.horizon_p) / context.pursuer.v_max
            + exposed * (config.exposed_penalty - config.turn_weight * self.turn_times(pursuer))
        )
        for candidates in (
            reachable & ~in_view & (d_e <= config.horizon),
            reachable & ~in_view,
            reachable,
        ):
            if candidates.any():
                return np.where(candidates, score, np.inf)
        return np.full(score.shape, np.inf)

    def turn_times(self, pursuer: Pose) -> np.ndarray:
        """Float (H * W,): the time (s) the pursuer at ``pursuer`` needs to turn in place
        until each cell centre (flat row-major) lies within its camera's field of view:
        max(0, |bearing - heading| - fov / 2) / w_max."""
        x, y = self._centres
        bearing = np.arctan2(y - pursuer.y, x - pursuer.x) - pursuer.theta
        off = np.abs(np.arctan2(np.sin(bearing), np.cos(bearing)))  # wrapped to [0, pi]
        return np.maximum(0.0, off - 0.5 * self.context.camera.fov) / self.context.pursuer.w_max

    def _grown(self, mask: np.ndarray, bounds: tuple[int, int, int, int]) -> np.ndarray:
        """Bool (H, W): the cells within hide_margin (m, Chebyshev distance between cell
        centres) of a True cell of ``mask``, whose True cells lie in the rows and columns
        ``bounds`` (r0, r1, c0, c1). A square margin is a little wider than a disc and
        separable, so it costs one running maximum per axis over the bounds."""
        reach = int(self.config.hide_margin / self.context.grid.resolution + 1e-9)
        r0, r1, c0, c1 = bounds
        if reach == 0 or r1 <= r0:
            return mask
        height, width = mask.shape
        r0, c0 = max(r0 - reach, 0), max(c0 - reach, 0)
        r1, c1 = min(r1 + reach, height), min(c1 + reach, width)
        grown = np.zeros_like(mask)
        grown[r0:r1, c0:c1] = maximum_filter(
            mask[r0:r1, c0:c1], size=2 * reach + 1, mode="constant"
        )
        return grown
