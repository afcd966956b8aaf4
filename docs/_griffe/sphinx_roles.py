"""A griffe extension for the API reference: pegame's docstrings use Sphinx's inline roles
(:class:`pegame.api.Pursuer`, :func:`~pegame.grid.load_map`); mkdocstrings renders
Markdown, so each role becomes a code span of its target's last name (or the whole target
where it is not a dotted path), and RST's double-backquoted literals single code spans. A
bare index such as detections[i][j] becomes a code span too, which Markdown would otherwise
read as a reference link."""

from __future__ import annotations

import re
from typing import Any

from griffe import Extension, Object

ROLE = re.compile(r":(?:py:)?(?:class|func|meth|mod|attr|data|obj|exc|const):`~?([^`]+)`")
LITERAL = re.compile(r"``([^`]+)``")
INDEXED = re.compile(r"(?<![`\w])(\w+(?:\[\w+\]){2,})")


def _code(match: re.Match[str]) -> str:
    target = match.group(1)
    return f"`{target.rsplit('.', 1)[-1] if '.' in target and ' ' not in target else target}`"


class SphinxRolesToCode(Extension):
    """Rewrites every docstring's Sphinx roles as Markdown code spans when it is loaded."""

    def on_instance(self, *, obj: Object, **kwargs: Any) -> None:
        if obj.docstring is not None:
            text = LITERAL.sub(r"`\1`", ROLE.sub(_code, obj.docstring.value))
            obj.docstring.value = INDEXED.sub(r"`\1`", text)
