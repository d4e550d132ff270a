"""The state of each row of a SLURM study (pure: no YADE): its files first, then the queue.

A row is finished when its run folder holds a summary.json, whatever SLURM says; failed when it holds
``failed.json`` (or its task record says so); otherwise ``squeue`` (pending, running) and ``sacct`` (ended
badly) decide where they answer.  The study's files are :mod:`.slurm`'s.
"""
from __future__ import annotations

import re
import shutil
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

from .runio import SUMMARY
from .slurm import (FAILED, cell_value, latest_submission, read_json_file, read_study, record_path, recorded_folder,
                    slurm_dir, task_record_path)

#: Seconds allowed to one squeue / sacct / sbatch call.
COMMAND_TIMEOUT_S = 60
#: SLURM job states of a task waiting to start, and of a task running.
QUEUED_STATES = {"PENDING", "CONFIGURING", "REQUEUED", "REQUEUE_HOLD", "REQUEUE_FED", "RESV_DEL_HOLD",
                 "SPECIAL_EXIT"}
RUNNING_STATES = {"RUNNING", "COMPLETING", "SUSPENDED", "STOPPED", "SIGNALING", "STAGE_OUT", "RESIZING"}
#: Accounting states of a task that ended badly.
ENDED_BADLY = {"CANCELLED", "FAILED", "TIMEOUT", "NODE_FAIL", "OUT_OF_MEMORY", "BOOT_FAIL", "DEADLINE",
               "PREEMPTED", "REVOKED"}


# --------------------------------------------------------------------------- the queue
@dataclass
class QueueView:
    """States of array tasks as a SLURM command reports them: {(array job id, task id): (state, reason)}.
    ``available`` False when the command is missing or refused (``note`` says why)."""
    tasks: dict = field(default_factory=dict)
    available: bool = False
    note: str = ""


def _run(cmd: list) -> tuple:
    """(exit status, stdout, first line of stderr) of a SLURM command; (None, "", reason) if it cannot run."""
    exe = shutil.which(cmd[0])
    if exe is None:
        return None, "", f"{cmd[0]} not found on PATH"
    try:
        res = subprocess.run([exe, *cmd[1:]], capture_output=True, text=True, timeout=COMMAND_TIMEOUT_S)
    except (OSError, subprocess.SubprocessError) as exc:
        return None, "", f"{cmd[0]} failed ({type(exc).__name__}: {exc})"
    err = next((ln.strip() for ln in res.stderr.splitlines() if ln.strip()), "")
    return res.returncode, res.stdout, err


def squeue_view(job_ids) -> QueueView:
    """Pending and running tasks of the given array jobs (``squeue``)."""
    job_ids = {str(j) for j in job_ids}
    rc, out, err = _run(["squeue", "-h", "-r", "-o", "%F|%K|%T|%r"])
    if rc is None or rc != 0:
        return QueueView(note=err or f"squeue exited with status {rc}")
    view = QueueView(available=True, note="squeue")
    for line in out.splitlines():
        parts = line.strip().split("|")
        if len(parts) == 4 and parts[0] in job_ids and parts[1].isdigit():
            view.tasks[(parts[0], int(parts[1]))] = (parts[2].split()[0], parts[3])
    return view


def sacct_view(job_ids) -> QueueView:
    """Accounting states of the given array jobs' tasks (``sacct``; often disabled on small clusters)."""
    job_ids = sorted({str(j) for j in job_ids})
    if not job_ids:
        return QueueView(available=True, note="sacct")
    rc, out, err = _run(["sacct", "-n", "-P", "-X", "-j", ",".join(job_ids), "-o", "JobID,State,ExitCode"])
    if rc is None or rc != 0:
        return QueueView(note=err or f"sacct exited with status {rc}")
    view = QueueView(available=True, note="sacct")
    for line in out.splitlines():
        parts = line.strip().split("|")
        m = re.match(r"^(\d+)_(\d+)$", parts[0]) if len(parts) >= 2 else None
        if m:
            view.tasks[(m.group(1), int(m.group(2)))] = (parts[1].split()[0], parts[2] if len(parts) > 2 else "")
    return view


# --------------------------------------------------------------------------- row states
@dataclass
class RowState:
    row: int
    line: int
    state: str          # one of STATES
    job: str | None     # "<array job id>_<row>" of the row's last submission
    folder: str | None
    detail: str = ""

    def to_dict(self) -> dict:
        return {"row": self.row, "line": self.line, "state": self.state, "job": self.job, "folder": self.folder,
                "detail": self.detail}


def _failed_error(folder: Path | None) -> str | None:
    if folder is None:
        return None
    data = read_json_file(folder / FAILED)
    if data is None:
        return None if not (folder / FAILED).exists() else "failed.json unreadable"
    return str(data.get("error") or "failed (no error line recorded)") + _checkpoint_note(folder)


def _checkpoint_note(folder: Path) -> str:
    """A note when the failed row's folder holds a checkpoint (batch code that resumes rows goes on from it)."""
    try:
        from .runio import checkpoint_folder
    except ImportError:   # batch code without checkpoints
        return ""
    return "; its checkpoint is kept: submitted again, the row goes on from it" if checkpoint_folder(folder) else ""


