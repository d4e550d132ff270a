"""Parameters for scripts run by ``yade`` / ``yade-batch`` (YADE's ``readParamsFromTable``).

Every parameter path (``section.key``, the names of ``--set``) is a possible
column of a batch table, plus ``seed``, ``out``, ``study``, ``description`` and
``on_change``.  Values are read with YADE's own ``readParamsFromTable`` (each cell
is a Python expression, so text is quoted: ``'fem'``) and validated like files.

A row whose folder already holds a finished run (summary.json) is skipped only if
that run's stored parameters (params.json) and run values (seed, load) equal the
row's; otherwise the row stops with one line naming the folder and the keys that
differ, or, with ``on_change`` = ``'new_folder'``, runs into ``<folder>_<digest>``
(:func:`grainfrac_yade.runs.runio.run_digest` of its parameters), skipped in turn once
finished there.  An unfinished creep, UCS or Brazilian row whose folder holds a checkpoint of the
same parameters and run values goes on from it (:func:`row_plan`); otherwise it starts again.
"""
from __future__ import annotations

import os
import sys
from contextlib import contextmanager
from pathlib import Path

from ...runs.batchrun import ON_CHANGE, RUN_COLUMNS, check_columns, read_table_rows, run_folder_name  # noqa: F401
from ...errors import GrainfracError
from ...params import shipped_values
from ...runs.runio import SUMMARY, checkpoint_differences, run_digest, stored_run_differences
from . import load_yade

def read_table(extra_columns=None) -> tuple:
    """Read this run's row (or the defaults outside a batch).

    Returns (overrides list of (key, value), run controls dict).
    """
    yade = load_yade()
    from yade import utils
    defaults = shipped_values()
    run_defaults = dict(RUN_COLUMNS, **(extra_columns or {}))
    spec = os.environ.get("YADE_BATCH", "")
    if spec:
        table, line = spec.rsplit(":", 1)
        columns, rows, problems = read_table_rows(table)
        if problems:   # YADE's own reader would end every row in an IndexError
            raise GrainfracError(f"batch table row {spec}: the table has bad lines ({'; '.join(problems)})")
        check_columns(columns, {**defaults, **run_defaults}, spec)
    try:
        utils.readParamsFromTable(noTableOk=True, **defaults, **run_defaults)
    except NameError as exc:   # YADE evaluates every cell as Python: text without quotes (columns checked above)
        raise GrainfracError(f"batch table row {spec}: {exc}; fix: text cells must be quoted, e.g. 'fem'"
                             ) from None
    table = yade.params.table
    overrides = [(k, getattr(table, k)) for k, v in defaults.items() if getattr(table, k) != v]
    controls = {k: getattr(table, k) for k in run_defaults}
    if controls["on_change"] not in ON_CHANGE:
        raise GrainfracError(f"batch table row {spec}: on_change = {controls['on_change']!r}; fix: use one of "
                             f"{', '.join(repr(v) for v in ON_CHANGE)}")
    if not controls["description"] and explicit_description_column():
        controls["description"] = yade.O.tags["description"]
    return overrides, controls


def explicit_description_column() -> bool:
    """True if the running yade-batch table has its own ``description`` column.

    YADE puts the row's description in ``O.tags["description"]`` and synthesizes one
    ("col=value,...") when the table has none; only an explicit one names the run folder.
    """
    spec = os.environ.get("YADE_BATCH", "")
    if not spec:
        return False
    table = spec.rsplit(":", 1)[0]
    try:
        with open(table) as fh:
            for line in fh:
                if line.strip() and not line.lstrip().startswith("#"):
                    return "description" in line.split()
    except OSError:
        return False
    return False


#: Environment variable naming a JSON file in which a row records the run folder it chose (set by the SLURM
#: task wrapper, :mod:`grainfrac_yade.runs.slurmtask`; the same name as ``grainfrac_yade.runs.slurm.ROW_FOLDER_ENV``).
ROW_FOLDER_ENV = "GRAINFRAC_ROW_FOLDER_FILE"


#: Environment variable naming a folder in which each yade-batch row records the run folder it chose, as
#: ``<line number>.json`` (set by the ``batch`` command and the demo, :func:`grainfrac_yade.runs.batchrun.run_batch`;
#: the same name as ``grainfrac_yade.runs.batchrun.ROW_FOLDERS_ENV``).
ROW_FOLDERS_ENV = "GRAINFRAC_ROW_FOLDERS"


def record_row_folder(out: Path) -> Path:
    """Write ``{"folder": <absolute out>}`` to the file named by :data:`ROW_FOLDER_ENV`, and to
    ``<line>.json`` in the folder named by :data:`ROW_FOLDERS_ENV`, if set; return ``out``.

    A SLURM task or a batch learns this way where its row runs (to mark it failed there, and to tell finished
    rows)."""
    spec = os.environ.get("YADE_BATCH", "")
    folders = os.environ.get(ROW_FOLDERS_ENV)
    if folders and ":" in spec:
        from ...runs.runio import write_json
        Path(folders).mkdir(parents=True, exist_ok=True)
        write_json(Path(folders) / f"{spec.rsplit(':', 1)[1]}.json", {"folder": str(Path(out).resolve())})
    target = os.environ.get(ROW_FOLDER_ENV)
    if target:
        from ...runs.runio import write_json
        Path(target).parent.mkdir(parents=True, exist_ok=True)
        write_json(target, {"folder": str(Path(out).resolve())})
    return out


def row_folder(out, params, controls: dict, run_values: dict) -> tuple:
    """(folder, done): the folder a batch row runs into, and whether it already holds this row's finished run.

    ``run_values``: what besides the parameters makes the run (e.g. seed, stress_pa), compared
    with the stored summary.json. A finished run that differs: GrainfracError naming the folder
    and the differing keys, or with ``controls["on_change"] == "new_folder"`` the folder
    ``<out>_<digest>`` (decided the same way).
    """
    out = Path(out)
    if not (out / SUMMARY).exists():
        return record_row_folder(out), False
    diffs = stored_run_differences(out, params, run_values)
    if not diffs:
        return record_row_folder(out), True
    if controls.get("on_change") == "new_folder":
        new = out.with_name(f"{out.name}_{run_digest(params, run_values)}")
        return row_folder(new, params, dict(controls, on_change="stop"), run_values)
    raise GrainfracError(f"{out}: holds a finished run with other parameters ({'; '.join(diffs)}); fix: give the "
                         "row another out or study, remove the folder, or add a column on_change with 'new_folder' "
                         "to run it into a new folder")


def row_plan(out, params, controls: dict, run_values: dict) -> tuple:
    """(folder, action, note): what a batch row of a resumable run (creep, UCS, Brazilian) does with its folder.

    ``action``: "skip" (the folder holds this row's finished run, :func:`row_folder`), "resume" (an
    unfinished run of this row with a checkpoint: same parameters, apart from those that do not change
    results, and the same run values), or "run" (start; an unfinished run without a usable checkpoint is
    replaced).  ``note``: why a checkpoint is not used ("" otherwise).
    """
    out, done = row_folder(out, params, controls, run_values)
    if done:
        return out, "skip", ""
    diffs = checkpoint_differences(out, params, run_values)
    if diffs is None:
        return out, "run", ""
    if diffs:
        return out, "run", f"{out}: its checkpoint is of another run ({'; '.join(diffs)}): started again"
    return out, "resume", ""


@contextmanager
def row_errors():
    """A GrainfracError inside a batch row becomes one ``error:`` line in its log and exit status 2."""
    try:
        yield
    except GrainfracError as exc:
        print(f"error: {exc}")
        sys.exit(2)
