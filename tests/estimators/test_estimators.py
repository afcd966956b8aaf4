"""Tests for the estimators: particle filter (paper's SIS with N_eff and rho), Kalman, last seen."""

from __future__ import annotations

import logging
import math
from importlib.resources import files
from pathlib import Path

import numpy as np
import pytest

from pegame import registry
from pegame.api import Context
from pegame.errors import ConfigError
from pegame.estimators.kalman import KalmanEstimator
from pegame.estimators.last_seen import LastSeen
from pegame.estimators.particle_filter import ParticleFilter
from pegame.estimators.resampling import RESAMPLERS
from pegame.grid import FREE, OCCUPIED, OccupancyGrid
from pegame.types import Body, BoundingBox, Camera, Detection, Pose
from pegame.visibility import MaskRegion, VisibilityRegion

CONF = Path(str(files("pegame.conf"))) / "estimator"
DT = 0.1  # s, control period
PURSUER = Pose(0.5, 0.5, 0.0)  # the estimators here do not use the pursuer's pose
LOGGER = "pegame.estimators.particle_filter"


# --------------------------------------------------------------------------- helpers


def room(height=40, width=50, resolution=0.1):
    """A walled room (4 m x 5 m at 0.1 m) with an occupied block at x 3.0-3.5 m, y 1.0-3.0 m."""
    data = np.full((height, width), FREE, dtype=np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = OCCUPIED
    data[10:30, 30:35] = OCCUPIED
    return OccupancyGrid(data, resolution)


def context(grid, v_max=0.5):
    return Context(
        grid=grid,
        pursuer=Body(0.2, v_max, 1.8),
        evader=Body(0.25, v_max, 1.8),
        camera=Camera(),
        control_dt=DT,
        decision_dt=1.0,
    )


def build(cls, grid, seed=0, **params):
    """A plugin built through the registry's config path, as the game builds it."""
    config = registry.make_config("estimator", cls, params)
    return cls(config, context(grid), np.random.default_rng(seed))


def detection(x, y):
    box = BoundingBox(0.0, 0.0, 10.0, 10.0)
    return Detection(box=box, depth=1.0, position=(float(x), float(y)))


def disc(grid, center, radius):
    """The region of the cells whose centre lies within ``radius`` m of ``center``."""
    rows, cols = np.mgrid[0 : grid.height, 0 : grid.width]
    x, y = grid.cell_to_world(rows, cols)
    return MaskRegion((x - center[0]) ** 2 + (y - center[1]) ** 2 <= radius**2)


def cell_values(grid, particles, mask):
    """``mask`` (H, W) at each particle's cell (N,); False off the grid."""
    row, col = grid.world_to_cell(particles[:, 0], particles[:, 1])
    on_grid = grid.contains(row, col)
    return on_grid & mask[np.clip(row, 0, grid.height - 1), np.clip(col, 0, grid.width - 1)]


def on_free(grid, particles):
    return cell_values(grid, particles, grid.free)


# --------------------------------------------------------------------------- configs


@pytest.mark.parametrize(
    ("cls", "key", "value"),
    [
        (ParticleFilter, "n_particles", 0),
        (ParticleFilter, "rho", 1.5),
        (ParticleFilter, "sigma", -1.0),
        (ParticleFilter, "resampler", "foo"),
        (ParticleFilter, "miss_factor", 1.5),
        (ParticleFilter, "in_region_boost", 0.5),
        (KalmanEstimator, "measurement_std", 0.0),
        (KalmanEstimator, "accel_std", -1.0),
    ],
)
def test_bad_config_names_the_key(cls, key, value):
    with pytest.raises(ConfigError, match=f"estimator.{key}") as info:
        registry.make_config("estimator", cls, {key: value})
    if key == "resampler":
        assert all(name in str(info.value) for name in RESAMPLERS)


# --------------------------------------------------------------------------- particle filter


def test_weights_stay_normalised_over_a_long_run():
    grid = room()
    pf = build(ParticleFilter, grid, seed=1, n_particles=500)
    rng = np.random.default_rng(2)
    target = np.array([1.5, 2.0])
    belief = pf.reset_1v1(PURSUER, detection(*target), disc(grid, target, 1.5))
    resamples = 0
    for _ in range(300):
        # The target walks at up to 0.4 m/s inside the free part left of the block.
        target = np.clip(target + rng.uniform(-0.04, 0.04, 2), [0.3, 0.3], [2.7, 3.7])
        view = disc(grid, rng.uniform([0.5, 0.5], [4.5, 3.5]), 1.2)
        in_region = bool(cell_values(grid, target[None, :], view.mask)[0])
        found = detection(*(target + rng.normal(0.0, 0.1, 2))) if in_region else None
        belief = pf.update_1v1(DT, PURSUER, found, view)
        w = belief.weights
        assert np.all(np.isfinite(w)) and np.all(w >= 0)
        assert w.sum() == pytest.approx(1.0, abs=1e-9)
        assert 1.0 <= belief.n_eff <= 500 + 1e-9
        assert np.all(np.isfinite(belief.particles)) and np.all(np.isfinite(belief.covariance))
        assert np.all(w[~on_free(grid, belief.particles)] == 0)
        resamples += belief.resampled
    assert 0 < resamples < 300


def test_localises_a_stationary_target():
    grid = room()
    target = np.array([2.0, 2.5])
    view = disc(grid, target, 1.5)
    rng = np.random.default_rng(3)
    pf = build(ParticleFilter, grid, seed=4)
    pf.reset_1v1(PURSUER, detection(*(target + rng.normal(0.0, 0.1, 2))), view)
    for _ in range(8):
        belief = pf.update_1v1(DT, PURSUER, detection(*(target + rng.normal(0.0, 0.1, 2))), view)
    assert math.dist(belief.mean, target) < 0.3


def test_negative_information_moves_mass_out_of_the_region():
    grid = room()
    pf = build(ParticleFilter, grid, seed=5, rho=0.0, init_spread=0.5)
    start = pf.reset_1v1(PURSUER, detection(1.5, 2.0), disc(grid, (1.5, 2.0), 2.0))
    view = disc(grid, (2.0, 2.0), 0.5)  # covers the cloud's right part
    before = start.weights[cell_values(grid, start.particles, view.mask)].sum()
    after = pf.update_1v1(0.0, PURSUER, None, view)  # dt 0: only the measurement acts
    inside = cell_values(grid, after.particles, view.mask)
    mass = after.weights[inside].sum()
    assert 0.1 < before < 0.9
    expected = 0.05 * before / (0.05 * before + (1.0 - before))  # miss_factor 0.05
    assert mass == pytest.approx(expected, rel=1e-9)
    assert after.mean[0] < start.mean[0]  # the belief moves away from the region


def reference_weights(grid, cfg, particles, prior, found, view):
    """The measurement update written particle by particle: the model in plain Python."""
    weights = []
    for (x, y, _), w in zip(particles, prior):
        row, col = grid.world_to_cell(x, y)
        if not grid.contains(row, col) or grid.blocked[row, col]:
            weights.append(0.0)
        elif found is None:
            weights.append(w * (cfg.miss_factor if view.mask[row, col] else 1.0))
        else:
            zx, zy = found.position
            likelihood = math.exp(-((x - zx) ** 2 + (y - zy) ** 2) / (2 * cfg.sigma**2))
            weights.append(w * likelihood * (cfg.in_region_boost if view.mask[row, col] else 1.0))
    return np.array(weights) / sum(weights)


def test_weight_update_matches_the_per_particle_reference():
    grid = room()
    pf = build(ParticleFilter, grid, seed=25, n_particles=300, rho=0.0, init_spread=0.6)
    belief = pf.reset_1v1(PURSUER, detection(2.6, 2.0), disc(grid, (2.6, 2.0), 1.0))
    rng = np.random.default_rng(26)
    for step in range(12):
        view = disc(grid, rng.uniform([1.5, 1.0], [3.0, 3.0]), 0.8)
        found = detection(*rng.normal([2.6, 2.0], 0.1)) if step % 2 else None
        prior = belief.weights
        belief = pf.update_1v1(DT, PURSUER, found, view)
        expected = reference_weights(grid, pf.config, belief.particles, prior, found, view)
        np.testing.assert_allclose(belief.weights, expected, rtol=1e-9, atol=1e-15)


def test_resampling_happens_exactly_below_rho_times_n():
    grid = room()
    n = 400

    def first_update(rho):
        pf = build(ParticleFilter, grid, seed=6, n_particles=n, rho=rho, init_spread=0.5)
        pf.reset_1v1(PURSUER, detection(1.5, 2.0), disc(grid, (1.5, 2.0), 1.0))
        return pf.update_1v1(DT, PURSUER, detection(1.7, 2.1), disc(grid, (1.5, 2.0), 1.0))

    # rho = 0 never resamples, so its weights are the pre-resampling weights of every rho:
    # resampling is the update's last step and the only one rho changes.
    kept = first_update(0.0)
    n_eff = 1.0 / np.sum(kept.weights**2)
    assert not kept.resampled and kept.n_eff == pytest.approx(n_eff, rel=1e-12)
    assert 1.0 < n_eff < n
    above = first_update(min(1.0, float(n_eff / n * (1 + 1e-9))))
    below = first_update(float(n_eff / n * (1 - 1e-9)))
    assert above.resampled and not below.resampled
    assert above.n_eff == pytest.approx(n_eff) and below.n_eff == pytest.approx(n_eff)
    assert np.all(above.weights == 1.0 / n)
    np.testing.assert_array_equal(below.weights, kept.weights)


@pytest.mark.parametrize("rho", [0.0, 0.8, 1.0])
def test_resampled_flag_follows_the_threshold_over_a_run(rho):
    grid = room()
    n = 300
    pf = build(ParticleFilter, grid, seed=7, n_particles=n, rho=rho)
    rng = np.random.default_rng(8)
    pf.reset_1v1(PURSUER, detection(1.5, 2.0), disc(grid, (1.5, 2.0), 1.0))
    flags = []
    for step in range(60):
        found = detection(*rng.normal([1.5, 2.0], 0.1)) if step % 3 else None
        belief = pf.update_1v1(DT, PURSUER, found, disc(grid, (1.5 + 0.02 * step, 2.0), 1.0))
        assert belief.resampled == (belief.n_eff < rho * n)
        flags.append(belief.resampled)
    if rho == 0.0:
        assert not any(flags)
    if rho == 1.0:  # a detection always leaves the weights unequal, so N_eff < N
        assert all(flag for step, flag in enumerate(flags) if step % 3)


def run_side_by_side(grid, steps, seed, **params):
    """Feed one random run of views and detections (some far off, so the track is lost)
    to a filter's update and to a twin's update_reference; yield both beliefs per step.
    After each step the twin takes the filter's particles and weights, so every step
    compares the two paths from the same state.

    Every other view is a camera's visibility region at a random pose, which the fast
    path asks only about its particles' block of cells and the reference as a whole."""
    fast = build(ParticleFilter, grid, seed=seed, **params)
    slow = build(ParticleFilter, grid, seed=seed, **params)
    rng = np.random.default_rng(seed + 1)
    x0, x1, y0, y1 = grid.extent
    start = detection(x0 + 1.5, y0 + 2.0)
    view = disc(grid, start.position, 1.5)
    yield fast.reset_1v1(PURSUER, start, view), slow.reset_1v1(PURSUER, start, view)
    for step in range(steps):
        view = disc(grid, rng.uniform([x0, y0], [x1, y1]), rng.uniform(0.5, 2.0))
        fast_view = slow_view = view
        if step % 2:
            camera = Pose(*rng.uniform([x0, y0, -math.pi], [x1, y1, math.pi]))
            fast_view, slow_view = (VisibilityRegion(grid, camera, Camera()) for _ in range(2))
        found = None
        if step % 3:
            far = step % 29 == 0
            found = detection(
                *rng.uniform([x0, y0], [x1, y1]) if far else rng.normal(start.position, 0.3)
            )
        yield (
            fast.update_1v1(DT, PURSUER, found, fast_view),
            slow.update_reference(DT, PURSUER, found, slow_view),
        )
        slow.particles, slow.weights = fast.particles, fast.weights
    assert fast.rng.bit_generator.state == slow.rng.bit_generator.state


def assert_same_belief(fast, slow):
    """The fast path's belief equals the reference's to round-off (module docstring)."""
    close = {"rtol": 1e-12, "atol": 1e-12}
    np.testing.assert_allclose(fast.particles[:, :2], slow.particles[:, :2], **close)
    turn = np.angle(np.exp(1j * (fast.particles[:, 2] - slow.particles[:, 2])))
    np.testing.assert_allclose(turn, 0.0, **close)  # headings may wrap to -pi and pi
    np.testing.assert_allclose(fast.weights, slow.weights, **close)
    np.testing.assert_allclose(fast.mean, slow.mean, **close)
    np.testing.assert_allclose(fast.covariance, slow.covariance, **close)
    np.testing.assert_allclose(fast.n_eff, slow.n_eff, **close)
    assert fast.resampled == slow.resampled


@pytest.mark.parametrize("scheme", RESAMPLERS)
@pytest.mark.parametrize("origin", [(0.0, 0.0, 0.0), (-1.3, 0.7, 0.6)])
def test_update_kernels_match_the_numpy_reference(scheme, origin):
    walls = room()
    grid = OccupancyGrid(walls.data, walls.resolution, origin)
    resampled = lost = 0
    for fast, slow in run_side_by_side(grid, 150, seed=27, n_particles=500, resampler=scheme):
        assert_same_belief(fast, slow)
        resampled += fast.resampled
        lost += fast.n_eff == 0.0
    assert 10 < resampled < 150 and lost > 0


def test_update_kernels_match_the_reference_when_the_weights_vanish():
    grid = room()
    beliefs = list(run_side_by_side(grid, 60, seed=28, n_particles=300, miss_factor=0.0))
    assert any(fast.n_eff == 0.0 for fast, _ in beliefs)
    for fast, slow in beliefs:
        assert_same_belief(fast, slow)


def test_motion_kernel_matches_the_reference_beyond_the_polynomial_range():
    # Headings past pegame.numerics's range take libm's sine and cosine in the kernel.
    grid = room()
    fast = build(ParticleFilter, grid, seed=5, n_particles=400)
    slow = build(ParticleFilter, grid, seed=5, n_particles=400)
    start = detection(2.0, 2.0)
    view = disc(grid, start.position, 1.0)
    fast.reset_1v1(PURSUER, start, view)
    slow.reset_1v1(PURSUER, start, view)
    headings = np.where(np.arange(400) % 2, 1e7, -3e9) + fast.particles[:, 2]
    fast.particles = slow.particles = np.column_stack([fast.particles[:, :2], headings])
    assert_same_belief(
        fast.update_1v1(DT, PURSUER, start, view), slow.update_reference(DT, PURSUER, start, view)
    )


def test_vanished_weights_reinitialise_outside_the_view(caplog):
    grid = room()
    pf = build(ParticleFilter, grid, seed=15, miss_factor=0.0)
    pf.reset_1v1(PURSUER, detection(1.5, 2.0), disc(grid, (1.5, 2.0), 1.5))
    view = disc(grid, (1.5, 2.0), 1.5)  # holds every particle, and the evader is not detected
    with caplog.at_level(logging.DEBUG, logger=LOGGER):
        belief = pf.update_1v1(DT, PURSUER, None, view)
    assert [r.levelname for r in caplog.records if "vanished" in r.message] == ["DEBUG"]
    assert belief.resampled and belief.n_eff == 0.0
    assert np.all(np.isfinite(belief.particles)) and np.all(np.isfinite(belief.mean))
    assert np.all(belief.weights == 1.0 / 2000)
    assert np.all(on_free(grid, belief.particles))
    assert not np.any(cell_values(grid, belief.particles, view.mask))
    # A region over the whole grid: no free cell is left outside it.
    everywhere = MaskRegion(np.ones((grid.height, grid.width), dtype=bool))
    pf.reset_1v1(PURSUER, detection(1.5, 2.0), everywhere)
    belief = pf.update_1v1(DT, PURSUER, None, everywhere)
    assert np.all(on_free(grid, belief.particles)) and np.all(np.isfinite(belief.weights))


def test_a_detection_far_from_every_particle_redraws_around_it(caplog):
    grid = room()
    pf = build(ParticleFilter, grid, seed=16)
    pf.reset_1v1(PURSUER, detection(1.0, 1.0), disc(grid, (1.0, 1.0), 1.0))
    with caplog.at_level(logging.DEBUG, logger=LOGGER):
        belief = pf.update_1v1(DT, PURSUER, detection(4.2, 3.2), disc(grid, (4.2, 3.2), 1.0))
    assert [r.levelname for r in caplog.records if "lost the track" in r.message] == ["DEBUG"]
    assert math.dist(belief.mean, (4.2, 3.2)) < 0.3


def test_no_weight_remains_on_blocked_cells():
    grid = room()
    pf = build(ParticleFilter, grid, seed=17, init_spread=1.0, rho=0.5)
    near_wall = (2.9, 2.0)  # 0.1 m left of the block
    view = disc(grid, near_wall, 1.0)
    belief = pf.reset_1v1(PURSUER, detection(*near_wall), view)
    assert np.all(on_free(grid, belief.particles))
    rng = np.random.default_rng(18)
    for step in range(40):
        found = detection(*rng.normal(near_wall, 0.1)) if step % 2 else None
        belief = pf.update_1v1(DT, PURSUER, found, view)
        assert np.all(belief.weights[~on_free(grid, belief.particles)] == 0)
        if belief.resampled:
            assert np.all(on_free(grid, belief.particles))


def test_detection_inside_an_obstacle_starts_on_free_cells(caplog):
    grid = room()
    pf = build(ParticleFilter, grid, seed=19)
    inside = (3.25, 2.0)  # the middle of the block
    with caplog.at_level(logging.INFO, logger=LOGGER):
        belief = pf.reset_1v1(PURSUER, detection(*inside), disc(grid, inside, 1.0))
    assert "blocked cell" in caplog.text
    assert np.all(on_free(grid, belief.particles))
    assert math.dist(belief.mean, inside) < 1.0
    off_map = pf.reset_1v1(PURSUER, detection(-3.0, 2.0), disc(grid, (0.5, 2.0), 1.0))
    assert np.all(on_free(grid, off_map.particles))


def test_reset_without_detection_covers_the_visible_free_cells():
    grid = room()
    pf = build(ParticleFilter, grid, seed=20)
    view = disc(grid, (3.0, 2.0), 1.0)  # straddles the block
    belief = pf.reset_1v1(PURSUER, None, view)
    assert np.all(cell_values(grid, belief.particles, view.mask & grid.free))
    nothing = MaskRegion(np.zeros((grid.height, grid.width), dtype=bool))
    belief = pf.reset_1v1(PURSUER, None, nothing)
    assert np.all(on_free(grid, belief.particles))
    assert np.ptp(belief.particles[:, 0]) > 3.5  # spread over the whole room


def test_belief_layout_and_determinism():
    grid = room()
    runs = []
    for seed in (21, 21, 22):
        pf = build(ParticleFilter, grid, seed=seed, n_particles=100)
        pf.reset_1v1(PURSUER, detection(1.5, 2.0), disc(grid, (1.5, 2.0), 1.0))
        runs.append(pf.update_1v1(DT, PURSUER, detection(1.6, 2.0), disc(grid, (1.5, 2.0), 1.0)))
    belief = runs[0]
    assert isinstance(belief.mean, tuple) and all(type(v) is float for v in belief.mean)
    assert belief.covariance.shape == (2, 2)
    np.testing.assert_allclose(belief.covariance, belief.covariance.T)
    assert np.all(np.linalg.eigvalsh(belief.covariance) >= 0)
    assert belief.particles.shape == (100, 3) and belief.weights.shape == (100,)
    theta = belief.particles[:, 2]
    assert np.all((theta > -math.pi) & (theta <= math.pi))
    np.testing.assert_array_equal(runs[0].particles, runs[1].particles)
    assert not np.array_equal(runs[0].particles, runs[2].particles)


def test_visibility_mask_of_the_wrong_shape_is_rejected():
    grid = room()
    pf = build(ParticleFilter, grid, n_particles=10)
    with pytest.raises(ValueError, match="shape"):
        pf.reset_1v1(PURSUER, None, MaskRegion(np.ones((3, 3), dtype=bool)))


# --------------------------------------------------------------------------- kalman


def straight_track(ticks, start=(1.0, 1.0), velocity=(0.3, 0.2)):
    """True positions (ticks, 2) of a constant-velocity target sampled every DT s."""
    return np.asarray(start) + np.outer(np.arange(ticks) * DT, velocity)


def test_kalman_converges_on_a_constant_velocity_track():
    grid = room()
    kf = build(KalmanEstimator, grid)
    truth = straight_track(40)
    noise = np.random.default_rng(23).normal(0.0, 0.1, truth.shape)
    belief = kf.reset((PURSUER,), (detection(*(truth[0] + noise[0])),), None)
    errors = []
    for k in range(1, 40):
        belief = kf.update(DT, (PURSUER,), (detection(*(truth[k] + noise[k])),), None)
        errors.append(math.dist(belief.mean, truth[k]))
    assert max(errors[29:]) < 0.2
    assert belief.covariance.shape == (2, 2)


def test_kalman_coasts_through_a_gap_of_misses():
    grid = room()
    kf = build(KalmanEstimator, grid)
    truth = straight_track(45)
    noise = np.random.default_rng(24).normal(0.0, 0.1, truth.shape)
    kf.reset((PURSUER,), (detection(*(truth[0] + noise[0])),), None)
    for k in range(1, 35):
        tracked = kf.update(DT, (PURSUER,), (detection(*(truth[k] + noise[k])),), None)
    for _ in range(35, 45):
        belief = kf.update(DT, (PURSUER,), (None,), None)
    assert math.dist(belief.mean, truth[44]) < 0.2
    assert math.dist(belief.mean, tracked.mean) > 0.3  # it moved along the track
    assert np.trace(belief.covariance) > np.trace(tracked.covariance)


def test_kalman_waits_for_a_detection_and_clamps_the_speed():
    grid = room()
    kf = build(KalmanEstimator, grid)
    assert kf.reset((PURSUER,), (None,), None).mean is None
    assert kf.update(DT, (PURSUER,), (None,), None).mean is None
    assert kf.update(DT, (PURSUER,), (detection(1.0, 1.0),), None).mean == (1.0, 1.0)
    for k in range(1, 20):  # detections moving at 3 m/s, six times the evader's v_max
        kf.update(DT, (PURSUER,), (detection(1.0 + 0.3 * k, 1.0),), None)
        assert math.hypot(*kf._kf.x[2:4]) <= 0.5 + 1e-12


# --------------------------------------------------------------------------- last seen


def test_last_seen_holds_the_last_detection():
    grid = room()
    estimator = build(LastSeen, grid)
    assert estimator.reset((PURSUER,), (None,), None).mean is None
    for position in straight_track(10):
        belief = estimator.update(DT, (PURSUER,), (detection(*position),), None)
        assert belief.mean == tuple(position)
    for _ in range(5):
        assert estimator.update(DT, (PURSUER,), (None,), None).mean == tuple(position)
