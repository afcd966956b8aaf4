"""How the process that runs a sweep and the jobs it launches coordinate.

Exit status: 0 when every game of every job finished, 1 when some games failed (their
records and the other games are written), 2 for bad input. A single run knows its status
in-process. In a multirun the jobs may run in other processes (the workers of pegame's
launcher or of the joblib launcher, submitit), and Hydra 1.3 drops what a job returns,
so the sweep's process creates a status directory in the sweep dir when the multirun
starts (:func:`start_sweep`), each job writes its status there (:func:`job_ended`), and
the sweep's process reads them when the multirun ends (:func:`end_sweep`).

One owner per sweep directory: :func:`start_sweep` takes an exclusive ``flock`` on
``<sweep dir>/.pegame-sweep``, which records the owner (PID, start time, command line),
before Hydra writes anything there, and holds it until :func:`end_sweep`. A second sweep
into the directory is refused (:class:`SweepOwnedError`, naming the first) without
touching a file: while the first runs, and after it ended unless it is a resume
(``resume=true``), which becomes the owner.

Orphaned workers: a worker process whose parent (the sweep's process) was killed
(``kill -9``) is re-parented and would go on appending games, racing a later resume.
:func:`sweep_parent` tells a job that it runs in such a worker; the job checks
:func:`orphaned` between games and stops. A worker whose job already ended waits for the
next job in its launcher (loky keeps an idle worker 300 s); :func:`watched_job` starts a
thread that ends such a worker as soon as the sweep's process is gone.
"""

from __future__ import annotations

import fcntl
import json
import os
import shlex
import shutil
import sys
import tempfile
import threading
import time
import uuid
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from pegame.errors import JobDirectoryError
from pegame.files import make_dir, write_atomic, write_failed

OK, GAMES_FAILED, BAD_INPUT = 0, 1, 2

#: set by the sweep's process for its jobs: the status directory and its own PID
STATUS_DIR_ENV = "PEGAME_STATUS_DIR"
SWEEP_PID_ENV = "PEGAME_SWEEP_PID"

#: the file of a sweep directory that names its owner and carries its flock
OWNER_FILE = ".pegame-sweep"

#: s between two looks of an idle worker's watchdog at its parent
WATCH_PERIOD = 0.5

_worst = OK
_owner_fd: int | None = None
_jobs_running = 0
_watched_parent: int | None = None


class SweepOwnedError(JobDirectoryError):
    """The sweep directory belongs to another sweep (running, or ended and not resumed)."""


def record(status: int) -> None:
    """Note the status of a job (or a whole sweep) run by this process."""
    global _worst
    _worst = max(_worst, status)


def worst() -> int:
    """The exit status of this process: the worst status recorded so far."""
    return _worst


def job_ended(status: int) -> None:
    """Record a job's status, and in a multirun also in the sweep's status directory."""
    record(status)
    directory = os.environ.get(STATUS_DIR_ENV)
    if directory and Path(directory).is_dir():
        write_atomic(Path(directory) / f"{os.getpid()}-{uuid.uuid4().hex}", f"{status}\n")


def start_sweep(sweep_dir: str | Path, resume: bool = False) -> None:
    """In the sweep's process, before any job: become the sweep directory's owner
    (SweepOwnedError when another sweep owns it, see the module docstring), create the
    status directory and tell the jobs (through the environment their processes inherit)
    where it is and who we are."""
    global _owner_fd
    sweep_dir = Path(sweep_dir)
    _owner_fd = take_ownership(sweep_dir, resume)
    try:
        status_dir = tempfile.mkdtemp(prefix=".pegame-status-", dir=sweep_dir)
    except OSError as exc:
        raise write_failed(sweep_dir, exc) from None
    os.environ[STATUS_DIR_ENV] = status_dir
    os.environ[SWEEP_PID_ENV] = str(os.getpid())


