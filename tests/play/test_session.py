"""The session between a page and a game: latest-only frames, ordered messages, the
command and its latency, a page that leaves, one page at a time."""

import time

import pytest

from pegame.errors import ConfigError
from pegame.play.session import PageClosed, Session, activate, active, now_ms
from pegame.types import STOP, Velocity


def test_a_page_that_reads_slower_than_the_ticks_gets_the_latest_frame_only():
    session = Session()
    for step in range(5):
        session.publish_frame({"type": "frame", "step": step})
    assert session.take() == [{"type": "frame", "step": 4}]
    assert session.take() == []


def test_a_message_follows_the_frame_before_it_and_nothing_is_lost():
    session = Session()
    session.publish_frame({"type": "frame", "step": 9})
    session.send({"type": "result"})
    session.publish_frame({"type": "frame", "step": 10})
    assert [m.get("step", m["type"]) for m in session.take()] == [9, "result", 10]


def test_the_command_is_stop_until_the_page_sets_one_and_its_latency_is_measured_once():
    session = Session()
    assert session.command() == STOP
    session.set_command(0.5, -1.0, now_ms() - 20.0)
    assert session.command() == Velocity(0.5, -1.0)
    assert session.command() == Velocity(0.5, -1.0)  # held until the next input
    (latency,) = session.latencies.key_to_command
    (transport,) = session.latencies.key_to_server
    assert 20.0 <= transport <= latency < 1000.0


def test_one_page_holds_the_session_and_its_leaving_fails_the_game_and_stops_the_evader():
    session = Session()
    assert session.connect()
    assert not session.connect()
    session.set_command(0.5, 0.0)
    session.wait(0.0)  # the page is there: no error
    session.disconnect()
    assert session.command() == STOP
    started = time.monotonic()
    with pytest.raises(PageClosed):
        session.wait(5.0)
    assert time.monotonic() - started < 1.0  # the leaving wakes the wait
    session.send({"type": "result"})  # the page that left never gets it
    assert session.connect()  # a new page may take it
    assert session.take() == []


def test_latency_summary_counts_and_orders_the_samples():
    session = Session()
    for sent in (10.0, 30.0, 20.0):
        session.frame_drawn(sent, 40.0)
    summary = session.latencies.summary()["tick_to_frame"]
    assert summary == {"count": 3, "median": 20.0, "p95": 30.0, "max": 30.0}
    assert session.latencies.summary()["key_to_command"]["count"] == 0


def test_without_a_served_page_the_human_roles_are_refused_naming_the_command():
    activate(None)
    with pytest.raises(ConfigError, match="python -m pegame.play"):
        active("evader")
    session = Session()
    activate(session)
    try:
        assert active("evader") is session
    finally:
        activate(None)
