"""The Hydra app: ``python -m pegame [overrides]`` (also the ``pegame`` console script).

Plays one game with the composed config and writes into Hydra's run directory:
``.hydra/`` (the composed config), ``trajectory.csv``, ``result.json`` (last, atomically)
and ``pegame.log``. A bad config, map or plugin name is reported as one paragraph with a
non-zero exit status and no traceback (set HYDRA_FULL_ERROR=1 for one).
"""

from __future__ import annotations

import logging
import os
import sys
import time

import hydra
from hydra.core.hydra_config import HydraConfig
from hydra.utils import get_original_cwd
from omegaconf import DictConfig

from pegame.config import register_schema
from pegame.errors import PegameError

log = logging.getLogger("pegame")


def run(cfg: DictConfig) -> dict:
    """Play the configured game in Hydra's output directory; return its result."""
    from pegame.game import Game, summary_line, write_outcome

    out_dir = HydraConfig.get().runtime.output_dir
    started = time.perf_counter()
    game = Game(cfg, base_dir=get_original_cwd())
    outcome = game.play(out_dir)
    write_outcome(outcome, out_dir)
    log.info("played in %.2f s wall time; outputs in %s", time.perf_counter() - started, out_dir)
    print(summary_line(outcome.result))
    return outcome.result


@hydra.main(version_base=None, config_path="pkg://pegame.conf", config_name="config")
def _app(cfg: DictConfig) -> None:
    try:
        run(cfg)
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
