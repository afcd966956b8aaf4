"""The Hydra app: ``python -m pegame [overrides]`` (also the ``pegame`` console script).

Plays ``game.trials`` games (one by default) with the composed config in Hydra's run
directory (see :mod:`pegame.job` for the files). In a multirun sweep (``-m``) the
recorder is off unless ``recorder=...`` is given on the command line. A bad config, map
or plugin name is reported as one paragraph with exit status 2 and no traceback (set
HYDRA_FULL_ERROR=1 for one); in a multirun the bad job writes an ``invalid`` line and
the other jobs run. Exit status (:mod:`pegame.sweep`): 0 every game of every job
finished, 1 some games failed (recorded), 2 bad input; 130 after Ctrl-C or SIGTERM.
"""

from __future__ import annotations

import logging
import os
import signal
import sys
from collections.abc import Sequence
from importlib.metadata import entry_points
from importlib.resources import files

import hydra
from hydra.core.hydra_config import HydraConfig
from hydra.errors import HydraException
from hydra.types import RunMode
from hydra.utils import get_original_cwd
from omegaconf import DictConfig, OmegaConf, open_dict
from omegaconf.errors import OmegaConfBaseException

from pegame import sweep
from pegame.api import PLUGIN_KINDS
from pegame.config import did_you_mean, register_schema
from pegame.errors import JobDirectoryError, PegameError, PluginChoiceError

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


@hydra.main(version_base=None, config_path="pkg://pegame.conf", config_name="config")
def _app(cfg: DictConfig) -> int:
    from pegame.job import run_job, write_invalid

    hydra_cfg = HydraConfig.get()
    out_dir, overrides = hydra_cfg.runtime.output_dir, list(hydra_cfg.overrides.task)
    try:
        sweep_defaults(cfg)
        status = run_job(cfg, out_dir, base_dir=get_original_cwd(), overrides=overrides).status
    except PegameError as exc:
        if os.environ.get("HYDRA_FULL_ERROR") == "1":
            raise
        report_error(exc)
        if hydra_cfg.mode == RunMode.MULTIRUN and not isinstance(exc, JobDirectoryError):
            write_invalid(out_dir, exc, overrides)  # another job's directory stays its own
        status = sweep.BAD_INPUT
    sweep.job_ended(status)
    return status


def plugin_options(kind: str) -> list[str]:
    """The config options of plugin group ``kind`` that Hydra finds on pegame's search
    path: pegame's own ``conf/<kind>/*.yaml`` and those of plugin distributions."""
    packages = ["pegame.conf", *(point.value for point in entry_points(group="pegame.configs"))]
    options = set()
    for package in packages:
        try:
            folder = files(package) / kind
        except ModuleNotFoundError:
            continue
        if folder.is_dir():
            options |= {item.name[:-5] for item in folder.iterdir() if item.name.endswith(".yaml")}
    return sorted(options)


def check_plugin_choices(args: Sequence[str]) -> None:
    """PluginChoiceError, with the closest option, for ``kind=name`` on the command line
    when ``name`` is no option of that plugin group (``pursuer=smrt``; every value of a
    sweep ``pursuer=smart,smrt``). Skipped when the user adds config directories, whose
    options only Hydra knows."""
    from hydra.core.override_parser.overrides_parser import OverridesParser

    if any(
        a.startswith(("--config-dir", "-cd", "--config-path", "-cp", "hydra.searchpath"))
        for a in args
    ):
        return
    candidates = [a for a in args if "=" in a and not a.startswith("-")]
    try:
        parsed = OverridesParser.create().parse_overrides(candidates)
    except Exception:
        return
    for override in parsed:
        kind = override.key_or_group
        if kind not in PLUGIN_KINDS or override.package or override.is_delete():
            continue
        values = (
            list(override.sweep_string_iterator())
            if override.is_sweep_override()
            else [override.get_value_element_as_str()]
        )
        options = plugin_options(kind)
        for value in values:
            if value not in options:
                raise PluginChoiceError(
                    f"Unknown {kind} '{value}'.{did_you_mean(value, options)} Available: "
                    f"{', '.join(options)}. A plugin option is a file {kind}/<name>.yaml in "
                    f"pegame's conf or a plugin distribution's (see python -m pegame.catalog)."
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
        check_plugin_choices(sys.argv[1:])
        _app()
    except SystemExit as exc:
        if exc.code == 1 and isinstance(exc.__context__, (HydraException, OmegaConfBaseException)):
            sys.exit(sweep.BAD_INPUT)  # Hydra reported (and exited on) a bad command line
        raise
    except PluginChoiceError as exc:
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
