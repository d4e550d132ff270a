"""Batch tables on a SLURM cluster: one job-array task per table row (pure: no YADE).

A study NAME submitted from a yade-batch table lives in ``results/NAME/`` (relative to the folder
``submit`` runs in, as local batch rows write ``results/<study>/``):

- ``slurm/study.json``: the study record: source table, frozen copy, YADE script, every row with
  its table line, and every submission (job id, rows, sbatch script, options);
- ``slurm/NAME.table``: the table as submitted with its ``study`` column set to NAME and its line
  numbers kept, so array task k runs ``YADE_BATCH=results/NAME/slurm/NAME.table:<line of row k>
  yade -n -x <script>`` and writes ``results/NAME/<row name>/`` exactly as a local batch row;
- ``slurm/submit_<k>.sbatch``: the script of submission k; ``slurm/logs/row<R>_job<J>.log``: output;
- ``slurm/tasks/row<R>.json``: the task's own record (state, job, node, times, run folder, error),
  written by :mod:`grainfrac_yade.runs.slurmtask`; ``slurm/tasks/row<R>_folder.json``: the run folder the
  row chose (written by the YADE script as soon as it knows it).

A row whose run ends without a summary.json writes ``failed.json`` (its error line) into its run
folder, or only into its task record when it failed before choosing a folder.  A row's state
(:data:`STATES`) comes from these files first (a summary.json is finished whatever SLURM says),
then from ``squeue`` / ``sacct`` where they answer (:mod:`.slurm_states`).
"""
from __future__ import annotations

import ast
import datetime as _dt
import hashlib
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path

from ..errors import GrainfracError
from .runio import write_json

#: Row states reported by ``status``.
STATES = ("finished", "running", "failed", "pending")
#: Marks a run folder whose row ended without a summary.json (the error line inside).
FAILED = "failed.json"
#: Sub-folder of a study folder holding the SLURM record, scripts, logs and task records.
SLURM_DIR = "slurm"
#: Environment variable naming the file in which a batch row records the run folder it chose.
ROW_FOLDER_ENV = "GRAINFRAC_ROW_FOLDER_FILE"
#: Debian's interpreter (YADE's); the task wrapper runs under it.
DEBIAN_PYTHON = "/usr/bin/python3"

_STUDY_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.+-]*$")
_SLURM_TIME = re.compile(r"^(\d+|\d+:\d{1,2}|\d+:\d{1,2}:\d{1,2}|\d+-\d+|\d+-\d+:\d{1,2}|\d+-\d+:\d{1,2}:\d{1,2}"
                         r"|UNLIMITED|INFINITE)$")
_PARTITION = re.compile(r"^[A-Za-z0-9_.-]+(,[A-Za-z0-9_.-]+)*$")


def now_iso() -> str:
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


# --------------------------------------------------------------------------- tables
@dataclass(frozen=True)
class TableRow:
    """One data row of a batch table: ``row`` counts data rows from 1 (the array task id), ``line``
    is its line in the file (what YADE_BATCH names), ``cells`` the cell texts by column ('=' resolved)."""
    row: int
    line: int
    cells: dict


@dataclass(frozen=True)
class BatchTable:
    path: Path
    header_line: int
    columns: tuple
    rows: tuple

    def value(self, row: TableRow, column: str, default=None):
        """A cell as YADE reads it (a Python literal), ``default`` if the column is absent."""
        if column not in row.cells:
            return default
        return cell_value(row.cells[column])


def cell_value(text: str):
    """A table cell as a Python value (cells are Python expressions); the text itself if not a literal."""
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return text


def _strip_comment(line: str) -> str:
    return re.sub(r"\s*#.*", "", line)


def read_batch_table(path) -> BatchTable:
    """Read a yade-batch table as YADE's ``TableParamReader`` does (first non-comment line = column
    names, ``=`` repeats the cell above, ``#`` starts a comment), stricter: every row must have one
    cell per column.  A missing or malformed table is a GrainfracError naming the line and the fix."""
    path = Path(path)
    if not path.is_file():
        raise GrainfracError(f"{path}: batch table not found; fix: give the path of a yade-batch table "
                             "(e.g. params/lifetime_small.table)")
    try:
        lines = [""] + path.read_text().splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise GrainfracError(f"{path}: cannot read the batch table ({exc}); fix: give a text file") from None
    usable = [i for i in range(1, len(lines)) if _strip_comment(lines[i]).strip()]
    if not usable:
        raise GrainfracError(f"{path}: no column names (the table is empty or all comments); fix: first line "
                             "names the columns, one row per run below it")
    header = _strip_comment(lines[usable[0]]).split()
    if "description" not in header:   # as YADE: a trailing '!' marks a column for the description
        header = [h[:-1] if h.endswith("!") else h for h in header]
    dupes = sorted({h for h in header if header.count(h) > 1})
    if dupes:
        raise GrainfracError(f"{path}:{usable[0]}: column {dupes[0]!r} named twice; fix: one column per name")
    rows, previous = [], None
    for k, i in enumerate(usable[1:], start=1):
        cells = _strip_comment(lines[i]).split()
        if len(cells) != len(header):
            raise GrainfracError(f"{path}:{i}: {len(cells)} cells but {len(header)} columns; fix: one cell per "
                                 "column, text quoted without spaces ('fem'), '=' repeats the cell above")
        row = {}
        for col, cell in zip(header, cells):
            if cell == "=":
                if previous is None:
                    raise GrainfracError(f"{path}:{i}: '=' in the first row (column {col}) repeats nothing; "
                                         "fix: give the value")
                cell = previous[col]
            row[col] = cell
        rows.append(TableRow(k, i, row))
        previous = row
    if not rows:
        raise GrainfracError(f"{path}: column names but no rows; fix: add one row per run")
    return BatchTable(path, usable[0], tuple(header), tuple(rows))


