"""sim=pybullet and detector=segmentation keep the plugin contract (pegame.testing)."""

from __future__ import annotations

import pytest

pytest.importorskip("pybullet")

from pegame.testing import DetectorConformance, SimulatorConformance


class TestPybulletSimulator(SimulatorConformance):
    plugin = "pybullet"
    bad_values = {"width": 2, "camera_height": 3.0, "camera_hz": 0.0}


class TestSegmentationDetector(DetectorConformance):
    plugin = "segmentation"
    overrides = ("sim=pybullet",)
    bad_values = {"min_pixels": 0}
