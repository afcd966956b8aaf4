"""Tell the user when the first game of a process will compile pegame's numba kernels.

pegame's kernels are compiled with ``@njit(cache=True)``: the first run after an install
compiles them (half a minute on a laptop) and writes numba's on-disk cache (``*.nbi``
index files in the ``__pycache__`` folders beside the modules, or under
``NUMBA_CACHE_DIR``); later runs load them in well under a second. Without a word a new
user would wait through that first compile in silence.
"""

from __future__ import annotations

import logging
import os
from functools import lru_cache
from pathlib import Path

log = logging.getLogger("pegame")

PACKAGE = Path(__file__).resolve().parent


def cache_is_cold(package: Path = PACKAGE) -> bool:
    """True when numba's cache holds no index of any kernel of ``package`` (numba keeps
    them under NUMBA_CACHE_DIR when it is set, else beside the modules)."""
    cache_dir = os.environ.get("NUMBA_CACHE_DIR")
    found = Path(cache_dir).rglob("*.nbi") if cache_dir else package.rglob("__pycache__/*.nbi")
    return next(found, None) is None


@lru_cache(maxsize=1)
def announce_compilation() -> bool:
    """Log one line, once per process, when the kernels are about to be compiled; return
    whether it did."""
    if not cache_is_cold():
        return False
    log.info(
        "First run after an install: compiling pegame's numba kernels, once (about half a "
        "minute); later runs load them from numba's cache."
    )
    return True
