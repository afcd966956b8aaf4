"""Recording file names, and the status each name tells.

A recording is held in memory while its game runs and written when the game ends, under a
temporary name renamed once the file is complete, so that a name never claims more than
the file holds:

=========================== ========== =====================================================
``<game_id>.rrd.partial``   partial    being written (the game has ended), or its process
                                       was killed while writing it
``<game_id>.rrd``           complete   the game finished; renamed from the partial file
                                       once every byte was written
                                       (``rerun rrd verify`` passes)
``<game_id>.failed.rrd``    failed     the game raised; written at the failure, readable
                                       up to the tick that failed
=========================== ========== =====================================================

The writes are :func:`pegame.files.write_atomic` (the partial file, its size checked, then
``os.replace`` in the same directory, atomic on POSIX): a complete name survives a killed
process, and a write that fails (a full disk) removes the partial file and fails the game.
The file is not fsynced: syncing a 2.3 MB recording took 2.7 ms more (ext4, median of
20), about 2% of a 150 ms game, and the game's line in ``results.jsonl`` is not synced
either (:func:`pegame.files.append_line`), so a crash of the machine can lose the last
games' lines and recordings alike. A later game of the same id replaces the file of its
status; a finished game also removes its failed file. This module imports nothing heavy:
:mod:`pegame.replay` lists recordings without rerun-sdk.
"""

from __future__ import annotations

from pathlib import Path

COMPLETE, FAILED, PARTIAL = "complete", "failed", "partial"

#: the blueprint file (the viewer's layout) of an output directory's recordings
#: (:mod:`pegame.recorders.rerun.blueprint`)
LAYOUT_FILE = "pegame.rbl"

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
