"""One Hydra job: ``game.trials`` games with seeds ``game.seed + i`` in one output dir.

Each finished game appends one JSON line ``{"kind": "game", ...result}`` to the job's
``results.jsonl`` and flushes it at once; a game that raises appends ``{"kind":
"failed", ...}`` with its traceback in ``failed_<seed>.txt`` and the job goes on; the job's
``{"kind": "summary", ...}`` line comes last. With ``resume=true`` games already stored
are skipped. A job of one game also writes ``result.json`` (last, atomically),
``trajectory.csv`` and ``trajectory.png``; recordings are ``game.rrd``, or
``game_<seed>.rrd`` when the job plays several games.
"""

from __future__ import annotations

import json
import logging
import os
import sys
import time
import traceback
from pathlib import Path
from typing import Any, Iterator

from omegaconf import DictConfig, OmegaConf

from pegame.config import GameConfig, typed
from pegame.errors import PegameError
from pegame.files import write_atomic
from pegame.game import Game, Outcome, pairing, summary_line, write_outcome

log = logging.getLogger("pegame")

RESULTS = "results.jsonl"


def stored_seeds(path: Path) -> set[int]:
    """Seeds of the games already in ``path`` (a results.jsonl); truncated lines skipped."""
    seeds = set()
    if path.exists():
        for line in path.read_text().splitlines():
            try:
                entry = json.loads(line)
            except json.JSONDecodeError:
                continue
            if entry.get("kind") == "game":
                seeds.add(int(entry["seed"]))
    return seeds


def append_line(path: Path, entry: dict[str, Any]) -> None:
    """Append one JSON line and flush it (append-only: earlier lines stay intact). After a
    job killed mid-line, the fragment is closed first so the new line stays readable."""
    with path.open("ab+") as handle:
        if handle.seek(0, os.SEEK_END) > 0:
            handle.seek(-1, os.SEEK_END)
            if handle.read(1) != b"\n":
                handle.write(b"\n")
        handle.write(json.dumps(entry).encode() + b"\n")
        handle.flush()


def with_seed(cfg: DictConfig, seed: int) -> DictConfig:
    """A copy of ``cfg`` with ``game.seed`` set to ``seed``."""
    copy = cfg.copy()
    OmegaConf.update(copy, "game.seed", seed)
    return copy


def progress(seeds: list[int]) -> Iterator[int]:
    """Iterate ``seeds`` with a progress bar when stderr is a terminal."""
    if not sys.stderr.isatty() or len(seeds) < 2:
        return iter(seeds)
    from tqdm import tqdm

    return iter(tqdm(seeds, desc="games", unit="game"))


def run_job(cfg: DictConfig, out_dir: str | Path, base_dir: str | Path | None = None) -> list[dict]:
    """Play the job's games into ``out_dir``; return the results of the games played now."""
    out_dir = Path(out_dir)
    settings = typed(cfg.game, GameConfig, "game")
    results_path = out_dir / RESULTS
    done = stored_seeds(results_path) if cfg.get("resume", False) else set()
    seeds = [s for s in range(settings.seed, settings.seed + settings.trials) if s not in done]
    if done:
        log.info("resume: %d of %d games already stored", settings.trials - len(seeds), settings.trials)
    single = settings.trials == 1
    results, failed = [], 0
    for seed in progress(seeds):
        started = time.perf_counter()
        try:
            game = Game(with_seed(cfg, seed), base_dir=base_dir)
            outcome = game.play(out_dir, "game" if single else f"game_{seed}")
        except PegameError:
            raise  # a bad config or map fails every game alike: stop and say why
        except Exception as exc:  # noqa: BLE001 - a failing game must not stop the sweep
            failed += 1
            record_failure(out_dir, seed, cfg, exc)
            continue
        log.info("seed %d played in %.2f s wall time", seed, time.perf_counter() - started)
        append_line(results_path, {"kind": "game", **outcome.result})
        results.append(outcome.result)
        if single:
            write_single(outcome, game, out_dir)
        print(summary_line(outcome.result))
    rates = [r["tracking_rate"] for r in results]
    append_line(results_path, {
        "kind": "summary",
        "games": len(results),
        "failed": failed,
        "tracking_rate_mean": round(sum(rates) / len(rates), 6) if rates else None,
    })
    return results


def write_single(outcome: Outcome, game: Game, out_dir: Path) -> None:
    """A one-game job's files: trajectory.png, trajectory.csv, then result.json."""
    from pegame.figures import plot_trajectory

    plot_trajectory(game.context.grid, outcome.trajectory, out_dir / "trajectory.png",
                    title=summary_line(outcome.result))
    write_outcome(outcome, out_dir)


def record_failure(out_dir: Path, seed: int, cfg: DictConfig, exc: Exception) -> None:
    """Log a failed game, keep its traceback, and append a 'failed' line."""
    text = "".join(traceback.format_exception(exc))
    write_atomic(out_dir / f"failed_{seed}.txt", text)
    log.error("seed %d failed: %s (traceback in failed_%d.txt)", seed, exc, seed)
    append_line(out_dir / RESULTS, {
        "kind": "failed",
        "seed": seed,
        "pairing": pairing(str(cfg.pursuer.name), str(cfg.evader.name)),
        "map": str(cfg.env.name),
        "speed_ratio": float(cfg.game.speed_ratio),
        "error": f"{type(exc).__name__}: {exc}".splitlines()[0],
        "traceback_file": f"failed_{seed}.txt",
    })
