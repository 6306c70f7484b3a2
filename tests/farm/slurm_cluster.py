"""A one-node Slurm cluster in a temporary folder, for the farm tests.

munged, slurmctld and slurmd run in the foreground as children of the test,
on 127.0.0.1 with ports the kernel hands out, every setting, state file and
log inside the folder. Nothing of the machine's own Slurm or munge set-up is
read or touched: the commands find this cluster through SLURM_CONF, and the
daemons talk through this munged's own socket.
"""

from __future__ import annotations

import contextlib
import getpass
import os
import secrets
import shutil
import socket
import subprocess
import time
from pathlib import Path
from typing import Iterator

DAEMONS = ("munged", "slurmctld", "slurmd")


def missing_programs() -> list[str]:
    """The Slurm and munge programs this machine lacks (Debian 12: slurmctld slurmd slurm-client munge)."""
    wanted = (*DAEMONS, "sbatch", "sinfo", "squeue")
    return [p for p in wanted if shutil.which(p) is None and not Path("/usr/sbin", p).exists()]


def _program(name: str) -> str:
    found = shutil.which(name)
    return found if found else str(Path("/usr/sbin", name))


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _configuration(folder: Path, user: str, host: str) -> str:
    cpus = os.cpu_count() or 1
    lines = [
        "ClusterName=snelltest",
        f"SlurmctldHost={host}(127.0.0.1)",
        f"SlurmUser={user}",
        f"SlurmdUser={user}",
        f"SlurmctldPort={_free_port()}",
        f"SlurmdPort={_free_port()}",
        "AuthType=auth/munge",
        f"AuthInfo=socket={folder / 'munge.socket'}",
        "CredType=cred/munge",
        f"StateSaveLocation={folder / 'state'}",
        f"SlurmdSpoolDir={folder / 'spool'}",
        f"SlurmctldPidFile={folder / 'slurmctld.pid'}",
        f"SlurmdPidFile={folder / 'slurmd.pid'}",
        f"SlurmctldLogFile={folder / 'slurmctld.log'}",
        f"SlurmdLogFile={folder / 'slurmd.log'}",
        # No cgroups or accounting daemon in a test folder: plain process tracking.
        "ProctrackType=proctrack/linuxproc",
        "TaskPlugin=task/none",
        "JobAcctGatherType=jobacct_gather/none",
        "AccountingStorageType=accounting_storage/none",
        "SelectType=select/cons_tres",
        "SelectTypeParameters=CR_CPU",
        "MpiDefault=none",
        "MailProg=/bin/true",
        "ReturnToService=2",
        # The node as written here, whatever the machine reports.
        "SlurmdParameters=config_overrides",
        "KillWait=5",
        f"NodeName=snellnode NodeAddr=127.0.0.1 CPUs={cpus} State=UNKNOWN",
        "PartitionName=debug Nodes=snellnode Default=YES MaxTime=INFINITE State=UP",
    ]
    return "\n".join(lines) + "\n"


class SlurmCluster:
    """A running one-node cluster; `env` is what a command needs to reach it."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.env = dict(os.environ, SLURM_CONF=str(folder / "slurm.conf"))
        self._children: list[tuple[str, subprocess.Popen]] = []

    def logs(self) -> str:
        """Every daemon's log, for a failing test's message."""
        text = []
        for name in ("munged.log", "slurmctld.log", "slurmd.log"):
            path = self.folder / name
            if path.exists():
                text.append(f"--- {name}\n" + path.read_text(errors="replace")[-4000:])
        return "\n".join(text)

    def _start(self, name: str, arguments: list[str]) -> None:
        log = open(self.folder / f"{name}.out", "wb")
        child = subprocess.Popen([_program(name), *arguments], env=self.env, stdout=log, stderr=subprocess.STDOUT,
                                 stdin=subprocess.DEVNULL)
        self._children.append((name, child))

    def start(self, deadline_s: float = 30.0) -> None:
        """Starts the daemons and waits, at most `deadline_s`, for the node to take jobs."""
        folder = self.folder
        for sub in ("state", "spool"):
            (folder / sub).mkdir()
        key = folder / "munge.key"
        key.write_bytes(secrets.token_bytes(1024))
        key.chmod(0o400)
        user = getpass.getuser()
        host = socket.gethostname().split(".")[0]
        (folder / "slurm.conf").write_text(_configuration(folder, user, host))

        self._start("munged", ["--foreground", "--force", f"--socket={folder / 'munge.socket'}",
                               f"--key-file={key}", f"--pid-file={folder / 'munged.pid'}",
                               f"--log-file={folder / 'munged.log'}", f"--seed-file={folder / 'munge.seed'}"])
        self._wait_for(lambda: (folder / "munge.socket").exists(), deadline_s, "munged's socket")
        self._start("slurmctld", ["-D", "-c", "-i", "-f", str(folder / "slurm.conf")])
        self._start("slurmd", ["-D", "-N", "snellnode", "-f", str(folder / "slurm.conf")])

        def node_idle() -> bool:
            state = subprocess.run(["sinfo", "--noheader", "--Node", "--format=%T"], env=self.env,
                                   capture_output=True, text=True, timeout=10)
            return state.returncode == 0 and state.stdout.strip() == "idle"

        self._wait_for(node_idle, deadline_s, "the node to come up idle")

    def _wait_for(self, ready, deadline_s: float, what: str) -> None:
        end = time.monotonic() + deadline_s
        while time.monotonic() < end:
            for name, child in self._children:
                if child.poll() is not None:
                    raise RuntimeError(f"{name} exited with {child.returncode} while waiting for {what}\n{self.logs()}")
            if ready():
                return
            time.sleep(0.2)
        raise TimeoutError(f"no {what} after {deadline_s:.0f} s\n{self.logs()}")

    def stop(self) -> None:
        """Cancels what still runs, then stops every daemon started, by its PID, last first."""
        if any(child.poll() is None for name, child in self._children if name == "slurmctld"):
            subprocess.run(["scancel", f"--user={getpass.getuser()}"], env=self.env, capture_output=True, timeout=30)
        for name, child in reversed(self._children):
            if child.poll() is None:
                child.terminate()
                try:
                    child.wait(timeout=15)
                except subprocess.TimeoutExpired:
                    child.kill()
                    child.wait(timeout=15)
        self._children.clear()


@contextlib.contextmanager
def slurm_cluster(folder: Path) -> Iterator[SlurmCluster]:
    """A cluster in `folder` (which must exist and be empty) for the `with` block; stopped however it ends."""
    cluster = SlurmCluster(folder)
    try:
        cluster.start()
        yield cluster
    finally:
        cluster.stop()
