"""Results lines for the report's tests: the old shape (today's top-level fields only) and
the contract of the jobs (with config, config_hash, overrides and provenance), and job
directories holding them."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

import numpy as np

STRATEGY = {"R": "random", "S": "smart"}


def game(map_name: str, ratio: float, pairing: str, seed: int, rate: float) -> dict:
    """A finished-game record as pegame writes it (only the fields the report reads, and some)."""
    pursuer, evader = (STRATEGY.get(letter, letter.lower()) for letter in pairing.split("-"))
    return {
        "kind": "game",
        "pairing": pairing,
        "pursuer": pursuer,
        "evader": evader,
        "estimator": "last_seen",
        "detector": "oracle",
        "sim": "grid",
        "map": map_name,
        "seed": seed,
        "speed_ratio": ratio,
        "t_max": 90.0,
        "tracking_rate": rate,
        "visible_rate": rate,
    }


def write_job(
    root: Path,
    name: str,
    records: list[dict],
    overrides: list[str] | None = None,
    tail: str = "",
    summary: bool = True,
) -> Path:
    """A job dir with .hydra/overrides.yaml and results.jsonl (``records``, a summary line
    unless ``summary`` is False, then ``tail`` verbatim)."""
    job = root / name
    (job / ".hydra").mkdir(parents=True)
    (job / ".hydra" / "overrides.yaml").write_text("".join(f"- {o}\n" for o in overrides or []))
    ok = [r for r in records if r["kind"] == "game"]
    if summary:
        records = records + [
            {
                "kind": "summary",
                "games": len(ok),
                "failed": len(records) - len(ok),
                "tracking_rate_mean": None,
            }
        ]
    lines = "".join(json.dumps(r) + "\n" for r in records)
    (job / "results.jsonl").write_text(lines + tail)
    return job


def sweep_games(rates: dict[tuple[str, float, str], list[float]]) -> list[dict]:
    """Game records for {(map, ratio, pairing): rates}, seeds 0.. within each cell."""
    return [
        game(m, r, p, seed, v)
        for (m, r, p), values in rates.items()
        for seed, v in enumerate(values)
    ]


def separated(high: str, low: str, n: int = 12) -> dict:
    """Rates where pairing ``high`` clearly beats ``low`` in 2 maps x 2 speed ratios."""
    rng = np.random.default_rng(1)
    cells = {}
    for m in ("hall", "brick"):
        for r in (0.5, 1.0):
            cells[(m, r, high)] = rng.uniform(0.6, 0.9, n).tolist()
            cells[(m, r, low)] = rng.uniform(0.1, 0.4, n).tolist()
    return cells


PROVENANCE = {
    "pegame": "0.3.0",
    "commit": "4f1c2d9e8a7b6c5d4e3f2a1b0c9d8e7f6a5b4c3d",
    "dirty": False,
    "python": "3.12.3",
    "numpy": "2.1.3",
    "numba": "0.60.0",
    "plugins": {"pegame-pybullet": "0.1.0", "pegame-vision": "0.1.0"},
}


def job_config(**settings: Any) -> dict[str, Any]:
    """A resolved job config (no game.seed, game.trials, resume, hydra) with dotted
    ``settings`` applied, e.g. ``job_config(**{"detector.miss_probability": 0.3})``; a value
    None removes the key."""
    config: dict[str, Any] = {
        "game": {"t_max": 20.0, "control_hz": 10.0, "decision_hz": 1.0, "speed_ratio": 1.0},
        "env": {"name": "enclosed", "map": "enclosed.yaml"},
        "sim": {"name": "grid"},
        "detector": {"name": "oracle", "range_noise": 0.0, "miss_probability": 0.0},
        "estimator": {"name": "particle_filter", "n_particles": 2000, "resampler": "systematic"},
        "pursuer": {"name": "smart", "radius": 0.2, "standoff": 1.5},
        "evader": {"name": "random", "radius": 0.25, "v_max": 0.5},
        "recorder": {"name": "none"},
    }
    for key, value in settings.items():
        *parents, leaf = key.split(".")
        node = config
        for parent in parents:
            node = node.setdefault(parent, {})
        if value is None:
            node.pop(leaf, None)
        else:
            node[leaf] = value
    return config


def config_game(
    seed: int,
    rate: float,
    overrides: tuple[str, ...] = (),
    provenance: dict[str, Any] | None = PROVENANCE,
    kind: str = "game",
    measures: dict[str, Any] | None = None,
    **settings: Any,
) -> dict[str, Any]:
    """A game (or failed) line of the contract: today's fields plus config, config_hash,
    overrides and provenance; a game's ``measures`` (result.json fields, e.g.
    ``{"mean_distance": 2.5}``) are added to it."""
    config = job_config(**settings)
    pursuer, evader = config["pursuer"]["name"], config["evader"]["name"]
    line = {
        "kind": kind,
        "seed": seed,
        "pairing": f"{pursuer[0].upper()}-{evader[0].upper()}",
        "map": config["env"]["name"],
        "speed_ratio": config["game"]["speed_ratio"],
        "config": config,
        "config_hash": hashlib.sha256(
            json.dumps(config, sort_keys=True, separators=(",", ":")).encode()
        ).hexdigest(),
        "overrides": list(overrides),
        "provenance": provenance,
    }
    if kind == "failed":
        return {**line, "error": "RuntimeError: boom", "traceback_file": f"failed_{seed}.txt"}
    return {
        **line,
        "pursuer": pursuer,
        "evader": evader,
        "estimator": config["estimator"]["name"],
        "detector": config["detector"]["name"],
        "sim": config["sim"]["name"],
        "t_max": config["game"]["t_max"],
        "control_hz": 10.0,
        "decision_hz": 1.0,
        "tracking_rate": rate,
        "visible_rate": rate,
        **(measures or {}),
    }


def config_job(
    root: Path,
    name: str,
    seeds: range,
    rates: list[float],
    measures: list[dict[str, Any]] | None = None,
    **settings: Any,
) -> Path:
    """A job of the games ``seeds`` with ``rates`` (and per game its ``measures``, see
    :func:`config_game`), all of one configuration."""
    overrides = [f"{k}={v}" for k, v in settings.items()]
    extra = measures or [{} for _ in seeds]
    return write_job(
        root,
        name,
        [
            config_game(s, r, tuple(overrides), measures=m, **settings)
            for s, r, m in zip(seeds, rates, extra)
        ],
        overrides,
    )


def table_rows(md: str) -> list[list[str]]:
    """The body rows of the first Markdown table, as lists of cell texts."""
    lines = md.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("| "))
    rows = []
    for line in lines[start:]:
        if not line.startswith("|"):
            break
        rows.append([cell.strip() for cell in line.strip("|").split("|")])
    return rows
