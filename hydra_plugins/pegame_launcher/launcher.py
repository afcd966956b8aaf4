"""``hydra/launcher=pegame``: the jobs of a multirun in a pool of worker processes, as
through the joblib launcher (n_jobs, numbering, directories, returns), where a worker
that dies fails only the job it ran (see :mod:`._pool`). The pool is imported when a
sweep launches, not when Hydra scans its plugins."""

from __future__ import annotations

from collections.abc import Sequence

from hydra.core.utils import JobReturn
from hydra.plugins.launcher import Launcher
from hydra.types import HydraContext, TaskFunction
from omegaconf import DictConfig


class PegameLauncher(Launcher):
    """``n_jobs`` worker processes (-1: one per CPU core, -2 one fewer, ...)."""

    def __init__(self, n_jobs: int = -1) -> None:
        self.n_jobs = n_jobs
        self.config: DictConfig | None = None
        self.task_function: TaskFunction | None = None
        self.hydra_context: HydraContext | None = None

    def setup(
        self, *, hydra_context: HydraContext, task_function: TaskFunction, config: DictConfig
    ) -> None:
        self.config, self.task_function, self.hydra_context = config, task_function, hydra_context

    def launch(
        self, job_overrides: Sequence[Sequence[str]], initial_job_idx: int
    ) -> Sequence[JobReturn]:
        """Run every job; their JobReturns in the order of ``job_overrides``."""
        from hydra_plugins.pegame_launcher._pool import Pool

        assert self.config is not None and self.task_function is not None
        assert self.hydra_context is not None
        pool = Pool(self.n_jobs, self.hydra_context, self.config, self.task_function)
        return pool.launch(job_overrides, initial_job_idx)
