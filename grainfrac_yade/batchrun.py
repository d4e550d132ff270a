"""Write yade-batch tables and run them (one YADE process per row, ``jobs`` rows at a time).

No YADE import: ``yade-batch`` runs in its own processes.  The same table runs
on a cluster one row per SLURM array task: YADE's ``readParamsFromTable`` reads
the row named by the environment variable ``YADE_BATCH=<table>:<line number in
the file>`` (yade utils.py), so a task runs
``YADE_BATCH=params/lifetime_ldb.table:$LINE yade -n -x yade_scripts/creep.py``.
"""
from __future__ import annotations

import shutil
import subprocess
import time
from pathlib import Path

from .errors import GrainfracError

#: Seconds between checks of the run folders while a batch runs.
POLL_S = 5.0


def format_value(value) -> str:
    """A table cell: numbers as they are, strings quoted (yade-batch evaluates cells as Python)."""
    if isinstance(value, str):
        return repr(value)
    return repr(value) if isinstance(value, float) else str(value)


def write_table(path, rows: list, comment: str = "") -> Path:
    """yade-batch table from ``rows`` (dicts with the same keys); returns its path."""
    if not rows:
        raise GrainfracError(f"{path}: a batch table needs at least one row; fix: give rows")
    columns = list(rows[0])
    lines = [f"# {line}" for line in comment.splitlines()] + [" ".join(columns)]
    lines += [" ".join(format_value(r[c]) for c in columns) for r in rows]
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")
    return path


def run_batch(table, script, jobs: int, log_dir, watch=(), progress=None, repo=None) -> int:
    """Run ``yade-batch -j jobs table script``; call ``progress`` as folders in ``watch`` get a summary.

    Returns yade-batch's exit status; the rows' own results are judged by their summary.json.
    """
    exe = shutil.which("yade-batch")
    if exe is None:
        raise GrainfracError("yade-batch not found on PATH; fix: apt-get install yade (see README)")
    log_dir = Path(log_dir)
    log_dir.mkdir(parents=True, exist_ok=True)
    cmd = [exe, "-j", str(jobs), "--log", str(log_dir / "%.log"), str(table), str(script)]
    pending = [Path(w) for w in watch]
    with open(log_dir / "yade-batch.txt", "w") as out:
        proc = subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT, cwd=repo)
        while True:
            finished = proc.poll() is not None
            for w in [w for w in pending if (w / "summary.json").exists()]:
                pending.remove(w)
                if progress:
                    progress(w)
            if finished:
                break
            time.sleep(POLL_S)
    return proc.returncode
