"""Recorders: what a game leaves behind besides its result."""

from __future__ import annotations

from pegame.api import Recorder, Tick


class NullRecorder(Recorder):
    """Records nothing (``recorder=none``)."""

    description = "Records nothing."

    def start(self, out_dir, game_id, properties) -> None:
        pass

    def log(self, tick: Tick) -> None:
        pass

    def finish(self, result) -> None:
        pass
