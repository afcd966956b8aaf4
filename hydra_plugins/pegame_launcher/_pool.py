"""The launcher's pool: worker processes (spawned, each a direct child of the sweep's
process, as loky's are), each running one job at a time; a job is numbered, placed and
run as through the joblib launcher (joblib's ``execute_job`` runs it in the worker).

A worker that dies while it runs a job (a signal, an exit without a result) fails that
job only (:func:`._dead.record_dead_job`); a fresh worker takes the next jobs, and the
jobs running in the other workers are not touched, so the sweep goes on and ends with
its report and exit status 1. On an interrupt (Ctrl-C, SIGTERM: a KeyboardInterrupt in
the sweep's process) or an error every worker is killed and reaped before it goes on.

The sweep's progress is counted in games (each job plays its cell's ``game.trials``): a
progress bar on stderr where it is a terminal, moved as each game's entry reaches its
job's results.jsonl (polled every :data:`POLL_S`); else one line per cell on stdout as
each job ends (``pegame: cell 3 of 36 done (#2 env=hall ...): exit 0, 41 s; games 120
of 1440``). A job's games stored by an earlier run (``resume=true``) count when it ends."""

from __future__ import annotations

import logging
import multiprocessing
import os
import sys
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait
from multiprocessing.process import BaseProcess
from pathlib import Path

import cloudpickle
from hydra.core.singleton import Singleton
from hydra.core.utils import JobReturn, JobStatus, configure_log, filter_overrides, setup_globals
from hydra.types import HydraContext, TaskFunction
from omegaconf import DictConfig, open_dict

from hydra_plugins.pegame_launcher._dead import cause, entries, record_dead_job
from hydra_plugins.pegame_launcher._worker import serve
from pegame import sweep
from pegame.job import say

log = logging.getLogger(__name__)

#: seconds between looks at the running jobs' results.jsonl for the progress bar
POLL_S = 1.0


@dataclass
class Worker:
    """One worker process, its end of the connection, and the job it runs (its index in
    the launch, and how many entries the job's results.jsonl held when it was sent)."""

    process: BaseProcess
    connection: Connection
    job: int | None = None
    before: int = 0

    def played(self, sweep_config: DictConfig) -> int:
        """Entries the running job's results.jsonl gained since it was sent."""
        return entries(sweep_config) - self.before


