"""The union of several visibility regions: what a team of pursuers sees together.

A team's negative information (the evader is not where any pursuer would have seen it)
and the team smart evader's hiding test both need the cells that at least one pursuer's
camera covers, V_k = V_k^1 u ... u V_k^N. :class:`UnionRegion` is that set as a
:class:`pegame.types.Region`, lazily: :meth:`UnionRegion.holds` asks each member only
about the given cells (a :class:`pegame.visibility.VisibilityRegion` casts rays only
towards them), and the whole mask is the members' masks OR-ed at the first read.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from pegame.types import Region


class UnionRegion:
    """The cells inside at least one of ``members`` (one or more regions over the same
    grid, all of shape (H, W))."""

    def __init__(self, members: Sequence[Region]) -> None:
        if not members:
            raise ValueError("A union region needs at least one member region.")
        self.members = tuple(members)
        self._mask: np.ndarray | None = None

    @property
    def shape(self) -> tuple[int, ...]:
        """(H, W) of the mask: the members'."""
        return self.members[0].shape

    @property
    def mask(self) -> np.ndarray:
        """Bool (H, W), read-only: the OR of the members' masks, computed once."""
        if self._mask is None:
            mask = np.array(self.members[0].mask, dtype=bool)
            for member in self.members[1:]:
                mask |= member.mask
            mask.setflags(write=False)
            self._mask = mask
        return self._mask

    @property
    def bounds(self) -> tuple[int, int, int, int]:
        """(r0, r1, c0, c1) holding every member's cells (r1 <= r0 when all are empty)."""
        boxes = [b for b in (m.bounds for m in self.members) if b[1] > b[0] and b[3] > b[2]]
        if not boxes:
            return (0, 0, 0, 0)
        r0, r1, c0, c1 = zip(*boxes)
        return (min(r0), max(r1), min(c0), max(c1))

    def holds(self, cells: np.ndarray) -> np.ndarray:
        """Bool (N,): whether some member holds each flat cell index of ``cells`` (N,)
        (row * width + col; negative: no cell, False)."""
        if self._mask is not None:
            cells = np.asarray(cells, dtype=np.int64)
            inside = np.zeros(cells.size, dtype=bool)
            valid = cells >= 0
            inside[valid] = self._mask.ravel()[cells[valid]]
            return inside
        inside = np.asarray(self.members[0].holds(cells), dtype=bool).copy()
        for member in self.members[1:]:
            inside |= member.holds(cells)
        return inside
