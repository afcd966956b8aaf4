"""The page's server: the page and its files, one WebSocket at a time, no other site's
page, and the page's messages applied to the session."""

import asyncio
import json

from aiohttp import WSServerHandshakeError
from aiohttp.test_utils import TestClient, TestServer

from pegame.play.server import Server, handle_message, make_app
from pegame.play.session import Session
from pegame.types import Velocity


def serve(session, body):
    async def run():
        async with TestClient(TestServer(make_app(session))) as client:
            return await body(client)

    return asyncio.run(run())


def test_the_page_and_its_files_are_served_and_nothing_else():
    async def body(client):
        page = await client.get("/")
        script = await client.get("/static/play.js")
        missing = await client.get("/static/../server.py")
        other = await client.get("/static/secret.txt")
        return page.status, await page.text(), script.status, missing.status, other.status

    status, text, script, missing, other = serve(Session(), body)
    assert (status, script) == (200, 200)
    assert '<script src="/static/play.js">' in text
    assert missing == 404 and other == 404


def test_a_second_page_is_refused_and_the_first_one_leaving_frees_the_game():
    session = Session()

    async def body(client):
        first = await client.ws_connect("/ws")
        try:
            await client.ws_connect("/ws")
        except WSServerHandshakeError as refused:
            second = refused.status
        await first.close()
        for _ in range(100):
            if not session.connected:
                break
            await asyncio.sleep(0.01)
        third = await client.ws_connect("/ws")
        await third.close()
        return second

    assert serve(session, body) == 409


def test_a_socket_opened_from_another_sites_page_is_refused():
    async def body(client):
        try:
            await client.ws_connect("/ws", headers={"Origin": "http://example.org"})
        except WSServerHandshakeError as refused:
            return refused.status

    assert serve(Session(), body) == 403


def test_frames_and_messages_reach_the_page_and_its_commands_the_session():
    session = Session()

    async def body(client):
        ws = await client.ws_connect("/ws")
        await ws.send_str(json.dumps({"type": "command", "v": 0.4, "w": -0.2, "stamp": 1.0}))
        await ws.send_str(json.dumps({"type": "start"}))
        for _ in range(100):
            if session.starts.acquire(blocking=False):
                break
            await asyncio.sleep(0.01)
        else:
            raise AssertionError("the page's start did not reach the session")
        session.publish_frame({"type": "frame", "step": 1})
        session.send({"type": "result", "tracking_rate": 0.5})
        received = [json.loads((await ws.receive()).data) for _ in range(2)]
        command = session.command()
        await ws.close()
        return received, command

    (frame, result), command = serve(session, body)
    assert frame == {"type": "frame", "step": 1}
    assert result == {"type": "result", "tracking_rate": 0.5}
    assert command == Velocity(0.4, -0.2)


def test_malformed_messages_are_ignored():
    session = Session()
    for message in (
        {"type": "command", "v": "fast", "w": 0.0},
        {"type": "command", "v": float("nan"), "w": 0.0},
        {"type": "command", "v": True, "w": 0.0},
        {"type": "drawn", "sent": None, "drawn": 2.0},
        {"type": "unknown"},
    ):
        handle_message(session, message)
    assert session.command() == Velocity(0.0, 0.0)
    assert session.latencies.tick_to_frame == []


def test_the_server_listens_on_localhost_on_a_free_port_and_stops():
    server = Server(Session(), port=0)
    url = server.start()
    try:
        assert url.startswith("http://127.0.0.1:")
        assert int(url.rsplit(":", 1)[1].strip("/")) > 0
    finally:
        server.stop()
    assert not server.thread.is_alive()
