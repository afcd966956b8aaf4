"""One PyBullet physics client, so that several games in one process never share state."""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import pybullet


class Client:
    """A connection to its own physics server (DIRECT, or GUI when ``gui``).

    Attribute access returns the pybullet function bound to this client
    (``client.getCameraImage(...)``). :meth:`disconnect` frees the server's memory and is
    idempotent; the id is forgotten at once, because pybullet reuses ids of closed clients.
    """

    def __init__(self, gui: bool = False) -> None:
        self.id = pybullet.connect(pybullet.GUI if gui else pybullet.DIRECT)
        if self.id < 0:
            raise RuntimeError("pybullet could not connect a physics server (GUI needs a display)")

    def __getattr__(self, name: str) -> Callable[..., Any]:
        if self.id < 0:
            raise RuntimeError("the pybullet client is disconnected")
        return functools.partial(getattr(pybullet, name), physicsClientId=self.id)

    @property
    def connected(self) -> bool:
        return self.id >= 0

    def disconnect(self) -> None:
        if self.id >= 0:
            pybullet.disconnect(physicsClientId=self.id)
            self.id = -1
