"""Recording file names, and the status each name tells.

A recording is written under a temporary name and renamed when its game ends, so that a
name never claims more than the file holds:

=========================== ========== =====================================================
``<game_id>.rrd.partial``   partial    being written: the game is running, or its process
                                       was killed (or the recorder failed) before it ended
``<game_id>.rrd``           complete   the game finished; renamed from the partial file
                                       once the file was closed (``rerun rrd verify`` passes)
``<game_id>.failed.rrd``    failed     the game raised; closed and renamed at the failure,
                                       readable up to the tick that failed
=========================== ========== =====================================================

The renames are ``os.replace`` in the same directory, atomic on POSIX file systems, done
after the file is closed: a complete name survives a killed process. The file is not
fsynced first (as :func:`pegame.files.write_atomic` does for results): a recording of
megabytes would add to every recorded game's time on a slow disk, and a power cut is not what
the names guard against. A later game of the same id replaces the file of its status; a
finished game also removes its failed file. This module imports nothing heavy:
:mod:`pegame.replay` lists recordings without rerun-sdk.
"""

from __future__ import annotations

from pathlib import Path

COMPLETE, FAILED, PARTIAL = "complete", "failed", "partial"

#: file name suffix per status, longest first (".failed.rrd" also ends in ".rrd")
SUFFIXES = {FAILED: ".failed.rrd", PARTIAL: ".rrd.partial", COMPLETE: ".rrd"}


def recording_path(out_dir: str | Path, game_id: str, status: str) -> Path:
    """The file of game ``game_id``'s recording in ``out_dir`` with ``status``."""
    return Path(out_dir) / f"{game_id}{SUFFIXES[status]}"


def recording_status(path: str | Path) -> str | None:
    """The status that ``path``'s name tells (None: not a recording's name)."""
    name = Path(path).name
    for status, suffix in SUFFIXES.items():
        if name.endswith(suffix) and len(name) > len(suffix):
            return status
    return None
