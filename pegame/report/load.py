"""Find the jobs of one or more sweep directories and read their ``results.jsonl`` lines.

A line is one JSON object whose ``kind`` is ``game``, ``failed``, ``invalid`` or
``summary`` (written by :mod:`pegame.job`). Each line is validated here, key by key and
type by type, so that later stages can trust it: a line that is cut (a job killed
mid-write), of an unknown kind, without a required key or with a value of the wrong type
is skipped and listed with its reason, never a traceback. Every record kept is tagged
with its ``job`` (a POSIX path relative to its sweep directory, prefixed with that
directory when several are read) and its ``line`` number; an old line without ``config``
of a job that kept its ``.hydra/config.yaml`` gets that config.
"""

from __future__ import annotations

import json
import logging
import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from pegame.errors import PegameError

log = logging.getLogger("pegame.report")

RESULTS = "results.jsonl"
NOT_CONFIG = (
    ("game", "seed"),
    ("game", "trials"),
    ("resume",),
    ("hydra",),
)  # vary per job, not per configuration


class ReportError(PegameError, OSError):
    """The report cannot read its sweep directories or cannot write its files."""


def is_number(value: Any) -> bool:
    """A finite int or float (not a bool)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def is_rate(value: Any) -> bool:
    """A number in [0, 1]."""
    return is_number(value) and 0 <= value <= 1


def is_int(value: Any) -> bool:
    """An int (not a bool)."""
    return isinstance(value, int) and not isinstance(value, bool)


def is_str(value: Any) -> bool:
    """A string."""
    return isinstance(value, str)


def is_str_list(value: Any) -> bool:
    """A list of strings."""
    return isinstance(value, list) and all(isinstance(v, str) for v in value)


def is_dict(value: Any) -> bool:
    """A JSON object."""
    return isinstance(value, dict)


Check = tuple[Callable[[Any], bool], str]  # (test, what is allowed)
NUMBER: Check = (is_number, "a finite number")
RATE: Check = (is_rate, "a number in [0, 1]")
INT: Check = (is_int, "an integer")
STR: Check = (is_str, "a string")
STR_LIST: Check = (is_str_list, "a list of strings")
DICT: Check = (is_dict, "an object")

# Per kind: the keys that must be present, and the optional keys checked when present.
REQUIRED: dict[str, dict[str, Check]] = {
    "game": {
        "map": STR,
        "speed_ratio": NUMBER,
        "pursuer": STR,
        "evader": STR,
        "seed": INT,
        "pairing": STR,
        "tracking_rate": RATE,
    },
    "failed": {"map": STR, "speed_ratio": NUMBER, "pairing": STR, "seed": INT, "error": STR},
    "invalid": {"error": STR},
    "summary": {},
}
OPTIONAL: dict[str, Check] = {
    "config": DICT,
    "config_hash": STR,
    "overrides": STR_LIST,
    "provenance": DICT,
    "estimator": STR,
    "detector": STR,
    "sim": STR,
    "t_max": NUMBER,
    "control_hz": NUMBER,
    "decision_hz": NUMBER,
    "loss_causes": DICT,
}


@dataclass
class Sweep:
    """What the sweep directories hold."""

    records: list[dict[str, Any]] = field(default_factory=list)  # game/failed, tagged job, line
    invalid: list[dict[str, Any]] = field(default_factory=list)  # invalid-config jobs
    summaries: list[dict[str, Any]] = field(default_factory=list)
    missing: list[dict[str, Any]] = field(default_factory=list)  # {"job", "overrides"}
    unfinished: list[str] = field(default_factory=list)  # jobs whose last record is no summary
    skipped: list[dict[str, Any]] = field(default_factory=list)  # {"file", "line", "reason"}


def natural_key(text: str) -> list[Any]:
    """Sort key that orders '2/x' before '10/x'."""
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", text)]


def relative(path: Path, root: Path) -> str:
    """``path`` relative to ``root`` as a POSIX string ('.' for root itself)."""
    return path.relative_to(root).as_posix() or "."


def find_job_dirs(root: Path) -> list[Path]:
    """Directories at or below ``root`` holding a job (a ``.hydra`` dir or a results.jsonl)."""
    dirs = {p.parent for p in root.rglob(RESULTS)}
    dirs |= {p.parent for p in root.rglob(".hydra") if p.is_dir()}
    return sorted(dirs, key=lambda d: natural_key(relative(d, root)))


def read_overrides(job: Path) -> list[str] | None:
    """The job's Hydra overrides from ``.hydra/overrides.yaml``, None when absent or unreadable."""
    path = job / ".hydra" / "overrides.yaml"
    try:
        overrides = yaml.safe_load(path.read_text()) if path.is_file() else None
    except (OSError, yaml.YAMLError):
        return None
    return [str(o) for o in overrides] if isinstance(overrides, list) else None


