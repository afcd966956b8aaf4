"""The example pursuer keeps the plugin contract (pegame.testing) and does what it says."""

from __future__ import annotations

import numpy as np
import pytest

from pegame.api import EMPTY_BELIEF, BoundingBox, Detection, Pose, PursuerObservation
from pegame.errors import ConfigError
from pegame.testing import PursuerConformance, small_context
from pegame.visibility import VisibilityRegion


class TestSpinner(PursuerConformance):
    plugin = "spinner"
    bad_values = {"turn_rate": -1.0}


def observe(detection):
    """(context, the observation of a pursuer at (0.5, 1.0) m facing +x) with ``detection``."""
    context = small_context()
    pose = Pose(0.5, 1.0, 0.0)
    return context, PursuerObservation(
        0.0, pose, detection, EMPTY_BELIEF, VisibilityRegion(context.grid, pose, context.camera)
    )


def test_spins_until_it_detects_then_steers_toward_the_box():
    from spinner import Spinner

    context, blind = observe(None)
    spinner = Spinner(Spinner.Config(turn_rate=1.2), context, np.random.default_rng(0))
    assert spinner.control(blind).w == pytest.approx(1.2) and spinner.control(blind).v == 0.0
    width = context.camera.image_width
    left_box = BoundingBox(0.0, 100.0, 0.25 * width, 300.0)  # centre left of the image centre
    _, seen = observe(Detection(position=(1.5, 1.2), depth=1.0, box=left_box))
    command = spinner.control(seen)
    assert command.v > 0 and command.w > 0  # drives on, turning left toward the box


def test_a_negative_turn_rate_is_a_config_error():
    from pegame.registry import make_config
    from spinner import Spinner

    with pytest.raises(ConfigError, match="pursuer.turn_rate"):
        make_config("pursuer", Spinner, {"turn_rate": -1.0})
