"""Hydra callbacks, run in the process that Hydra starts in: check the output directory
before Hydra writes to it, collect a multirun's exit statuses and write the sweep report."""

from __future__ import annotations

import logging
import sys
from typing import Any, NoReturn

from hydra.experimental.callback import Callback
from omegaconf import DictConfig

from pegame import sweep
from pegame.errors import PegameError
from pegame.files import make_dir

log = logging.getLogger("pegame")


def refuse(exc: PegameError) -> NoReturn:
    """Stop the run before Hydra writes a file: one message, exit status 2."""
    print(f"pegame: error: {exc}", file=sys.stderr)
    raise SystemExit(sweep.BAD_INPUT)  # passes through Hydra, which catches Exception only


class OutputDirCallback(Callback):
    """A single run's directory must be one pegame can write to (not a file, not on a
    read-only file system): checked, and created, before Hydra writes its log there."""

    def on_run_start(self, config: DictConfig, **kwargs: Any) -> None:
        try:
            make_dir(config.hydra.run.dir)
        except PegameError as exc:
            refuse(exc)


class ExitStatusCallback(Callback):
    """Gives the jobs of a multirun a status directory and collects their statuses at the
    end, so ``python -m pegame -m ...`` exits with the worst (see :mod:`pegame.sweep`)."""

    def on_multirun_start(self, config: DictConfig, **kwargs: Any) -> None:
        try:
            sweep.start_sweep(config.hydra.sweep.dir, resume=bool(config.get("resume", False)))
        except PegameError as exc:  # another sweep's directory, or one pegame cannot write
            refuse(exc)

    def on_multirun_end(self, config: DictConfig, **kwargs: Any) -> None:
        status = sweep.end_sweep()
        if status != sweep.OK:
            log.warning("some jobs of the sweep did not finish every game (exit status %d)", status)


class ReportCallback(Callback):
    """Runs :func:`pegame.report.write_report` on the sweep directory at the end of a
    multirun, so the tables, plots and hypothesis tests sit beside the results."""

    def on_multirun_end(self, config: DictConfig, **kwargs: Any) -> None:
        from pegame.report import write_report

        sweep_dir = config.hydra.sweep.dir
        try:
            write_report(sweep_dir)
        except Exception as exc:
            log.error("could not write the sweep report in %s: %s", sweep_dir, exc)
        else:
            log.info("sweep report written in %s", sweep_dir)
