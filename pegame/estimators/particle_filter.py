"""Particle filter tracking of the evader (paper, Secs. "Particle Filter based Tracking"
and "Smart Pursuer").

Sequential Importance Sampling (SIS) over the evader state (x m, y m, theta rad) in the map
frame (x right, y up, theta from +x, counter-clockwise, in (-pi, pi]). The filter is given
the map (``context.grid``), the evader's max speed (``context.evader.v_max``, m/s) and, at
every control tick, the pursuer's detection (or None) and visibility region V_k^p (a
:class:`pegame.visibility.VisibilityRegion`); never the true evader pose.

- Motion model, the paper's unicycle u = [V cos(phi), V sin(phi), omega]: every particle
  draws a speed V ~ U[0, v_max] (m/s) and a turn rate omega ~ N(0, turn_rate_std^2) (rad/s)
  and moves for dt seconds along the heading at the middle of the step.
- Measurement model: with a detection at z (map frame, m), w_i *= exp(-|p_i - z|^2 /
  (2 sigma^2)) and the particles in_region (their cell inside V_k^p) are multiplied by
  in_region_boost; without one, the particles in_region are multiplied by
  miss_factor ** (control_dt * miss_factor_hz) (negative information: the evader would
  have been detected there), i.e. by miss_factor per 1 / miss_factor_hz s, so the evidence
  of a second without detections is the same at any game.control_hz (at the default 10 Hz
  and control_hz 10, exactly miss_factor per tick). Particles in blocked
  cells (occupied or unknown) or off the grid get weight 0. Weights are then normalised to
  sum to 1.
- Degeneracy, the paper's Eq. for the effective sample size: N_eff = 1 / sum_i w_i^2. When
  N_eff < rho * N (0 <= rho <= 1, the paper uses rho = 0.8) the particles are resampled and
  the weights reset to 1/N.
- Lost track: the set is redrawn when the weights vanish (their sum is 0 or not finite),
  or when a detection is unexplained by the predicted set, i.e. its likelihood
  sum_i w_i exp(-|p_i - z|^2 / (2 sigma^2)) is below exp(-LOST_GATE^2 / 2), as if every
  particle were LOST_GATE sigmas away. Otherwise the few far particles nearest to z would
  take all the weight and the estimate would crawl towards z at the evader's speed. The
  new set is drawn around the detection when there is one, else uniformly over the free
  cells outside V_k^p.

The estimate is the weighted mean of the particle positions (the paper), with their
weighted covariance (m^2).

Resampling (``Config.resampler``) is one of the schemes of
:mod:`pegame.estimators.resampling` (systematic, stratified, residual or multinomial, as
filterpy.monte_carlo draws them, on the plugin's own Generator), behind its
:class:`~pegame.estimators.resampling.ThresholdResampler` with the threshold rho.

Fast path. :meth:`ParticleFilter.update` runs the per-particle work in numba kernels:
one moves the particles and finds their cells, one weighs them, normalises the weights
and computes N_eff, one computes the mean and covariance; the resampler's kernels invert
the cumulative weights. It asks V_k^p only about
the cells its moved particles landed in (``VisibilityRegion.holds``), so the camera's
rays are cast only towards those in its field of view, with the same answer as the whole
mask. The motion draws come from the component's Generator, a batch of updates at a
time, and both paths use the same draws. The plain numpy reference
:meth:`ParticleFilter.update_reference` gives the same particles, weights, N_eff and
moments to round-off (the tests hold it to 1e-12 relative): the kernels sum in order
where numpy sums pairwise, and take the headings' sines and cosines from a vectorised
polynomial (:mod:`pegame.numerics`, within 2^-52 of libm's), about four times faster.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numba import njit
from scipy.ndimage import distance_transform_edt

from pegame.api import Context, OneOnOneEstimator
from pegame.errors import MapError, require
from pegame.estimators.resampling import RESAMPLERS, ThresholdResampler, effective_sample_size
from pegame.grid.occupancy import COS_YAW, OX, OY, RESOLUTION, ROTATED, SIN_YAW
from pegame.numerics import (
    MAX_ANGLE,
    exps,
    sin_cos,
    wrap_angle_kernel,
    wrap_angles,
    wrap_angles_reference,
)
from pegame.types import Belief, Detection, Pose, Region

log = logging.getLogger(__name__)

#: a detection this many sigmas from all the particles' weight means the track is lost
LOST_GATE = 5.0
#: redraws of initial particles that land in blocked cells before snapping them to free ones
RESEED_TRIES = 5
#: updates whose motion draws are made at once (one call into numba per this many updates)
NOISE_BATCH = 32


# --------------------------------------------------------------------------- kernels


@njit(cache=True)
def _fill_noise(rng: np.random.Generator, unit_speeds: np.ndarray, normals: np.ndarray) -> None:
    """Fill ``unit_speeds`` with U[0, 1) and ``normals`` with N(0, 1) draws from ``rng``.

    Numba's Generator runs numpy's algorithms on the same bit generator, so these are the
    numbers ``rng.random`` and ``rng.standard_normal`` would give.
    """
    for i in range(unit_speeds.size):
        unit_speeds[i] = rng.random()
    for i in range(normals.size):
        normals[i] = rng.standard_normal()


@njit(cache=True, error_model="numpy")  # res > 0: no zero-division branch
def _move_and_locate(
    particles: np.ndarray,
    unit_speeds: np.ndarray,
    normals: np.ndarray,
    v_max: float,
    turn_rate_std: float,
    dt: float,
    frame: tuple,
    blocked: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """The particles (N, 3) moved by the unicycle model and the flat cell index (N,) each
    lands in (-1 in a blocked cell or off the grid).

    Particle i moves at speed v_max * unit_speeds[i] (m/s) and turn rate turn_rate_std *
    normals[i] (rad/s), as :meth:`ParticleFilter._predict` does with the same draws; the
    headings' sines and cosines come from :func:`pegame.numerics.sin_cos` (within 2^-52 of
    numpy's) and the cells from ``OccupancyGrid.world_to_cell`` operation for operation.

    frame: the grid's :class:`pegame.grid.GridFrame`.
    """
    n = particles.shape[0]
    moved = np.empty((n, 3))
    heading, sin_h, cos_h = np.empty(n), np.empty(n), np.empty(n)
    for i in range(n):
        turn = turn_rate_std * normals[i]
        heading[i] = particles[i, 2] + 0.5 * turn * dt
        moved[i, 2] = particles[i, 2] + turn * dt
    for i in range(n):  # contiguous and branch-free, so vectorised
        sin_h[i], cos_h[i] = sin_cos(heading[i])
    for i in range(n):  # its own pass: the branches slow the passes above 2.5x
        moved[i, 2] = wrap_angle_kernel(moved[i, 2])
    cells = np.empty(n, dtype=np.int64)
    ox, oy, res, rotate = frame[OX], frame[OY], frame[RESOLUTION], frame[ROTATED]
    c, s = frame[COS_YAW], frame[SIN_YAW]
    height, width = blocked.shape
    for i in range(n):
        if not abs(heading[i]) <= MAX_ANGLE:
            sin_h[i], cos_h[i] = math.sin(heading[i]), math.cos(heading[i])
        step = v_max * unit_speeds[i] * dt
        moved[i, 0] = particles[i, 0] + step * cos_h[i]
        moved[i, 1] = particles[i, 1] + step * sin_h[i]
        dx, dy = moved[i, 0] - ox, moved[i, 1] - oy
        if rotate:
            dx, dy = c * dx + s * dy, -s * dx + c * dy
        # floor stays a float until the range check: no integer overflow off the grid.
        row, col = np.floor(dy / res), np.floor(dx / res)
        if not (0.0 <= row < height and 0.0 <= col < width) or blocked[int(row), int(col)]:
            cells[i] = -1
        else:
            cells[i] = int(row) * width + int(col)
    return moved, cells


@njit(cache=True, error_model="numpy")  # two_sigma2 > 0: no zero-division branch
def _likelihoods(moved: np.ndarray, zx: float, zy: float, two_sigma2: float) -> np.ndarray:
    """exp(-|p_i - z|^2 / (2 sigma^2)) per particle (N,): the Gaussian likelihood of a
    detection at (zx, zy) (map frame, m), 0 where it would be below the smallest normal
    float (:func:`pegame.numerics.exps`, the same bits on every CPU)."""
    exponents = np.empty(moved.shape[0])
    for i in range(moved.shape[0]):
        dx, dy = moved[i, 0] - zx, moved[i, 1] - zy
        exponents[i] = -(dx * dx + dy * dy) / two_sigma2
    return exps(exponents)


@njit(cache=True, error_model="numpy")  # divides by total > 0 only: no branch
def _weigh(
    prior: np.ndarray,
    cells: np.ndarray,
    in_region: np.ndarray,
    likelihood: np.ndarray,
    detected: bool,
    in_region_boost: float,
    miss_factor: float,
) -> tuple[np.ndarray, float, float, float]:
    """Measurement update of the weights (module docstring): (weights (N,), total,
    evidence, n_eff).

    ``likelihood`` (N,) is the detection's Gaussian likelihood per particle when
    ``detected``, else ones. The weights are normalised to sum to 1 when their
    pre-normalisation ``total`` is positive and finite (n_eff = 1 / sum w^2 then, else 0).
    ``evidence`` = sum_i prior_i L_i over the particles on free cells (0 without a
    detection). cells: flat cell index per particle (-1 blocked); in_region: per particle,
    whether V holds its cell.
    """
    n = prior.size
    inside = in_region_boost if detected else miss_factor
    weights = np.empty(n)
    total = evidence = 0.0
    for i in range(n):  # selects, not branches: vectorised
        free = cells[i] >= 0
        evidence += prior[i] * likelihood[i] if free else 0.0
        weights[i] = prior[i] * (likelihood[i] * (inside if in_region[i] else 1.0)) if free else 0.0
        total += weights[i]
    if not detected:
        evidence = 0.0
    if not (total > 0.0 and math.isfinite(total)):
        return weights, total, evidence, 0.0
    squares = 0.0
    for i in range(n):
        weights[i] /= total
    for i in range(n):
        squares += weights[i] * weights[i]
    return weights, total, evidence, 1.0 / squares


@njit(cache=True)
def _moments(particles: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Weighted mean (2,) (m) and covariance (2, 2) (m^2) of the particle positions (N, 3)
    with the normalised ``weights`` (N,), in one pass over offsets from the first particle
    (which keeps the cancellation in E[d^2] - E[d]^2 to the cloud's own spread)."""
    x0, y0 = particles[0, 0], particles[0, 1]
    sx = sy = sxx = sxy = syy = 0.0
    for i in range(weights.size):
        dx, dy = particles[i, 0] - x0, particles[i, 1] - y0
        wx, wy = weights[i] * dx, weights[i] * dy
        sx += wx
        sy += wy
        sxx += wx * dx
        sxy += wx * dy
        syy += wy * dy
    cxy = sxy - sx * sy
    return np.array([x0 + sx, y0 + sy]), np.array([[sxx - sx * sx, cxy], [cxy, syy - sy * sy]])


