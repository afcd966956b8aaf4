"""The launcher's pool: worker processes (spawned, each a direct child of the sweep's
process, as loky's are), each running one job at a time; a job is numbered, placed and
run as through the joblib launcher (joblib's ``execute_job`` runs it in the worker).

A worker that dies while it runs a job (a signal, an exit without a result) fails that
job only (:func:`._dead.record_dead_job`); a fresh worker takes the next jobs, and the
jobs running in the other workers are not touched, so the sweep goes on and ends with
its report and exit status 1. On an interrupt (Ctrl-C, SIGTERM: a KeyboardInterrupt in
the sweep's process) or an error every worker is killed and reaped before it goes on.

The sweep's progress over its cells is shown as each job ends: a progress bar on stderr
where it is a terminal, else one line per cell on stdout (``pegame: cell 3 of 36 done
(#2 env=hall ...): exit 0, 41 s``)."""

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

log = logging.getLogger(__name__)


@dataclass
class Worker:
    """One worker process, its end of the connection, and the job it runs (its index in
    the launch, and how many entries the job's results.jsonl held when it was sent)."""

    process: BaseProcess
    connection: Connection
    job: int | None = None
    before: int = 0


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
        self.progress = Progress(len(jobs))
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
            ready = wait([w.connection for w in self.workers])
            for worker in [w for w in self.workers if w.connection in ready]:
                job = worker.job
                assert job is not None
                try:
                    returns[job] = cloudpickle.loads(worker.connection.recv_bytes())
                    worker.job = None
                except EOFError:
                    returns[job] = self.dead(worker, first, jobs)
                    self.retire(worker)
                self.progress.done(first + job, jobs[job], returns[job])

    def send(self, worker: Worker, job: int, first: int, jobs: list[list[str]]) -> None:
        """Give ``worker`` the job of index ``job``."""
        worker.job, worker.before = job, entries(self.sweep_config(first + job, jobs[job]))
        task = (first + job, jobs[job], self.context, self.config, self.task, Singleton.get_state())
        worker.connection.send_bytes(cloudpickle.dumps(task))

    def dead(self, worker: Worker, first: int, jobs: list[list[str]]) -> JobReturn:
        """The return of the job whose worker died: recorded as failed, status 1."""
        assert worker.job is not None
        worker.process.join()
        why, overrides = cause(worker.process.exitcode), jobs[worker.job]
        sweep_config = self.sweep_config(first + worker.job, overrides)
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
    """The sweep's progress over its ``total`` cells (module docstring)."""

    def __init__(self, total: int) -> None:
        self.total, self.count, self.started = total, 0, time.perf_counter()
        self.bar = None
        if sys.stderr.isatty() and total > 1:
            from tqdm import tqdm

            self.bar = tqdm(total=total, desc="cells", unit="cell")

    def done(self, num: int, overrides: list[str], returned: JobReturn) -> None:
        """Job ``num`` (its ``overrides``) ended with ``returned``."""
        self.count += 1
        if self.bar is not None:
            self.bar.update(1)
            return
        status = returned.return_value if returned.status == JobStatus.COMPLETED else "error"
        elapsed = time.perf_counter() - self.started
        print(
            f"pegame: cell {self.count} of {self.total} done (#{num} "
            f"{' '.join(filter_overrides(overrides))}): exit {status}, {elapsed:.0f} s",
            flush=True,
        )

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def spawn() -> Worker:
    """A new worker process (spawned: it inherits the sweep's environment, not its state)."""
    context = multiprocessing.get_context("spawn")
    ours, theirs = context.Pipe()
    process = context.Process(target=serve, args=(theirs,), name="pegame-worker")
    process.start()
    theirs.close()
    return Worker(process, ours)
