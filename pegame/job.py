"""One Hydra job: ``game.trials`` games with seeds ``game.seed + i`` in one output dir.

Each finished game appends one JSON line ``{"kind": "game", ...result}`` to the job's
``results.jsonl`` and flushes it at once; a game that raises (a SpawnError for its seed, a
plugin failing mid-game) appends ``{"kind": "failed", ...}`` naming the seed and the
cause, with its traceback in ``failed_<seed>.txt``, and the job goes on; the job's
``{"kind": "summary", ...}`` line comes last. Game and failed lines carry the job's
``config`` (without seed, trials, resume and hydra), its ``config_hash``, the
command-line ``overrides`` and the ``provenance`` of the software
(:mod:`pegame.provenance`).

Everything that does not depend on the seed is checked before the first game (the whole
config, the map, every plugin and its options): a bad value is a
:class:`~pegame.errors.PegameError` and nothing is played. The job holds the directory's
lock (:mod:`pegame.joblock`) while it runs. With ``resume=true`` a game is skipped when a
game with the same config hash and seed is stored; a directory holding games of another
config is an error naming the keys that differ. Only a job that passed those checks
writes to the directory: ``adopt`` (Hydra's files of the job, its log) is called then, so
a refused job leaves the directory as it was. A job of one game also writes
``result.json`` (last, atomically), ``trajectory.csv`` and ``trajectory.png``;
recordings are ``game.rrd``, or ``game_<seed>.rrd`` when the job plays several games.
"""

from __future__ import annotations

import json
import logging
import math
import os
import sys
import time
import traceback
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from omegaconf import DictConfig

from pegame import files, sweep
from pegame.bootstrap import bootstrap_ci
from pegame.config import check_known_keys
from pegame.errors import JobDirectoryError, PegameError, ResultsWriteError, SpawnError
from pegame.game import Game, Outcome, Scenario, pairing, summary_line, write_outcome
from pegame.joblock import JobLock
from pegame.provenance import config_hash, differing_keys, job_config, provenance

log = logging.getLogger("pegame")

RESULTS = "results.jsonl"


@dataclass
class JobRun:
    """What one call of :func:`run_job` did: the results of the games it played and the
    seeds of the games that failed."""

    played: list[dict[str, Any]] = field(default_factory=list)
    failed: list[int] = field(default_factory=list)

    @property
    def status(self) -> int:
        """The job's exit status: 0 every game finished, 1 some failed."""
        return sweep.GAMES_FAILED if self.failed else sweep.OK


def read_lines(path: Path) -> Iterator[dict[str, Any]]:
    """The entries (JSON objects) of a results.jsonl; lines truncated by a killed job,
    lines that are no JSON object and bytes that are no UTF-8 are skipped (and anything but
    a regular file holds none)."""
    if path.is_file():
        for line in path.read_bytes().decode("utf-8", errors="replace").splitlines():
            try:
                entry = json.loads(line)
            except (json.JSONDecodeError, RecursionError):
                continue
            if isinstance(entry, dict):
                yield entry


def stored_seeds(path: Path, config: dict[str, Any]) -> set[int]:
    """Seeds of the games of ``config`` already stored in ``path`` (a results.jsonl).

    Raises JobDirectoryError naming the differing keys when ``path`` holds games or failed
    games of another config: one job directory holds one config's games."""
    digest, seeds = config_hash(config), set()
    for entry in read_lines(path):
        if entry.get("kind") not in ("game", "failed"):
            continue
        if entry.get("config_hash") != digest:
            other = entry.get("config")
            keys = (
                differing_keys(other, config)
                if isinstance(other, dict)
                else ["(unrecorded config)"]
            )
            raise JobDirectoryError(
                f"{path} holds games of another config (seed {entry.get('seed')}); this job "
                f"differs in: {', '.join(keys)}. One job directory holds one config's games: "
                f"choose another output directory (hydra.run.dir or hydra.sweep.dir) or move "
                f"the old results away."
            )
        seed = entry.get("seed")
        if entry["kind"] == "game" and isinstance(seed, int) and not isinstance(seed, bool):
            seeds.add(seed)
    return seeds


