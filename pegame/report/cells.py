"""A sweep's cells are its configurations.

Every game record carries its settings: the job's resolved ``config`` flattened to dotted
keys (``detector.miss_probability``), or, for old lines without ``config``, the top-level
fields named in :data:`LEGACY` under the same dotted keys. A setting whose value differs
between two games (among the games that have it) is a *factor*. The paper's axes are the
environment (``map``), the speed ratio v_p/v_e and the pairing; the settings that follow
those axes (``env.*`` follows the map, ``pursuer.*`` and ``evader.*`` follow the pairing)
belong to them. Every other factor is shown beside them, so a *cell* is one combination
of (map, speed ratio, pairing, other factors): one configuration.

Games are identified by (config hash, seed): only two games of the same configuration
and seed are duplicates, and the later one wins (jobs in the order read, lines in file
order). A cell that mixes code versions or config hashes is flagged.
"""

from __future__ import annotations

import hashlib
import json
import re
from dataclasses import dataclass, field
from typing import Any

from pegame.report.measures import is_value, values
from pegame.report.statistics import describe

MAP_ORDER = ("hall", "enclosed", "brick")
PAIRING_ORDER = ("R-R", "S-R", "S-S", "R-S")
AXES = ("map", "speed_ratio", "pairing")
# Old lines (no "config"): their top-level fields and the config keys they stand for.
LEGACY = {
    "map": "env.name",
    "speed_ratio": "game.speed_ratio",
    "pursuer": "pursuer.name",
    "evader": "evader.name",
    "estimator": "estimator.name",
    "detector": "detector.name",
    "sim": "sim.name",
    "t_max": "game.t_max",
    "control_hz": "game.control_hz",
    "decision_hz": "game.decision_hz",
}
# Settings that belong to a paper axis: the key (or key prefix) and the axis it follows.
FOLLOWS = (
    ("env.", "map"),
    ("game.speed_ratio", "speed_ratio"),
    ("pursuer.", "pairing"),
    ("evader.", "pairing"),
)
CODE = ("pegame", "commit", "dirty")  # the provenance fields that name the code version


