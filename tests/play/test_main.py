"""python -m pegame.play: the person is the evader of an ordinary pegame game (the same
job, files and provenance), a closed page fails the game (recorded, exit 1), bad input
is exit 2 before anything is served."""

import asyncio
import json
import signal
import time

import aiohttp
import pytest

from pegame.errors import ConfigError
from pegame.play.__main__ import game_overrides, main
from pegame.play.latency import served


def test_the_person_is_the_evader_and_a_recorder_choice_is_what_the_page_tees_to():
    assert game_overrides(["env=brick", "recorder=none", "evader.show=[belief]"]) == [
        "evader=human",
        "recorder=play",
        "recorder.then=none",
        "env=brick",
        "evader.show=[belief]",
    ]
    with pytest.raises(ConfigError, match="Allowed: human"):
        game_overrides(["evader=smart"])


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        (["evader=smart"], "Allowed: human"),
        (["game.trials=2"], "game.trials"),
        (["env=nowhere"], "env"),
        (["game.t_max=[1"], "input '[1'"),
        (["--host", "192.0.2.1"], "--host"),
    ],
)
def test_bad_input_is_one_paragraph_and_exit_2_before_serving(capsys, overrides, message):
    assert main(["--port", "0", *overrides]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pegame: error:") and message in err


async def page(url: str, leave_after: float | None = None, games: int = 1) -> list[dict]:
    """A page without a browser: start a game, go forward and left, acknowledge frames,
    and start another at its result, ``games`` in all; leave ``leave_after`` s into the
    first game (None: play to the last result)."""
    received = []
    async with aiohttp.ClientSession() as client, client.ws_connect(url + "ws") as ws:
        await ws.send_json({"type": "start"})
        started, results = None, 0
        async for message in ws:
            data = json.loads(message.data)
            received.append(data)
            if data["type"] == "game":
                started = time.monotonic()
                await ws.send_json(
                    {"type": "command", "v": 0.5, "w": 0.4, "stamp": time.time() * 1000}
                )
            elif data["type"] == "frame":
                await ws.send_json(
                    {"type": "drawn", "sent": data["sent"], "drawn": time.time() * 1000}
                )
                if leave_after is not None and time.monotonic() - started > leave_after:
                    break
            else:
                results += 1
                if results == games:
                    break
                await ws.send_json({"type": "start"})  # the page's "Another game"
    return received


@pytest.mark.slow
def test_played_games_write_what_every_pegame_game_writes(tmp_path):
    overrides = ["game.t_max=2", "pursuer=random", "estimator=last_seen"]
    with served(overrides, tmp_path, games=2) as (process, url):
        assert url.startswith("http://127.0.0.1:")
        started = time.monotonic()
        received = asyncio.run(page(url, games=2))
        elapsed = time.monotonic() - started
        output, _ = process.communicate(timeout=60)
    assert process.returncode == 0, output
    assert elapsed >= 4.0  # paced in real time: twice 20 ticks of 0.1 s
    kinds = [m["type"] for m in received]
    assert kinds[0] == "game" and kinds[-1] == "result" and kinds.count("frame") >= 20
    games = [m for m in received if m["type"] == "game"]
    assert [g["seed"] for g in games] == [0, 1]  # another game, another start
    assert json.loads((tmp_path / "game_2" / "result.json").read_text())["seed"] == 1
    game_dir = tmp_path / "game_1"
    for name in ("result.json", "trajectory.csv", "game.rrd", "latency.json", "trajectory.png"):
        assert (game_dir / name).is_file(), name
    line = json.loads((game_dir / "results.jsonl").read_text().splitlines()[0])
    assert (line["kind"], line["evader"], line["pursuer"]) == ("game", "human", "random")
    assert line["config"]["evader"]["show"] == ["pursuer", "cone"]
    assert "provenance" in line and line["overrides"][0] == "game.t_max=2"
    rows = (game_dir / "trajectory.csv").read_text().splitlines()
    header, first, last = rows[0].split(","), rows[1].split(","), rows[-1].split(",")
    x = header.index("evader_x")
    assert (
        abs(float(last[x]) - float(first[x])) + abs(float(last[x + 1]) - float(first[x + 1])) > 0.2
    )
    latency = json.loads((game_dir / "latency.json").read_text())
    # frames a busy page did not take in time are dropped, by design: some, not all, count
    assert latency["key_to_command"]["count"] == 1 and latency["tick_to_frame"]["count"] >= 1
    assert "latency: key->command" in output


@pytest.mark.slow
def test_a_page_closed_during_a_game_fails_it_recorded_and_exit_1(tmp_path):
    with served(["game.t_max=30", "pursuer=random", "estimator=last_seen"], tmp_path) as (
        process,
        url,
    ):
        asyncio.run(page(url, leave_after=0.5))
        output, _ = process.communicate(timeout=60)
    assert process.returncode == 1, output
    lines = [
        json.loads(line)
        for line in (tmp_path / "game_1" / "results.jsonl").read_text().splitlines()
    ]
    assert [line["kind"] for line in lines] == ["failed", "summary"]
    assert lines[0]["error"].startswith("PageClosed")
    assert not (tmp_path / "game_1" / "result.json").exists()


@pytest.mark.slow
def test_ctrl_c_during_a_game_is_exit_130_and_between_games_the_games_status(tmp_path):
    overrides = ["game.t_max=30", "pursuer=random", "estimator=last_seen", "recorder=none"]
    with served(overrides, tmp_path / "during") as (process, url):

        async def interrupt():
            async with aiohttp.ClientSession() as client, client.ws_connect(url + "ws") as ws:
                await ws.send_json({"type": "start"})
                async for message in ws:
                    if json.loads(message.data)["type"] == "frame":
                        process.send_signal(signal.SIGINT)
                        break
                await asyncio.sleep(0.5)

        asyncio.run(interrupt())
        output, _ = process.communicate(timeout=60)
    assert process.returncode == 130, output
    with served(overrides, tmp_path / "between") as (process, url):
        process.send_signal(signal.SIGINT)
        output, _ = process.communicate(timeout=60)
    assert process.returncode == 0, output