def append_line(path: Path, entry: dict[str, Any]) -> None:
    """Append one JSON line and flush it (append-only: earlier lines stay intact). After a
    job killed mid-line, the fragment is closed first so the new line stays readable.

    A write that fails (a full disk) raises ResultsWriteError naming the file; the line
    is printed in full on stderr first, so a finished game's result can be recovered."""
    line = json.dumps(entry).encode() + b"\n"
    try:
        files.append_line(path, line)
    except ResultsWriteError as exc:
        print(
            f"pegame: this line could not be written to {path}:\n{line.decode()}",
            file=sys.stderr,
            end="",
        )
        raise ResultsWriteError(f"{exc} The unwritten line is printed above on stderr.") from None


def say(line: str) -> None:
    """Print ``line`` on stdout in one write with its newline: under PYTHONUNBUFFERED,
    print writes a line and its end apart, and a sweep's processes share the stream, so
    another's line could be written between them and join this one."""
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


def progress(seeds: list[int]) -> Iterator[int]:
    """Iterate ``seeds`` with a progress bar when stderr is a terminal."""
    if not sys.stderr.isatty() or len(seeds) < 2:
        return iter(seeds)
    from tqdm import tqdm

    return iter(tqdm(seeds, desc="games", unit="game"))


def run_job(
    cfg: DictConfig,
    out_dir: str | Path,
    base_dir: str | Path | None = None,
    overrides: Sequence[str] = (),
    adopt: Callable[[], None] | None = None,
    cell: str | None = None,
) -> JobRun:
    """Play the job's games into ``out_dir``, holding its lock; ``overrides`` are the
    command-line overrides recorded with every game; ``adopt`` is called once every check
    passed, before the first game (the app writes Hydra's files and the log then); ``cell``
    names the job at the head of each game line (a sweep's cell, ``#3 env=hall ...``).
    A job of several games ends with a line of their mean tracking rate and its 95%
    bootstrap CI.
    PegameError before the first game for a config that cannot be played at all, or a
    directory that belongs to another job; nothing is written to the directory then."""
    out_dir = Path(out_dir)
    with sweep.watched_job(), JobLock(out_dir):
        return _run_locked(cfg, out_dir, base_dir, list(overrides), adopt, cell)


def _run_locked(
    cfg: DictConfig,
    out_dir: Path,
    base_dir: str | Path | None,
    overrides: list[str],
    adopt: Callable[[], None] | None,
    cell: str | None,
) -> JobRun:
    scenario = checked_scenario(cfg, base_dir)
    settings = scenario.settings
    config = job_config(cfg)
    results_path = out_dir / RESULTS
    stored = stored_seeds(results_path, config)
    done = stored if cfg.get("resume", False) else set()
    seeds = [s for s in range(settings.seed, settings.seed + settings.trials) if s not in done]
    prepared = built_game(scenario, seeds[0] if seeds else settings.seed)
    if adopt is not None:
        adopt()
    if done:
        log.info(
            "resume: %d of %d games already stored", settings.trials - len(seeds), settings.trials
        )
    identity = {
        "config": config,
        "config_hash": config_hash(config),
        "overrides": overrides,
        "provenance": provenance(),
    }
    single, parent, run = settings.trials == 1, sweep.sweep_parent(), JobRun()
    for seed in progress(seeds):
        if sweep.orphaned(parent):
            stop_orphaned(len(run.played))
        started = time.perf_counter()
        try:
            game = (
                prepared if prepared is not None and prepared.seed == seed else scenario.game(seed)
            )
            prepared = None
            outcome = game.play(out_dir, "game" if single else f"game_{seed}")
        except (Exception, SystemExit) as exc:  # a plugin's sys.exit fails its game only
            run.failed.append(seed)
            record_failure(out_dir, seed, cfg, exc, identity)
            continue
        log.info("seed %d played in %.2f s wall time", seed, time.perf_counter() - started)
        append_line(results_path, {"kind": "game", **outcome.result, **identity})
        run.played.append(outcome.result)
        if single:
            write_single(outcome, game, out_dir)
        say(f"{cell}: {summary_line(outcome.result)}" if cell else summary_line(outcome.result))
    if prepared is not None:
        prepared.plugins.sim.close()
    rates = [r["tracking_rate"] for r in run.played]
    if settings.trials > 1 and rates:
        say(f"{cell}: {mean_line(rates)}" if cell else mean_line(rates))
    append_line(
        results_path,
        {
            "kind": "summary",
            "games": len(run.played),
            "failed": len(run.failed),
            "tracking_rate_mean": round(sum(rates) / len(rates), 6) if rates else None,
            "status": run.status,
        },
    )
    return run


