"""Tests for the perception model (pegame.detectors.perception): each part off changes
nothing, and each part on does what its config says, per second at any control rate."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pegame.api import Context
from pegame.detectors.oracle import OracleDetector
from pegame.detectors.perception import Perception, PerceptionConfig
from pegame.errors import ConfigError
from pegame.grid import FREE, OccupancyGrid
from pegame.registry import make_config
from pegame.types import Body, BoundingBox, Camera, Detection, Pose

CAMERA = Camera()  # pi/3 FOV, 0.3-5 m, 640 x 480 px
EVADER = Body(radius=0.25, v_max=0.5, w_max=1.8)
ORIGIN = Pose(0.0, 0.0, 0.0)


def context(hz: float = 10.0) -> Context:
    grid = OccupancyGrid(np.full((10, 10), FREE, dtype=np.int8), 0.1)
    return Context(grid, Body(0.2, 0.5, 1.8), EVADER, CAMERA, 1.0 / hz, 1.0)


def perception(hz: float = 10.0, seed: int = 0, **params) -> Perception:
    config = make_config("detector", OracleDetector, params)
    return Perception(config, context(hz), np.random.default_rng(seed))


def seen_at(x: float, y: float = 0.0, depth: float | None = None) -> Detection:
    """A detection of an evader at (x, y) m seen from ORIGIN."""
    box = BoundingBox(CAMERA.column_of(math.atan2(y, x)) - 10.0, 200.0, 20.0, 80.0)
    return Detection(box=box, depth=x if depth is None else depth, position=(x, y))


def run(model: Perception, ticks: int, capture, hz: float = 10.0) -> list:
    """The detections delivered over ``ticks`` control ticks; ``capture(k)`` is the raw
    detection of the frame captured at tick k."""
    return [model.deliver(k / hz, ORIGIN, lambda k=k: capture(k)) for k in range(ticks)]


def test_with_every_part_off_each_tick_delivers_its_own_capture_and_draws_nothing():
    rng = np.random.default_rng(3)
    model = Perception(PerceptionConfig(), context(), rng)
    frames = [seen_at(2.0 + 0.01 * k) if k % 3 else None for k in range(50)]
    assert run(model, 50, lambda k: frames[k]) == frames
    assert rng.random() == np.random.default_rng(3).random()  # spawning leaves the stream
    assert all(model.degrade(frame, ORIGIN) is frame for frame in frames)


def test_a_rate_that_does_not_divide_the_control_rate_captures_on_schedule_without_drift():
    captured = []
    run(perception(rate=3.0), 3001, lambda k: captured.append(k))
    # Frames are due at n / 3 s; each is captured at the first tick at or after it.
    assert captured == [math.ceil(n / 3 * 10 - 1e-6) for n in range(len(captured))]
    assert len(captured) == 901


@pytest.mark.parametrize(("rate", "every"), [(2.0, 5), (1.0, 10), (5.0, 2), (40.0, 1)])
def test_a_rate_captures_every_one_over_rate_seconds_and_holds_the_result(rate, every):
    captured = []
    model = perception(rate=rate)

    def capture(k):
        captured.append(k)
        return seen_at(1.0 + k)

    delivered = run(model, 40, capture)
    assert captured == list(range(0, 40, every))
    assert [d.position[0] - 1.0 for d in delivered] == [k - k % every for k in range(40)]


@pytest.mark.parametrize(
    ("hz", "latency", "ticks"), [(10.0, 0.3, 3), (20.0, 0.3, 6), (5.0, 1.0, 5)]
)
def test_latency_delivers_each_result_that_many_ticks_later(hz, latency, ticks):
    model = perception(hz, latency=latency)
    delivered = run(model, 30, lambda k: seen_at(1.0 + k), hz)
    assert delivered[:ticks] == [None] * ticks
    assert [d.position[0] - 1.0 for d in delivered[ticks:]] == list(range(30 - ticks))


def test_rate_and_latency_together_deliver_old_frames_at_the_rate():
    delivered = run(perception(rate=1.0, latency=0.5), 30, lambda k: seen_at(1.0 + k))
    frames = [None if d is None else d.position[0] - 1.0 for d in delivered]
    assert frames == [None] * 5 + [0.0] * 10 + [10.0] * 10 + [20.0] * 5


def bursts(missed: np.ndarray) -> np.ndarray:
    """Lengths (frames) of the runs of True in ``missed``, the last unfinished one dropped."""
    edges = np.diff(np.concatenate([[0], missed.astype(int), [0]]))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    lengths = ends - starts
    return lengths[:-1] if missed[-1] else lengths


@pytest.mark.slow
@pytest.mark.parametrize("hz", [5.0, 10.0, 20.0])
def test_bursty_misses_have_the_configured_fraction_and_burst_length_at_any_rate(hz):
    fraction, length, seconds = 0.3, 1.5, 20000.0
    model = perception(hz, seed=int(hz), burst_miss_fraction=fraction, burst_length=length)
    n = int(seconds * hz)
    missed = np.array([d is None for d in run(model, n, lambda k: seen_at(2.0), hz)])
    # The chain's lag-one correlation is 1 - P(G->B) - P(B->G): the fraction's variance is
    # the binomial one times (1 + c) / (1 - c) (the variance of a two-state Markov mean).
    p_bg = (1.0 / hz) / length
    p_gb = p_bg * fraction / (1 - fraction)
    c = 1 - p_gb - p_bg
    std = math.sqrt(fraction * (1 - fraction) / n * (1 + c) / (1 - c))
    assert abs(missed.mean() - fraction) < 4 * std
    runs = bursts(missed) / hz  # s; a burst's frames are geometric with mean 1 / P(B->G)
    std = math.sqrt((1 - p_bg) / p_bg**2 / runs.size) / hz
    assert abs(runs.mean() - length) < 4 * std


def test_independent_misses_are_binomial():
    n, p = 20000, 0.2
    model = perception(miss_probability=p)
    delivered = [model.degrade(seen_at(2.0), ORIGIN) for _ in range(n)]
    missed = sum(d is None for d in delivered)
    assert abs(missed / n - p) < 4 * math.sqrt(p * (1 - p) / n)


def test_the_range_miss_grows_linearly_from_its_start_to_the_detection_range():
    model = perception(miss_range_start=2.0, detection_range=4.0, miss_at_range=0.8)
    chances = [model.miss_chance(r) for r in (1.0, 2.0, 3.0, 3.5, 4.0)]
    assert chances == pytest.approx([0.0, 0.0, 0.4, 0.6, 0.8])
    n = 20000
    missed = sum(model.degrade(seen_at(3.0), ORIGIN) is None for _ in range(n))
    assert abs(missed / n - 0.4) < 4 * math.sqrt(0.24 / n)
    assert model.degrade(seen_at(4.2), ORIGIN) is None  # beyond the detection range


def test_the_occlusion_miss_grows_with_the_hidden_fraction_and_combines_with_range():
    model = perception(occlusion_miss=0.5, miss_range_start=2.0, detection_range=4.0)
    assert model.miss_chance(1.0, hidden=0.4) == pytest.approx(0.2)
    assert model.miss_chance(3.0, hidden=0.4) == pytest.approx(1 - 0.5 * 0.8)


def test_depth_noise_grows_with_the_square_of_the_range():
    a, b, n = 0.01, 0.004, 20000
    model = perception(range_noise=a, range_noise_growth=b)
    for r in (1.0, 4.0):
        depths = np.array([model.degrade(seen_at(r), ORIGIN).depth for _ in range(n)])
        expected = a + b * r**2
        assert np.mean(depths) == pytest.approx(r, abs=4 * expected / math.sqrt(n))
        # The sample std of n normals has a relative std of about 1 / sqrt(2 n).
        assert np.std(depths) == pytest.approx(expected, rel=4 / math.sqrt(2 * n))


def test_bearing_noise_turns_the_position_about_the_camera_and_shifts_the_box():
    std, n = 0.05, 20000
    model = perception(bearing_noise=std)
    truth = seen_at(3.0, 0.5)
    seen = [model.degrade(truth, ORIGIN) for _ in range(n)]
    errors = np.array(
        [math.atan2(s.position[1], s.position[0]) - math.atan2(0.5, 3.0) for s in seen]
    )
    assert np.std(errors) == pytest.approx(std, rel=4 / math.sqrt(2 * n))
    assert all(math.hypot(*s.position) == pytest.approx(math.hypot(3.0, 0.5)) for s in seen[:50])
    columns = np.array([s.box.center_x for s in seen[:50]])
    bearings = np.arctan2(0.5, 3.0) + errors[:50]
    assert columns == pytest.approx([CAMERA.column_of(b) for b in bearings])


@pytest.mark.parametrize("hz", [5.0, 10.0, 20.0])
def test_false_positives_arrive_at_their_rate_per_second_inside_the_view(hz):
    rate, seconds = 0.5, 4000.0
    model = perception(hz, seed=int(hz), false_positive_rate=rate, detection_range=4.0)
    n = int(seconds * hz)
    fakes = [d for d in run(model, n, lambda k: None, hz) if d is not None]
    # A frame holds one when at least one arrived in its 1/hz s: a binomial count of frames.
    p = -math.expm1(-rate / hz)
    assert abs(len(fakes) - n * p) < 4 * math.sqrt(n * p * (1 - p))
    assert len(fakes) / seconds == pytest.approx(rate, rel=0.1)  # about the Poisson rate
    ranges = np.array([math.hypot(*f.position) for f in fakes])
    bearings = np.array([math.atan2(f.position[1], f.position[0]) for f in fakes])
    assert ranges.min() >= CAMERA.near and ranges.max() <= 4.0
    assert np.abs(bearings).max() <= CAMERA.fov / 2
    # Uniform over the wedge's area: P(r < R/2) = (R^2/4 - near^2) / (R^2 - near^2).
    inner = (4.0 - CAMERA.near**2) / (16.0 - CAMERA.near**2)
    assert abs(np.mean(ranges < 2.0) - inner) < 4 * math.sqrt(inner * (1 - inner) / len(fakes))
    assert all(0 < f.box.w and 0 < f.box.h <= CAMERA.image_height for f in fakes)


def test_a_detected_evader_is_reported_over_a_false_positive():
    model = perception(false_positive_rate=1000.0)
    truth = seen_at(2.0)
    assert all(d is truth for d in run(model, 50, lambda k: truth))


@pytest.mark.parametrize(
    ("params", "key"),
    [
        ({"rate": 0.0}, "rate"),
        ({"rate": -1.0}, "rate"),
        ({"latency": -0.1}, "latency"),
        ({"detection_range": 0.0}, "detection_range"),
        ({"detection_range": 0.2}, "detection_range"),  # not past camera.near
        ({"miss_probability": 1.5}, "miss_probability"),
        ({"burst_miss_fraction": 1.0}, "burst_miss_fraction"),
        ({"burst_length": 0.0}, "burst_length"),
        ({"burst_miss_fraction": 0.3, "burst_length": 0.05}, "burst_length"),  # < a frame
        ({"burst_miss_fraction": 0.3, "burst_length": 0.5, "rate": 1.0}, "burst_length"),
        ({"miss_range_start": -1.0}, "miss_range_start"),
        ({"miss_range_start": 5.0}, "miss_range_start"),  # not below the detection range
        ({"miss_at_range": 2.0}, "miss_at_range"),
        ({"occlusion_miss": -0.5}, "occlusion_miss"),
        ({"range_noise": -0.1}, "range_noise"),
        ({"range_noise_growth": math.inf}, "range_noise_growth"),
        ({"bearing_noise": -0.1}, "bearing_noise"),
        ({"false_positive_rate": -1.0}, "false_positive_rate"),
    ],
)
def test_bad_values_name_their_detector_key(params, key):
    with pytest.raises(ConfigError, match=f"detector.{key}"):
        perception(**params)


# ------------------------------------------------- the particle filter's miss factor per second


def pf_mass_in_view_after_a_second_of_misses(hz: float, **params) -> tuple[float, float]:
    """(mass inside a view before, after one second of misses at ``hz``) for a particle
    filter whose measurement alone acts (updates of dt 0, no resampling)."""
    from pegame.estimators.particle_filter import ParticleFilter
    from pegame.visibility import MaskRegion

    grid = OccupancyGrid(np.full((40, 50), FREE, dtype=np.int8), 0.1)
    ctx = Context(grid, Body(0.2, 0.5, 1.8), EVADER, CAMERA, 1.0 / hz, 1.0)
    config = make_config("estimator", ParticleFilter, {"rho": 0.0, "init_spread": 0.5, **params})
    pf = ParticleFilter(config, ctx, np.random.default_rng(5))
    everywhere, right = np.ones((40, 50), bool), np.zeros((40, 50), bool)
    right[:, 20:] = True  # x >= 2 m
    belief = pf.reset_1v1(ORIGIN, seen_at(2.0, 2.0), MaskRegion(everywhere))
    inside = belief.particles[:, 0] >= 2.0
    before = belief.weights[inside].sum()
    for _ in range(round(hz)):
        belief = pf.update_1v1(0.0, ORIGIN, None, MaskRegion(right))
    return before, belief.weights[belief.particles[:, 0] >= 2.0].sum()


@pytest.mark.parametrize("hz", [5.0, 10.0, 20.0])
def test_the_particle_filter_miss_factor_means_the_same_per_second_at_any_rate(hz):
    factor = 0.05  # per 1/10 s by default: 0.05 ** 10 per second
    before, after = pf_mass_in_view_after_a_second_of_misses(hz, miss_factor=factor)
    per_second = factor**10
    assert 0.1 < before < 0.9
    assert after == pytest.approx(
        per_second * before / (per_second * before + 1 - before), rel=1e-6
    )
    # Stated per second instead: one factor of 0.05 over the whole second.
    before, after = pf_mass_in_view_after_a_second_of_misses(
        hz, miss_factor=factor, miss_factor_hz=1.0
    )
    assert after == pytest.approx(factor * before / (factor * before + 1 - before), rel=1e-6)


def test_the_particle_filter_miss_factor_at_10_hz_is_the_configured_factor_per_tick():
    from pegame.estimators.particle_filter import ParticleFilter

    config = make_config("estimator", ParticleFilter, {"miss_factor": 0.05})
    assert ParticleFilter(config, context(10.0), np.random.default_rng(0))._miss_factor == 0.05
    with pytest.raises(ConfigError, match="estimator.miss_factor_hz"):
        make_config("estimator", ParticleFilter, {"miss_factor_hz": 0.0})


# ------------------------------------------------------------------------- in a game

PAPER_LIKE = [
    "detector.rate=1.0",
    "detector.latency=0.5",
    "detector.burst_miss_fraction=0.2",
    "detector.burst_length=2.0",
    "detector.miss_range_start=3.0",
    "detector.range_noise=0.01",
    "detector.range_noise_growth=0.002",
    "detector.bearing_noise=0.02",
    "detector.false_positive_rate=0.1",
    "detector.occlusion_miss=0.5",
]


def play(overrides: list[str], seed: int = 0) -> dict:
    from pegame.config import compose
    from pegame.game import Game

    base = ["env=enclosed", "game.t_max=10", "recorder=none", f"game.seed={seed}"]
    return Game(compose([*base, *overrides])).play("unused").result


@pytest.mark.slow
def test_a_game_with_every_part_on_plays_the_same_for_the_same_seed_and_differs_from_the_oracle():
    slow = play(PAPER_LIKE)
    assert slow == play(PAPER_LIKE)
    assert slow != play([])


@pytest.mark.parametrize(
    ("overrides", "key"),
    [
        (["detector.burst_miss_fraction=0.3", "detector.burst_length=0.05"], "burst_length"),
        (["detector.detection_range=0.2"], "detection_range"),
        (["detector.miss_range_start=6.0"], "miss_range_start"),
    ],
)
def test_the_scenario_checks_what_needs_the_camera_and_the_control_rate_before_any_game(
    overrides, key
):
    from pegame.config import compose
    from pegame.game import Scenario

    with pytest.raises(ConfigError, match=f"detector.{key}"):
        Scenario(compose(["env=enclosed", *overrides]))


def _pipeline_reference(rate, latency, period, times, capture):
    """The pipeline's rate and latency in plain Python (a deque, the model before its
    kernels): the result held at each of ``times``."""
    from collections import deque

    first, captures, pending, held, out = None, 0, deque(), None, []
    for time in times:
        first = time if first is None else first
        if rate is None or time >= first + captures * period - 1e-9:
            pending.append((time + latency, capture(time)))
            while rate is not None and first + captures * period <= time + 1e-9:
                captures += 1
        while pending and pending[0][0] <= time + 1e-9:
            held = pending.popleft()[1]
        out.append(held)
    return out


@pytest.mark.parametrize(
    ("hz", "rate", "latency"),
    [(10.0, 1.0, 0.1), (10.0, 3.0, 0.25), (10.0, None, 0.3), (7.0, 25.0, 0.05), (10.0, 0.7, 2.0)],
)
def test_the_pipeline_kernels_deliver_what_the_plain_pipeline_does(hz, rate, latency):
    """The kernels on a batch of one, skipping the ticks between events, hold and deliver
    the results of a deque of (delivery time, result), tick for tick."""
    model = perception(hz, rate=rate, latency=latency)
    times = [k / hz for k in range(400)]
    want = _pipeline_reference(rate, latency, model.period, times, lambda t: round(t * hz))
    got = [model.deliver(t, ORIGIN, lambda t=t: round(t * hz)) for t in times]
    assert got == want and len(set(got)) > 10
    model.reset()  # a new game starts empty
    assert model.deliver(0.0, ORIGIN, lambda: 0) == (0 if latency == 0 else None)
