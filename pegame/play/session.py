"""The link between a game and the page a person plays it on: the latest command, the
latest frame, whether the page is there, and the latencies measured on the way.

The game's thread and the web server's thread share one :class:`Session` (every method
is thread-safe). The page side (:mod:`pegame.play.server`) connects, sets the command
from the person's keys or gamepad and takes frames; the game side
(:class:`pegame.evaders.human.HumanEvader` and :class:`pegame.play.recorder.PlayRecorder`)
reads the command once per control tick and publishes one frame per tick. Frames are
kept latest-only: a page that draws slower than the ticks come misses frames, and the
game never waits for it. While a game is served, the session is :func:`active`.

Times: ``stamp`` values are wall-clock milliseconds since the Unix epoch (the page's
``performance.timeOrigin + event.timeStamp``, Python's ``time.time() * 1000``), so the
page's and the game's clocks on one machine compare directly.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from pegame.errors import ConfigError
from pegame.types import STOP, Velocity


class PageClosed(RuntimeError):
    """The page left during a game (a closed tab, a lost connection): the game fails."""


def now_ms() -> float:
    """Wall-clock milliseconds since the Unix epoch, the clock the page stamps with."""
    return time.time() * 1000.0


@dataclass
class Latencies:
    """Measured latencies (ms): ``key_to_command``, from the page's key or gamepad event
    to the control tick that first applies it (it includes the wait for that tick, up to
    one control period); ``key_to_server``, from the event to its command reaching the
    session (the page and the network alone); ``tick_to_frame``, from a tick handed to
    the recorder to the page drawing it; ``tick_lag``, by how much each control tick came
    after its wall-clock time (0 when on time)."""

    key_to_command: list[float] = field(default_factory=list)
    key_to_server: list[float] = field(default_factory=list)
    tick_to_frame: list[float] = field(default_factory=list)
    tick_lag: list[float] = field(default_factory=list)

    def summary(self) -> dict[str, dict[str, float | int | None]]:
        """For each kind: the count, median, 95th percentile and maximum (ms)."""
        kinds = ("key_to_command", "key_to_server", "tick_to_frame", "tick_lag")
        return {name: _stats(getattr(self, name)) for name in kinds}


def _stats(samples: Sequence[float]) -> dict[str, float | int | None]:
    ordered = sorted(samples)
    if not ordered:
        return {"count": 0, "median": None, "p95": None, "max": None}

    def at(q: float) -> float:
        return round(ordered[min(len(ordered) - 1, int(q * len(ordered)))], 1)

    return {"count": len(ordered), "median": at(0.5), "p95": at(0.95), "max": at(1.0)}


class Session:
    """One person's page and the game it plays (module docstring).

    ``notify`` is called (from the game's thread) whenever a frame or message is
    published; the server sets it to wake its sender."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._connected = False
        self._left = threading.Event()
        self._command = STOP
        self._stamp: float | None = None  # the page's stamp of the command not yet applied
        self._outbox: list[dict[str, Any]] = []  # messages, sent in order
        self._frame: dict[str, Any] | None = None  # the latest frame, not yet sent
        self.latencies = Latencies()
        self.starts = threading.Semaphore(0)  # one release per game the page asked for
        self.notify: Callable[[], None] = lambda: None
        self.show: tuple[str, ...] = ()  # what the page may draw (the human evader's show)
        self.evader_taken = False  # a human evader plays in this session's game

    # -- the page's side

    def connect(self) -> bool:
        """Take the session for a page; False when another page holds it."""
        with self._lock:
            if self._connected:
                return False
            self._connected = True
            self._outbox, self._frame = [], None  # what a page that left did not get
            self._left.clear()
            return True

    def disconnect(self) -> None:
        """The page left: a game being played fails (:class:`PageClosed`)."""
        with self._lock:
            self._connected, self._command, self._stamp = False, STOP, None
        self._left.set()
        self.starts.release()  # wakes a server waiting for a game to start

    @property
    def connected(self) -> bool:
        """Whether a page holds the session."""
        return self._connected

    def set_command(self, v: float, w: float, stamp: float | None = None) -> None:
        """The person's command (v m/s, w rad/s, the evader's frame), from an input
        event at ``stamp`` (ms, page clock); the next control tick applies it."""
        with self._lock:
            self._command = Velocity(float(v), float(w))
            self._stamp = stamp
            if stamp is not None:
                self.latencies.key_to_server.append(now_ms() - stamp)

    def frame_drawn(self, sent: float, drawn: float) -> None:
        """The page drew the frame published at ``sent`` at ``drawn`` (both ms)."""
        with self._lock:
            self.latencies.tick_to_frame.append(drawn - sent)

    def take(self) -> list[dict[str, Any]]:
        """The messages to send now, in order: those queued, then the latest frame."""
        with self._lock:
            out, self._outbox = self._outbox, []
            if self._frame is not None:
                out.append(self._frame)
                self._frame = None
            return out

    # -- the game's side

    def command(self) -> Velocity:
        """The command for this control tick (STOP before the first input); records the
        key-to-command latency of an input applied for the first time."""
        with self._lock:
            if self._stamp is not None:
                self.latencies.key_to_command.append(now_ms() - self._stamp)
                self._stamp = None
            return self._command

    def publish_frame(self, frame: dict[str, Any]) -> None:
        """Replace the latest frame (an unsent older one is dropped)."""
        with self._lock:
            self._frame = frame
        self.notify()

    def send(self, message: dict[str, Any]) -> None:
        """Queue a message that must reach the page (a game's start, its result); any
        unsent frame goes first, so the page sees the last tick before the result."""
        with self._lock:
            if self._frame is not None:
                self._outbox.append(self._frame)
                self._frame = None
            self._outbox.append(message)
        self.notify()

    def wait(self, seconds: float) -> None:
        """Sleep ``seconds`` (s) or until the page leaves; PageClosed if it has left."""
        if self._left.wait(max(seconds, 0.0)) or not self._connected:
            raise PageClosed(
                "the page closed during the game (its tab closed or its connection was lost)"
            )


_active: Session | None = None


def activate(session: Session | None) -> None:
    """Serve ``session`` to the games of this process (None: none)."""
    global _active
    _active = session


def active(role: str) -> Session:
    """The session served now; ConfigError naming ``role`` when nothing is served (the
    human evader and the page recorder play only under ``python -m pegame.play``)."""
    if _active is None:
        raise ConfigError(
            f"Invalid value for '{role}': it plays only with a person at a browser page. "
            "Allowed: start the game with python -m pegame.play (it serves the page), or "
            "another plugin (evader=replay plays a recorded person)."
        )
    return _active
