"""A real single-node SLURM for the tests: munged, slurmctld and slurmd on localhost, all in one folder.

Nothing system-wide is touched: the munge key, socket, slurm.conf, state, spool and logs live in the
given folder, the daemons listen on free ports, and :meth:`LocalSlurm.stop` ends exactly the
processes it started (their pid files).  Clients find the cluster through ``SLURM_CONF``
(:attr:`LocalSlurm.env`).  :func:`why_not` says why SLURM cannot start here (None if it can).
"""
from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import time
from pathlib import Path

#: Where Debian puts the daemons (not on a normal user's PATH).
SBIN = "/usr/sbin:/sbin"
DAEMONS = ("munged", "slurmctld", "slurmd")
CLIENTS = ("sbatch", "squeue", "scancel", "sinfo")
#: CPUs slurmd announces (this machine's 2 cores).
NODE_CPUS = 2


def _which(name):
    return shutil.which(name, path=os.environ.get("PATH", "") + os.pathsep + SBIN)


def why_not() -> str | None:
    """Why a local SLURM cannot be started here, or None."""
    missing = [n for n in DAEMONS + CLIENTS if _which(n) is None]
    if missing:
        return (f"SLURM not installed ({', '.join(missing)} not found); fix: apt-get install slurm-wlm munge "
                "(setup.sh installs them)")
    if os.geteuid() != 0:
        return (f"slurmd must run as root to start jobs (the tests run as uid {os.geteuid()}); fix: run the tests "
                "as root")
    return None


def _free_ports(n):
    socks = [socket.socket() for _ in range(n)]
    try:
        for s in socks:
            s.bind(("127.0.0.1", 0))
        return [s.getsockname()[1] for s in socks]
    finally:
        for s in socks:
            s.close()


class LocalSlurm:
    """Single-node SLURM in ``root`` (a fresh folder): :meth:`start`, :attr:`env` for clients, :meth:`stop`."""

    def __init__(self, root, cpus: int = NODE_CPUS):
        self.root = Path(root).resolve()
        self.cpus = cpus
        self.host = socket.gethostname().split(".")[0]
        self.conf = self.root / "slurm.conf"
        self.env = dict(os.environ, SLURM_CONF=str(self.conf))
        self.pid_files = {"munged": self.root / "munge" / "munged.pid", "slurmctld": self.root / "slurmctld.pid",
                          "slurmd": self.root / "slurmd.pid"}
        self.logs = {"munged": self.root / "log" / "munged.log", "slurmctld": self.root / "log" / "slurmctld.log",
                     "slurmd": self.root / "log" / "slurmd.log"}

    def _write_files(self):
        for d in ("munge", "log", "state", "spool"):
            (self.root / d).mkdir(parents=True, exist_ok=True)
            os.chmod(self.root / d, 0o755)
        key = self.root / "munge" / "munge.key"
        fd = os.open(key, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        with os.fdopen(fd, "wb") as fh:
            fh.write(os.urandom(1024))
        ctl_port, d_port = _free_ports(2)
        r = self.root
        self.conf.write_text(f"""# single-node SLURM for grainfrac-yade tests (generated)
ClusterName=grainfrac-test
SlurmctldHost={self.host}(127.0.0.1)
SlurmctldPort={ctl_port}
SlurmdPort={d_port}
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket={r}/munge/munge.socket
SlurmUser=root
SlurmdUser=root
StateSaveLocation={r}/state
SlurmdSpoolDir={r}/spool
SlurmctldPidFile={self.pid_files['slurmctld']}
SlurmdPidFile={self.pid_files['slurmd']}
SlurmctldLogFile={self.logs['slurmctld']}
SlurmdLogFile={self.logs['slurmd']}
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
PlugStackConfig=/dev/null
NodeName={self.host} NodeAddr=127.0.0.1 CPUs={self.cpus} State=UNKNOWN
PartitionName=grainfrac Nodes={self.host} Default=YES MaxTime=INFINITE State=UP
""")

    def start(self, timeout: float = 30.0) -> str | None:
        """Start the daemons; None once the node is idle, else why not (the daemons started are stopped)."""
        self._write_files()
        r = self.root
        steps = [
            ("munged", [_which("munged"), "--force", f"--socket={r}/munge/munge.socket",
                        f"--key-file={r}/munge/munge.key", f"--log-file={self.logs['munged']}",
                        f"--pid-file={self.pid_files['munged']}", f"--seed-file={r}/munge/munged.seed"]),
            ("slurmctld", [_which("slurmctld"), "-f", str(self.conf)]),
            ("slurmd", [_which("slurmd"), "-f", str(self.conf), "-N", self.host]),
        ]
        for name, cmd in steps:
            res = subprocess.run(cmd, capture_output=True, text=True, env=self.env, timeout=30)
            if res.returncode != 0 or not self._wait_pid(name, 10.0):
                why = f"{name} did not start (status {res.returncode}): {self._last_words(name, res)}"
                self.stop()
                return why
        t_end = time.time() + timeout
        state = ""
        while time.time() < t_end:
            res = subprocess.run([_which("sinfo"), "-h", "-o", "%T"], capture_output=True, text=True, env=self.env)
            state = res.stdout.strip() or res.stderr.strip()
            if res.returncode == 0 and state.startswith("idle"):
                return None
            time.sleep(0.5)
        self.stop()
        return (f"the SLURM node did not become idle within {timeout:.0f} s (sinfo: {state!r}); see "
                f"{self.logs['slurmd']}")

    def _wait_pid(self, name, timeout):
        t_end = time.time() + timeout
        while time.time() < t_end:
            pid = self.pid(name)
            if pid and _alive(pid):
                return True
            time.sleep(0.1)
        return False

    def _last_words(self, name, res):
        text = (res.stderr or res.stdout or "").strip()
        log = self.logs[name]
        if log.exists():
            lines = [ln for ln in log.read_text(errors="replace").splitlines() if "error" in ln.lower()]
            text = (text + " | " if text else "") + (lines[-1] if lines else "")
        return text or "no message"

    def pid(self, name):
        try:
            return int(self.pid_files[name].read_text().split()[0])
        except (OSError, ValueError, IndexError):
            return None

    def stop(self):
        """Cancel what is left in the queue, then end slurmd, slurmctld and munged (by their pid files)."""
        if self.pid("slurmctld") and _which("scancel"):
            subprocess.run([_which("scancel"), "--user", "root"], capture_output=True, env=self.env, timeout=30)
            time.sleep(0.5)
        for name in ("slurmd", "slurmctld", "munged"):
            pid = self.pid(name)
            if pid and _alive(pid):
                os.kill(pid, signal.SIGTERM)
                t_end = time.time() + 15
                while _alive(pid) and time.time() < t_end:
                    time.sleep(0.1)
                if _alive(pid):
                    os.kill(pid, signal.SIGKILL)


def _alive(pid) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:   # a zombie (ended, not reaped by its parent) counts as ended
        return Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0] != "Z"
    except OSError:
        return False
