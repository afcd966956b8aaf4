"""A single-node Slurm cluster on this host, for the tests of the cluster path.

:func:`start_cluster` writes a minimal ``slurm.conf`` and a munge key into a directory of
its own, starts ``munged``, ``slurmctld`` and ``slurmd`` in the foreground as child
processes (Debian's ``munge`` and ``slurm-wlm`` packages; ``.ci/run`` installs them) and
waits until ``sinfo`` reports the node idle. Nothing outside that directory is read or
written: the daemons listen on free ports, munge on a socket in the directory, and the
client commands find the configuration through ``SLURM_CONF`` in :attr:`SlurmCluster.env`.
Accounting is off (no ``slurmdbd``): ``sacct`` fails, which submitit tolerates (it then
waits for each job's result file).

Where a cluster cannot be brought up, :class:`SlurmUnavailable` says exactly why, so that
a test can skip with that reason.
"""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

#: The executables the cluster needs, and the Debian package that ships each.
EXECUTABLES = {
    "munged": "munge",
    "slurmctld": "slurmctld",
    "slurmd": "slurmd",
    "sinfo": "slurm-client",
    "sbatch": "slurm-client",
}


class SlurmUnavailable(RuntimeError):
    """A local Slurm cluster cannot be started here; the message says why."""


@dataclass
class SlurmCluster:
    """A running single-node cluster: its directory, configuration and daemons."""

    root: Path
    conf: Path
    node: str
    partition: str
    processes: dict[str, subprocess.Popen] = field(default_factory=dict)

    @property
    def env(self) -> dict[str, str]:
        """This process's environment with ``SLURM_CONF`` pointing at the cluster."""
        return {**os.environ, "SLURM_CONF": str(self.conf)}

    def run(self, *command: str, timeout_s: float = 30.0) -> subprocess.CompletedProcess:
        """Runs a Slurm client command (``sinfo``, ``squeue``, ...) against this cluster."""
        return subprocess.run(
            command, env=self.env, capture_output=True, text=True, timeout=timeout_s, check=False
        )

    def logs(self, lines: int = 20) -> str:
        """The last ``lines`` lines of every daemon's log, for failure messages."""
        parts = []
        for log in sorted(self.root.glob("*.log")):
            tail = log.read_text(errors="replace").splitlines()[-lines:]
            parts.append(f"--- {log.name}\n" + "\n".join(tail))
        return "\n".join(parts)

    def stop(self) -> None:
        """Stops the daemons this cluster started (slurmd first, munged last)."""
        for name in ("slurmd", "slurmctld", "munged"):
            process = self.processes.pop(name, None)
            if process is None or process.poll() is not None:
                continue
            process.terminate()
            try:
                process.wait(timeout=15)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait(timeout=5)


def missing_executables() -> list[str]:
    """The executables of :data:`EXECUTABLES` that are not on ``PATH`` (nor in sbin)."""
    path = os.pathsep.join([os.environ.get("PATH", ""), "/usr/sbin", "/sbin"])
    return [name for name in EXECUTABLES if shutil.which(name, path=path) is None]


def _which(name: str) -> str:
    path = os.pathsep.join([os.environ.get("PATH", ""), "/usr/sbin", "/sbin"])
    found = shutil.which(name, path=path)
    assert found is not None, name
    return found


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _node_hardware() -> tuple[int, int]:
    """(CPUs, RealMemory in MiB) of this host as slurmd sees it (``slurmd -C``)."""
    out = subprocess.run(
        [_which("slurmd"), "-C"], capture_output=True, text=True, timeout=30, check=False
    ).stdout
    fields = dict(word.split("=", 1) for word in out.split() if "=" in word)
    try:
        return int(fields["CPUs"]), int(fields["RealMemory"])
    except (KeyError, ValueError):
        raise SlurmUnavailable(f"`slurmd -C` did not report CPUs and RealMemory: {out!r}") from None


