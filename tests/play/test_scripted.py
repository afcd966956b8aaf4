"""The scripted keyboard player of the shipped recordings: keyboard commands only, the
styles as documented, walls turned away from."""

import math
import threading
import time

from pegame.play.scripted import REACTION, KeyboardPlayer
from pegame.play.session import Session
from pegame.testing import walled_room
from pegame.types import Velocity

GAME = {
    "camera": {"fov": math.pi / 3, "near": 0.3, "far": 5.0},
    "evader": {"radius": 0.25, "v_max": 0.5, "w_max": 1.8},
}


def player(style: str) -> KeyboardPlayer:
    keyboard = KeyboardPlayer(Session(), walled_room(), style, seed=0)
    keyboard.game = GAME
    return keyboard


def frame(evader, pursuer):
    return {"evader": list(evader), "pursuers": [list(pursuer)]}


def test_a_hider_runs_away_inside_the_cone_and_stands_outside_it():
    hider = player("hide")
    # the pursuer at (0.5, 0.5) looking along +x at the evader (1.2, 0.5), which faces +x
    assert hider.keys(frame((1.2, 0.5, 0.0), (0.5, 0.5, 0.0))) == (1, 0)
    # behind the pursuer's back: out of the cone, it stands
    assert hider.keys(frame((1.2, 0.5, 0.0), (2.0, 0.5, 0.0))) == (0, 0)


def test_a_player_facing_away_from_where_it_wants_turns_on_the_spot_first():
    runner = player("run")
    forward, turn = runner.keys(frame((1.2, 2.5, math.pi), (0.5, 2.5, 0.0)))
    assert forward == 0 and turn in (-1, 1)


def test_a_wall_ahead_is_turned_away_from_and_commands_are_keys():
    wanderer = player("wander")
    # at x = 3.6 m facing the east wall (x = 3.95 m)
    assert wanderer.wall_ahead(3.6, 0.6, 0.0)
    assert not wanderer.wall_ahead(1.0, 0.6, 0.0)
    for _ in range(50):
        forward, turn = wanderer.keys(frame((3.6, 0.6, 0.0), (0.5, 2.5, 0.0)))
        assert forward in (-1, 0, 1) and turn in (-1, 0, 1)
        assert not (forward == 1 and turn == 0)  # never straight into the wall


def test_the_player_presses_keys_through_the_session_after_a_reaction_time():
    hider = player("hide")
    hider.game = None
    hider.session.send({"type": "game", **GAME})
    hider.session.publish_frame({"type": "frame", **frame((1.2, 0.5, 0.0), (0.5, 0.5, 0.0))})
    thread = threading.Thread(target=hider.run)
    started = time.monotonic()
    thread.start()
    while not hider.session.latencies.key_to_server and time.monotonic() - started < 5:
        time.sleep(0.01)
    hider.stop.set()
    thread.join()
    assert time.monotonic() - started >= REACTION[0]
    assert hider.session.command() == Velocity(0.5, 0.0)  # full speed ahead, a key held
