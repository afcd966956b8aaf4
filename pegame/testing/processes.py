"""Processes of a running sweep, for the tests that interrupt or kill one (Linux /proc)."""

from __future__ import annotations

from pathlib import Path


def loky_workers(pid: int) -> list[int]:
    """The live (not zombie) loky worker processes whose parent is ``pid``: the joblib
    launcher's workers, which run the jobs (not loky's resource tracker, which runs none)."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
            command = (stat.parent / "cmdline").read_bytes()
        except OSError:
            continue
        if int(fields[1]) == pid and fields[0] != "Z" and b"popen_loky" in command:
            found.append(int(stat.parent.name))
    return found
