"""How the process that runs a sweep and the jobs it launches coordinate.

Exit status: 0 when every game of every job finished, 1 when some games failed (their
records and the other games are written), 2 for bad input. A single run knows its status
in-process. In a multirun the jobs may run in other processes (the joblib launcher's loky
workers, submitit), and Hydra 1.3 drops what a job returns, so the sweep's process
creates a status directory in the sweep dir when the multirun starts
(:func:`start_sweep`), each job writes its status there (:func:`job_ended`), and the
sweep's process reads them when the multirun ends (:func:`end_sweep`).

Orphaned workers: a worker process whose parent (the sweep's process) was killed
(``kill -9``) is re-parented and would go on appending games, racing a later resume.
:func:`sweep_parent` tells a job that it runs in such a worker; the job checks
:func:`orphaned` between games and stops.
"""

from __future__ import annotations

import os
import shutil
import tempfile
import uuid
from pathlib import Path

OK, GAMES_FAILED, BAD_INPUT = 0, 1, 2

#: set by the sweep's process for its jobs: the status directory and its own PID
STATUS_DIR_ENV = "PEGAME_STATUS_DIR"
SWEEP_PID_ENV = "PEGAME_SWEEP_PID"

_worst = OK


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
        (Path(directory) / f"{os.getpid()}-{uuid.uuid4().hex}").write_text(f"{status}\n")


def start_sweep(sweep_dir: str | Path) -> None:
    """In the sweep's process, before any job: create the status directory and tell the
    jobs (through the environment their processes inherit) where it is and who we are."""
    Path(sweep_dir).mkdir(parents=True, exist_ok=True)
    os.environ[STATUS_DIR_ENV] = tempfile.mkdtemp(prefix=".pegame-status-", dir=sweep_dir)
    os.environ[SWEEP_PID_ENV] = str(os.getpid())


def end_sweep() -> int:
    """In the sweep's process, after every job: record and return the worst job status,
    and remove the status directory."""
    directory = os.environ.pop(STATUS_DIR_ENV, None)
    os.environ.pop(SWEEP_PID_ENV, None)
    statuses = [OK]
    if directory and Path(directory).is_dir():
        statuses += [int(path.read_text()) for path in Path(directory).iterdir()]
        shutil.rmtree(directory, ignore_errors=True)
    record(max(statuses))
    return max(statuses)


def sweep_parent() -> int | None:
    """The sweep process's PID when this process is one of its worker processes (a direct
    child, as loky and submitit-local workers are), else None: a single run or a job run
    in the sweep's own process has no parent to watch, and a job on another machine
    (slurm) has a parent that is not the sweep's process."""
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
