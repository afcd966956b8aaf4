"""Hydra callbacks of a multirun, run in the sweep's process: collect the jobs' exit
statuses and write the sweep report."""

from __future__ import annotations

import logging
from typing import Any

from hydra.experimental.callback import Callback
from omegaconf import DictConfig

from pegame import sweep

log = logging.getLogger("pegame")


class ExitStatusCallback(Callback):
    """Gives the jobs of a multirun a status directory and collects their statuses at the
    end, so ``python -m pegame -m ...`` exits with the worst (see :mod:`pegame.sweep`)."""

    def on_multirun_start(self, config: DictConfig, **kwargs: Any) -> None:
        sweep.start_sweep(config.hydra.sweep.dir)

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
