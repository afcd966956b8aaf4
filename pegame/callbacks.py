"""Hydra callbacks: write the sweep report when a multirun ends."""

from __future__ import annotations

import logging
from typing import Any

from hydra.experimental.callback import Callback
from omegaconf import DictConfig

log = logging.getLogger("pegame")


class ReportCallback(Callback):
    """Runs :func:`pegame.report.write_report` on the sweep directory at the end of a
    multirun, so the tables, plots and hypothesis tests sit beside the results."""

    def on_multirun_end(self, config: DictConfig, **kwargs: Any) -> None:
        from pegame.report import write_report

        sweep_dir = config.hydra.sweep.dir
        try:
            write_report(sweep_dir)
        except Exception as exc:  # noqa: BLE001 - a report problem must not hide the results
            log.error("could not write the sweep report in %s: %s", sweep_dir, exc)
        else:
            log.info("sweep report written in %s", sweep_dir)
