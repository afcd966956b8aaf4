"""evader=human: plays only with a served page, paces the loop in real time, returns the
page's command, fails the game when the page leaves, one person per game."""

import time

import numpy as np
import pytest

from pegame.api import EvaderObservation
from pegame.errors import ConfigError
from pegame.evaders.human import HumanEvader
from pegame.play.session import PageClosed, Session, activate
from pegame.testing import small_context
from pegame.types import STOP, Pose, Velocity


@pytest.fixture
def session():
    session = Session()
    session.connect()
    activate(session)
    yield session
    activate(None)


def human(**options) -> HumanEvader:
    return HumanEvader(HumanEvader.Config(**options), small_context(), np.random.default_rng(0))


def observation(time_s: float) -> EvaderObservation:
    return EvaderObservation(time_s, Pose(1.0, 1.0, 0.0), Pose(2.0, 1.0, 3.0))


def test_without_the_play_server_the_evader_is_refused_naming_it():
    activate(None)
    with pytest.raises(ConfigError, match="python -m pegame.play"):
        human()


def test_each_tick_waits_for_its_wall_clock_time_and_returns_the_pages_command(session):
    evader = human()
    evader.reset(Pose(1.0, 1.0, 0.0))
    assert evader.control(observation(0.0)) == STOP
    session.set_command(0.3, 0.7)
    started = time.monotonic()
    assert evader.control(observation(0.25)) == Velocity(0.3, 0.7)
    assert time.monotonic() - evader.start >= 0.25
    assert time.monotonic() - started < 1.0
    late = time.monotonic() - evader.start + 0.05
    time.sleep(0.1)
    evader.control(observation(late))  # a late tick is not waited for: its lag is measured
    assert session.latencies.tick_lag[-1] > 10.0


def test_a_page_that_leaves_fails_the_game(session):
    evader = human()
    evader.reset(Pose(1.0, 1.0, 0.0))
    session.disconnect()
    with pytest.raises(PageClosed):
        evader.control(observation(0.1))


def test_one_person_plays_one_evader_and_show_names_what_the_page_may_draw(session):
    human(show=["pursuer", "cone", "belief"])
    assert session.show == ("pursuer", "cone", "belief")
    with pytest.raises(ConfigError, match="one person plays one evader"):
        human()
    with pytest.raises(ConfigError, match="show"):
        HumanEvader.Config(show=["everything"])
