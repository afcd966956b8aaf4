"""pegame's writes to disk, in one place: atomic files (results, figures, map files,
recordings, Hydra's files of a job) and appended lines (``results.jsonl``).

A write that fails (a full disk, a read-only directory, a path that names a file) raises
:class:`~pegame.errors.ResultsWriteError` naming the file and the cause (its
``strerror`` is the system's), which the app reports as one message with exit status 2;
nothing half-written is left under the file's name.
"""

from __future__ import annotations

import errno
import os
import tempfile
from pathlib import Path

from pegame.errors import ResultsWriteError


def write_failed(path: str | os.PathLike, exc: OSError) -> ResultsWriteError:
    """The error for a write to ``path`` that failed with ``exc``."""
    error = ResultsWriteError(
        f"Could not write to {path}: {exc.strerror or exc}. Free space or choose another "
        f"output directory, then run again (resume=true keeps the games stored)."
    )
    error.strerror = exc.strerror or str(exc)
    return error


def write_atomic(
    path: str | os.PathLike,
    data: str | bytes,
    staging: str | os.PathLike | None = None,
    sync: bool = True,
) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same directory, then
    rename it into place (atomic on POSIX), so ``path`` is either absent, old or complete:
    the rename comes after the data was written, synced to disk (unless ``sync`` is
    False) and its size checked. ``staging``: the temporary file's path (a recording's
    ``.rrd.partial``), by default a new hidden name. ResultsWriteError when any of it
    fails (the temporary file is removed).

    Without ``sync`` the file is complete for every reader and survives a killed process
    (the kernel holds the bytes), but not a crash of the machine before the kernel writes
    them back: the durability of :func:`append_line`, which ``results.jsonl`` has."""
    path = Path(path)
    raw = data.encode() if isinstance(data, str) else data
    tmp: str | None = None
    try:
        if staging is None:
            fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        else:
            tmp = str(staging)
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        with os.fdopen(fd, "wb") as handle:
            handle.write(raw)
            handle.flush()
            if sync:
                os.fsync(handle.fileno())
            written = os.fstat(handle.fileno()).st_size
        if written != len(raw):
            raise OSError(f"{written} of {len(raw)} bytes written")
        os.chmod(tmp, 0o644)  # mkstemp creates 0600; results are meant to be shared
        os.replace(tmp, path)
    except OSError as exc:
        if tmp is not None:
            Path(tmp).unlink(missing_ok=True)
        raise write_failed(path, exc) from None
    except BaseException:
        if tmp is not None:
            Path(tmp).unlink(missing_ok=True)
        raise


def append_line(path: str | os.PathLike, line: bytes) -> None:
    """Append ``line`` (ending in a newline) to ``path`` and flush it; earlier lines stay
    intact. After a writer killed mid-line, the fragment is closed with a newline first so
    the new line stays readable. ResultsWriteError when the write fails."""
    try:
        with Path(path).open("ab+") as handle:
            if handle.seek(0, os.SEEK_END) > 0:
                handle.seek(-1, os.SEEK_END)
                if handle.read(1) != b"\n":
                    handle.write(b"\n")
            handle.write(line)
            handle.flush()
    except OSError as exc:
        raise write_failed(path, exc) from None


def make_dir(path: str | os.PathLike) -> Path:
    """Create directory ``path`` (and its parents) if missing; ResultsWriteError when it
    cannot be created or written to (a read-only file system, a file of that name)."""
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
        if not os.access(path, os.W_OK | os.X_OK):
            raise PermissionError(errno.EACCES, "not writable (read-only file system?)")
    except OSError as exc:
        raise write_failed(path, exc) from None
    return path
