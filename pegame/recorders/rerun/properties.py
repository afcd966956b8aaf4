"""A recording's identity and properties: its id, its name, the config and the result.

Recording id: a UUID5 of the output directory, the game id and the run config. The same
game written to the same place always gets the same id, and two runs (two Hydra run
directories) opened together stay two recordings instead of being merged by the viewer.
Properties (Rerun's ``__properties`` entities): ``config`` (the run config, flattened to
dotted keys), and at the end ``result`` (a finished game's result dict) or ``failure``
(a failed game's error).
"""

from __future__ import annotations

import json
import uuid
from pathlib import Path
from typing import Any

import pyarrow as pa
import rerun as rr


def recording_id(out_dir: str | Path, game_id: str, properties: dict[str, Any]) -> str:
    """UUID5 of the absolute output directory, the game id and the config (see module doc)."""
    key = json.dumps(
        [str(Path(out_dir).resolve()), game_id, properties], sort_keys=True, default=str
    )
    return str(uuid.uuid5(uuid.NAMESPACE_URL, f"pegame:{key}"))


def recording_name(game_id: str, properties: dict[str, Any]) -> str:
    """'<game_id>: <pursuer> pursuer vs <evader> evader on <map>', from the run config."""

    def name(group: str) -> str:
        node = properties.get(group)
        return str(node.get("name", "?")) if isinstance(node, dict) else "?"

    return f"{game_id}: {name('pursuer')} pursuer vs {name('evader')} evader on {name('env')}"


def send_property(rec: rr.RecordingStream, name: str, values: dict[str, Any]) -> None:
    """A recording property of flat {key: value} pairs (none: nothing to send). The values
    go in as one-element Arrow arrays: the same column types as rerun-sdk infers, without
    its per-value inference (half the time)."""
    if values:
        rec.send_property(
            name, rr.AnyValues(**{key: pa.array([value]) for key, value in values.items()})
        )


def flat_config(tree: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """The config as {'game.seed': 0, ...}: numbers, bools and strings kept, the rest as text."""
    flat: dict[str, Any] = {}
    for key, value in tree.items():
        if isinstance(value, dict):
            flat.update(flat_config(value, f"{prefix}{key}."))
        elif value is not None:
            flat[f"{prefix}{key}"] = (
                value if isinstance(value, (bool, int, float, str)) else str(value)
            )
    return flat
