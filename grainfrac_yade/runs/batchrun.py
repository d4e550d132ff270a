"""Write yade-batch tables and run them (one YADE process per row, ``jobs`` rows at a time).

No YADE import: ``yade-batch`` runs in its own processes.  The same table runs
on a cluster one row per SLURM array task: YADE's ``readParamsFromTable`` reads
the row named by the environment variable ``YADE_BATCH=<table>:<line number in
the file>`` (yade utils.py), so a task runs
``YADE_BATCH=params/lifetime_ldb.table:$LINE yade -n -x yade_scripts/creep.py``.
"""
from __future__ import annotations

import ast
import json
import os
import re
import shutil
import subprocess
from pathlib import Path

from ..errors import GrainfracError
from ..params import nearest_key, renamed_key_fix

#: Seconds between checks of the run folders while a batch runs; the wait ends as soon as yade-batch exits
#: (a fixed sleep made every call last a multiple of it: a 6.6 s batch took 10 s).
POLL_S = 5.0
#: Environment variable naming the folder where each row records its run folder as ``<line>.json``
#: (``grainfrac_yade.engines.yade.batch.ROW_FOLDERS_ENV``, the same name).
ROW_FOLDERS_ENV = "GRAINFRAC_ROW_FOLDERS"
#: Subfolder of a batch's log folder holding the rows' ``<line>.json`` records.
ROW_RECORDS = "rows"
#: yade-batch's line when a job ends: ``#<job> (<description>) done|FAILED (exit status N), duration ..., log <path>``.
JOB_END = re.compile(r"^#\d+ \((?P<desc>.*)\) (?P<state>done|FAILED)\s+\(exit status (?P<status>-?\d+)\).*, log (?P<log>\S+)")


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


def run_batch(table, script, jobs: int, log_dir, watch=(), progress=None, repo=None, on_row_end=None) -> int:
    """Run ``yade-batch -j jobs table script``; call ``progress`` as folders in ``watch`` get a summary, and
    ``on_row_end(line number)`` as yade-batch reports a row ended.

    Returns yade-batch's exit status; the rows' own results are judged by their summary.json.
    """
    exe = shutil.which("yade-batch")
    if exe is None:
        raise GrainfracError("yade-batch not found on PATH; fix: apt-get install yade (see README)")
    log_dir = Path(log_dir).resolve()
    log_dir.mkdir(parents=True, exist_ok=True)   # yade-batch hangs forever when its log folder is missing
    records = log_dir / ROW_RECORDS
    shutil.rmtree(records, ignore_errors=True)   # records of an earlier batch in the same log folder
    cmd = [exe, "-j", str(jobs), "--log", str(log_dir / "%.log"), str(Path(table).resolve()), str(script)]
    pending = [Path(w) for w in watch]
    ended = []
    env = dict(os.environ, **{ROW_FOLDERS_ENV: str(records)})
    with open(log_dir / "yade-batch.txt", "w") as out:
        proc = subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT, cwd=repo, env=env)
        while True:
            finished = proc.poll() is not None
            for w in [w for w in pending if (w / "summary.json").exists()]:
                pending.remove(w)
                if progress:
                    progress(w)
            if on_row_end:
                for line in _ended_rows(log_dir / "yade-batch.txt")[len(ended):]:
                    ended.append(line)
                    on_row_end(line)
            if finished:
                break
            try:
                proc.wait(timeout=POLL_S)
            except subprocess.TimeoutExpired:
                pass
    return proc.returncode


def _ended_rows(output: Path) -> list:
    """Table lines of the rows yade-batch reported ended in its ``output``, in order."""
    try:
        text = output.read_text(errors="replace")
    except OSError:
        return []
    lines = []
    for row in text.splitlines():
        m = JOB_END.match(row)
        if m and Path(m["log"]).stem.isdigit():
            lines.append(int(Path(m["log"]).stem))
    return lines