def flatten(tree: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """A nested dict as {dotted key: leaf value}; lists are leaves."""
    flat: dict[str, Any] = {}
    for key, value in tree.items():
        if isinstance(value, dict) and value:
            flat.update(flatten(value, f"{prefix}{key}."))
        else:
            flat[f"{prefix}{key}"] = value
    return flat


def canonical(value: Any) -> str:
    """Canonical JSON: sorted keys, no spaces (what config hashes are computed over)."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"), default=str)


def settings(record: dict[str, Any]) -> dict[str, Any]:
    """The game's settings as {dotted key: value}."""
    if record.get("config") is not None:
        return flatten(record["config"])
    return {key: record[field_] for field_, key in LEGACY.items() if record.get(field_) is not None}


def identity(record: dict[str, Any]) -> str:
    """The configuration's hash: the line's ``config_hash``, else the sha256 of the canonical
    JSON of its ``config`` (of its :data:`LEGACY` settings for old lines)."""
    if record.get("config_hash"):
        return record["config_hash"]
    config = record["config"] if record.get("config") is not None else settings(record)
    return hashlib.sha256(canonical(config).encode()).hexdigest()


def code_version(record: dict[str, Any]) -> dict[str, Any] | None:
    """(pegame version, commit, dirty) of the line, None for lines without provenance."""
    provenance = record.get("provenance")
    return None if provenance is None else {key: provenance.get(key) for key in CODE}


def value_key(value: Any) -> tuple:
    """A sort key for setting values of mixed types: numbers, strings, others, then None."""
    if value is None:
        return (3, "")
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return (0, float(value))
    return (1, value) if isinstance(value, str) else (2, canonical(value))


def value_text(value: Any) -> str:
    """A setting value for a table: numbers with :g, None as '–'."""
    if value is None:
        return "–"
    if isinstance(value, float):
        return f"{value:g}"
    return value if isinstance(value, str) else canonical(value)


def ordered(values: set[str], preferred: tuple[str, ...]) -> list[str]:
    """``values`` with the ``preferred`` ones first in that order, the rest sorted."""
    return [v for v in preferred if v in values] + sorted(values - set(preferred))


@dataclass
class Selection:
    """The games the report counts, the failed games still open, and the duplicates."""

    games: list[dict[str, Any]]
    failed: list[dict[str, Any]]
    duplicates: list[dict[str, Any]]  # {"config_hash", "seed", "kept", "dropped": [...]}


def where(record: dict[str, Any]) -> str:
    """'<job> line <n>'."""
    return f"{record['job']} line {record['line']}"


def failure_key(record: dict[str, Any], legacy: bool) -> tuple:
    """What a failed line names: (config hash, seed), or for old failed lines (they carry no
    strategy names) (map, speed_ratio, pairing, seed)."""
    if legacy:
        return (
            "legacy",
            record["map"],
            float(record["speed_ratio"]),
            record["pairing"],
            record["seed"],
        )
    return identity(record), record["seed"]


def select(records: list[dict[str, Any]]) -> Selection:
    """The latest game per (config hash, seed), the duplicates it replaced, and the failed
    games (latest per config hash and seed) that no later finished game replaced."""
    games: dict[tuple, tuple[int, dict]] = {}
    dropped: dict[tuple, list[dict]] = {}
    failures: dict[tuple, tuple[int, dict]] = {}
    for index, record in enumerate(records):
        if record["kind"] == "game":
            key = identity(record), record["seed"]
            if key in games:
                dropped.setdefault(key, []).append(games[key][1])
            games[key] = (index, record)
        else:
            failures[failure_key(record, record.get("config") is None)] = (index, record)
    finished: dict[tuple, int] = {}
    for index, record in games.values():
        for legacy in (False, True):
            key = failure_key(record, legacy)
            finished[key] = max(index, finished.get(key, -1))
    failed = [r for key, (i, r) in failures.items() if finished.get(key, -1) < i]
    duplicates = [
        {
            "config_hash": key[0],
            "seed": key[1],
            "kept": where(games[key][1]),
            "dropped": [where(r) for r in old],
        }
        for key, old in dropped.items()
    ]
    return Selection([record for _, record in games.values()], failed, duplicates)


def axis_value(record: dict[str, Any], axis: str) -> Any:
    """The record's value on one paper axis (map, speed_ratio or pairing)."""
    return float(record["speed_ratio"]) if axis == "speed_ratio" else record[axis]


def follows_axis(key: str) -> str | None:
    """The paper axis a setting belongs to, None for the others."""
    return next(
        (
            axis
            for prefix, axis in FOLLOWS
            if key == prefix or (prefix.endswith(".") and key.startswith(prefix))
        ),
        None,
    )


def hashable(value: Any) -> Any:
    """A setting value usable as a dict key (lists and dicts by their canonical JSON)."""
    return canonical(value) if isinstance(value, (list, dict)) else value


def other_factors(games: list[dict[str, Any]]) -> list[str]:
    """The settings that differ between games (among the games that have them), other than
    those that follow a paper axis (a setting of ``env.*`` that is one value per map, of
    ``pursuer.*``/``evader.*`` one value per pairing), sorted."""
    values: dict[str, set] = {}
    per_axis: dict[str, dict[Any, set]] = {}
    for game in games:
        for key, value in settings(game).items():
            values.setdefault(key, set()).add(hashable(value))
            axis = follows_axis(key)
            if axis is not None:
                per_axis.setdefault(key, {}).setdefault(axis_value(game, axis), set()).add(
                    hashable(value)
                )
    differing = [key for key, seen in values.items() if len(seen) > 1]
    return sorted(
        key
        for key in differing
        if follows_axis(key) is None or any(len(s) > 1 for s in per_axis[key].values())
    )


@dataclass
class Cell:
    """One configuration: its place in the paper's table, its other factors, its games."""

    map: str
    speed_ratio: float
    pairing: str
    factors: dict[str, Any]  # {setting: value} of the other factors (None: the game lacks it)
    games: list[dict[str, Any]] = field(default_factory=list)

    @property
    def rates(self) -> list[float]:
        """The tracking rates of its games, fractions in [0, 1]."""
        return [float(g["tracking_rate"]) for g in self.games]

    def values(self, name: str) -> list[float]:
        """The measure ``name`` of its games that define it (:mod:`~pegame.report.measures`)."""
        return values(self.games, name)

    @property
    def facet(self) -> tuple:
        """The combination of the other factors (for figures and hypothesis tests)."""
        return tuple(hashable(v) for v in self.factors.values())

    def config_hashes(self) -> list[str]:
        """The distinct config hashes of its games, sorted."""
        return sorted({identity(g) for g in self.games})

    def code_versions(self) -> list[dict[str, Any] | None]:
        """The distinct code versions of its games (None: a line without provenance)."""
        versions = {canonical(code_version(g)): code_version(g) for g in self.games}
        return [versions[k] for k in sorted(versions)]

    def mixed(self) -> list[str]:
        """What this cell mixes ('code versions', 'config hashes'), empty when nothing."""
        return [
            what
            for what, n in (
                ("code versions", len(self.code_versions())),
                ("config hashes", len(self.config_hashes())),
            )
            if n > 1
        ]

    def label(self) -> str:
        """'enclosed, v_p/v_e 1, S-R, detector.miss_probability=0.3'."""
        parts = [self.map, f"v_p/v_e {self.speed_ratio:g}", self.pairing]
        return ", ".join(parts + [f"{k}={value_text(v)}" for k, v in self.factors.items()])

    def summary(self, name: str = "tracking_rate") -> dict[str, Any]:
        """The cell for report.json: its place, factors, statistics of the measure ``name``
        and provenance."""
        return {
            "map": self.map,
            "speed_ratio": self.speed_ratio,
            "pairing": self.pairing,
            "factors": self.factors,
            **describe(self.values(name)),
            "config_hashes": self.config_hashes(),
            "code_versions": self.code_versions(),
        }


def group_cells(games: list[dict[str, Any]], factors: list[str]) -> list[Cell]:
    """The games grouped into cells, ordered by other factors, then map (paper order),
    speed ratio and pairing (paper order)."""
    cells: dict[tuple, Cell] = {}
    for game in games:
        flat = settings(game)
        values = {key: flat.get(key) for key in factors}
        key = (
            game["map"],
            float(game["speed_ratio"]),
            game["pairing"],
            tuple(hashable(v) for v in values.values()),
        )
        cells.setdefault(key, Cell(*key[:3], values)).games.append(game)
    maps = ordered({c.map for c in cells.values()}, MAP_ORDER)
    pairings = ordered({c.pairing for c in cells.values()}, PAIRING_ORDER)
    return sorted(
        cells.values(),
        key=lambda c: (
            [value_key(v) for v in c.factors.values()],
            maps.index(c.map),
            c.speed_ratio,
            pairings.index(c.pairing),
        ),
    )


def file_safe(text: str) -> str:
    """``text`` as a file name stem: characters unsafe in file names as '_'."""
    return re.sub(r"[^\w.-]", "_", text)


def numeric_factors(cells: list[Cell]) -> list[str]:
    """The other factors whose value is a number in every cell (n_particles = 100, 500,
    2000), in factor order: those a figure draws as a curve."""
    factors = list(cells[0].factors) if cells else []
    return [f for f in factors if all(is_value(c.factors[f]) for c in cells)]


def facets(cells: list[Cell]) -> list[tuple[dict[str, Any], list[Cell]]]:
    """The cells split by combination of the other factors, in table order: [(factors,
    cells)]; one facet with empty factors when there are none (or no cells)."""
    split: dict[tuple, tuple[dict[str, Any], list[Cell]]] = {}
    for cell in cells:
        split.setdefault(cell.facet, (cell.factors, []))[1].append(cell)
    return list(split.values()) or [({}, [])]
