"""``python -m pegame.catalog``: every registered plugin per group, with the distribution
that provides it and its one-line description."""

from __future__ import annotations

from pegame import registry


def table() -> str:
    """The listing as text, one block per config group."""
    lines = []
    for group, ep_group in registry.GROUPS.items():
        lines.append(f"{group} ({ep_group})")
        for name, dist, text in registry.describe(group):
            lines.append(f"  {name:<16} {dist:<16} {text}")
    return "\n".join(lines)


if __name__ == "__main__":
    print(table())
