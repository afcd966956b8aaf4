"""detector=person: the HOG person detector finds the rendered person and nothing in an
empty room, tracks it, and plays a game through the app."""

from __future__ import annotations

import pytest

pytest.importorskip("cv2")
pytest.importorskip("pybullet")  # the frames are rendered by sim=pybullet

import json
import os
import subprocess
import sys

import numpy as np

from pegame.api import Context
from pegame.errors import ConfigError
from pegame.grid import OccupancyGrid
from pegame.registry import load, make_config
from pegame.testing import DetectorConformance
from pegame.types import Body, Camera, Pose
from pegame_pybullet.segmentation import SegmentationDetector
from pegame_pybullet.sim import PybulletSimulator
from pegame_vision.evaluate import iou
from pegame_vision.person import PersonDetector


@pytest.fixture(scope="module")
def room():
    """(context, sim): an empty 8 m x 4 m room, a level camera at the default 320 x 240."""
    grid = OccupancyGrid(np.zeros((80, 160), dtype=np.int8), 0.05, name="room")
    context = Context(grid, Body(0.2, 0.5, 1.8), Body(0.25, 0.5, 1.8), Camera(), 0.1, 1.0)
    config = PybulletSimulator.Config(camera_tilt=0.0)
    sim = PybulletSimulator(config, context, np.random.default_rng(0))
    yield context, sim
    sim.close()


def detector(context, **options) -> PersonDetector:
    return PersonDetector(PersonDetector.Config(**options), context, np.random.default_rng(0))


@pytest.mark.parametrize("heading", [0.0, 3.0])
def test_finds_the_person_and_its_box_and_place_match_the_segmentation(room, heading):
    context, sim = room
    sim.reset_1v1(Pose(0.3, 2.0, 0.0), Pose(4.0, 2.1, heading))  # 3.7 m ahead, whole in view
    frame = sim.sense_1v1(0.0)
    truth = SegmentationDetector(
        SegmentationDetector.Config(), context, np.random.default_rng(0)
    ).detect(frame)
    found = detector(context).detect(frame)
    assert truth is not None and found is not None
    assert iou(truth.box, found.box) >= 0.6
    assert np.hypot(found.position[0] - 4.0, found.position[1] - 2.1) < 0.2


def test_finds_nothing_in_an_empty_room(room):
    context, sim = room
    person = detector(context)
    for k in range(4):  # looking at walls, floor and corners; the person behind the camera
        sim.reset_1v1(Pose(1.0, 1.0 + 0.6 * k, 0.4 - 0.3 * k), Pose(0.4, 2.0, 0.0))
        frame = sim.sense_1v1(0.0)
        assert not np.any(frame.segmentation == sim.labels["evader"])
        assert person.detect(frame) is None


def test_tracks_the_person_between_detections(room):
    context, sim = room
    person = detector(context, redetect_every=3)
    sources = []
    for k in range(6):  # walking across the view, 5 cm per frame
        sim.reset_1v1(Pose(0.3, 2.0, 0.0), Pose(4.0, 1.8 + 0.05 * k, 3.0))
        found = person.detect(sim.sense_1v1(0.1 * k))
        assert found is not None
        sources.append(person.source)
    assert sources == ["detect", "track", "track", "detect", "track", "track"]


def test_the_entry_point_and_its_config_errors():
    assert load("detector", "person") is PersonDetector
    assert make_config("detector", PersonDetector, {}).model == "inria"
    with pytest.raises(ConfigError, match="detector.model"):
        make_config("detector", PersonDetector, {"model": "openpose"})


class TestPersonDetector(DetectorConformance):
    plugin = "person"
    overrides = ("sim=pybullet", "sim.camera_tilt=0")
    bad_values = {"model": "yolo", "scale": 1.0, "depth_tolerance": 0.0}


@pytest.mark.slow
def test_a_short_game_through_the_app(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "HYDRA_FULL_ERROR"}
    out = tmp_path / "run"
    overrides = [
        "sim=pybullet",
        "detector=person",
        "sim.camera_tilt=0",
        "pursuer=smart",
        "evader=smart",
        "recorder=none",
        "game.t_max=4",
        f"hydra.run.dir={out}",
    ]
    proc = subprocess.run(
        [sys.executable, "-m", "pegame", *overrides],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    result = json.loads((out / "result.json").read_text())
    assert result["detector"] == "person" and 0.0 <= result["tracking_rate"] <= 1.0