def row_states(study_dir, record: dict, queue: QueueView | None = None, acct: QueueView | None = None) -> list:
    """State of every row of the study: files first (summary.json, failed.json, task record), then the queue.

    Relative run folders are resolved against the study's working folder (``record["workdir"]``)."""
    study_dir = Path(study_dir)
    queue = queue or QueueView()
    acct = acct or QueueView()
    workdir = Path(record.get("workdir") or ".")
    last = latest_submission(record)
    out = []
    for r in record["rows"]:
        row, line = int(r["row"]), int(r["line"])
        sub = last.get(row)
        job_id = str(sub["job_id"]) if sub else None
        job = f"{job_id}_{row}" if job_id else None
        task = read_json_file(task_record_path(study_dir, row))
        folder = recorded_folder(study_dir, row)
        if folder is not None and not folder.is_absolute():
            folder = workdir / folder
        # a task record of an earlier submission says nothing about this one
        if task is not None and job_id is not None and str(task.get("array_job_id")) != job_id:
            task = None
        shown = str(folder) if folder is not None else None

        def state(s, detail=""):
            out.append(RowState(row, line, s, job, shown, detail))

        if folder is not None and (folder / SUMMARY).exists():
            state("finished")
            continue
        q = queue.tasks.get((job_id, row)) if job_id else None
        if q and q[0] in QUEUED_STATES:
            state("pending", f"queued ({q[1]})" if q[1] and q[1] != "None" else "queued")
            continue
        if q and q[0] in RUNNING_STATES:
            state("running", "")
            continue
        error = _failed_error(folder) if (task is None or task.get("state") != "running") else None
        if task is not None and task.get("state") == "failed":
            error = error or task.get("error")
        if error:
            state("failed", error)
            continue
        a = acct.tasks.get((job_id, row)) if job_id else None
        if a and a[0] in ENDED_BADLY:
            state("failed", f"SLURM state {a[0]} (exit {a[1]}), no summary.json")
            continue
        if task is not None and task.get("state") == "running":
            if queue.available:
                state("failed", "the task ended without recording its end (killed by SIGKILL, node failure or "
                                "time limit?); see its log")
            else:
                state("running", f"from its task record ({queue.note}: not confirmed by squeue)")
            continue
        if task is not None and task.get("state") == "finished":
            state("failed", f"task finished but {shown}/summary.json is missing (removed since?)")
            continue
        if sub is None:
            state("pending", "never submitted")
        elif a and a[0] == "COMPLETED":
            state("failed", "SLURM state COMPLETED but no task record and no summary.json")
        elif queue.available:
            state("failed", "left the queue without starting (cancelled before it started?)")
        else:
            state("pending", f"not started yet ({queue.note}: not confirmed by squeue)")
    return out


def study_states(study_dir, record: dict | None = None) -> tuple:
    """(record, row states, queue view, accounting view) of a submitted study, asking squeue and sacct."""
    record = record or read_study(study_dir)
    jobs = {str(s["job_id"]) for s in record.get("submissions", [])}
    queue = squeue_view(jobs) if jobs else QueueView(available=True, note="squeue (no job submitted)")
    acct = sacct_view(jobs) if jobs else QueueView()
    return record, row_states(study_dir, record, queue, acct), queue, acct


# --------------------------------------------------------------------------- for the analysis
def rows_without_runs(study_dir, seen_folders) -> list:
    """Rows of a SLURM study with no run folder among ``seen_folders`` (resolved paths of folders
    holding a run.json or failed.json), as rows for the analysis: ``status`` ``pending`` (not started,
    or started without a folder yet) or ``failed`` (failed before choosing a folder: ``problem``).

    Files only (no squeue): the analysis of a running study reads what is on disk. [] if the folder
    is no SLURM study."""
    study_dir = Path(study_dir)
    record = read_json_file(record_path(study_dir))
    if record is None or not isinstance(record.get("rows"), list):
        return []
    seen = {Path(f).resolve() for f in seen_folders}
    workdir = Path(record.get("workdir") or ".")
    last = latest_submission(record)
    out = []
    for r in record["rows"]:
        row, line = int(r["row"]), int(r["line"])
        folder = recorded_folder(study_dir, row)
        if folder is not None and not folder.is_absolute():
            folder = workdir / folder
        if folder is not None and folder.resolve() in seen:
            continue
        task = read_json_file(task_record_path(study_dir, row)) or {}
        sub = last.get(row)
        if sub is not None and str(task.get("array_job_id")) != str(sub["job_id"]):
            task = {}
        seed = cell_value(r["cells"]["seed"]) if "seed" in r.get("cells", {}) else None
        item = {"run": f"slurm row {row} (table line {line})", "folder": str(slurm_dir(study_dir)),
                "command": record.get("command"), "seed": seed if isinstance(seed, int) else None}
        if task.get("state") == "failed":
            item.update(status="failed", problem=f"SLURM row {row} failed before its run folder: {task.get('error')}")
        elif task.get("state") == "running":
            item.update(status="pending", problem=f"SLURM row {row}: started, no run folder yet")
        else:
            item.update(status="pending", problem=f"SLURM row {row}: not started (no run folder yet)")
        out.append(item)
    return out
