"""pegame's Hydra launcher (``hydra/launcher=pegame``, the default of pegame's config): the
jobs of a multirun run in a pool of worker processes, as through the joblib launcher, and
a worker that dies (``kill -9``, out of memory) fails only the job it was running; the
other jobs go on (see :mod:`.launcher`)."""
