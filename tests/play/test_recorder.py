"""recorder=play: the page's frames hold what the human evader's show allows, and every
tick also reaches the recorder that records the game."""

import base64
import io

import numpy as np
import pytest
from PIL import Image

from pegame import registry
from pegame.api import Recorder, Tick
from pegame.errors import ConfigError
from pegame.play.recorder import MAX_PARTICLES, OUTLINE_RAYS, PlayRecorder, frame, map_message
from pegame.play.session import Session, activate
from pegame.testing import small_context, small_map
from pegame.types import STOP, Belief, Plan, Pose, SensorFrame
from pegame.visibility.outlines import NEAR_ARC_POINTS


def tick(belief: Belief) -> Tick:
    pursuer, evader = Pose(1.0, 1.0, 0.5), Pose(2.0, 1.5, -1.0)
    return Tick.one_on_one(
        3,
        0.3,
        pursuer,
        evader,
        SensorFrame(0.3, pursuer),
        None,
        belief,
        None,
        True,
        (STOP, STOP),
        (Plan(), Plan()),
    )


def test_a_frame_shows_the_pursuer_and_belief_only_when_allowed():
    particles = np.random.default_rng(0).uniform(0, 3, size=(1000, 3))
    t = tick(Belief((2.0, 1.4), particles=particles, weights=np.full(1000, 1e-3)))
    hidden = frame(t, (), small_context())
    assert hidden["evader"] == [2.0, 1.5, -1.0]
    assert "pursuers" not in hidden and "belief" not in hidden
    cone = frame(t, ("cone",), small_context())
    assert cone["pursuers"] == [[1.0, 1.0, 0.5]]
    (outline,) = cone["cones"]  # the pursuer's view, walls hiding what is behind them
    assert len(outline) == OUTLINE_RAYS + NEAR_ARC_POINTS + 1 and outline[0] == outline[-1]
    camera = small_context().camera
    reach = [((x - 1.0) ** 2 + (y - 1.0) ** 2) ** 0.5 for x, y in outline]
    assert max(reach) <= camera.far + 1e-3 and min(reach) >= camera.near - 1e-3
    assert "cones" not in frame(t, ("pursuer",), small_context())
    shown = frame(t, ("pursuer", "belief"), small_context())
    assert shown["belief"]["mean"] == [2.0, 1.4]
    assert 0 < len(shown["belief"]["particles"]) <= MAX_PARTICLES
    assert frame(tick(Belief(None)), ("belief",), small_context())["belief"] == {}


def test_the_map_image_has_a_pixel_per_cell_with_the_highest_row_on_top():
    grid = small_map()
    message = map_message(grid)
    png = base64.b64decode(message["image"].split(",", 1)[1])
    image = np.asarray(Image.open(io.BytesIO(png)))
    assert image.shape == (grid.height, grid.width)
    assert ((image[::-1] < 128) == grid.blocked).all()


class Spy(Recorder):
    def start(self, out_dir, game_id, properties):
        self.events = ["start"]

    def log(self, tick):
        self.events.append(tick.step)

    def finish(self, result):
        self.events.append("finish")


def test_every_tick_goes_to_the_page_and_to_the_recorder_named_by_then(monkeypatch):
    monkeypatch.setattr(registry, "load", lambda kind, name: Spy)
    session = Session()
    session.show = ("pursuer", "cone")
    activate(session)
    try:
        recorder = PlayRecorder(
            PlayRecorder.Config(then="spy"), small_context(), np.random.default_rng(0)
        )
    finally:
        activate(None)
    recorder.start("out", "game", {"game": {"t_max": 2.0, "control_hz": 10.0, "seed": 4}})
    recorder.log(tick(Belief(None)))
    recorder.finish({"tracking_rate": 0.25, "visible_rate": 0.5})
    assert recorder.inner.events == ["start", 3, "finish"]
    game, shown, result = session.take()
    assert (game["type"], game["seed"], game["show"]) == ("game", 4, ["pursuer", "cone"])
    assert shown["step"] == 3 and "pursuers" in shown
    assert (result["type"], result["tracking_rate"]) == ("result", 0.25)


def test_the_page_cannot_tee_to_itself():
    with pytest.raises(ConfigError, match="then"):
        PlayRecorder.Config(then="play")
