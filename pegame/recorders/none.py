"""The recorder that records nothing (``recorder=none``): imports nothing heavy."""

from __future__ import annotations

from typing import Any

from pegame.api import Recorder, Tick


class NullRecorder(Recorder):
    """Records nothing (``recorder=none``)."""

    description = "Records nothing."

    def start(self, out_dir: str, game_id: str, properties: dict[str, Any]) -> None:
        pass

    def log(self, tick: Tick) -> None:
        pass

    def finish(self, result: dict[str, Any]) -> None:
        pass
