"""One SLURM array task: run one table row's YADE command, record the task, mark a failed row.

    python3 -m grainfrac_yade.runs.slurmtask STUDY_DIR ROW COMMAND -- yade -n -x yade_scripts/creep.py

The sbatch script written by ``submit`` calls this with YADE_BATCH naming the row's table line. The
YADE command runs exactly as one local yade-batch row (its output goes to the task's log); this
wrapper only records, in ``STUDY_DIR/slurm/tasks/row<ROW>.json`` (atomic writes), when the task ran,
where and how it ended, and, when the row ends without a summary.json (an error, a crash, scancel or
the time limit: SIGTERM), writes ``failed.json`` with the error line into the run folder the row
chose (``row<ROW>_folder.json``, written by the YADE script), or only into the task record when the
row failed before choosing one.  A stale failed.json of an earlier attempt is removed when the row
starts again.  No YADE import.
"""
from __future__ import annotations

import collections
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

from .runio import SUMMARY, write_json
from .slurm import (FAILED, ROW_FOLDER_ENV, cell_value, folder_record_path, log_path, now_iso, read_json_file,
                    record_path, task_record_path)

#: Output lines kept to find the error line of a failed row.
TAIL_LINES = 400
#: Seconds the wrapper waits for the YADE process after forwarding SIGTERM (SLURM's KillWait is 30 s).
TERM_WAIT_S = 20.0


def error_line(lines, status: int | None, terminated: str | None, command) -> str:
    """The one line saying why a row ended without a summary.json."""
    if terminated:
        return f"terminated by {terminated} (scancel, or the --time limit) before its summary.json"
    lines = [ln.rstrip() for ln in lines]
    errors = [ln for ln in lines if ln.startswith("error:")]
    if errors:
        return errors[-1][len("error:"):].strip()
    if any(ln.startswith("Traceback") for ln in lines):
        last_tb = max(i for i, ln in enumerate(lines) if ln.startswith("Traceback"))
        exc = [ln for ln in lines[last_tb + 1:] if re.match(r"^[A-Za-z_][\w.]*(: |$)", ln)]
        if exc:
            return exc[-1].strip()
    if status is not None and status < 0:
        name = signal.Signals(-status).name if -status in signal.Signals._value2member_map_ else str(-status)
        return f"{command[0]} killed by signal {name}" + (" (out of memory?)" if name == "SIGKILL" else "")
    return f"{' '.join(command)} exited with status {status} without writing summary.json"


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if "--" not in argv or argv.index("--") != 3 or len(argv) < 5:
        print("usage: python3 -m grainfrac_yade.runs.slurmtask STUDY_DIR ROW COMMAND -- yade -n -x SCRIPT", file=sys.stderr)
        return 2
    study_dir, row, command_name, cmd = Path(argv[0]), int(argv[1]), argv[2], argv[4:]
    env = os.environ
    array_job = env.get("SLURM_ARRAY_JOB_ID", env.get("SLURM_JOB_ID", "local"))
    task = {"row": row, "table_line": int(env.get("YADE_BATCH", ":0").rsplit(":", 1)[-1] or 0),
            "yade_batch": env.get("YADE_BATCH"), "array_job_id": array_job,
            "job": f"{array_job}_{env.get('SLURM_ARRAY_TASK_ID', row)}", "slurm_job_id": env.get("SLURM_JOB_ID"),
            "node": env.get("SLURMD_NODENAME") or os.uname().nodename, "command": command_name, "argv": cmd,
            "log": str(log_path(study_dir, row, array_job)), "state": "running", "started": now_iso()}
    record = task_record_path(study_dir, row)
    folder_file = folder_record_path(study_dir, row)
    record.parent.mkdir(parents=True, exist_ok=True)
    # an earlier attempt's marks: its failed.json (the row runs again) and its folder record
    old = read_json_file(folder_file) or read_json_file(record) or {}
    if old.get("folder"):
        Path(old["folder"], FAILED).unlink(missing_ok=True)
    folder_file.unlink(missing_ok=True)
    write_json(record, task)
    cells = next((r.get("cells", {}) for r in (read_json_file(record_path(study_dir)) or {}).get("rows", [])
                  if r.get("row") == row), {})
    seed = cell_value(cells["seed"]) if "seed" in cells else None

    terminated = []
    proc = None

    def on_term(signum, _frame):
        terminated.append(signal.Signals(signum).name)
        if proc is not None and proc.poll() is None:
            try:
                proc.send_signal(signal.SIGTERM)
            except OSError:
                pass

    signal.signal(signal.SIGTERM, on_term)
    signal.signal(signal.SIGINT, on_term)
    t0 = time.time()
    tail = collections.deque(maxlen=TAIL_LINES)
    child_env = dict(env, PYTHONUNBUFFERED="1", **{ROW_FOLDER_ENV: str(folder_file)})
    try:
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=child_env, text=True,
                                errors="replace", bufsize=1)
    except OSError as exc:
        status, tail = 127, [f"error: {cmd[0]} cannot be started on {task['node']} ({exc}); fix: install YADE "
                             "on the compute nodes (apt-get install yade) or put it on PATH"]
        print(tail[0], flush=True)
    else:
        for line in proc.stdout:
            sys.stdout.write(line)
            sys.stdout.flush()
            tail.append(line)
        try:
            status = proc.wait(timeout=TERM_WAIT_S if terminated else None)
        except subprocess.TimeoutExpired:
            proc.kill()
            status = proc.wait()
    folder_rec = read_json_file(folder_file) or {}
    folder = Path(folder_rec["folder"]) if folder_rec.get("folder") else None
    task.update(ended=now_iso(), wall_s=round(time.time() - t0, 3), exit_status=status,
                folder=str(folder) if folder else None)
    if folder is not None and (folder / SUMMARY).exists():
        task["state"] = "finished"
        write_json(record, task)
        return 0
    error = error_line(tail, status, terminated[0] if terminated else None, cmd)
    task.update(state="failed", error=error)
    if folder is not None:   # the row may have chosen its folder without creating it yet
        folder.mkdir(parents=True, exist_ok=True)
        write_json(folder / FAILED, {
            "error": error, "row": row, "table_line": task["table_line"], "yade_batch": task["yade_batch"],
            "command": command_name, "seed": seed if isinstance(seed, int) else None, "job": task["job"],
            "node": task["node"], "exit_status": status,
            "signal": terminated[0] if terminated else None, "started": task["started"], "ended": task["ended"],
            "log": task["log"], "task_record": str(record)})
    write_json(record, task)
    print(f"error: row {row} failed: {error}", flush=True)
    return status if isinstance(status, int) and status > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