class Pool:
    """The workers of one launch of ``n_jobs`` (joblib's convention: -1 one per CPU core,
    -2 one fewer, ...)."""

    def __init__(
        self, n_jobs: int, context: HydraContext, config: DictConfig, task: TaskFunction
    ) -> None:
        self.n_jobs, self.context, self.config, self.task = n_jobs, context, config, task
        self.workers: list[Worker] = []

    def size(self, jobs: int) -> int:
        """How many workers ``jobs`` jobs get: n_jobs, at most one per job."""
        cores = os.cpu_count() or 1
        wanted = self.n_jobs if self.n_jobs > 0 else max(1, cores + 1 + self.n_jobs)
        return max(1, min(wanted, jobs))

    def launch(self, job_overrides: Sequence[Sequence[str]], first: int) -> list[JobReturn]:
        """Run every job, numbered from ``first``; their JobReturns in order (a dead
        worker's job returns status 1, as a job whose games failed)."""
        setup_globals()
        configure_log(self.config.hydra.hydra_logging, self.config.hydra.verbose)
        sweep_dir = Path(str(self.config.hydra.sweep.dir))
        sweep_dir.mkdir(parents=True, exist_ok=True)
        jobs = [list(overrides) for overrides in job_overrides]
        log.info(f"pegame launcher: {len(jobs)} jobs in {self.size(len(jobs))} worker processes")
        log.info(f"Launching jobs, sweep output dir : {sweep_dir}")
        for idx, overrides in enumerate(jobs):
            log.info(f"\t#{idx} : {' '.join(filter_overrides(overrides))}")
        returns: dict[int, JobReturn] = {}
        self.configs = [self.sweep_config(first + i, job) for i, job in enumerate(jobs)]
        self.progress = Progress([trials(config) for config in self.configs])
        try:
            self.run(jobs, first, returns)
        finally:
            self.stop()
            self.progress.close()
        return [returns[i] for i in range(len(jobs))]

    def run(self, jobs: list[list[str]], first: int, returns: dict[int, JobReturn]) -> None:
        """Send the jobs to the workers and collect their returns into ``returns``."""
        pending = deque(range(len(jobs)))
        while len(returns) < len(jobs):
            while pending and len(self.workers) < self.size(len(jobs)):
                self.workers.append(spawn())
            for worker in list(self.workers):
                if worker.job is None and pending:
                    self.send(worker, pending.popleft(), first, jobs)
                elif worker.job is None:
                    self.retire(worker)  # no job left for it
            ready = wait([w.connection for w in self.workers], self.progress.poll)
            if not ready:
                self.progress.running(
                    {
                        w.job: w.played(self.configs[w.job])
                        for w in self.workers
                        if w.job is not None
                    }
                )
            for worker in [w for w in self.workers if w.connection in ready]:
                job = worker.job
                assert job is not None
                try:
                    returns[job] = cloudpickle.loads(worker.connection.recv_bytes())
                    worker.job = None
                except EOFError:
                    returns[job] = self.dead(worker, first, jobs)
                    self.retire(worker)
                self.progress.done(job, first + job, jobs[job], returns[job])

    def send(self, worker: Worker, job: int, first: int, jobs: list[list[str]]) -> None:
        """Give ``worker`` the job of index ``job``."""
        worker.job, worker.before = job, entries(self.configs[job])
        task = (first + job, jobs[job], self.context, self.config, self.task, Singleton.get_state())
        worker.connection.send_bytes(cloudpickle.dumps(task))

    def dead(self, worker: Worker, first: int, jobs: list[list[str]]) -> JobReturn:
        """The return of the job whose worker died: recorded as failed, status 1."""
        assert worker.job is not None
        worker.process.join()
        why, overrides = cause(worker.process.exitcode), jobs[worker.job]
        sweep_config = self.configs[worker.job]
        log.error(f"job #{first + worker.job} ({' '.join(overrides)}): {why}")
        record_dead_job(sweep_config, overrides, worker.before, why)
        return JobReturn(
            overrides=overrides,
            cfg=sweep_config,
            working_dir=os.getcwd(),
            task_name=str(sweep_config.hydra.job.name),
            status=JobStatus.COMPLETED,
            _return_value=sweep.GAMES_FAILED,
        )

    def sweep_config(self, num: int, overrides: list[str]) -> DictConfig:
        """The job's config, numbered as joblib's ``execute_job`` numbers it."""
        config = self.context.config_loader.load_sweep_config(self.config, overrides)
        with open_dict(config):
            config.hydra.job.id = f"{config.hydra.job.name}_{num}"
            config.hydra.job.num = num
        return config

    def retire(self, worker: Worker) -> None:
        """Let ``worker`` go: closing its connection ends it (or it has died)."""
        worker.connection.close()
        worker.process.join()
        self.workers.remove(worker)

    def stop(self) -> None:
        """Kill the workers still running (after an interrupt or an error) and reap them."""
        for worker in self.workers:
            if worker.process.is_alive():
                worker.process.kill()
        for worker in self.workers:
            worker.connection.close()
            worker.process.join()
        self.workers.clear()


class Progress:
    """The sweep's progress over its games, ``games[job]`` per job (module docstring)."""

    def __init__(self, games: list[int]) -> None:
        self.games, self.total = games, sum(games)
        self.counted = [0] * len(games)  # games of each job counted so far
        self.cells, self.started = 0, time.perf_counter()
        self.bar = None
        self.poll: float | None = None  # no polling without a bar
        if sys.stderr.isatty() and len(games) > 1:
            from tqdm import tqdm

            self.bar = tqdm(total=self.total, desc="games", unit="game")
            self.poll = POLL_S

    def _count(self, job: int, games: int) -> None:
        games = max(self.counted[job], min(games, self.games[job]))
        if self.bar is not None:
            self.bar.update(games - self.counted[job])
        self.counted[job] = games

    def running(self, played: dict[int, int]) -> None:
        """The running jobs have played ``played[job]`` games so far."""
        for job, games in played.items():
            self._count(job, games)

    def done(self, job: int, num: int, overrides: list[str], returned: JobReturn) -> None:
        """Job ``job`` (numbered ``num``, its ``overrides``) ended with ``returned``: all
        its games count."""
        self.cells += 1
        self._count(job, self.games[job])
        if self.bar is not None:
            return
        status = returned.return_value if returned.status == JobStatus.COMPLETED else "error"
        elapsed = time.perf_counter() - self.started
        say(
            f"pegame: cell {self.cells} of {len(self.games)} done (#{num} "
            f"{' '.join(filter_overrides(overrides))}): exit {status}, {elapsed:.0f} s; "
            f"games {sum(self.counted)} of {self.total}"
        )

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def trials(sweep_config: DictConfig) -> int:
    """The games a job plays (its ``game.trials``); 1 where that is no positive integer,
    which the job itself then refuses with its error."""
    try:
        value = int(sweep_config.game.trials)
    except Exception:  # a missing or malformed value: the job reports it
        return 1
    return max(value, 1)


def spawn() -> Worker:
    """A new worker process (spawned: it inherits the sweep's environment, not its state)."""
    context = multiprocessing.get_context("spawn")
    ours, theirs = context.Pipe()
    process = context.Process(target=serve, args=(theirs,), name="pegame-worker")
    process.start()
    theirs.close()
    return Worker(process, ours)
