"""``submit``: run a yade-batch table on a SLURM cluster, one job-array task per row.

    python3 -m grainfrac_yade submit TABLE --study NAME [--partition P --time T --cpus-per-task C
                                                          --max-running K --script S --dry-run]

Writes ``results/NAME/slurm/`` (the study record, the frozen table, the sbatch script of each
submission, logs, task records; see :mod:`grainfrac_yade.runs.slurm`) and submits the array with
``sbatch``.  Each task runs its row exactly as a local batch row (``YADE_BATCH=<table>:<line> yade
-n -x <script>``) into ``results/NAME/<row name>/``.  Submitting the study again submits only the
rows without a finished summary.json that are neither queued nor running; a resubmitted row
goes on from its run folder as a local batch row would (a finished row is skipped, an unfinished
one starts again, or resumes where the batch code resumes it).
"""
from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

from ..errors import GrainfracError
from ..params import shipped_values
from ..runs.batchrun import RUN_COLUMNS, check_columns
from ..runs.slurm import (SubmitOptions, cell_value, frozen_table_text, log_path, new_record, now_iso, read_batch_table,
                          read_json_file, record_path, render_sbatch, slurm_dir, study_dir_of, table_digest,
                          write_record, write_text_atomically)
from ..runs.slurm_states import study_states
from ._loads import CREEP_ROW_COLUMNS

#: Scripts by the table columns that make a row a creep row.
CREEP_COLUMNS = ("ratio", "stress")


def register(sub, common):
    p = sub.add_parser("submit", help="run a batch table on SLURM: one job-array task per row (results/NAME/)",
                       description="Submit a yade-batch table as a SLURM job array, one task per row, into "
                                   "results/NAME/; again: only the rows without a finished summary.json.")
    p.add_argument("table", help="yade-batch table (e.g. params/lifetime_small.table)")
    p.add_argument("--study", required=True, help="study name: run folders go to results/NAME/ (the table's study "
                                                  "column is set to NAME)")
    p.add_argument("--script", help="YADE script of each row (default: yade_scripts/creep.py if the table has a "
                                    "ratio or stress column, else yade_scripts/ucs.py)")
    p.add_argument("--partition", help="SLURM partition (default: the cluster's default)")
    p.add_argument("--time", help="time limit per task, e.g. 2:00:00 or 1-00:00:00 (default: the partition's)")
    p.add_argument("--cpus-per-task", type=int, default=1, help="CPUs per task (default 1; YADE runs one thread)")
    p.add_argument("--max-running", type=int, help="at most K tasks of the array at a time (sbatch --array=...%%K)")
    p.add_argument("--dry-run", action="store_true", help="print the sbatch script and the rows; write and submit "
                                                          "nothing")
    p.set_defaults(func=cmd_submit)


def _repo() -> Path:
    return Path(__file__).resolve().parents[2]


def choose_script(table, script) -> Path:
    """The YADE script of the rows: ``script`` if given, else creep.py for creep tables, else ucs.py."""
    if script is None:
        name = "creep.py" if any(c in table.columns for c in CREEP_COLUMNS) else "ucs.py"
        return _repo() / "yade_scripts" / name
    path = Path(script)
    if not path.is_file():
        raise GrainfracError(f"--script {script}: file not found; fix: give a YADE script such as "
                             "yade_scripts/creep.py or yade_scripts/ucs.py")
    return path.resolve()


def check_table_columns(table, command: str) -> None:
    """Columns must be parameter paths or run columns the script reads (one line naming the column)."""
    extra = {}
    if command == "creep":
        extra = CREEP_ROW_COLUMNS
    elif command not in ("ucs",):
        return   # another script: its own columns
    valid = {**shipped_values(), **RUN_COLUMNS, **extra}
    check_columns(table.columns, valid, str(table.path))


def check_out_column(table, study_dir: Path) -> None:
    """A row's ``out`` cell must keep its run folder inside the study folder (or be empty)."""
    for r in table.rows:
        out = cell_value(r.cells.get("out", "''"))
        if out in ("", None):
            continue
        if not isinstance(out, str) or not Path(out).resolve().is_relative_to(study_dir.resolve()):
            raise GrainfracError(f"{table.path}:{r.line}: out = {r.cells['out']} puts the run outside "
                                 f"{study_dir}; fix: drop the out column (rows go to {study_dir}/<row name>/) "
                                 "or point it inside that folder")