class ParticleFilter(OneOnOneEstimator):
    """SIS particle filter over the evader's (x, y, theta), with negative information."""

    description = "SIS particle filter over the evader's pose with negative information (paper)."

    @dataclass
    class Config:
        n_particles: int = 2000  # number of particles N
        rho: float = 0.8  # resample when N_eff < rho * N, in [0, 1] (the paper's 0.8)
        resampler: str = "systematic"  # systematic, stratified, residual or multinomial
        sigma: float = 0.3  # m, std of the Gaussian likelihood of a detected position
        turn_rate_std: float = 1.0  # rad/s, std of the motion model's random turn rate
        in_region_boost: float = (
            2.0  # weight factor (>= 1) inside the visible region on a detection
        )
        miss_factor: float = 0.05  # weight factor in [0, 1] inside the visible region on a miss
        miss_factor_hz: float = 10.0  # Hz, the rate miss_factor is the factor per tick at
        init_spread: float = 0.3  # m, std of the initial cloud around the first detection

        def __post_init__(self) -> None:
            require(self.n_particles >= 1, "n_particles", "an integer >= 1", self.n_particles)
            allowed = "one of " + ", ".join(RESAMPLERS)
            require(self.resampler in RESAMPLERS, "resampler", allowed, self.resampler)
            require(0.0 <= self.rho <= 1.0, "rho", "[0, 1]", self.rho)
            require(self.sigma > 0.0, "sigma", "a std > 0 m", self.sigma)
            turn = self.turn_rate_std
            require(turn >= 0.0, "turn_rate_std", "a std >= 0 rad/s", turn)
            boost = self.in_region_boost
            require(boost >= 1.0, "in_region_boost", "a factor >= 1", boost)
            require(0.0 <= self.miss_factor <= 1.0, "miss_factor", "[0, 1]", self.miss_factor)
            hz = self.miss_factor_hz
            require(math.isfinite(hz) and hz > 0, "miss_factor_hz", "a rate > 0 Hz", hz)
            require(self.init_spread >= 0.0, "init_spread", "a std >= 0 m", self.init_spread)
            for name in ("sigma", "turn_rate_std", "in_region_boost", "init_spread"):
                value = getattr(self, name)
                require(math.isfinite(value), name, "a finite number", value)

    def __init__(self, config: Config, context: Context, rng: np.random.Generator) -> None:
        super().__init__(config, context, rng)
        grid = context.grid
        self._blocked = grid.blocked.ravel()
        self._free_cells = np.flatnonzero(~self._blocked)
        if self._free_cells.size == 0:
            raise MapError(f"Map '{grid.name}' has no free cell for the particle filter to use.")
        # The miss factor per control tick, stated per second in the config (module docstring).
        self._miss_factor = config.miss_factor ** (context.control_dt * config.miss_factor_hz)
        n = config.n_particles
        self.particles = np.zeros((n, 3))
        self.weights = np.full(n, 1.0 / n)
        self._unit_speeds = np.empty(NOISE_BATCH * n)
        self._normals = np.empty(NOISE_BATCH * n)
        self._noise_used = self._unit_speeds.size  # none drawn yet
        self._ones = np.ones(n)  # the likelihood of no detection
        self._resampler = ThresholdResampler(RESAMPLERS[config.resampler](), config.rho)

    # ------------------------------------------------------------------ interface

    def reset_1v1(self, pursuer: Pose, detection: Detection | None, visible: Region) -> Belief:
        """Draw the initial particles: around the detection if any (N(z, init_spread) on
        free cells), else uniformly over the free cells inside ``visible`` (or over all
        free cells when none is visible); headings uniform, weights 1/N."""
        if detection is not None:
            if not self.context.grid.is_free(*detection.position):
                log.info(
                    "The first detection %s lies in a blocked cell or off the map; starting "
                    "the particles on the free cells around it.",
                    detection.position,
                )
            self.particles = self._around(detection.position)
        else:
            inside = self._free_cells[self._flat_mask(visible.mask)[self._free_cells]]
            self.particles = self._uniform(inside if inside.size else self._free_cells)
        n = self.config.n_particles
        self.weights = np.full(n, 1.0 / n)
        return self._belief(float(n), resampled=False)

    def update_1v1(
        self, dt: float, pursuer: Pose, detection: Detection | None, visible: Region
    ) -> Belief:
        """Predict ``dt`` s with the unicycle model, weigh by the detection (or its absence)
        and the pursuer's visibility region, resample when N_eff < rho * N.

        The belief's ``n_eff`` is N_eff of the normalised weights before any resampling
        (the value compared with rho * N), or 0 when the particle set was lost and redrawn.
        """
        return self._update(dt, detection, visible, reference=False)

    def update_reference(
        self, dt: float, pursuer: Pose, detection: Detection | None, visible: Region
    ) -> Belief:
        """:meth:`update_1v1` in plain numpy: the reference the tests hold the kernels to."""
        return self._update(dt, detection, visible, reference=True)

    def _update(
        self, dt: float, detection: Detection | None, visible: Region, reference: bool
    ) -> Belief:
        """:meth:`update_1v1`, or with ``reference`` :meth:`update_reference`."""
        cfg = self.config
        self._check_shape(visible.shape)  # before any draw
        weigh = self._weigh_reference if reference else self._weigh
        moved, weights, total, evidence, n_eff = weigh(dt, detection, visible)
        lost = detection is not None and evidence < math.exp(-0.5 * LOST_GATE**2)
        if lost or not (total > 0.0 and math.isfinite(total)):
            return self._reinitialise(detection, visible)
        resample = self._resampler.resample_reference if reference else self._resampler.resample
        drawn = resample(weights, self.rng, n_eff)
        resampled = drawn is not None
        if drawn is not None:
            # take() copies rows three times faster than fancy indexing.
            moved = np.take(moved, drawn, axis=0)
            weights = np.full(cfg.n_particles, 1.0 / cfg.n_particles)
        self.particles, self.weights = moved, weights
        return self._belief(n_eff, resampled, reference)

    # ------------------------------------------------------------------ models

    def _weigh(
        self, dt: float, detection: Detection | None, visible: Region
    ) -> tuple[np.ndarray, np.ndarray, float, float, float]:
        """Draw the motion and return the moved particles (N, 3), their weights (N,)
        normalised when their sum ``total`` is positive and finite, ``total``, the
        detection's evidence sum_i w_i L_i (0 without one) and N_eff (0 when not
        normalised), by the kernels."""
        cfg = self.config
        moved, cells = _move_and_locate(
            self.particles,
            *self._draw(),
            self.context.evader.v_max,
            cfg.turn_rate_std,
            dt,
            self.context.grid.kernel_frame,
            self.context.grid.blocked,
        )
        in_region = visible.holds(cells)  # V only where the particles are (module docstring)
        if detection is None:
            likelihood = self._ones
        else:
            zx, zy = detection.position
            likelihood = _likelihoods(moved, zx, zy, 2.0 * cfg.sigma**2)
        weights, total, evidence, n_eff = _weigh(
            self.weights,
            cells,
            in_region,
            likelihood,
            detection is not None,
            cfg.in_region_boost,
            self._miss_factor,
        )
        return moved, weights, total, evidence, n_eff

    def _weigh_reference(
        self, dt: float, detection: Detection | None, visible: Region
    ) -> tuple[np.ndarray, np.ndarray, float, float, float]:
        """Plain numpy :meth:`_weigh`."""
        cfg = self.config
        unit_speeds, normals = self._draw()
        moved = self._predict(
            dt, self.context.evader.v_max * unit_speeds, cfg.turn_rate_std * normals
        )
        flat, on_grid = self._cells(moved[:, 0], moved[:, 1])
        valid = on_grid & ~self._blocked[flat]
        in_region = on_grid & self._flat_mask(visible.mask)[flat]
        if detection is None:
            evidence = 0.0
            factor = np.where(in_region, self._miss_factor, 1.0)
        else:
            likelihood = self._likelihood(moved, detection.position) * valid
            evidence = float(np.dot(self.weights, likelihood))
            factor = likelihood * np.where(in_region, cfg.in_region_boost, 1.0)
        weights = self.weights * factor * valid
        total = float(weights.sum())
        if not (total > 0.0 and math.isfinite(total)):
            return moved, weights, total, evidence, 0.0
        weights /= total
        return moved, weights, total, evidence, effective_sample_size(weights)

    def _draw(self) -> tuple[np.ndarray, np.ndarray]:
        """The next update's motion draws (N,) each: U[0, 1) for the speeds (times v_max)
        and N(0, 1) for the turn rates (times turn_rate_std). They are drawn from the
        component's Generator NOISE_BATCH updates at a time: passing the Generator into
        numba costs about 8 us, the draws themselves 6 ns per particle."""
        n = self.config.n_particles
        if self._noise_used == self._unit_speeds.size:
            _fill_noise(self.rng, self._unit_speeds, self._normals)
            self._noise_used = 0
        drawn = slice(self._noise_used, self._noise_used + n)
        self._noise_used += n
        return self._unit_speeds[drawn], self._normals[drawn]

    def _predict(self, dt: float, speed: np.ndarray, turn: np.ndarray) -> np.ndarray:
        """The particles (N, 3) moved over dt seconds by the unicycle model with speeds
        (N,) (m/s) and turn rates (N,) (rad/s)."""
        p = self.particles
        heading = p[:, 2] + 0.5 * turn * dt
        return np.column_stack(
            (
                p[:, 0] + speed * dt * np.cos(heading),
                p[:, 1] + speed * dt * np.sin(heading),
                wrap_angles_reference(p[:, 2] + turn * dt),
            )
        )

    def _likelihood(self, particles: np.ndarray, position: tuple[float, float]) -> np.ndarray:
        """Gaussian likelihood (N,) of the detected map position (m) for each particle."""
        dx = particles[:, 0] - position[0]
        dy = particles[:, 1] - position[1]
        return np.exp(-(dx * dx + dy * dy) / (2.0 * self.config.sigma**2))

    # ------------------------------------------------------------------ sampling

    def _reinitialise(self, detection: Detection | None, visible: Region) -> Belief:
        """Redraw the lost particle set: around the detection, or uniformly over the free
        cells outside ``visible`` (all free cells when every one is visible). Said at DEBUG
        level: it happens many times in some games."""
        if detection is not None:
            log.debug(
                "Particle filter lost the track (no particle near the detection %s); "
                "redrawing the particles around it.",
                detection.position,
            )
            self.particles = self._around(detection.position)
        else:
            log.debug(
                "Particle filter weights vanished; redrawing the particles uniformly over "
                "the free cells outside the pursuer's view."
            )
            hidden = self._free_cells[~self._flat_mask(visible.mask)[self._free_cells]]
            self.particles = self._uniform(hidden if hidden.size else self._free_cells)
        n = self.config.n_particles
        self.weights = np.full(n, 1.0 / n)
        return self._belief(0.0, resampled=True)

    def _around(self, position: tuple[float, float]) -> np.ndarray:
        """N particles (N, 3) from N(position, init_spread^2) on free cells, headings
        uniform. Draws in blocked cells are redrawn a few times, then moved to the centre
        of the nearest free cell (the detection may itself lie in an obstacle)."""
        n, spread = self.config.n_particles, self.config.init_spread
        xy = self.rng.normal(position, spread, (n, 2))
        for _ in range(RESEED_TRIES):
            bad = ~self._valid(xy)
            if not bad.any():
                break
            xy[bad] = self.rng.normal(position, spread, (int(bad.sum()), 2))
        bad = ~self._valid(xy)
        if bad.any():
            xy[bad] = self._nearest_free(xy[bad])
        return np.column_stack((xy, self._headings(n)))

    def _uniform(self, cells: np.ndarray) -> np.ndarray:
        """N particles (N, 3) uniform over the given flat cell indices, headings uniform."""
        n, width = self.config.n_particles, self.context.grid.width
        rows, cols = np.divmod(cells[self.rng.integers(cells.size, size=n)], width)
        # cell_to_world maps (row, col) to the cell centre; a U(-0.5, 0.5) offset spreads
        # the particle uniformly over the cell.
        x, y = self.context.grid.cell_to_world(
            rows + self.rng.random(n) - 0.5, cols + self.rng.random(n) - 0.5
        )
        return np.column_stack((x, y, self._headings(n)))

    def _headings(self, n: int) -> np.ndarray:
        return wrap_angles(self.rng.uniform(-np.pi, np.pi, n))

    # ------------------------------------------------------------------ grid lookups

    def _cells(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Flat cell index (N,) of map-frame points (m), 0 where off the grid, and the bool
        (N,) mask of points on the grid."""
        grid = self.context.grid
        row, col = grid.world_to_cell(x, y)
        on_grid = (row >= 0) & (row < grid.height) & (col >= 0) & (col < grid.width)
        return np.where(on_grid, row * grid.width + col, 0), on_grid

    def _valid(self, xy: np.ndarray) -> np.ndarray:
        """True where a point (N, 2) (m) lies on a free cell of the grid."""
        flat, on_grid = self._cells(xy[:, 0], xy[:, 1])
        return on_grid & ~self._blocked[flat]

    def _check_shape(self, shape: tuple[int, ...]) -> None:
        """Raise ValueError unless a visibility mask of ``shape`` covers the grid."""
        grid = self.context.grid
        if shape != (grid.height, grid.width):
            raise ValueError(
                f"The visibility mask has shape {shape}; the grid's is {(grid.height, grid.width)}."
            )

    def _flat_mask(self, visible: np.ndarray) -> np.ndarray:
        """The visibility mask (H, W) as a flat bool array, checked against the grid."""
        self._check_shape(visible.shape)
        return visible.ravel()

    @cached_property
    def _nearest_free_cell(self) -> np.ndarray:
        """Flat index of the nearest free cell, per flat cell index (H * W,); built once,
        only when a draw needs it."""
        grid = self.context.grid
        rows, cols = distance_transform_edt(
            grid.blocked, return_distances=False, return_indices=True
        )
        return (rows * grid.width + cols).ravel()

    def _nearest_free(self, xy: np.ndarray) -> np.ndarray:
        """Centres (K, 2) (m) of the free cells nearest to points (K, 2) (m), on or off the grid."""
        grid = self.context.grid
        row, col = grid.world_to_cell(xy[:, 0], xy[:, 1])
        row = np.clip(row, 0, grid.height - 1)
        col = np.clip(col, 0, grid.width - 1)
        rows, cols = np.divmod(self._nearest_free_cell[row * grid.width + col], grid.width)
        return np.column_stack(grid.cell_to_world(rows, cols))

    # ------------------------------------------------------------------ output

    def _belief(self, n_eff: float, resampled: bool, reference: bool = False) -> Belief:
        """The belief: weighted mean (m) and covariance (m^2) of the particle positions.

        The particle and weight arrays are shared with the belief, so they are made
        read-only; every update builds new ones.
        """
        self.particles.setflags(write=False)
        self.weights.setflags(write=False)
        if reference:
            xy, w = self.particles[:, :2], self.weights
            mean = w @ xy
            offset = xy - mean
            covariance = (offset * w[:, None]).T @ offset
        else:
            mean, covariance = _moments(self.particles, self.weights)
        return Belief(
            mean=(float(mean[0]), float(mean[1])),
            covariance=covariance,
            particles=self.particles,
            weights=self.weights,
            n_eff=n_eff,
            resampled=resampled,
        )
