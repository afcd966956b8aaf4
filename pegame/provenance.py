"""Where a result came from: the software that produced it and the config that identifies it.

Every game and failed-game line of a job's ``results.jsonl`` carries both (see
:mod:`pegame.job`): ``provenance`` (pegame's version, the git commit and whether the
checkout had uncommitted changes, the Python, numpy and numba versions, and every
distribution that provides pegame plugins) and ``config`` with its ``config_hash``. The
config of a job is its resolved config without the keys that vary between the games of
one study cell or only steer the run (``game.seed``, ``game.trials``, ``resume``,
``hydra``), so two games belong together exactly when their config hashes are equal.
"""

from __future__ import annotations

import hashlib
import json
import platform
import subprocess
from collections.abc import Mapping
from functools import lru_cache
from importlib.metadata import distributions, version
from pathlib import Path
from typing import Any

from omegaconf import DictConfig, OmegaConf

from pegame.api import PLUGIN_KINDS

#: dotted keys left out of a job's config identity: they differ between the games of one cell
RUN_KEYS = ("game.seed", "game.trials", "resume", "hydra")

#: entry-point groups whose providers count as pegame plugin distributions
PLUGIN_ENTRY_POINT_GROUPS = frozenset(
    [spec.entry_point_group for spec in PLUGIN_KINDS.values()] + ["pegame.configs"]
)


def job_config(cfg: DictConfig | Mapping[str, Any]) -> dict[str, Any]:
    """The job's resolved config as a nested dict, without :data:`RUN_KEYS`."""
    config = OmegaConf.to_container(cfg, resolve=True) if isinstance(cfg, DictConfig) else dict(cfg)
    config = json.loads(json.dumps(config))  # a deep copy made only of JSON types
    for dotted in RUN_KEYS:
        *parents, leaf = dotted.split(".")
        node = config
        for part in parents:
            node = node.get(part, {}) if isinstance(node, dict) else {}
        if isinstance(node, dict):
            node.pop(leaf, None)
    return config


def config_hash(config: Mapping[str, Any]) -> str:
    """Hex sha256 of the canonical JSON of ``config`` (sorted keys, no whitespace)."""
    canonical = json.dumps(config, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(canonical.encode()).hexdigest()


def differing_keys(a: Mapping[str, Any], b: Mapping[str, Any], prefix: str = "") -> list[str]:
    """Dotted keys whose values differ between the nested dicts ``a`` and ``b`` (a key
    present in only one of them counts), sorted."""
    keys = []
    for key in sorted(set(a) | set(b)):
        dotted = f"{prefix}{key}"
        left, right = a.get(key, _ABSENT), b.get(key, _ABSENT)
        if isinstance(left, Mapping) and isinstance(right, Mapping):
            keys += differing_keys(left, right, f"{dotted}.")
        elif left != right:
            keys.append(dotted)
    return keys


_ABSENT = object()


@lru_cache(maxsize=1)
def provenance() -> dict[str, Any]:
    """The software behind this process's results; computed once per process."""
    import numba
    import numpy

    commit, dirty = git_state(Path(__file__).resolve().parent.parent)
    return {
        "pegame": version("pegame"),
        "commit": commit,
        "dirty": dirty,
        "python": platform.python_version(),
        "numpy": numpy.__version__,
        "numba": numba.__version__,
        "plugins": plugin_distributions(),
    }


def git_state(root: Path) -> tuple[str | None, bool | None]:
    """(commit, has uncommitted changes) of the git checkout at ``root``, or (None, None)
    when pegame does not run from a git checkout (an installed wheel) or git is missing."""
    if not (root / ".git").exists():
        return None, None
    try:
        commit = _git(root, "rev-parse", "HEAD")
        status = _git(root, "status", "--porcelain", "--untracked-files=no")
    except (OSError, subprocess.SubprocessError):
        return None, None
    return commit, bool(status)


def _git(root: Path, *args: str) -> str:
    return subprocess.run(
        ["git", "-C", str(root), *args], capture_output=True, text=True, check=True, timeout=10
    ).stdout.strip()


def plugin_distributions() -> dict[str, str]:
    """{distribution: version} of every installed distribution providing pegame entry
    points (pegame itself included), sorted by name."""
    found = {}
    for dist in distributions():
        if any(point.group in PLUGIN_ENTRY_POINT_GROUPS for point in dist.entry_points):
            found[dist.metadata["Name"]] = dist.version
    return dict(sorted(found.items()))
