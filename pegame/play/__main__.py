"""``python -m pegame.play [--host H] [--port P] [--games N] [--out DIR] [overrides]``:
play the evader yourself, in a browser, against any pursuer.

Serves the page (:mod:`pegame.play.server`) on ``--host`` (localhost unless told
otherwise) and ``--port`` (0: any free port), prints its URL, and plays one game each
time the page asks: a pegame game of the composed config (any Hydra override:
``env=brick pursuer=anticipating``) with ``evader=human`` and ``recorder=play`` (the
page, teed to the recorder chosen with ``recorder=``, by default ``rerun``), run by
:func:`pegame.job.run_job` as ``python -m pegame`` runs it. Game n (from 1) is played
with seed ``game.seed + n - 1`` in ``DIR/game_<n>/`` (default DIR:
``outputs/play/<date>_<time>``): ``result.json``, ``results.jsonl`` with provenance,
``trajectory.csv``, ``game.rrd``, and ``latency.json`` (the latencies measured in that
game, :class:`pegame.play.session.Latencies`).

The run ends after ``--games`` games (0: no limit), when the page closes between games
(before the first game the server waits for a page), or on Ctrl-C. Exit status: 0 every
game finished, 1 some game failed (a page closed during a game fails that game, which is
recorded, and ends the run), 2 bad input, 130 on Ctrl-C during a game.
"""

from __future__ import annotations

import argparse
import datetime
import json
import logging
import os
import sys
from collections.abc import Sequence
from pathlib import Path

from hydra.errors import HydraException
from omegaconf import DictConfig, OmegaConf, open_dict
from omegaconf.errors import OmegaConfBaseException

from pegame import sweep
from pegame.config import compose
from pegame.errors import ConfigError, PegameError
from pegame.files import write_atomic
from pegame.job import checked_scenario, run_job
from pegame.play.server import Server
from pegame.play.session import Latencies, Session, activate

LOOPBACK = ("127.0.0.1", "localhost", "::1")


def game_overrides(overrides: Sequence[str]) -> list[str]:
    """The command line's overrides with the person as the evader and the page as the
    recorder (a ``recorder=X`` choice becomes ``recorder.then=X``); ConfigError for an
    evader other than human."""
    out, then = [], "rerun"
    for override in overrides:
        key, _, value = override.partition("=")
        if key.lstrip("+~") == "evader" and value != "human":
            raise ConfigError(
                f"Invalid value for 'evader': {value!r}. Allowed: human (the person at the "
                "page is the evader; python -m pegame plays the other evaders)."
            )
        if key.lstrip("+~") == "recorder":
            then = value
            continue
        if key.lstrip("+~") != "evader":
            out.append(override)
    return ["evader=human", "recorder=play", f"recorder.then={then}", *out]


def composed(overrides: Sequence[str]) -> DictConfig:
    """The game's config; ConfigError for one that plays several games per job."""
    cfg = compose(game_overrides(overrides))
    if cfg.game.trials != 1:
        raise ConfigError(
            f"Invalid value for 'game.trials': {cfg.game.trials}. Allowed: 1 (the page "
            "offers another game after each one)."
        )
    return cfg


def parse(argv: Sequence[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        prog="python -m pegame.play",
        description="Play the evader in a browser against any pursuer (a pegame game).",
    )
    parser.add_argument("--host", default="127.0.0.1", help="address to listen on (localhost)")
    parser.add_argument("--port", type=int, default=8765, help="port (0: any free port)")
    parser.add_argument("--games", type=int, default=0, help="stop after N games (0: no limit)")
    parser.add_argument("--out", type=Path, default=None, help="output directory")
    parser.add_argument("overrides", nargs="*", help="Hydra overrides, e.g. env=brick")
    args = parser.parse_args(argv)
    if args.games < 0:
        parser.error(f"--games must be 0 or more, got {args.games}")
    return args


def play(args: argparse.Namespace) -> int:
    """Serve the page and play its games (module docstring); the exit status."""
    cfg = composed(args.overrides)
    checked_scenario(cfg, os.getcwd())  # a bad config fails here, before serving
    stamp = datetime.datetime.now().strftime("%Y-%m-%d_%H-%M-%S")
    out = (args.out or Path("outputs") / "play" / stamp).resolve()
    session = Session()
    server = Server(session, args.host, args.port)
    try:
        url = server.start()
    except OSError as exc:
        raise ConfigError(
            f"Invalid value for '--host'/'--port': {args.host}:{args.port} cannot be served "
            f"({exc.strerror or exc}). Allowed: an address of this machine and a free port "
            "(--port 0 picks one)."
        ) from None
    played, status, playing = 0, sweep.OK, False
    try:
        if args.host not in LOOPBACK:
            print(f"pegame.play: listening on {args.host}, reachable from other machines")
        print(f"pegame.play: open {url} in a browser (Ctrl-C stops)", flush=True)
        activate(session)
        while not args.games or played < args.games:
            session.starts.acquire()
            if not session.connected:
                if played:
                    break  # the page closed after a game: nobody is left to play
                continue
            played, playing = played + 1, True
            status = max(status, play_one(cfg, session, out / f"game_{played}", played, args))
            playing = False
            if not session.connected:
                break
    except KeyboardInterrupt:
        if playing:
            print("pegame.play: interrupted during a game", file=sys.stderr)
            return 130
    finally:
        activate(None)
        server.stop()
    return status


def play_one(
    cfg: DictConfig, session: Session, out_dir: Path, number: int, args: argparse.Namespace
) -> int:
    """Game ``number`` into ``out_dir``, its latencies written beside its results."""
    game_cfg = OmegaConf.create(OmegaConf.to_container(cfg))
    assert isinstance(game_cfg, DictConfig)
    with open_dict(game_cfg):
        game_cfg.game.seed = int(cfg.game.seed) + number - 1
    session.evader_taken, session.latencies = False, Latencies()
    session.set_command(0.0, 0.0)  # the evader stands until the page sends a command
    try:
        run = run_job(game_cfg, out_dir, base_dir=os.getcwd(), overrides=list(args.overrides))
    finally:
        session.evader_taken = False
    latencies = session.latencies.summary()
    write_atomic(out_dir / "latency.json", json.dumps(latencies, indent=2) + "\n")
    print(latency_line(latencies))
    print(f"output: {out_dir}", flush=True)
    return run.status


def latency_line(summary: dict[str, dict[str, float | int | None]]) -> str:
    """One line of a game's measured latencies (ms)."""
    parts = []
    labels = (
        ("key_to_command", "key->command"),
        ("key_to_server", "key->server"),
        ("tick_to_frame", "tick->frame"),
    )
    for name, label in labels:
        s = summary[name]
        parts.append(
            f"{label} median {s['median']} ms, p95 {s['p95']} ms (n={s['count']})"
            if s["count"]
            else f"{label}: no samples"
        )
    return (
        "latency: " + "; ".join(parts) + f"; ticks late by at most {summary['tick_lag']['max']} ms"
    )


def main(argv: Sequence[str] | None = None) -> int:
    """Console entry point: the exit status (module docstring)."""
    logging.basicConfig(level=logging.WARNING, format="pegame.play: %(message)s")
    args = parse(sys.argv[1:] if argv is None else argv)
    try:
        return play(args)
    except PegameError as exc:
        print(f"pegame: error: {exc}", file=sys.stderr)
        return sweep.BAD_INPUT
    except (HydraException, OmegaConfBaseException) as exc:  # an override Hydra refused
        print(f"pegame: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return sweep.BAD_INPUT


if __name__ == "__main__":
    sys.exit(main())
