"""detector.profile: the oracle detects with the chance an identified 3D profile gives
(pegame.detectors.profile, naive Bayes over its marginal tables) and moves its position by
the profile's error; a profile that is off draws nothing; bad names are refused."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pegame.api import Context
from pegame.detectors.oracle import OracleDetector
from pegame.detectors.perception import PARTS
from pegame.detectors.profile import PRIOR_FRAMES, DetectionProfile, profile_names
from pegame.errors import ConfigError
from pegame.grid import FREE, OccupancyGrid
from pegame.registry import make_config
from pegame.types import Body, Camera, Pose, SensorFrame

CAMERA = Camera()  # pi/3 FOV, 0.3-5 m
EVADER = Body(radius=0.25, v_max=0.5, w_max=1.8)
CAMERA_POSE = Pose(1.0, 5.0, 0.0)
#: a profile whose detection chance depends on the range only: 0.9 below 2 m, 0.3 beyond
#: (the other variables one bin each, at the overall rate); a 0.2 m bias along the line of
#: sight and no noise
PROFILE = """variable,low,high,frames,p_detect
range,0,2,1000,0.9
range,2,5,1000,0.3
bearing,0,0.55,2000,0.6
visible,0,1.0001,2000,0.6
lateral_speed,0,10,2000,0.6
false_detection,,,50,0
position_error_m,,,1200,0.2
error_along_mean_m,,,1200,0.2
error_along_std_m,,,1200,0
error_across_std_m,,,1200,0
cpu_ms,,,2000,1.0
"""


@pytest.fixture
def profile(tmp_path: Path) -> Path:
    path = tmp_path / "range_only.csv"
    path.write_text(PROFILE)
    return path


def detector(seed: int = 0, **params) -> OracleDetector:
    grid = OccupancyGrid(np.full((100, 100), FREE, dtype=np.int8), 0.1)
    context = Context(grid, Body(0.2, 0.5, 1.8), EVADER, CAMERA, 0.1, 1.0)
    config = make_config("detector", OracleDetector, params)
    return OracleDetector(config, context, np.random.default_rng(seed))


def detections(model: OracleDetector, distance: float, frames: int) -> list:
    """The oracle's detections of an evader ``distance`` m ahead over ``frames`` ticks."""
    evader = Pose(CAMERA_POSE.x + distance, CAMERA_POSE.y)
    return [
        model.detect(SensorFrame(time=0.1 * k, camera_pose=CAMERA_POSE, evader_truth=evader))
        for k in range(frames)
    ]


def rate(found: int, frames: int) -> float:
    """A bin's rate: the m-estimate towards the overall rate of PROFILE (Laplace's rule)."""
    overall = 1201 / 2002
    return (found + PRIOR_FRAMES * overall) / (frames + PRIOR_FRAMES)


def combined(*rates: float) -> float:
    """Naive Bayes: the overall odds times each rate's odds ratio to the overall's."""
    logit = lambda p: math.log(p / (1 - p))  # noqa: E731
    base = logit(1201 / 2002)
    return 1 / (1 + math.exp(-(base + sum(logit(p) - base for p in rates))))


def test_the_profile_gives_each_bin_its_rate_and_combines_variables_by_their_odds(profile):
    table = DetectionProfile.read(profile)
    flat = rate(1200, 2000)  # the one bin of bearing, visible and lateral speed
    near, far = combined(rate(900, 1000), flat, flat, flat), combined(rate(300, 1000), flat, flat)
    assert table.probability(1.5, 0.1, 1.0, 0.2) == pytest.approx(near)
    assert table.probability(3.0, 0.1, 1.0, math.nan) == pytest.approx(far)  # no lateral factor
    assert table.probability(9.0, 0.1, 1.0, math.nan) == pytest.approx(far)  # the nearest bin
    assert near == pytest.approx(0.9, abs=0.002) and far == pytest.approx(0.3, abs=0.002)
    # two informative variables multiply their odds ratios
    two = PROFILE.replace(
        "bearing,0,0.55,2000,0.6", "bearing,0,0.2,1000,0.9\nbearing,0.2,0.55,1000,0.3"
    )
    profile.write_text(two)
    expected = combined(rate(900, 1000), rate(900, 1000), flat, flat)
    assert DetectionProfile.read(profile).probability(1.5, 0.1, 1.0, 0.2) == pytest.approx(expected)


def test_detector_profile_detects_at_the_rate_the_profile_gives_the_range(profile):
    frames, table = 2000, DetectionProfile.read(profile)
    for distance in (1.5, 3.0):
        chance = table.probability(distance, 0.0, 1.0, 0.0)  # the evader stands still ahead
        assert chance == pytest.approx(0.9 if distance < 2 else 0.3, abs=0.002)
        seen = detections(detector(profile=str(profile)), distance, frames)
        found = sum(d is not None for d in seen)
        sigma = math.sqrt(frames * chance * (1 - chance))
        assert abs(found - frames * chance) < 4 * sigma, (distance, found / frames, chance)
        # the position carries the profile's bias, 0.2 m beyond the evader's centre
        x = [d.position[0] - CAMERA_POSE.x for d in seen if d is not None]
        assert np.mean(x) == pytest.approx(distance + 0.2, abs=1e-6)


def test_without_a_profile_the_oracle_detects_every_frame_and_spawns_no_generator():
    rng = np.random.default_rng(0)
    context = detector().context
    OracleDetector(make_config("detector", OracleDetector, {}), context, rng)
    assert rng.bit_generator.seed_seq.n_children_spawned == len(PARTS)
    assert all(d is not None for d in detections(detector(), 3.0, 50))


@pytest.mark.slow
def test_a_profile_with_the_occlusion_miss_or_in_the_batched_env_is_refused(profile):
    from pegame.config import compose
    from pegame.envs.vector import vector_env
    from pegame.game import Scenario

    overrides = ["env=enclosed", f"detector.profile={profile}", "detector.occlusion_miss=1"]
    with pytest.raises(ConfigError, match="detector.occlusion_miss, range_noise"):
        Scenario(compose(overrides))
    with pytest.raises(ConfigError, match="'detector.profile' in a batched env"):
        vector_env(2, overrides=["env=hall", f"detector.profile={profile}"], opponent="random")


@pytest.mark.slow
def test_an_unknown_profile_name_exits_2_with_one_paragraph_naming_the_allowed(tmp_path):
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "pegame",
            "detector.profile=nope",
            "recorder=none",
            f"hydra.run.dir={tmp_path / 'run'}",
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 2
    message = next(line for line in proc.stderr.splitlines() if line.startswith("pegame: error"))
    assert "'detector.profile': 'nope'" in message and "null (no profile)" in message
    assert all(name in message for name in profile_names())
    assert "Traceback" not in proc.stderr


def test_with_a_profile_a_body_whose_centre_left_the_view_is_still_detected(profile):
    """The profile's frames are those on which any of the body shows (a 3D detector finds
    legs at the image's edge); the oracle without one tests the centre."""
    bearing = 0.5 * CAMERA.fov + 0.05  # the centre out of view, the near edge inside
    evader = Pose(CAMERA_POSE.x + 1.5 * math.cos(bearing), CAMERA_POSE.y + 1.5 * math.sin(bearing))
    frames = [SensorFrame(0.1 * k, CAMERA_POSE, evader) for k in range(400)]
    with_profile, plain = detector(profile=str(profile)), detector()
    found = sum(with_profile.detect(f) is not None for f in frames)
    assert abs(found - 0.9 * 400) < 4 * math.sqrt(400 * 0.9 * 0.1)
    assert all(plain.detect(f) is None for f in frames)