def mean_line(rates: list[float]) -> str:
    """The closing line of a job of several games: their mean tracking rate with its 95%
    percentile-bootstrap CI (:mod:`pegame.bootstrap`, the report's)."""
    low, high = bootstrap_ci(rates)
    return (
        f"{len(rates)} games: mean tracking rate {100 * math.fsum(rates) / len(rates):.1f}% "
        f"[{100 * low:.1f}, {100 * high:.1f}] (95% bootstrap CI)"
    )


def checked_scenario(cfg: DictConfig, base_dir: str | Path | None) -> Scenario:
    """The job's scenario, built once: building it checks everything that does not depend
    on the seed (every key, the map, every plugin and its options), so a bad value fails
    here, before any game is played."""
    check_known_keys(cfg)
    scenario = Scenario(cfg, base_dir)
    check_room_to_spawn(scenario)
    return scenario


def built_game(scenario: Scenario, seed: int) -> Game | None:
    """The game of ``seed``, built before the first game is played: building it builds
    every plugin, which loads what the plugins read (a policy file or module), so a bad
    path is a PegameError here, not a failure of every game. Any other error (a plugin
    failing for this seed, even with SystemExit) is left to the game: None."""
    try:
        return scenario.game(seed)
    except PegameError:
        raise
    except (Exception, SystemExit):
        return None


def check_room_to_spawn(scenario: Scenario) -> None:
    """SpawnError before the first game when the map has no free pose at all for the
    pursuer or the evader: then no seed can spawn them (a seed that finds no valid pair
    where poses exist is that game's failure, recorded like any other)."""
    from pegame.navigation import Planner

    context = scenario.context
    for role, body in (("pursuer", context.pursuer), ("evader", context.evader)):
        if not Planner.shared(context.grid, body.radius).traversable.any():
            raise SpawnError(
                f"No valid spawn on map '{context.grid.name}': no cell is free for the {role} "
                f"(radius {body.radius} m). Use a map with more free space or a smaller "
                f"{role}.radius."
            )


def stop_orphaned(stored: int) -> None:
    """Exit this worker process at once: the sweep's process died, so nothing would
    collect its work and a resume may already be running. The games stored so far stay
    (each line was flushed when its game finished); the lock goes with the process."""
    log.warning(
        "the sweep's process died: this worker stops after %d games played now; "
        "run the sweep again with resume=true to complete it",
        stored,
    )
    logging.shutdown()
    os._exit(sweep.GAMES_FAILED)


def write_invalid(out_dir: str | Path, error: PegameError, overrides: Sequence[str]) -> None:
    """Record a multirun job whose config cannot be played: one ``invalid`` line, so the
    sweep report shows the cell as failed and the other cells still run."""
    files.make_dir(out_dir)
    append_line(
        Path(out_dir) / RESULTS,
        {
            "kind": "invalid",
            "error": " ".join(str(error).split()),
            "overrides": list(overrides),
        },
    )


def write_single(outcome: Outcome, game: Game, out_dir: Path) -> None:
    """A one-game job's files: trajectory.png, trajectory.csv, then result.json."""
    from pegame.figures import plot_trajectory

    try:
        plot_trajectory(
            game.context.grid,
            outcome.trajectory,
            out_dir / "trajectory.png",
            title=summary_line(outcome.result),
            header=outcome.header or None,
        )
        write_outcome(outcome, out_dir)
    except OSError as exc:
        raise ResultsWriteError(
            f"{exc} The game's result is stored in {out_dir / RESULTS}."
        ) from None


def record_failure(
    out_dir: Path, seed: int, cfg: DictConfig, exc: BaseException, identity: dict[str, Any]
) -> None:
    """Log a failed game, keep its traceback, and append a 'failed' line naming the seed
    and the cause."""
    text = "".join(traceback.format_exception(exc))
    files.write_atomic(out_dir / f"failed_{seed}.txt", text)
    log.error("seed %d failed: %s (traceback in failed_%d.txt)", seed, exc, seed)
    append_line(
        out_dir / RESULTS,
        {
            "kind": "failed",
            "seed": seed,
            "pairing": pairing(str(cfg.pursuer.name), str(cfg.evader.name)),
            "map": str(cfg.env.name),
            "speed_ratio": float(cfg.game.speed_ratio),
            "error": f"{type(exc).__name__}: {exc}".splitlines()[0],
            "traceback_file": f"failed_{seed}.txt",
            **identity,
        },
    )
