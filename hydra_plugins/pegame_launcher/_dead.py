"""What the sweep's process records for a job whose worker process died: the game the
job was playing is a failed game of the job (a ``failed`` line naming the cause, as
:func:`pegame.job.record_failure` writes for a game that raised), and the job's status
is 1. The line carries the job's config identity, so ``resume=true`` plays that game
again and keeps the games stored before it."""

from __future__ import annotations

import copy
import logging
import signal
from pathlib import Path

from hydra.core.hydra_config import HydraConfig
from omegaconf import DictConfig, open_dict, read_write

from pegame import sweep
from pegame.errors import PegameError
from pegame.job import RESULTS, read_lines, record_failure
from pegame.joblock import JobLock
from pegame.provenance import config_hash, job_config, provenance

log = logging.getLogger("pegame")


class WorkerDied(Exception):
    """The worker process running a job died (a signal, or an exit without a result)."""


def cause(exitcode: int | None) -> str:
    """How a worker process ended, from its exit code: 'worker killed by signal 9
    (SIGKILL)', or 'worker exited with status 1'."""
    if exitcode is not None and exitcode < 0:
        try:
            name = f" ({signal.Signals(-exitcode).name})"
        except ValueError:
            name = ""
        return f"worker killed by signal {-exitcode}{name}"
    return f"worker exited with status {exitcode}"


def job_dir(sweep_config: DictConfig) -> Path:
    """The job's directory, as Hydra's run_job resolves it."""
    return Path(str(sweep_config.hydra.sweep.dir)) / str(sweep_config.hydra.sweep.subdir)


def entries(sweep_config: DictConfig) -> int:
    """How many entries the job's results.jsonl holds (before the job starts)."""
    return sum(1 for _ in read_lines(job_dir(sweep_config) / RESULTS))


def task_config(sweep_config: DictConfig) -> DictConfig:
    """The config the job's games were played with: what pegame's app makes of the job's
    config (its multirun defaults applied with the job's Hydra config in place)."""
    from pegame.__main__ import sweep_defaults

    cfg = copy.deepcopy(sweep_config)
    with read_write(cfg), open_dict(cfg):
        del cfg["hydra"]
    hydra_config = HydraConfig.instance()
    previous = hydra_config.cfg
    hydra_config.set_config(sweep_config)
    try:
        sweep_defaults(cfg)
    finally:
        hydra_config.cfg = previous
    return cfg


def record_dead_job(sweep_config: DictConfig, overrides: list[str], before: int, why: str) -> None:
    """Record the job of ``sweep_config`` as failed: its worker died (``why``) while it
    played the first game of its seeds that is neither stored nor failed since it started
    (its results.jsonl held ``before`` entries then); status 1 for the sweep."""
    sweep.job_ended(sweep.GAMES_FAILED)
    cfg = task_config(sweep_config)
    out_dir = job_dir(sweep_config)
    lines = list(read_lines(out_dir / RESULTS))
    settled = {e.get("seed") for e in lines if e.get("kind") == "game"}
    settled |= {e.get("seed") for e in lines[before:] if e.get("kind") == "failed"}
    first = int(cfg.game.seed)
    seed = next((s for s in range(first, first + int(cfg.game.trials)) if s not in settled), None)
    num = sweep_config.hydra.job.num
    if seed is None:  # it died after its last game: every game is stored
        log.error("job #%d: %s after its last game (no summary line)", num, why)
        return
    config = job_config(cfg)
    identity = {
        "config": config,
        "config_hash": config_hash(config),
        "overrides": overrides,
        "provenance": provenance(),
    }
    try:
        with JobLock(out_dir):
            record_failure(out_dir, seed, cfg, WorkerDied(why), identity)
    except PegameError as exc:
        log.error("job #%d: %s; its failure could not be recorded: %s", num, why, exc)
