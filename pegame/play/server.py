"""The web server of :mod:`pegame.play`: the page and its WebSocket, on aiohttp.

aiohttp gives the HTTP server and the WebSocket in one well-kept package with no ASGI
server beside it; it runs its own event loop in a thread of the play process, while the
game runs in the main thread as every pegame game does.

Routes: ``/`` the page; ``/static/<file>`` its script and style (package data,
``pegame/play/static``); ``/ws`` the one WebSocket of the person's page. A second page
while one is connected is refused (HTTP 409), and so is a WebSocket opened from another
site's page (HTTP 403, its Origin is not this server).

Messages are JSON objects with a ``type``. From the page: ``start`` (play a game),
``command`` (``v`` m/s, ``w`` rad/s, ``stamp``: the input event's time, ms since the
epoch), ``drawn`` (``sent``, ``drawn``: a frame's publish and draw times, ms). To the
page: ``game`` (the map, the camera and the settings), ``frame`` (one tick, see
:mod:`pegame.play.recorder`), ``result`` or ``failed`` at a game's end.
"""

from __future__ import annotations

import asyncio
import json
import math
import threading
from importlib import resources
from typing import Any
from urllib.parse import urlsplit

from aiohttp import WSCloseCode, WSMsgType, web

from pegame.play.session import Session

STATIC = resources.files("pegame.play") / "static"
FILES = {"play.js": "text/javascript", "play.css": "text/css", "index.html": "text/html"}


def _finite(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def handle_message(session: Session, message: dict[str, Any]) -> None:
    """Apply one message from the page to the session; malformed ones are ignored."""
    kind = message.get("type")
    if kind == "start":
        session.starts.release()
    elif kind == "command" and _finite(message.get("v")) and _finite(message.get("w")):
        stamp = message.get("stamp")
        session.set_command(message["v"], message["w"], stamp if _finite(stamp) else None)
    elif kind == "drawn" and _finite(message.get("sent")) and _finite(message.get("drawn")):
        session.frame_drawn(message["sent"], message["drawn"])


def make_app(
    session: Session, sockets: set[web.WebSocketResponse] | None = None
) -> web.Application:
    """The page's application for ``session``; ``sockets`` holds its open WebSockets."""
    sockets = set() if sockets is None else sockets

    async def page(request: web.Request) -> web.Response:
        return _file("index.html")

    async def static(request: web.Request) -> web.Response:
        name = request.match_info["name"]
        if name not in FILES:
            raise web.HTTPNotFound()
        return _file(name)

    async def socket(request: web.Request) -> web.StreamResponse:
        origin = request.headers.get("Origin")
        if origin is not None and urlsplit(origin).netloc != request.host:
            raise web.HTTPForbidden(text="This game's page is served by this server only.")
        if not session.connect():
            raise web.HTTPConflict(text="Another page is playing this game; one person plays it.")
        ws = web.WebSocketResponse(heartbeat=10.0)
        sockets.add(ws)
        try:
            await ws.prepare(request)
            wake = asyncio.Event()
            loop = asyncio.get_running_loop()

            def notify() -> None:
                loop.call_soon_threadsafe(wake.set)

            session.notify = notify
            sender = asyncio.create_task(_send(ws, session, wake))
            try:
                async for message in ws:
                    if message.type != WSMsgType.TEXT:
                        continue
                    try:
                        data = json.loads(message.data)
                    except json.JSONDecodeError:
                        continue
                    if isinstance(data, dict):
                        handle_message(session, data)
            finally:
                sender.cancel()
        finally:
            sockets.discard(ws)
            session.notify = lambda: None
            session.disconnect()
        return ws

    app = web.Application()
    app.router.add_get("/", page)
    app.router.add_get("/static/{name}", static)
    app.router.add_get("/ws", socket)
    return app


def _file(name: str) -> web.Response:
    body = (STATIC / name).read_bytes()
    return web.Response(body=body, content_type=FILES[name], headers={"Cache-Control": "no-store"})


async def _send(ws: web.WebSocketResponse, session: Session, wake: asyncio.Event) -> None:
    """Send what the session holds whenever it is woken: while a send waits for a slow
    page, newer frames replace older ones in the session, which are never sent."""
    while not ws.closed:
        await wake.wait()
        wake.clear()
        for message in session.take():
            await ws.send_str(json.dumps(message))


class Server:
    """The page's server on its own thread: :meth:`start` binds ``host``:``port`` (port 0:
    any free port) and returns the page's URL; :meth:`stop` closes it."""

    def __init__(self, session: Session, host: str = "127.0.0.1", port: int = 8765) -> None:
        self.session, self.host, self.port = session, host, port
        self.loop = asyncio.new_event_loop()
        self.sockets: set[web.WebSocketResponse] = set()
        self.runner = web.AppRunner(make_app(session, self.sockets), handle_signals=False)
        self.thread = threading.Thread(
            target=self.loop.run_forever, name="pegame-play", daemon=True
        )

    def start(self) -> str:
        """Serve in the background; the URL of the page. OSError when the address cannot
        be bound (in use, or not this machine's)."""
        asyncio.set_event_loop(self.loop)
        self.loop.run_until_complete(self.runner.setup())
        site = web.TCPSite(self.runner, self.host, self.port)
        self.loop.run_until_complete(site.start())
        port = self.runner.addresses[0][1]
        self.thread.start()
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"http://{host}:{port}/"

    async def _shutdown(self) -> None:
        """Close the open page (it says the server closed the game), then the server."""
        for ws in list(self.sockets):
            await ws.close(code=WSCloseCode.GOING_AWAY, message=b"the server stopped")
        await self.runner.cleanup()

    def stop(self) -> None:
        """Close the connections and the server, and end its thread."""
        if self.thread.is_alive():
            asyncio.run_coroutine_threadsafe(self._shutdown(), self.loop).result(timeout=10)
            self.loop.call_soon_threadsafe(self.loop.stop)
            self.thread.join(timeout=10)
        self.loop.close()