def run_folder_name(controls: dict, overrides) -> str:
    """Folder name of a batch row: its description, else the overridden values and seed (``overrides``: (key,
    value) pairs in the order of the shipped parameters, as YADE's reader gives them)."""
    desc = controls.get("description") or "_".join(f"{k.split('.')[-1]}={v}" for k, v in overrides)
    desc = f"{desc}_seed{controls['seed']}" if "seed" not in desc else desc
    return re.sub(r"[^A-Za-z0-9_.=+-]+", "_", desc).strip("_") or f"seed{controls['seed']}"


#: What a row script prints (after "creep", "UCS" or "Brazilian") when its folder already holds its finished run.
ROW_SKIPPED = "row already finished, skipped"


class RowOutcome:
    """What one table row did: ``ok`` (its run folder holds a finished run with a result), ``numerical`` (a
    finished run that ended as a numerical failure: no result, not ok), ``skipped`` (finished before this batch:
    the row script found its finished run and did not run it), the folder, and one line."""

    def __init__(self, line: int, ok: bool, text: str, folder=None, log=None, skipped=False, numerical=False):
        self.line, self.ok, self.text, self.folder, self.log = line, ok, text, folder, log
        self.skipped, self.numerical = skipped, numerical

    def __str__(self):
        state = "numerical failure" if self.numerical else "ok" if self.ok else "FAILED"
        if self.skipped:
            state = "skipped (finished)" if self.ok else f"skipped (finished before: {state})"
        return f"line {self.line}: {state}: {self.text}"


def _skipped(log: Path) -> bool:
    """Whether the row's log says its script skipped it (a finished run of the row was already there)."""
    try:
        return ROW_SKIPPED in log.read_text(errors="replace")
    except OSError:
        return False


def row_outcomes(table, log_dir, lines, describe=None) -> list:
    """The :class:`RowOutcome` of each table line in ``lines`` after :func:`run_batch` ran it into ``log_dir``.

    A row succeeded if the run folder it recorded holds summary.json (and the summary does not say the test
    failed before it began, ``failed_before_test``); otherwise the reason is the row's last ``error:`` line, or
    the last line of its traceback, in its log.  A finished run whose summary says ``numerical_failure`` is
    neither: ``numerical`` (no result).  ``describe(summary)``: the result phrase of a finished row."""
    log_dir = Path(log_dir).resolve()
    out = []
    for line in lines:
        log = log_dir / f"{line}.log"
        folder = None
        try:
            folder = Path(json.loads((log_dir / ROW_RECORDS / f"{line}.json").read_text())["folder"])
        except (OSError, ValueError, KeyError, TypeError):
            pass
        summary = None
        if folder is not None:
            try:
                summary = json.loads((folder / "summary.json").read_text())
            except (OSError, ValueError):
                summary = None
        if summary is not None and not summary.get("failed_before_test"):
            numerical = bool(summary.get("numerical_failure"))
            text = describe(summary) if describe else "finished"
            out.append(RowOutcome(line, not numerical, f"{text} -> {folder}", folder, log, skipped=_skipped(log),
                                  numerical=numerical))
            continue
        reason = summary.get("end_reason") if summary else _log_reason(log)
        out.append(RowOutcome(line, False, f"{reason} (log {log})", folder, log))
    return out


def _log_reason(log: Path) -> str:
    """The reason a row failed, from its log: its last ``error:`` line, else the last line of a traceback."""
    try:
        lines = [l.strip() for l in log.read_text(errors="replace").splitlines() if l.strip()]
    except OSError:
        return "the row did not run (no log)"
    errors = [l for l in lines if l.startswith("error:")]
    if errors:
        return errors[-1]
    if any(l.startswith("Traceback") for l in lines):
        after = lines[max(i for i, l in enumerate(lines) if l.startswith("Traceback")):]
        last = [l for l in after if re.match(r"^[A-Za-z_.]*(Error|Exception|Interrupt)\b", l)]
        return last[-1] if last else after[-1]
    return "no finished run (no summary.json): the row stopped without an error line"


#: A column name: a parameter path (section.key, a quoted mineral pair in contacts."a/b".key) or a run column,
#: optionally with YADE's leading or trailing ``!``.
COLUMN_NAME = re.compile(r'^!?[A-Za-z_][A-Za-z0-9_./"-]*!?$')
#: A table cell that repeats the value of the line above (yade-batch's rule).
SAME_AS_ABOVE = "="


