"""Measure the page's latencies in a real browser:
``python -m pegame.play.latency [--seconds S] [--screenshot PNG] [overrides]``.

Starts ``python -m pegame.play --port 0 --games 1`` with the overrides, opens its page in
headless Chromium (Debian's ``chromium`` and ``chromium-driver``, driven with
selenium), starts a game of ``--seconds`` s, holds and releases keys along
:data:`PRESSES`, and prints the latencies the game measured
(:class:`pegame.play.session.Latencies`, the game's ``latency.json``): key press to the
evader's command in the tick loop, and tick to its frame drawn on the page, in ms. The
key-to-command time includes the wait for the next control tick (up to one
``control_dt``, 100 ms at the default 10 Hz).

Needs selenium (the ``test`` extra) and the two Debian packages; ``tests/play`` plays
through :func:`browser_game` as well.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"

#: the keys the measurement holds, as (key, seconds after the game's start it is
#: pressed, seconds it is held): forward, turns, back; 0.537 s apart, so the presses
#: fall at spread phases of the 0.1 s control tick (equal phases would measure one wait)
PRESSES = tuple(
    (key, round(0.3 + 0.537 * i, 3), 0.3)
    for i, key in enumerate(
        ("ArrowUp", "ArrowLeft", "ArrowUp", "ArrowRight", "ArrowDown", "ArrowUp", "ArrowLeft")
    )
)


def missing_browser() -> str | None:
    """Why a browser game cannot be played here, or None when it can."""
    for path, package in ((CHROMIUM, "chromium"), (CHROMEDRIVER, "chromium-driver")):
        if not os.access(path, os.X_OK):
            return f"{path} is missing (apt-get install {package})"
    try:
        import selenium  # noqa: F401
    except ImportError:
        return "selenium is not installed (pip install -e '.[test]')"
    return None


@dataclass
class BrowserGame:
    """A played browser game: its directory, the play command's exit status and
    output, and what the page held at the end (``window.pegame``)."""

    out_dir: Path
    status: int
    output: str
    page: dict[str, Any]
    cone_pixel: list[int] | None

    @property
    def latencies(self) -> dict[str, Any]:
        """The game's ``latency.json``."""
        loaded: dict[str, Any] = json.loads((self.out_dir / "latency.json").read_text())
        return loaded


@contextmanager
def served(overrides: Sequence[str], out: Path, games: int = 1) -> Iterator[tuple[Any, str]]:
    """A ``python -m pegame.play`` process on a free port, and its page's URL."""
    command = [sys.executable, "-m", "pegame.play", "--port", "0", "--games", str(games)]
    process = subprocess.Popen(
        [*command, "--out", str(out), *overrides],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    assert process.stdout is not None
    try:
        before = []  # what the command printed before its URL (a cold kernel cache's notice)
        for line in process.stdout:
            if "in a browser" in line:
                break
            before.append(line)
        else:
            raise RuntimeError(f"python -m pegame.play did not serve: {''.join(before)}")
        yield process, line.split("open ", 1)[1].split()[0]
    finally:
        if process.poll() is None:
            process.terminate()
        process.wait(timeout=30)


def chromium() -> Any:
    """Headless Chromium through chromedriver (Debian's paths)."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--window-size=1180,760"):
        options.add_argument(flag)
    return webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)


def press_keys(driver: Any, presses: Sequence[tuple[str, float, float]], start: float) -> None:
    """Hold and release the keys of ``presses`` at their times after ``start`` (s,
    time.monotonic)."""
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.keys import Keys

    keys = {
        "ArrowUp": Keys.ARROW_UP,
        "ArrowDown": Keys.ARROW_DOWN,
        "ArrowLeft": Keys.ARROW_LEFT,
        "ArrowRight": Keys.ARROW_RIGHT,
    }
    events = sorted(
        [(at, True, key) for key, at, _ in presses]
        + [(at + held, False, key) for key, at, held in presses]
    )
    for at, down, key in events:
        time.sleep(max(0.0, start + at - time.monotonic()))
        chain = ActionChains(driver)
        (chain.key_down if down else chain.key_up)(keys[key]).perform()


def browser_game(
    overrides: Sequence[str],
    out: Path,
    presses: Sequence[tuple[str, float, float]] = PRESSES,
    screenshot: Path | None = None,
    screenshot_at: float = 3.0,
    probe: str | None = None,
) -> BrowserGame:
    """Play one game of ``python -m pegame.play`` with ``overrides`` in headless
    Chromium, pressing ``presses`` (see :data:`PRESSES`); a ``screenshot`` of the page
    is taken ``screenshot_at`` s into the game, or once the last key is released; the
    JavaScript ``probe`` (a function body) is run on the page at the end, its value in
    ``page["probe"]``."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    with served(overrides, out) as (process, url):
        driver = chromium()
        try:
            driver.get(url)
            wait = WebDriverWait(driver, 30)
            button = driver.find_element(By.ID, "start")
            wait.until(lambda d: button.is_enabled())
            button.click()
            wait.until(lambda d: d.execute_script("return window.pegame.framesDrawn > 0"))
            start = time.monotonic()
            press_keys(driver, presses, start)
            if screenshot is not None:
                time.sleep(max(0.0, start + screenshot_at - time.monotonic()))
                driver.save_screenshot(str(screenshot))
            WebDriverWait(driver, 120).until(
                lambda d: d.execute_script("return window.pegame.result !== null")
            )
            page = driver.execute_script(
                "const p = window.pegame; return {framesDrawn: p.framesDrawn, "
                "conesDrawn: p.conesDrawn, conePoint: p.conePoint, result: p.result, "
                "text: document.getElementById('result').textContent};"
            )
            page["probe"] = driver.execute_script(probe) if probe else None
            pixel = driver.execute_script(
                "const p = window.pegame.conePoint; if (!p) return null;"
                "const c = document.getElementById('view').getContext('2d');"
                "return Array.from(c.getImageData(Math.round(p[0]), Math.round(p[1]), 1, 1).data);"
            )
        finally:
            driver.quit()
        output, _ = process.communicate(timeout=60)
        return BrowserGame(out / "game_1", process.returncode, output, page, pixel)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m pegame.play.latency", description=__doc__)
    parser.add_argument("--seconds", type=float, default=6.0, help="game length (s)")
    parser.add_argument("--screenshot", type=Path, default=None, help="save the page as PNG")
    parser.add_argument("overrides", nargs="*", help="Hydra overrides, e.g. env=brick")
    args = parser.parse_args(argv)
    reason = missing_browser()
    if reason is not None:
        print(f"pegame: error: no browser to measure with: {reason}", file=sys.stderr)
        return 2
    out = Path(tempfile.mkdtemp(prefix="pegame-latency-"))
    try:
        game = browser_game(
            [f"game.t_max={args.seconds}", *args.overrides], out, screenshot=args.screenshot
        )
        print(game.output, end="")
        print(json.dumps(game.latencies, indent=2))
    finally:
        shutil.rmtree(out, ignore_errors=True)
    return game.status


if __name__ == "__main__":
    sys.exit(main())
