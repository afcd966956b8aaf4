"""The Hydra app: ``python -m pegame [overrides]`` (also the ``pegame`` console script).

Plays ``game.trials`` games (one by default) with the composed config in Hydra's run
directory (see :mod:`pegame.job` for the files). In a multirun sweep (``-m``) the
recorder is off unless ``recorder=...`` is given on the command line. A bad config, map
or plugin name is reported as one paragraph with exit status 2 and no traceback (set
HYDRA_FULL_ERROR=1 for one); in a multirun the bad job writes an ``invalid`` line and
the other jobs run. Exit status (:mod:`pegame.sweep`): 0 every game of every job
finished, 1 some games failed (recorded), 2 bad input; 130 after Ctrl-C or SIGTERM.

A job writes to its directory only once it owns it (:func:`pegame.job.run_job` calls
``adopt``): Hydra's files (``.hydra/``, which Hydra is told not to write,
``hydra.output_subdir: null``) and the job's log (``pegame.log``; its records until then
are held in memory) are written then, so a refused run leaves the directory as it was.
"""

from __future__ import annotations

import logging
import logging.handlers
import os
import signal
import sys
from collections.abc import Callable
from pathlib import Path

import hydra
from hydra.core.hydra_config import HydraConfig
from hydra.errors import HydraException
from hydra.types import RunMode
from hydra.utils import get_original_cwd
from omegaconf import DictConfig, OmegaConf, open_dict
from omegaconf.errors import OmegaConfBaseException

from pegame import sweep
from pegame.config import register_schema
from pegame.errors import JobDirectoryError, PegameError, ResultsWriteError
from pegame.files import make_dir, write_atomic
from pegame.overrides import check_overrides

log = logging.getLogger("pegame")


def sweep_defaults(cfg: DictConfig) -> None:
    """In a multirun, turn the recorder off unless the command line chose one; never open
    a live viewer per game when a run plays several games."""
    hydra_cfg = HydraConfig.get()
    multirun = hydra_cfg.mode == RunMode.MULTIRUN
    chosen = any(o.split("=", 1)[0].lstrip("+~") == "recorder" for o in hydra_cfg.overrides.task)
    with open_dict(cfg):
        if multirun and not chosen and cfg.recorder.name != "none":
            cfg.recorder = OmegaConf.create({"name": "none"})
        if (multirun or cfg.game.trials > 1) and cfg.recorder.get("spawn", False):
            log.warning("recorder.spawn ignored: this run plays several games")
            cfg.recorder.spawn = False


def report_error(exc: PegameError) -> None:
    """The one paragraph a user sees for bad input, on stderr and in the job's log."""
    print(f"pegame: error: {exc}", file=sys.stderr)
    log.error("%s", exc)


class HeldLog:
    """The job's log file held back: its handlers (Hydra's file handler, opened lazily,
    ``delay: true``) are detached from the root logger and the records kept in memory
    until :meth:`write` attaches them, with the records so far, or :meth:`drop` discards
    them (a refused run writes no log into another job's directory)."""

    def __init__(self, out_dir: str) -> None:
        root = logging.getLogger()
        inside = Path(out_dir).resolve()
        self.handlers = [
            h
            for h in root.handlers
            if isinstance(h, logging.FileHandler) and Path(h.baseFilename).parent == inside
        ]
        self.memory = logging.handlers.MemoryHandler(capacity=1 << 30, flushLevel=1 << 30)
        for handler in self.handlers:
            root.removeHandler(handler)
        root.addHandler(self.memory)

    def write(self) -> None:
        """Attach the log's handlers and write the records held so far."""
        root = logging.getLogger()
        root.removeHandler(self.memory)
        for handler in self.handlers:
            for record in self.memory.buffer:
                if record.levelno >= handler.level:
                    handler.handle(record)
            root.addHandler(handler)
        self.memory.buffer.clear()
        self.handlers = []

    def drop(self) -> None:
        """Discard the records and close the log's handlers unopened."""
        logging.getLogger().removeHandler(self.memory)
        self.memory.buffer.clear()
        for handler in self.handlers:
            handler.close()
        self.handlers = []