def take_ownership(sweep_dir: Path, resume: bool) -> int:
    """The descriptor of ``sweep_dir``'s owner file, flocked and naming this sweep.
    SweepOwnedError, with nothing written, when another sweep owns the directory."""
    path = sweep_dir / OWNER_FILE
    make_dir(sweep_dir)
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o644)
    except FileExistsError:
        fd = os.open(path, os.O_RDWR)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise SweepOwnedError(
                f"Another sweep is running in {sweep_dir}: {describe_owner(path)}. A sweep "
                f"directory has one sweep: wait for it to end or stop it, or choose another "
                f"hydra.sweep.dir."
            ) from None
        if not resume:
            os.close(fd)
            raise SweepOwnedError(
                f"{sweep_dir} holds another sweep: {describe_owner(path)}. A sweep directory "
                f"has one sweep: run it again with resume=true to complete it, or choose "
                f"another hydra.sweep.dir."
            ) from None
    except OSError as exc:
        raise write_failed(path, exc) from None
    else:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # created here: no one else holds it
    owner = {"pid": os.getpid(), "started": time.strftime("%Y-%m-%d %H:%M:%S")}
    owner["command"] = shlex.join(["pegame", *sys.argv[1:]])
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, (json.dumps(owner) + "\n").encode(), 0)
    except OSError as exc:
        os.close(fd)
        raise write_failed(path, exc) from None
    os.set_inheritable(fd, False)
    return fd


def describe_owner(path: Path) -> str:
    """Who owns a sweep directory, from its owner file: 'PID p, started t: command'."""
    try:
        owner = json.loads(path.read_text())
        return f"PID {owner['pid']}, started {owner['started']}: {owner['command']}"
    except (OSError, ValueError, KeyError, TypeError):
        return "an unknown sweep (its owner file is unreadable)"


def end_sweep() -> int:
    """In the sweep's process, after every job: record and return the worst job status,
    remove the status directory and release the sweep directory (its owner file stays)."""
    global _owner_fd
    if _owner_fd is not None:
        os.close(_owner_fd)  # closing the descriptor releases the flock
        _owner_fd = None
    directory = os.environ.pop(STATUS_DIR_ENV, None)
    os.environ.pop(SWEEP_PID_ENV, None)
    statuses = [OK]
    if directory and Path(directory).is_dir():
        written = [p for p in Path(directory).iterdir() if not p.name.startswith(".")]
        statuses += [int(path.read_text()) for path in written]  # not a cut temporary file
        shutil.rmtree(directory, ignore_errors=True)
    record(max(statuses))
    return max(statuses)


def end_broken_sweep() -> Path | None:
    """After Hydra stopped a multirun with an error (joblib's TerminatedWorkerError when a
    worker process died: the launcher cancels every job it had not finished): end the sweep
    as :func:`end_sweep` does, with at least status 1 (jobs did not finish), and return its
    directory; None when no sweep of this process is open."""
    directory = os.environ.get(STATUS_DIR_ENV)
    if directory is None:
        return None
    end_sweep()
    record(GAMES_FAILED)
    return Path(directory).parent


def sweep_parent() -> int | None:
    """The sweep process's PID when this process is one of its worker processes (a direct
    child, as the workers of pegame's launcher, loky's and submitit-local's are), else
    None: a single run or a job run in the sweep's own process has no parent to watch, and
    a job on another machine (slurm) has a parent that is not the sweep's process."""
    recorded = os.environ.get(SWEEP_PID_ENV)
    if recorded and recorded.isdigit():
        pid = int(recorded)
        if pid != os.getpid() and os.getppid() == pid:
            return pid
    return None


def orphaned(parent: int | None) -> bool:
    """Whether the sweep process ``parent`` (from :func:`sweep_parent`) has died: the
    worker was re-parented, so its parent PID changed."""
    return parent is not None and os.getppid() != parent


@contextmanager
def watched_job() -> Iterator[None]:
    """Run a job in this process; when it is a sweep's worker (:func:`sweep_parent`), a
    daemon thread, started with its first job, exits the process within
    :data:`WATCH_PERIOD` s of the sweep's process dying while no job runs here (a running
    job stops itself between games, after a complete line). Without it an idle worker of
    a killed sweep would linger until its launcher's idle timeout."""
    global _jobs_running, _watched_parent
    parent = sweep_parent()
    if parent is not None and _watched_parent is None:
        _watched_parent = parent
        threading.Thread(
            target=_watch, args=(parent,), name="pegame-orphan-watch", daemon=True
        ).start()
    _jobs_running += 1
    try:
        yield
    finally:
        _jobs_running -= 1


def _watch(parent: int) -> None:
    while not (orphaned(parent) and _jobs_running == 0):
        time.sleep(WATCH_PERIOD)
    os._exit(GAMES_FAILED)