def job_config(job: Path) -> dict[str, Any] | None:
    """The job's resolved config from ``.hydra/config.yaml`` without the keys of
    :data:`NOT_CONFIG`; None when absent or unreadable. For old lines, which carry no
    ``config`` of their own."""
    path = job / ".hydra" / "config.yaml"
    try:
        config = yaml.safe_load(path.read_text()) if path.is_file() else None
    except (OSError, yaml.YAMLError):
        return None
    if not isinstance(config, dict):
        return None
    for *parents, leaf in NOT_CONFIG:
        node: Any = config
        for parent in parents:
            node = node.get(parent) if isinstance(node, dict) else None
        if isinstance(node, dict):
            node.pop(leaf, None)
    return config


def problem(record: Any) -> str | None:
    """Why a decoded line is unusable, or None when it is a valid record."""
    if not isinstance(record, dict) or record.get("kind") not in REQUIRED:
        return f"not a record of kind {', '.join(REQUIRED)}"
    kind = record["kind"]
    absent = [key for key in REQUIRED[kind] if record.get(key) is None]
    if absent:
        return f"{kind} record without {', '.join(absent)}"
    checks = {**OPTIONAL, **REQUIRED[kind]}
    wrong = [
        f"'{key}' is {record[key]!r}, allowed: {checks[key][1]}"
        for key in checks
        if record.get(key) is not None and not checks[key][0](record[key])
    ]
    return f"{kind} record with a wrong type: {'; '.join(wrong)}" if wrong else None


def parse_line(line: str) -> tuple[dict[str, Any] | None, str | None]:
    """A results.jsonl line as (record, None), or (None, why it is unusable)."""
    try:
        record = json.loads(line)
    except json.JSONDecodeError as error:
        return None, f"invalid JSON ({error.msg}; truncated write?)"
    except RecursionError:
        return None, "invalid JSON (nested too deeply)"
    reason = problem(record)
    return (None, reason) if reason else (record, None)


def read_jsonl(path: Path, name: str) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """The records of one results.jsonl, tagged with their ``line``, and its skipped lines
    ({file: name, line, reason}); an unreadable file is one skipped entry with line None."""
    records, skipped = [], []
    try:
        text = path.read_text(encoding="utf-8", errors="replace")  # a cut may split a character
    except OSError as error:
        log.warning("skipping %s: cannot read it (%s)", name, error.strerror or error)
        return [], [
            {"file": name, "line": None, "reason": f"unreadable ({error.strerror or error})"}
        ]
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        record, reason = parse_line(line)
        if reason is not None:
            log.warning("skipping %s line %d: %s", name, number, reason)
            skipped.append({"file": name, "line": number, "reason": reason})
        elif record is not None:  # parse_line gives a record or a reason
            records.append({**record, "line": number})
    return records, skipped


def load_sweep(roots: str | Path | Sequence[str | Path]) -> Sweep:
    """Read every job below the sweep directories ``roots`` (one path or several, in order:
    later directories' lines come after earlier ones')."""
    paths = [Path(r) for r in ([roots] if isinstance(roots, (str, Path)) else roots)]
    for root in paths:
        if not root.is_dir():
            raise ReportError(
                f"No such sweep directory: {root}. Give the directory of a "
                f"multirun (the one holding the numbered job directories)."
            )
    sweep = Sweep()
    for root in paths:
        prefix = "" if len(paths) == 1 else f"{root.as_posix()}/"
        for job in find_job_dirs(root):
            read_job(
                sweep, job, prefix + relative(job, root), prefix + relative(job / RESULTS, root)
            )
    return sweep


def read_job(sweep: Sweep, job: Path, name: str, file_name: str) -> None:
    """Add one job's records to ``sweep``."""
    path = job / RESULTS
    if not path.is_file():
        sweep.missing.append({"job": name, "overrides": read_overrides(job)})
        return
    records, skipped = read_jsonl(path, file_name)
    sweep.skipped += skipped
    old = [r for r in records if r["kind"] in ("game", "failed") and r.get("config") is None]
    config = job_config(job) if old else None
    for record in old if config is not None else []:
        record["config"] = config
    tagged = [{**record, "job": name} for record in records]
    sweep.records += [r for r in tagged if r["kind"] in ("game", "failed")]
    sweep.invalid += [r for r in tagged if r["kind"] == "invalid"]
    sweep.summaries += [r for r in tagged if r["kind"] == "summary"]
    if not tagged or tagged[-1]["kind"] not in ("summary", "invalid"):
        sweep.unfinished.append(name)  # killed, maybe after a resume
