"""``python -m pegame.catalog``: every registered plugin per group, with the distribution
that provides it and its one-line description.

``python -m pegame.catalog GROUP/NAME`` (``pursuer/smart``) prints that plugin's
parameters: each field of its ``Config`` dataclass with its type, its default (the
option file's value where the file sets one) and the field's comment, which gives its
unit. The comment is the one written beside the field in the source, the single place a
default is documented.
"""

from __future__ import annotations

import argparse
import ast
import dataclasses
import inspect
import sys
import textwrap
from collections.abc import Sequence
from typing import Any

from omegaconf import OmegaConf

from pegame import registry
from pegame.config import did_you_mean
from pegame.defaults import option_file


def table() -> str:
    """The listing as text, one block per config group."""
    lines = []
    for group, ep_group in registry.GROUPS.items():
        lines.append(f"{group} ({ep_group})")
        for name, dist, text in registry.describe(group):
            lines.append(f"  {name:<16} {dist:<16} {text}")
    return "\n".join(lines)


def field_comments(config: type) -> dict[str, str]:
    """The comment beside each field of the dataclass ``config`` and of its bases, read
    from their source (``standoff: float = 1.5  # m, distance ...``, or inside the value's
    parentheses where the formatter wrapped it); a subclass's wins."""
    comments: dict[str, str] = {}
    for cls in reversed(config.__mro__):
        if not dataclasses.is_dataclass(cls):
            continue
        try:
            source = textwrap.dedent(inspect.getsource(cls))
        except (OSError, TypeError):
            continue
        lines, tree = source.splitlines(), ast.parse(source).body[0]
        if not isinstance(tree, ast.ClassDef):
            continue
        for node in tree.body:
            if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
                span = lines[node.lineno - 1 : node.end_lineno or node.lineno]
                found = [line.partition("# ")[2].strip() for line in span if "# " in line]
                if found:
                    comments[node.target.id] = " ".join(found)
    return comments


def parameters(group: str, name: str) -> list[tuple[str, str, Any, str]]:
    """(field, type, default, comment) of every parameter of plugin ``name`` of ``group``;
    the default is the option file's value where it sets one."""
    config = registry.load(group, name).Config
    file = option_file(group, name)
    written = OmegaConf.to_container(OmegaConf.load(file.open())) if file is not None else {}
    assert isinstance(written, dict)
    comments = field_comments(config)
    rows = []
    for field in dataclasses.fields(config):
        if field.default is not dataclasses.MISSING:
            default: Any = field.default
        elif field.default_factory is not dataclasses.MISSING:
            default = field.default_factory()
        else:
            default = "(required)"
        default = written.get(field.name, default)
        kind = field.type if isinstance(field.type, str) else getattr(field.type, "__name__", "")
        rows.append((field.name, str(kind), default, comments.get(field.name, "")))
    return rows


def describe_plugin(group: str, name: str) -> str:
    """One plugin's heading, description and parameter table, as text."""
    cls = registry.load(group, name)
    rows = parameters(group, name)
    head = [f"{group}={name}  ({registry.GROUPS[group]}, {cls.__module__}.{cls.__qualname__})"]
    text = (cls.description or cls.__doc__ or "").strip()
    head += [textwrap.fill(text, 90), ""] if text else [""]
    if not rows:
        return "\n".join([*head, "  no parameters"])
    width = max(len(f"{group}.{row[0]}") for row in rows)
    body = [
        f"  {f'{group}.{field}':<{width}}  {kind:<6} {default!s:<10} {comment}".rstrip()
        for field, kind, default, comment in rows
    ]
    return "\n".join([*head, *body])


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m pegame.catalog",
        description="List the registered plugins, or one plugin's parameters.",
    )
    parser.add_argument("plugin", nargs="?", help="GROUP/NAME, e.g. pursuer/smart")
    args = parser.parse_args(argv)
    if args.plugin is None:
        print(table())
        return 0
    group, _, name = args.plugin.partition("/")
    if group not in registry.GROUPS:
        allowed = ", ".join(registry.GROUPS)
        print(
            f"pegame.catalog: unknown group {group!r} in {args.plugin!r}: give GROUP/NAME with "
            f"GROUP one of {allowed}.{did_you_mean(group, list(registry.GROUPS))}",
            file=sys.stderr,
        )
        return 2
    names = registry.available(group)
    if name not in names:
        print(
            f"pegame.catalog: no {group} plugin named {name!r}; the {group} plugins are "
            f"{', '.join(sorted(names))}.{did_you_mean(name, list(names))}",
            file=sys.stderr,
        )
        return 2
    print(describe_plugin(group, name))
    return 0


if __name__ == "__main__":
    sys.exit(main())