def rows_to_submit(study_dir, record, table) -> tuple:
    """(rows, states, note) of a study submitted before: rows neither finished nor queued/running."""
    if record.get("table_digest") != table_digest(table):
        raise GrainfracError(f"{record_path(study_dir)}: study {record['study']!r} was submitted from "
                             f"{record['source_table']} with other rows or columns than {table.path}; fix: "
                             "submit the same table again, or a changed one under a new --study NAME")
    _, states, queue, _ = study_states(study_dir, record)
    if record.get("submissions") and not queue.available:
        raise GrainfracError(f"{queue.note}: cannot tell which rows of {study_dir} are still queued or running; "
                             "fix: run submit where squeue works (apt-get install slurm-client)")
    by_row = {r.row: r for r in table.rows}
    todo = [by_row[s.row] for s in states if s.state not in ("finished", "running", "pending") or
            (s.state == "pending" and s.detail == "never submitted")]
    return todo, states


def cmd_submit(args) -> int:
    options = SubmitOptions(study=args.study, partition=args.partition, time=args.time,
                            cpus_per_task=args.cpus_per_task, max_running=args.max_running)
    table = read_batch_table(args.table)
    script = choose_script(table, args.script)
    command = script.stem
    check_table_columns(table, command)
    study_dir = study_dir_of(options.study)
    check_out_column(table, study_dir)
    workdir = Path.cwd()
    sdir = slurm_dir(study_dir)
    frozen = sdir / f"{options.study}.table"
    record = read_json_file(record_path(study_dir))
    if record is not None:
        if Path(record.get("script", "")) != script:
            raise GrainfracError(f"{record_path(study_dir)}: study {options.study!r} runs {record.get('script')}, "
                                 f"not {script}; fix: drop --script or submit under a new --study NAME")
        todo, states = rows_to_submit(study_dir, record, table)
        counts = {s: sum(1 for x in states if x.state == s) for s in ("finished", "running", "pending")}
        if not todo:
            print(f"{study_dir}: nothing to submit: {counts['finished']} finished, {counts['running']} running, "
                  f"{counts['pending']} pending of {len(states)} rows")
            return 0
        print(f"{study_dir}: {counts['finished']} finished, {counts['running']} running, {counts['pending']} "
              f"pending; submitting the other {len(todo)} row(s)")
    else:
        todo = list(table.rows)
        record = new_record(table, options, frozen, script, command, workdir, _repo())
    submission = len(record["submissions"]) + 1
    text = render_sbatch(study_dir=study_dir, options=options, rows=todo, all_rows=table.rows, frozen_table=frozen,
                         script=script, command=command, workdir=workdir, repo=_repo(), source_table=args.table,
                         submission=submission)
    rows_text = ", ".join(f"{r.row} (line {r.line})" for r in todo)
    if args.dry_run:
        print(text, end="")
        print(f"# dry run: {len(todo)} row(s) {rows_text} of {args.table} would run into {study_dir}/; "
              "nothing written or submitted")
        return 0
    sbatch = shutil.which("sbatch")
    if sbatch is None:
        raise GrainfracError("sbatch not found on PATH; fix: submit from a SLURM login node (Debian: apt-get install "
                             "slurm-client), run the table locally with yade-batch, or see the script with --dry-run")
    (sdir / "logs").mkdir(parents=True, exist_ok=True)
    (sdir / "tasks").mkdir(parents=True, exist_ok=True)
    if not frozen.exists():   # written once: tasks of earlier submissions may be reading it
        write_text_atomically(frozen, frozen_table_text(table, options.study))
    script_file = sdir / f"submit_{submission}.sbatch"
    script_file.write_text(text)
    write_record(study_dir, record)
    try:
        res = subprocess.run([sbatch, "--parsable", str(script_file)], capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.SubprocessError) as exc:
        script_file.unlink(missing_ok=True)
        raise GrainfracError(f"sbatch {script_file} failed ({type(exc).__name__}: {exc}); fix: check that slurmctld "
                             "answers (sinfo)") from None
    job_id = res.stdout.strip().split(";")[0]
    if res.returncode != 0 or not job_id.isdigit():
        script_file.unlink(missing_ok=True)
        why = next((ln.strip() for ln in (res.stderr + res.stdout).splitlines() if ln.strip()), "no message")
        raise GrainfracError(f"sbatch {script_file} refused the array ({why}); fix: check --partition and --time "
                             "against sinfo, and that sinfo reaches the cluster (SLURM_CONF or /etc/slurm/slurm.conf)")
    record["submissions"].append({"submission": submission, "job_id": job_id, "rows": [r.row for r in todo],
                                  "sbatch": str(script_file), "submitted": now_iso(), "options": options.to_dict()})
    write_record(study_dir, record)
    print(f"submitted job {job_id}: {len(todo)} array task(s), rows {rows_text} of {args.table} -> {study_dir}/")
    print(f"script: {script_file}; logs: {log_path(study_dir, '<row>', job_id)}")
    print(f"status: python3 -m grainfrac_yade status {study_dir}")
    return 0
