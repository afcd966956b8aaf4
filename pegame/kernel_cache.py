"""Tell the user, once per process, when pegame's numba kernels are being compiled.

pegame's kernels are compiled with ``@njit(cache=True)``: the first run after an install
compiles them (half a minute on a laptop, longer on a loaded machine) and writes numba's
on-disk cache (beside the modules, or under ``NUMBA_CACHE_DIR``); later runs load them in
well under a second. Without a word a new user would wait through that first compile in
silence.

Numba broadcasts a ``numba:compile`` event whenever it compiles a function, and never
when it loads one from its cache (numba's event API, ``numba.core.event``).
:func:`watch_compilation` installs a listener that, at the first compile of a function of
pegame's own modules, says so: through the ``pegame`` logger once logging is set up (the
console and ``pegame.log`` of a run), else on stderr (an import in a fresh process, before
Hydra configures logging). So the notice comes exactly when a compile starts: on a cold
cache, for a game, the batched env or a benchmark alike, and never on a warm one.
Every game, environment and benchmark is built from a :class:`pegame.game.Scenario`, which
installs it before any kernel is called (numba compiles a kernel at its first call; the
few eager ufuncs that compile at import send no event, and take about a second).
"""

from __future__ import annotations

import logging
import sys
from functools import lru_cache
from typing import Any

from numba.core import event

log = logging.getLogger("pegame")

NOTICE = (
    "Compiling pegame's numba kernels (the first run after an install, about half a minute); "
    "later runs load them from numba's cache."
)


class CompileNotice(event.Listener):
    """Says :data:`NOTICE` at the first compile of a pegame function, then stays quiet."""

    def __init__(self) -> None:
        self.said = False

    def on_start(self, ev: Any) -> None:
        if self.said or not _is_pegame(ev.data):
            return
        self.said = True
        if log.hasHandlers():
            log.info(NOTICE)
        else:
            print(f"pegame: {NOTICE}", file=sys.stderr, flush=True)

    def on_end(self, ev: Any) -> None:
        pass


def _is_pegame(data: Any) -> bool:
    """Whether a compile event's data is about a function of a pegame module."""
    dispatcher = data.get("dispatcher") if isinstance(data, dict) else None
    module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
    return module == "pegame" or module.startswith("pegame.")


@lru_cache(maxsize=1)
def watch_compilation() -> CompileNotice:
    """Install the listener, once per process; returns it."""
    notice = CompileNotice()
    event.register("numba:compile", notice)
    return notice
