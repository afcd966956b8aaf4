"""A person as the evader: ``python -m pegame.play`` serves a browser page on which a
person plays the evader of a pegame game (paper, Sec. V-B, its human evader), with the
keyboard or a gamepad, against any pursuer.

=============================== ==========================================================
:mod:`pegame.play.__main__`     the command: serve the page, play its games as jobs
:mod:`pegame.play.server`       the aiohttp server: the page and its WebSocket
:mod:`pegame.play.session`      the link between the page and the game (thread-safe)
:mod:`pegame.play.recorder`     ``recorder=play``: each tick to the page and the recorder
:mod:`pegame.play.latency`      measures the latencies in headless Chromium
=============================== ==========================================================

The evader itself is :class:`pegame.evaders.human.HumanEvader` (``evader=human``).
"""
