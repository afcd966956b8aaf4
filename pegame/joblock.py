"""One writer per job directory: an exclusive ``flock`` on ``<job dir>/.lock``.

The operating system releases the lock when the process that holds it exits, however it
exits (``kill -9`` included), so a stale lock never blocks a later run; a second process
on a directory whose writer is still alive gets :class:`JobLockedError` at once instead
of interleaving its games with the other's (a resume started while the workers of a
killed sweep still run, two sweeps with the same ``hydra.sweep.dir``).
"""

from __future__ import annotations

import fcntl
import os
from pathlib import Path
from types import TracebackType

from pegame.errors import JobDirectoryError
from pegame.files import make_dir, write_failed

LOCK_FILE = ".lock"


class JobLockedError(JobDirectoryError):
    """Another live process writes to the job directory."""


class JobLock:
    """``with JobLock(out_dir):`` holds the job directory's lock for the block; the lock
    file records the holder's PID (for the error message only: the flock is the lock)."""

    def __init__(self, out_dir: str | Path) -> None:
        self.path = Path(out_dir) / LOCK_FILE
        self._fd: int | None = None

    def __enter__(self) -> JobLock:
        make_dir(self.path.parent)
        try:
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise write_failed(self.path, exc) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.read(fd, 32).decode(errors="replace").strip() or "unknown"
            os.close(fd)
            raise JobLockedError(
                f"Another pegame process (PID {holder}) is writing to {self.path.parent}: a "
                f"job directory has one writer. Wait for it to finish or stop it, then run "
                f"again (with resume=true to keep its games)."
            ) from None
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()}\n".encode())
        os.set_inheritable(fd, False)
        self._fd = fd
        return self

    def __exit__(
        self, kind: type | None, error: BaseException | None, tb: TracebackType | None
    ) -> None:
        if self._fd is not None:
            os.close(self._fd)  # closing the descriptor releases the flock
            self._fd = None