def frozen_table_text(table: BatchTable, study: str) -> str:
    """The table's text with its ``study`` column set to ``study`` on every row (added if absent);
    comments, blank lines and line numbers kept, so YADE_BATCH lines stay the source's."""
    lines = table.path.read_text().splitlines()
    by_line = {r.line: r for r in table.rows}
    cell = repr(study)
    out = []
    for i, text in enumerate(lines, start=1):
        if i == table.header_line:
            cols = _strip_comment(text).split()
            out.append(" ".join(cols + ([] if "study" in table.columns else ["study"])))
        elif i in by_line:
            cells = _strip_comment(text).split()
            if "study" in table.columns:
                cells[table.columns.index("study")] = cell
            else:
                cells.append(cell)
            out.append(" ".join(cells))
        else:
            out.append(text)
    return "\n".join(out) + "\n"


def write_text_atomically(path, text: str) -> Path:
    """Write ``text`` to a temporary name beside ``path``, flush it to disk, rename it to ``path``."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "w") as fh:
        fh.write(text)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)
    return path


def compress_rows(rows) -> str:
    """Row numbers as an sbatch --array list: [1, 2, 3, 5] -> "1-3,5"."""
    rows = sorted(set(int(r) for r in rows))
    parts, start = [], None
    for k, r in enumerate(rows):
        if start is None:
            start = r
        if k + 1 == len(rows) or rows[k + 1] != r + 1:
            parts.append(f"{start}-{r}" if r > start else f"{r}")
            start = None
    return ",".join(parts)


# --------------------------------------------------------------------------- options and script
@dataclass(frozen=True)
class SubmitOptions:
    """sbatch options of a study's job array, validated on creation."""
    study: str
    partition: str | None = None
    time: str | None = None
    cpus_per_task: int = 1
    max_running: int | None = None

    def __post_init__(self):
        if not isinstance(self.study, str) or not _STUDY_NAME.match(self.study) or ".." in self.study:
            raise GrainfracError(f"--study {self.study!r}: not a folder name; fix: letters, digits and _ . + - "
                                 "(the study folder is results/NAME)")
        if self.partition is not None and not _PARTITION.match(self.partition):
            raise GrainfracError(f"--partition {self.partition!r}: not a partition name; fix: e.g. --partition "
                                 "compute (sinfo lists them)")
        if self.time is not None and not _SLURM_TIME.match(self.time):
            raise GrainfracError(f"--time {self.time!r}: not a SLURM time; fix: minutes, HH:MM:SS or D-HH:MM:SS, "
                                 "e.g. --time 2:00:00")
        for name, value, low in (("--cpus-per-task", self.cpus_per_task, 1), ("--max-running", self.max_running, 1)):
            if value is None and name == "--max-running":
                continue
            if isinstance(value, bool) or not isinstance(value, int) or value < low:
                raise GrainfracError(f"{name} {value!r}: must be a whole number >= {low}; fix: e.g. {name} 1")

    def to_dict(self) -> dict:
        return {"partition": self.partition, "time": self.time, "cpus_per_task": self.cpus_per_task,
                "max_running": self.max_running}


def study_dir_of(study: str) -> Path:
    """The study folder of ``--study NAME``: results/NAME, relative to the current folder."""
    return Path("results") / study


def slurm_dir(study_dir) -> Path:
    return Path(study_dir) / SLURM_DIR


def record_path(study_dir) -> Path:
    return slurm_dir(study_dir) / "study.json"


def task_record_path(study_dir, row: int) -> Path:
    return slurm_dir(study_dir) / "tasks" / f"row{row}.json"


def folder_record_path(study_dir, row: int) -> Path:
    return slurm_dir(study_dir) / "tasks" / f"row{row}_folder.json"


def log_path(study_dir, row: int, job_id) -> Path:
    return slurm_dir(study_dir) / "logs" / f"row{row}_job{job_id}.log"


