"""The Hydra app: ``python -m pegame [overrides]`` (also the ``pegame`` console script).

Plays ``game.trials`` games (one by default) with the composed config in Hydra's run
directory (see :mod:`pegame.job` for the files). In a multirun sweep (``-m``) the
recorder is off unless ``recorder=...`` is given on the command line. A bad config, map
or plugin name is reported as one paragraph with exit status 2 and no traceback (set
HYDRA_FULL_ERROR=1 for one).
"""

from __future__ import annotations

import logging
import os
import sys

import hydra
from hydra.core.hydra_config import HydraConfig
from hydra.types import RunMode
from hydra.utils import get_original_cwd
from omegaconf import DictConfig, OmegaConf, open_dict

from pegame.config import register_schema
from pegame.errors import PegameError

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


@hydra.main(version_base=None, config_path="pkg://pegame.conf", config_name="config")
def _app(cfg: DictConfig) -> None:
    from pegame.job import run_job

    try:
        sweep_defaults(cfg)
        run_job(cfg, HydraConfig.get().runtime.output_dir, base_dir=get_original_cwd())
    except PegameError as exc:
        if os.environ.get("HYDRA_FULL_ERROR") == "1":
            raise
        log.error("%s", exc)
        print(f"pegame: error: {exc}", file=sys.stderr)
        sys.exit(2)


def main() -> None:
    """Console-script entry point."""
    register_schema()
    _app()


if __name__ == "__main__":
    main()