def slurm_conf(root: Path, node: str, cpus: int, memory_mib: int, partition: str) -> str:
    """A minimal slurm.conf for one node (this host) that runs everything as root.

    The plugins are the ones that need nothing from the host: process tracking by the
    parent pid (no cgroup mounts), no task binding, no accounting storage; cores and
    memory are consumable so that jobs asking for one core run side by side.
    """
    return f"""\
ClusterName=pegame-test
SlurmctldHost={node}(127.0.0.1)
SlurmctldPort={_free_port()}
SlurmdPort={_free_port()}
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket={root / "munge.socket"}
StateSaveLocation={root / "state"}
SlurmdSpoolDir={root / "spool"}
SlurmctldPidFile={root / "slurmctld.pid"}
SlurmdPidFile={root / "slurmd.pid"}
SlurmctldLogFile={root / "slurmctld.log"}
SlurmdLogFile={root / "slurmd.log"}
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
SchedulerType=sched/builtin
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
MpiDefault=none
ReturnToService=2
MailProg=/bin/true
NodeName={node} NodeAddr=127.0.0.1 CPUs={cpus} RealMemory={memory_mib} State=UNKNOWN
PartitionName={partition} Nodes={node} Default=YES MaxTime=INFINITE State=UP
"""


def _start(cluster: SlurmCluster, name: str, *command: str) -> None:
    log = open(cluster.root / f"{name}.out", "wb")  # noqa: SIM115 - owned by the child
    cluster.processes[name] = subprocess.Popen(
        command, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, env=cluster.env
    )
    log.close()


def _wait_for(cluster: SlurmCluster, what: str, ready, timeout_s: float) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if ready():
            return
        dead = [n for n, p in cluster.processes.items() if p.poll() is not None]
        if dead:
            raise SlurmUnavailable(
                f"{', '.join(dead)} exited while waiting for {what}:\n{_outputs(cluster)}"
            )
        time.sleep(0.5)
    raise SlurmUnavailable(f"timed out after {timeout_s:.0f} s waiting for {what}:\n{_outputs(cluster)}")


def _outputs(cluster: SlurmCluster) -> str:
    parts = [cluster.logs()]
    for out in sorted(cluster.root.glob("*.out")):
        parts.append(f"--- {out.name}\n" + out.read_text(errors="replace")[-2000:])
    return "\n".join(parts)


def start_cluster(root: Path, timeout_s: float = 60.0) -> SlurmCluster:
    """Starts munged, slurmctld and slurmd under ``root`` and waits for the node to be idle.

    Raises :class:`SlurmUnavailable` (with the reason and the daemons' last log lines) if
    the executables are missing, this process is not root (the daemons run as root), or a
    daemon exits or the node is not idle within ``timeout_s`` seconds. On failure, the
    daemons already started are stopped.
    """
    missing = missing_executables()
    if missing:
        packages = sorted({EXECUTABLES[name] for name in missing})
        raise SlurmUnavailable(
            f"{', '.join(missing)} not installed (Debian packages: {' '.join(packages)})"
        )
    if os.geteuid() != 0:
        raise SlurmUnavailable("the test cluster runs its daemons as root; this is not root")
    root.mkdir(parents=True, exist_ok=True)
    root.chmod(0o700)  # munged refuses a socket or key in a directory others can write
    for sub in ("state", "spool"):
        (root / sub).mkdir(exist_ok=True)
    node = socket.gethostname().split(".")[0]
    cpus, memory_mib = _node_hardware()
    cluster = SlurmCluster(root=root, conf=root / "slurm.conf", node=node, partition="debug")
    cluster.conf.write_text(slurm_conf(root, node, cpus, memory_mib, cluster.partition))
    key = root / "munge.key"
    key.write_bytes(os.urandom(1024))
    key.chmod(0o600)
    try:
        _start(
            cluster, "munged", _which("munged"), "--foreground", "--force",
            f"--socket={root / 'munge.socket'}", f"--key-file={key}",
            f"--pid-file={root / 'munged.pid'}", f"--log-file={root / 'munged.log'}",
            f"--seed-file={root / 'munged.seed'}",
        )  # fmt: skip
        _wait_for(cluster, "munged's socket", (root / "munge.socket").exists, timeout_s)
        _start(cluster, "slurmctld", _which("slurmctld"), "-D", "-i", "-f", str(cluster.conf))
        _start(cluster, "slurmd", _which("slurmd"), "-D", "-f", str(cluster.conf))

        def node_idle() -> bool:
            state = cluster.run("sinfo", "-h", "-n", node, "-o", "%t", timeout_s=10).stdout
            return state.strip() == "idle"

        _wait_for(cluster, f"sinfo to report node {node} idle", node_idle, timeout_s)
    except BaseException:
        cluster.stop()
        raise
    return cluster
