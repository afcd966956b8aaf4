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
from collections.abc import Callable
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
        """The last ``lines`` lines of every daemon's log file and captured output."""
        parts = []
        for log in sorted([*self.root.glob("*.log"), *self.root.glob("*.out")]):
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


def _which(name: str) -> str | None:
    """Where ``name`` is on ``PATH`` or in sbin (where Debian puts the daemons)."""
    search = os.pathsep.join([os.environ.get("PATH", ""), "/usr/sbin", "/sbin"])
    return shutil.which(name, path=search)


def _executable(name: str) -> str:
    """The path of ``name`` (:func:`_which`); SlurmUnavailable when it is not installed."""
    path = _which(name)
    if path is None:
        raise SlurmUnavailable(f"{name} is not installed (on PATH or in sbin).")
    return path


def missing_executables() -> list[str]:
    """The executables of :data:`EXECUTABLES` that are not installed."""
    return [name for name in EXECUTABLES if _which(name) is None]


def _free_ports(count: int) -> list[int]:
    """``count`` distinct TCP ports free on this host now (held together while chosen)."""
    probes = [socket.socket() for _ in range(count)]
    try:
        for probe in probes:
            probe.bind(("127.0.0.1", 0))
        return [probe.getsockname()[1] for probe in probes]
    finally:
        for probe in probes:
            probe.close()


def _node_hardware() -> tuple[int, int]:
    """(CPUs, RealMemory in MiB) of this host as slurmd sees it (``slurmd -C``)."""
    out = subprocess.run(
        [_executable("slurmd"), "-C"], capture_output=True, text=True, timeout=30, check=False
    ).stdout
    fields = dict(word.split("=", 1) for word in out.split() if "=" in word)
    try:
        return int(fields["CPUs"]), int(fields["RealMemory"])
    except (KeyError, ValueError):
        raise SlurmUnavailable(f"`slurmd -C` did not report CPUs and RealMemory: {out!r}") from None


def slurm_conf(root: Path, node: str, cpus: int, memory_mib: int, partition: str) -> str:
    """A minimal slurm.conf for one node (this host, all its cores and memory), run as root.

    Everything the daemons keep (state, spool, pid and log files, munge's socket) lives
    under ``root``, and they listen on free ports, so a real Slurm on the host is not
    disturbed. The plugins are the ones that need nothing from the host: processes are
    tracked by parent pid (no cgroup mounts), tasks are not bound to cores, and there is
    no accounting storage (no slurmdbd). Cores and memory are consumable resources, so
    one-core jobs (the sweep's array tasks) run side by side, one per core.
    """
    ctld_port, slurmd_port = _free_ports(2)  # not 6817/6818: a real Slurm may run here
    return f"""\
ClusterName=pegame-test
SlurmctldHost={node}(127.0.0.1)
SlurmctldPort={ctld_port}
SlurmdPort={slurmd_port}
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
    log = open(cluster.root / f"{name}.out", "wb")
    cluster.processes[name] = subprocess.Popen(
        command, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, env=cluster.env
    )
    log.close()


def _wait_for(
    cluster: SlurmCluster, what: str, ready: Callable[[], bool], timeout_s: float
) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if ready():
            return
        dead = [n for n, p in cluster.processes.items() if p.poll() is not None]
        if dead:
            raise SlurmUnavailable(
                f"{', '.join(dead)} exited while waiting for {what}:\n{cluster.logs()}"
            )
        time.sleep(0.5)
    raise SlurmUnavailable(
        f"timed out after {timeout_s:.0f} s waiting for {what}:\n{cluster.logs()}"
    )


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
    if len(str(root / "munge.socket")) > 100:  # sun_path holds 108 bytes
        raise SlurmUnavailable(f"{root} is too long a path for munged's socket")
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
        # --force: munged would refuse a key or socket below a directory others can write
        # (a custom --basetemp, say); this key guards a throwaway cluster.
        _start(
            cluster, "munged", _executable("munged"), "--foreground", "--force",
            f"--socket={root / 'munge.socket'}", f"--key-file={key}",
            f"--pid-file={root / 'munged.pid'}", f"--log-file={root / 'munged.log'}",
            f"--seed-file={root / 'munged.seed'}",
        )  # fmt: skip
        _wait_for(cluster, "munged's socket", (root / "munge.socket").exists, timeout_s)
        _start(cluster, "slurmctld", _executable("slurmctld"), "-D", "-i", "-f", str(cluster.conf))
        _start(cluster, "slurmd", _executable("slurmd"), "-D", "-f", str(cluster.conf))

        def node_idle() -> bool:
            state = cluster.run("sinfo", "-h", "-n", node, "-o", "%t", timeout_s=10).stdout
            return state.strip() == "idle"

        _wait_for(cluster, f"sinfo to report node {node} idle", node_idle, timeout_s)
    except BaseException:
        cluster.stop()
        raise
    return cluster
