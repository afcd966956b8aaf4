"""The page in a real browser (headless Chromium, Debian's chromium and
chromium-driver): keys move the evader of the game's trajectory, the pursuer's cone is
drawn, the game ends with its result on the page, and the latencies are measured."""

import json

import pytest

from pegame.play.latency import PRESSES, browser_game, missing_browser

MISSING = missing_browser()

#: the page's command mapping for fake gamepads (the Gamepad API's shape): stick forward,
#: stick left inside the dead zone, d-pad right; and held keys winning over a pad
GAMEPAD_PROBE = """
const c = window.pegame.commandFrom, e = {v_max: 0.5, w_max: 1.8};
const pad = (axes, pressed) => ({axes, buttons: [...Array(16)].map((_, i) => ({pressed: pressed.includes(i)}))});
return [
  c(new Set(), pad([0, -1], []), e),
  c(new Set(), pad([-0.1, 0], []), e),
  c(new Set(), pad([0, 0], [15]), e),
  c(new Set(["ArrowDown"]), pad([0, -1], []), e),
  c(new Set(), null, e),
];
"""


@pytest.mark.slow
@pytest.mark.skipif(MISSING is not None, reason=f"no headless browser: {MISSING}")
def test_a_person_at_the_page_moves_the_evader_sees_the_cone_and_gets_the_result(tmp_path):
    # the presses end 3.8 s after the first frame is drawn; the game runs in real time
    # whatever the page does, so a loaded machine that draws late needs slack: at
    # t_max=4.5, one run of the suite at load 9 saw the evader not move at all
    game = browser_game(
        ["game.t_max=9", "pursuer=random", "estimator=last_seen", "recorder=none"],
        tmp_path,
        probe=GAMEPAD_PROBE,
    )
    assert game.status == 0, game.output
    rows = (game.out_dir / "trajectory.csv").read_text().splitlines()
    header = rows[0].split(",")
    x, y = header.index("evader_x"), header.index("evader_y")
    path = [(float(r.split(",")[x]), float(r.split(",")[y])) for r in rows[1:]]
    walked = sum(((b[0] - a[0]) ** 2 + (b[1] - a[1]) ** 2) ** 0.5 for a, b in zip(path, path[1:]))
    assert walked > 0.4  # forward and back keys held 0.3 s four times at 0.5 m/s: 0.6 m
    page = game.page
    assert page["conesDrawn"] > 0 and page["framesDrawn"] > 10
    red, green, blue, _ = game.cone_pixel
    assert red > green + 30 and red > blue + 30  # the cone's translucent red, not the map
    assert "the pursuer tracked you" in page["text"]
    result = json.loads((game.out_dir / "result.json").read_text())
    assert page["result"]["tracking_rate"] == result["tracking_rate"]
    forward, dead, right, keys, none = page["probe"]
    assert forward == {"v": 0.5, "w": 0} and dead == {"v": 0, "w": 0}
    assert right == {"v": 0, "w": -1.8} and keys == {"v": -0.5, "w": 0} and none == {"v": 0, "w": 0}
    latency = game.latencies
    assert latency["key_to_command"]["count"] >= len(PRESSES)  # a down and an up per press
    assert latency["key_to_command"]["median"] < 200.0  # up to one 100 ms tick of wait
    assert latency["tick_to_frame"]["median"] < 200.0
