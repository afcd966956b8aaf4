"""Every built-in plugin passes the conformance kit (pegame.testing), and the kit catches
plugins that break each of its rules."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from pegame import registry
from pegame.api import Pursuer, Velocity
from pegame.errors import require
from pegame.pursuers.random import RandomPursuer
from pegame.testing import (
    ConformanceError,
    DetectorConformance,
    EstimatorConformance,
    EvaderConformance,
    PursuerConformance,
    RecorderConformance,
    SimulatorConformance,
    check_config_errors,
    check_interface,
    check_plugin,
    check_same_seed_same_game,
)

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


class TestGridSimulator(SimulatorConformance):
    plugin = "grid"


class TestOracleDetector(DetectorConformance):
    plugin = "oracle"
    bad_values = {"miss_probability": 1.5, "range_noise": -0.1}


class TestParticleFilter(EstimatorConformance):
    plugin = "particle_filter"
    bad_values = {"n_particles": 0, "rho": 2.0, "resampler": "bogus"}


class TestKalman(EstimatorConformance):
    plugin = "kalman"
    bad_values = {"measurement_std": 0.0}


@pytest.mark.slow
class TestLastSeen(EstimatorConformance):
    plugin = "last_seen"


@pytest.mark.slow
class TestSmartPursuer(PursuerConformance):
    plugin = "smart"
    bad_values = {"radius": -0.2, "standoff": -1.0}


class TestRandomPursuer(PursuerConformance):
    plugin = "random"
    bad_values = {"w_max": 0.0}


@pytest.mark.slow
class TestPolicyPursuer(PursuerConformance):
    plugin = "policy"
    overrides = (f"pursuer.path={EXAMPLES / 'cem_pursuer.npz'}",)
    bad_values = {"path": "policy.txt", "crop_cells": 0}


class TestSmartEvader(EvaderConformance):
    plugin = "smart"
    bad_values = {"v_max": 0.0, "distance": "manhattan", "candidate_stride": 0}


class TestRandomEvader(EvaderConformance):
    plugin = "random"
    bad_values = {"radius": 0.0}


class TestPolicyEvader(EvaderConformance):
    plugin = "policy"
    overrides = ("evader.path=pegame.testing:flee",)
    bad_values = {"belief": True, "decision_period": -1.0}


class TestNullRecorder(RecorderConformance):
    plugin = "none"


@pytest.mark.slow
class TestRerunRecorder(RecorderConformance):
    plugin = "rerun"
    bad_values = {"jpeg_quality": 0, "trail_every": 0}


# ------------------------------------------------------- the kit refuses broken plugins


class Spiteful(Pursuer):
    """Breaks the seeding rule: draws its turn rate from numpy's global generator."""

    description = "Turns at a random rate from the global generator."

    def reset(self, pose):
        pass

    def decide(self, observation):
        from pegame.api import Plan

        return Plan()

    def control(self, observation):
        return Velocity(0.0, float(np.random.uniform(-1.0, 1.0)))  # noqa: NPY002 - the defect tested


class Lenient(Pursuer):
    """Breaks the config rule: accepts a negative gain."""

    description = "Accepts anything."

    @dataclass
    class Config(Pursuer.Config):
        gain: float = 1.0  # 1/s

    reset = Spiteful.reset
    decide = Spiteful.decide

    def control(self, observation):
        return Velocity(0.0, self.config.gain)


class Strict(Lenient):
    """Refuses a negative gain, but names the wrong key."""

    @dataclass
    class Config(Pursuer.Config):
        gain: float = 1.0  # 1/s

        def __post_init__(self) -> None:
            super().__post_init__()
            require(self.gain > 0, "speed", "a positive number", self.gain)


def test_an_unregistered_plugin_is_refused_with_the_entry_point_group():
    with pytest.raises(ConformanceError, match="pegame.pursuers"):
        check_interface("pursuer", Spiteful)


def test_a_class_of_another_kind_or_missing_methods_is_refused():
    with pytest.raises(ConformanceError, match="subclass pegame.api.Evader"):
        check_interface("evader", RandomPursuer)

    class Half(Pursuer):
        description = "Half done."

        def reset(self, pose):
            pass

    with pytest.raises(ConformanceError, match="decide"):
        check_interface("pursuer", Half)


def test_a_config_that_accepts_a_bad_value_or_misnames_the_key_is_refused():
    with pytest.raises(ConformanceError, match="was accepted"):
        check_config_errors("pursuer", Lenient, {"gain": -1.0})
    with pytest.raises(ConformanceError, match="must name 'pursuer.gain'"):
        check_config_errors("pursuer", Strict, {"gain": -1.0})
    check_config_errors("pursuer", Strict, {"radius": -1.0})  # the body's checks name their keys


class Reseeding(Spiteful):
    """Plays the same game twice, but by reseeding numpy's global generator."""

    def reset(self, pose):
        np.random.seed(7)  # noqa: NPY002 - the defect tested


@pytest.fixture
def registered(monkeypatch):
    """``registered(name, cls)``: make ``cls`` the pursuer plugin ``name`` of the registry."""
    real = registry._entry_points
    extra = {}

    def with_extra(group):
        points = dict(real(group))
        if group == "pursuer":
            points.update(extra)
        return points

    def register(name, cls):
        extra[name] = registry.EntryPoint(
            name, f"{__name__}:{cls.__name__}", registry.GROUPS["pursuer"]
        )

    monkeypatch.setattr(registry, "_entry_points", with_extra)
    return register


# A pursuer registered here has no config file: the games take random's (the body alone)
# and rename it.


def test_a_plugin_drawing_from_the_global_generator_is_refused(registered):
    registered("spiteful", Spiteful)
    with pytest.raises(ConformanceError, match="different results|diverge"):
        check_same_seed_same_game(
            "pursuer", "random", ["pursuer.name=spiteful", "~pursuer.model"], t_max=2.0
        )


def test_a_plugin_reseeding_the_global_generator_is_refused(registered):
    registered("reseeding", Reseeding)
    with pytest.raises(ConformanceError, match="numpy's global generator"):
        check_same_seed_same_game(
            "pursuer", "random", ["pursuer.name=reseeding", "~pursuer.model"], t_max=2.0
        )


def test_check_plugin_runs_every_rule_on_a_built_in():
    check_plugin("estimator", registry.load("estimator", "last_seen"), t_max=2.0)
