"""A worker process of the launcher's pool: it runs the jobs the sweep's process sends
it, one at a time, until the sweep's process closes its connection."""

from __future__ import annotations

import signal
from multiprocessing.connection import Connection

import cloudpickle
from hydra_plugins.hydra_joblib_launcher._core import execute_job


def serve(connection: Connection) -> None:
    """Run each job received on ``connection`` (the arguments of joblib's
    ``execute_job``, pickled) and send back its pickled JobReturn. SIGINT is ignored: the
    sweep's process decides on an interrupt, and stops its workers."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    while True:
        try:
            task = connection.recv_bytes()
        except EOFError:  # the sweep's process is done with this worker, or died
            return
        connection.send_bytes(cloudpickle.dumps(execute_job(*cloudpickle.loads(task))))
