"""The one cache of objects derived from a grid: :func:`per_grid` (and :func:`read_only`).

Planners, inflated masks, obstacle distances, recorder images and the like depend only on
a grid (and a few numbers) and take milliseconds or more to build, so the modules that
need them build each once per grid and share it. A grid never changes after construction
(:class:`pegame.grid.OccupancyGrid`), so a derived object stays valid for the grid's
whole life.

The cache is stored on the grid itself, so it lives exactly as long as the grid: what it
holds is freed with the grid, and it never keeps a grid alive. (A module-level
WeakKeyDictionary keyed by grid would keep every grid alive forever, since most cached
objects refer back to their grid; a dict keyed by name keeps the last grid of each name.)
A pickled or copied grid starts with an empty cache: its contents are rebuilt on demand
and can be large.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import TypeVar

import numpy as np

from pegame.grid.occupancy import OccupancyGrid

T = TypeVar("T")

#: the grid attribute that holds the cache (the grid is a frozen dataclass)
_ATTRIBUTE = "_per_grid_cache"


class _Cache(dict):
    """The objects derived from one grid, by key; pickled (or deep-copied) empty."""

    def __reduce__(self) -> tuple[type[_Cache], tuple[()]]:
        return (_Cache, ())


def per_grid(grid: OccupancyGrid, key: Hashable, build: Callable[[OccupancyGrid], T]) -> T:
    """``build(grid)``, computed at the first call for ``grid`` and ``key`` and returned
    again by every later call with the same grid and an equal key, for as long as the grid
    exists.

    ``key`` names what ``build`` derives and every parameter it depends on besides the grid,
    e.g. ``("inflation", radius)``; keys of different modules must not collide, so start
    them with a name of the module's own. The result is shared by every caller: make its
    arrays read-only (:func:`read_only`). If two threads build the same key at once, both
    get the object stored first.
    """
    cache = vars(grid).get(_ATTRIBUTE)
    if cache is None:
        cache = vars(grid).setdefault(_ATTRIBUTE, _Cache())
    try:
        return cache[key]
    except KeyError:
        return cache.setdefault(key, build(grid))


def read_only(array: np.ndarray) -> np.ndarray:
    """``array`` itself, flagged read-only because it is shared."""
    array.setflags(write=False)
    return array