def render_sbatch(*, study_dir: Path, options: SubmitOptions, rows, all_rows, frozen_table: Path, script: Path,
                  command: str, workdir: Path, repo: Path, source_table, submission: int) -> str:
    """The sbatch script of one submission: a job array over ``rows`` (TableRow), task k = row k.

    Paths below ``workdir`` are written relative to it (the job runs there, as ``submit`` did)."""
    def rel(p: Path) -> str:
        p = (workdir / p).resolve()   # relative paths are below workdir
        try:
            return str(p.relative_to(workdir.resolve()))
        except ValueError:
            return str(p)
    array = compress_rows(r.row for r in rows)
    if options.max_running:
        array += f"%{options.max_running}"
    lines_map = " ".join(f"[{r.row}]={r.line}" for r in all_rows)
    out = (workdir / slurm_dir(study_dir) / "logs").resolve() / "row%a_job%A.log"
    head = [
        "#!/bin/bash",
        f"# grainfrac-yade study {options.study!r}, submission {submission}: one array task per row of",
        f"# {source_table} (frozen copy {rel(frozen_table)}, its study column set to {options.study!r}).",
        f"# Written by: python3 -m grainfrac_yade submit {source_table} --study {options.study}",
        "# Task k runs table row k as one local yade-batch row does:",
        f"#   YADE_BATCH={rel(frozen_table)}:<line of row k> yade -n -x {rel(script)}",
        f"# through grainfrac_yade.runs.slurmtask, which records the task in {rel(slurm_dir(study_dir) / 'tasks')}/ and",
        "# writes failed.json (the error line) into the run folder if the row ends without a summary.json.",
        f"#SBATCH --job-name=grainfrac-{options.study}",
        f"#SBATCH --array={array}",
        f"#SBATCH --cpus-per-task={options.cpus_per_task}",
    ]
    if options.time:
        head.append(f"#SBATCH --time={options.time}")
    if options.partition:
        head.append(f"#SBATCH --partition={options.partition}")
    head += [
        f"#SBATCH --chdir={workdir.resolve()}",
        f"#SBATCH --output={out}",
        "set -eu",
        f"LINES=({lines_map})   # table line of each row",
        f"export YADE_BATCH=\"{rel(frozen_table)}:${{LINES[$SLURM_ARRAY_TASK_ID]}}\"",
        "export OMP_NUM_THREADS=1   # one thread per run: deterministic; a study runs in parallel across rows",
        f"export PYTHONPATH=\"{repo.resolve()}${{PYTHONPATH:+:$PYTHONPATH}}\"",
        f"exec {DEBIAN_PYTHON} -m grainfrac_yade.runs.slurmtask {rel(study_dir)} \"$SLURM_ARRAY_TASK_ID\" {command} -- "
        f"yade -n -x {rel(script)}",
    ]
    return "\n".join(head) + "\n"


# --------------------------------------------------------------------------- records
def read_json_file(path):
    """A JSON object from ``path``; None if missing or unreadable (a record being replaced is renamed
    atomically, so unreadable means damaged)."""
    try:
        data = json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def read_study(study_dir) -> dict:
    """The study record of ``study_dir``; GrainfracError naming the file and the fix if absent."""
    study_dir = Path(study_dir)
    if not study_dir.is_dir():
        raise GrainfracError(f"{study_dir}: study folder not found; fix: give results/NAME of a study submitted "
                             "with python3 -m grainfrac_yade submit TABLE --study NAME")
    path = record_path(study_dir)
    if not path.exists():
        raise GrainfracError(f"{path}: no SLURM study record in {study_dir}; fix: submit the study first "
                             "(python3 -m grainfrac_yade submit TABLE --study NAME), or for a local study use "
                             "analyze / analyze-ucs")
    data = read_json_file(path)
    if data is None or not isinstance(data.get("rows"), list):
        raise GrainfracError(f"{path}: unreadable study record; fix: restore it or submit under a new --study")
    return data


def table_digest(table: BatchTable) -> str:
    """Digest of a table's columns and rows (cells after '='; comments and the study column ignored)."""
    rows = [{k: v for k, v in r.cells.items() if k != "study"} for r in table.rows]
    cols = [c for c in table.columns if c != "study"]
    return hashlib.sha256(json.dumps([cols, rows], sort_keys=True).encode()).hexdigest()[:16]


def new_record(table: BatchTable, options: SubmitOptions, frozen: Path, script: Path, command: str,
               workdir: Path, repo: Path) -> dict:
    return {
        "study": options.study, "source_table": str(table.path), "table": str(frozen), "table_digest":
        table_digest(table), "script": str(script), "command": command, "workdir": str(workdir.resolve()),
        "repo": str(repo.resolve()), "created": now_iso(),
        "rows": [{"row": r.row, "line": r.line, "cells": r.cells} for r in table.rows],
        "submissions": [],
    }


def write_record(study_dir, record: dict) -> Path:
    return write_json(record_path(study_dir), record)


def latest_submission(record: dict) -> dict:
    """{row: submission} for the last submission that included each row."""
    out = {}
    for sub in record.get("submissions", []):
        for r in sub.get("rows", []):
            out[int(r)] = sub
    return out


def recorded_folder(study_dir, row: int) -> Path | None:
    """The run folder row ``row`` chose (relative paths are below the study's working folder)."""
    rec = read_json_file(folder_record_path(study_dir, row)) or read_json_file(task_record_path(study_dir, row)) or {}
    folder = rec.get("folder")
    return Path(folder) if folder else None