def read_table_rows(path) -> tuple:
    """(columns, {line number: {column: cell text}}, [problem lines]) of a yade-batch table, read as
    YADE's ``TableParamReader`` reads it (``#`` comments, blank lines skipped, whitespace-separated cells,
    ``=`` repeats the line above, a trailing ``!`` on a column name dropped) but without its
    IndexError: a line with another number of cells than the header is one problem line naming it."""
    path = Path(path)
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise GrainfracError(f"{path}: cannot read the batch table ({type(exc).__name__}: {exc}); "
                             "fix: give a readable text file") from None
    lines = [re.sub(r"\s*#.*", "", line) for line in text.splitlines()]
    used = [(i + 1, line.split()) for i, line in enumerate(lines) if line.strip()]
    if not used:
        raise GrainfracError(f"{path}: no header line (column names); fix: a first line of column names, "
                             "then one line per run")
    (header_line, header), body = used[0], used[1:]
    not_names = [h for h in header if not COLUMN_NAME.match(h)]
    if not_names:
        raise GrainfracError(f"{path}:{header_line}: not a batch table: its first line is not column names "
                             f"({', '.join(repr(h) for h in not_names[:3])}); fix: a batch table is a first line of "
                             "column names (parameter paths such as specimen.width, ratio or stress, seed, study, "
                             "out), then one line of values per run, e.g. `ratio seed` then `0.7 1`")
    columns = [h[:-1] if h.endswith("!") and h != "!" else h for h in header]
    rows, problems, previous = {}, [], None
    for number, cells in body:
        if len(cells) != len(columns):
            missing = "a missing (empty) cell" if len(cells) < len(columns) else "an extra cell"
            problems.append(f"{path}:{number}: {len(cells)} cells for {len(columns)} columns ({missing}); fix: one "
                            "value per column on every line (= repeats the value above)")
            continue
        row = {}
        for col, cell in zip(columns, cells):
            if cell == SAME_AS_ABOVE:
                if previous is None:
                    problems.append(f"{path}:{number}: column {col}: '=' on the first row has no value above; "
                                    "fix: give the value")
                    break
                cell = previous[col]
            row[col] = cell
        else:
            rows[number] = previous = row
    if not rows and not problems:
        raise GrainfracError(f"{path}: no rows below the header; fix: one line per run")
    return columns, rows, problems


def cell_value(text: str):
    """A table cell as YADE evaluates it (a Python literal); ValueError if it is not one (e.g. unquoted text)."""
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError):
        pass
    try:   # arithmetic of literals (2*1e6), as YADE's eval allows; nothing else
        tree = ast.parse(text, mode="eval")
    except SyntaxError:
        tree = None
    allowed = (ast.Expression, ast.BinOp, ast.UnaryOp, ast.Constant, ast.operator, ast.unaryop)
    if tree is not None and all(isinstance(node, allowed) for node in ast.walk(tree)):
        return eval(compile(tree, "<cell>", "eval"), {"__builtins__": {}}, {})
    raise ValueError(f"{text!r} is not a number or a quoted text")


#: Table columns that are not model parameters: run controls, with defaults.
RUN_COLUMNS = {"seed": 1, "out": "", "study": "default", "description": "", "on_change": "stop"}
#: What a row does when its folder holds a finished run with other parameters (column ``on_change``).
ON_CHANGE = ("stop", "new_folder")


def check_columns(columns, valid, where: str) -> None:
    """GrainfracError naming the first column not in ``valid`` and the valid key it most likely misspells
    (``where``: the table row, as YADE_BATCH names it)."""
    for col in columns:
        if col == "description" or col.startswith("!") or col in valid:
            continue
        renamed = renamed_key_fix(col)
        if renamed:
            raise GrainfracError(f"batch table {where}: column {col!r} is a renamed key; fix: {renamed}")
        close = nearest_key(col, valid)
        hint = f"did you mean {close}?" if close else ("columns are parameter paths (section.key, as in "
                                                       "params/*.toml) or " + ", ".join(RUN_COLUMNS))
        raise GrainfracError(f"batch table {where}: unknown column {col!r}; fix: {hint}")