def adopter(cfg: DictConfig, out_dir: str, held: HeldLog) -> Callable[[], None]:
    """What a job writes once it owns ``out_dir``: Hydra's files of the job in ``.hydra/``
    (the composed ``cfg``, Hydra's config and the overrides, as Hydra writes them) and the
    log held so far."""
    hydra_cfg = HydraConfig.instance().cfg
    texts = {
        "config.yaml": OmegaConf.to_yaml(cfg),
        "hydra.yaml": OmegaConf.to_yaml(hydra_cfg),
        "overrides.yaml": OmegaConf.to_yaml(HydraConfig.get().overrides.task),
    }

    def adopt() -> None:
        folder = make_dir(Path(out_dir) / ".hydra")
        for name, text in texts.items():
            write_atomic(folder / name, text)
        held.write()

    return adopt


@hydra.main(version_base=None, config_path="pkg://pegame.conf", config_name="config")
def _app(cfg: DictConfig) -> int:
    from pegame.job import run_job, write_invalid

    hydra_cfg = HydraConfig.get()
    out_dir, overrides = hydra_cfg.runtime.output_dir, list(hydra_cfg.overrides.task)
    held = HeldLog(out_dir)
    adopt = adopter(cfg, out_dir, held)
    try:
        sweep_defaults(cfg)
        multirun = hydra_cfg.mode == RunMode.MULTIRUN
        cell = f"#{hydra_cfg.job.num} {' '.join(overrides)}".rstrip() if multirun else None
        status = run_job(
            cfg, out_dir, base_dir=get_original_cwd(), overrides=overrides, adopt=adopt, cell=cell
        ).status
        if not multirun:
            print(f"output: {out_dir}")
    except PegameError as exc:
        if os.environ.get("HYDRA_FULL_ERROR") == "1":
            raise
        mine = hydra_cfg.mode == RunMode.MULTIRUN and not isinstance(
            exc, (JobDirectoryError, ResultsWriteError)
        )  # not another job's directory, nor one that cannot be written
        if mine:  # an invalid cell of this sweep: its log and its line say why
            held.write()
        report_error(exc)
        if mine:
            try:
                write_invalid(out_dir, exc, overrides)
            except PegameError as unwritten:
                report_error(unwritten)
        status = sweep.BAD_INPUT
    finally:
        held.drop()  # a refused run's records were shown on the console only
    sweep.job_ended(status)
    return status


def report_broken_sweep(sweep_dir: Path, error: BaseException | None) -> None:
    """After the launcher stopped a multirun (a worker process died): the report of the
    games stored so far, and one paragraph saying what happened and how to complete it."""
    from pegame.report import write_report

    try:
        write_report(sweep_dir)
        written = f"the report of the games stored so far is in {sweep_dir}"
    except Exception as exc:
        written = f"no report could be written ({exc})"
    print(
        f"pegame: error: the launcher stopped the sweep ({type(error).__name__}: a worker "
        f"process died, e.g. killed or out of memory); the jobs it ran and those not yet "
        f"started did not finish; {written}. Run the sweep again with resume=true to "
        f"complete it.",
        file=sys.stderr,
    )


def _terminate(signum: int, frame: object) -> None:
    raise KeyboardInterrupt  # SIGTERM unwinds like Ctrl-C: the launcher stops its workers


def main() -> None:
    """Console-script entry point; exits with the run's status."""
    register_schema()
    signal.signal(signal.SIGTERM, _terminate)
    # SIGINT as well: Python leaves it ignored when the process starts with it ignored (a
    # background job, a test runner's worker), and an interrupt must still stop the sweep.
    signal.signal(signal.SIGINT, _terminate)
    try:
        check_overrides(sys.argv[1:])
        _app()
    except SystemExit as exc:
        if exc.code == 1 and isinstance(exc.__context__, (HydraException, OmegaConfBaseException)):
            sys.exit(sweep.BAD_INPUT)  # Hydra reported (and exited on) a bad command line
        broken = sweep.end_broken_sweep() if exc.code == 1 else None
        if broken is None:
            raise
        report_broken_sweep(broken, exc.__context__)
        sys.exit(sweep.GAMES_FAILED)
    except PegameError as exc:
        print(f"pegame: error: {exc}", file=sys.stderr)  # before Hydra: no job log yet
        sys.exit(sweep.BAD_INPUT)
    except KeyboardInterrupt:
        print(
            "pegame: interrupted; the games stored so far are kept (resume=true completes the run)",
            file=sys.stderr,
        )
        sys.exit(130)
    sys.exit(sweep.worst())


if __name__ == "__main__":
    main()
