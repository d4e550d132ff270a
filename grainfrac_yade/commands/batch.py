"""``batch TABLE``: run a yade-batch table of creep, UCS or Brazilian rows, checked before anything runs.

Every row is checked first as the CLI checks its flags (unknown column, a cell that is not a number
or quoted text, a missing cell, ratio and stress in one row, a ratio outside (0, 1), a stress or
confinement out of range, parameters the schema refuses), and the rows together (a row that repeats
another, two rows that would run into one folder): one line per bad row, exit status 2, nothing run.
Then the log folder (``--log-dir``, default ``results/logs/<table name>/``) and each row's study
folder are made, yade-batch runs the rows, and one line per row is printed as it ends: ``ok``,
``skipped (finished)``, ``numerical failure`` (the run finished without a result: its summary.json
says ``numerical_failure: true``) or ``FAILED`` (no finished run).  The exit status is 0 when every
row gave a result, 1 when a row FAILED, else 3 (:data:`~grainfrac_yade.errors.EXIT_NUMERICAL_FAILURE`)
when rows ended as numerical failures; the last line names those rows.
"""
from __future__ import annotations

import os
import re
from pathlib import Path

from ..errors import EXIT_NUMERICAL_FAILURE, GrainfracError
from ..geometry.specimen import MAX_SEED, check_cell_count
from ..geometry.tessellation import n_cells_for
from ..params import load_parameters, require_plane, shipped_values
from ..params.schema import field_spec
from ..runs.batchrun import (ON_CHANGE, RUN_COLUMNS, cell_value, check_columns, read_table_rows, row_outcomes,
                             run_batch, run_folder_name)
from ..protocols.brazilian_output import require_disc_model
from ._loads import CREEP_ROW_COLUMNS, check_stress_range, creep_name_parts, resolve_stress
from ._outcome import outcome

#: The scripts of each kind of row, in yade_scripts/.
SCRIPTS = {"creep": "creep.py", "ucs": "ucs.py", "brazilian": "brazilian.py"}
#: Bad rows listed by a refusal; the rest are counted (a file that is no table would list every line).
MAX_LISTED_PROBLEMS = 10
#: Exit status of a batch in which some row did not finish (rows checked and run; not a user error).
EXIT_ROWS_FAILED = 1


def register(sub, common):
    p = sub.add_parser("batch", help="run a yade-batch table (creep, UCS or Brazilian rows), every row checked first")
    p.add_argument("table", help="yade-batch table: one row per run; columns are parameter paths (Pa for "
                                 "stresses), seed, out, study, and for creep rows ratio or stress [Pa], ucs [Pa]")
    p.add_argument("--test", choices=tuple(SCRIPTS),
                   help="kind of rows (default: creep if the table has a ratio or stress column, brazilian if "
                        "it has a brazilian.* column or its name says brazilian, else ucs)")
    p.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="rows run at a time (default: cores)")
    p.add_argument("--log-dir", help="folder of the rows' logs (default results/logs/<table name>)")
    p.set_defaults(func=cmd_batch)


def guess_test(columns, name: str = "") -> str:
    """The kind of rows a table holds, from its columns and its file ``name`` (see ``--test``)."""
    if "ratio" in columns or "stress" in columns:
        return "creep"
    if any(c.startswith("brazilian.") for c in columns) or "brazilian" in name:
        return "brazilian"
    return "ucs"


def row_columns(test: str) -> dict:
    """The run-control columns of a kind of row, with defaults (parameters aside)."""
    if test == "creep":
        return dict(RUN_COLUMNS, **CREEP_ROW_COLUMNS)
    return dict(RUN_COLUMNS)


def expected_cell(col: str, defaults: dict, controls: dict) -> str:
    """What a cell of column ``col`` must be, as a fix: its type from the schema (unit, choices), else from the
    type of its default (run columns: seed, out, study, ratio, ...)."""
    try:
        spec = field_spec(col)
    except GrainfracError:
        spec = None
    if spec is not None:
        unit = f" [{spec['unit']}]" if spec["unit"] not in ("", "1") else ""
        if spec["check"] == "bool":
            return f"column {col} takes True or False"
        if spec["check"] == "choice":
            return f"column {col} takes quoted text, one of {', '.join(repr(c) for c in spec['choices'])}"
        if spec["check"].endswith("_int"):
            return f"column {col} takes a whole number, e.g. {defaults.get(col, 1)!r}"
        return f"column {col} takes a number{unit}, e.g. {defaults.get(col, 1.0)!r}"
    default = defaults.get(col, controls.get(col))
    if isinstance(default, str):
        return f"column {col} takes quoted text, e.g. {default or 'name'!r}"
    if isinstance(default, bool):
        return f"column {col} takes True or False"
    if isinstance(default, int):
        return f"column {col} takes a whole number, e.g. {default!r}"
    if isinstance(default, float):
        return f"column {col} takes a number, e.g. {default!r}"
    return "text cells must be quoted, e.g. 'fem'; numbers as they are, e.g. 1.5e6"


def check_out_writable(out: str, where: str):
    """GrainfracError (one line naming ``where``) if the row's ``out`` folder cannot be made or written: its
    nearest existing folder must be a writable folder (checked with the rows, before any row runs)."""
    path = Path(out).expanduser().absolute()
    probe = path
    while not probe.exists():
        probe = probe.parent
    if not probe.is_dir():
        raise GrainfracError(f"batch table {where}: out = {out!r}: {probe} is a file, not a folder; fix: give the "
                             "row an out below a folder")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise GrainfracError(f"batch table {where}: out = {out!r}: {probe} is not writable; fix: give the row an out "
                             "in a folder you can write, or make that folder writable")


def check_row(test: str, columns, cells: dict, where: str):
    """(overrides, controls) of one row, checked as the CLI and the row script check them; GrainfracError
    (one line, naming ``where``) if the row would be refused."""
    defaults, controls = shipped_values(), row_columns(test)
    check_columns(columns, {**defaults, **controls}, where)
    values = {}
    for col, text in cells.items():
        if col.startswith("!"):
            continue
        try:
            values[col] = cell_value(text)
        except ValueError as exc:
            raise GrainfracError(f"batch table {where}: column {col}: {exc}; fix: "
                                 f"{expected_cell(col, defaults, controls)}") from None
    overrides = [(k, v) for k, v in values.items() if k in defaults and v != defaults[k]]
    controls.update({k: v for k, v in values.items() if k in controls})
    if controls["on_change"] not in ON_CHANGE:
        raise GrainfracError(f"batch table {where}: on_change = {controls['on_change']!r}; fix: use one of "
                             f"{', '.join(repr(v) for v in ON_CHANGE)}")
    if (not isinstance(controls["seed"], int) or isinstance(controls["seed"], bool)
            or not 0 <= controls["seed"] <= MAX_SEED):
        raise GrainfracError(f"batch table {where}: seed = {controls['seed']!r}; fix: a whole number from 0 to "
                             f"{MAX_SEED} (the range of a 32-bit seed)")
    check_out_writable(str(controls["out"]) or str(Path("results", str(controls["study"]))), where)
    try:
        params = load_parameters(overrides=overrides)
    except GrainfracError as exc:
        raise GrainfracError(f"batch table {where}: {exc}") from None
    try:
        sp = params.specimen
        check_cell_count(n_cells_for([sp.width, sp.height], sp.grain_size), "the row's specimen", sp.grain_size)
        _check_kind(test, params, controls)
    except GrainfracError as exc:
        raise GrainfracError(f"batch table {where}: {exc}") from None
    return overrides, controls


def _check_kind(test, params, controls):
    if test == "brazilian":
        require_disc_model(params)
        return
    require_plane(params, test)
    check_stress_range(params)
    if test == "creep":
        given = {k: (float(controls[k]) or None) for k in ("stress", "ratio", "ucs")}
        if given["ratio"] and given["stress"]:
            raise GrainfracError("the row gives both ratio and stress; fix: keep one of the two columns per row "
                                 "(stress in Pa, ratio of the UCS)")
        resolve_stress(params, given["stress"], given["ratio"], given["ucs"])


def row_out(test: str, overrides, controls: dict) -> Path:
    """The folder a checked row runs into, named as its row script names it (``out``, else
    ``results/<study>/<row name>``: :func:`~grainfrac_yade.runs.batchrun.run_folder_name` of the load columns and
    the parameters in the shipped files' order, as YADE's reader lists them), absolute from the working folder
    (where yade-batch runs).  A row with ``on_change = 'new_folder'`` may move on from it at run time."""
    order = {k: i for i, k in enumerate(shipped_values())}
    ordered = sorted(overrides, key=lambda kv: order[kv[0]])
    parts = creep_name_parts(controls) if test == "creep" else []
    out = str(controls["out"]) or f"results/{controls['study']}/{run_folder_name(controls, parts + ordered)}"
    return Path(out).expanduser().absolute()


def repeated_rows(table, test: str, checked: dict) -> list:
    """One line per row that repeats an earlier one (the same load, seed and parameters: the second run would
    only find the first finished) or runs into an earlier row's folder (two runs in one folder)."""
    problems, same, folders = [], {}, {}
    for line, (overrides, controls) in checked.items():
        key = repr((sorted(overrides), sorted(controls.items())))
        if key in same:
            problems.append(f"{table}:{line}: repeats line {same[key]} (the same run twice: the second would only "
                            "skip it); fix: remove one, or give it another seed")
            continue
        same[key] = line
        out = row_out(test, overrides, controls)
        if out in folders:
            problems.append(f"{table}:{line}: runs into {out}, as line {folders[out]} does (two runs cannot share a "
                            "folder); fix: give each row its own out (or description)")
        else:
            folders[out] = line
    return problems


def check_table(table, test=None) -> tuple:
    """(kind of rows, {line: (overrides, controls)}) of a table whose every row passes :func:`check_row` and
    that repeats no row and no folder (:func:`repeated_rows`); else GrainfracError with one line per bad row."""
    columns, rows, problems = read_table_rows(table)
    test = test or guess_test(columns, Path(table).name)
    checked = {}
    for line, cells in rows.items():
        try:
            checked[line] = check_row(test, columns, cells, f"{table}:{line}")
        except GrainfracError as exc:
            problems.append(str(exc))
    problems += repeated_rows(table, test, checked)
    if len(problems) == 1:   # one bad row: one line
        raise GrainfracError(f"{table}: 1 bad row, nothing run: {problems[0]}")
    if problems:
        problems.sort(key=_line_of)
        listed = problems[:MAX_LISTED_PROBLEMS]
        if len(problems) > len(listed):
            listed.append(f"... and {len(problems) - len(listed)} more bad rows (fix the ones above first)")
        raise GrainfracError(f"{table}: {len(problems)} bad row(s), nothing run; fix each:\n" + "\n".join(listed))
    return test, checked


def _line_of(problem: str) -> int:
    m = re.search(r":(\d+)\b", problem)
    return int(m.group(1)) if m else 0


def describe(summary: dict) -> str:
    """The result phrase of a finished row."""
    if "lifetime_s" in summary:
        return f"creep {summary['stress_pa'] / 1e6:.1f} MPa: {outcome(summary)}"
    if "tensile_strength_pa" in summary:
        t = summary["tensile_strength_pa"]
        return "Brazilian: no result" if t is None else f"Brazilian tensile strength {t / 1e6:.2f} MPa"
    u = summary.get("ucs_pa")
    return f"UCS: no result ({summary.get('end_reason')})" if u is None else f"UCS {u / 1e6:.1f} MPa"


def cmd_batch(args) -> int:
    table = Path(args.table)
    if args.jobs < 1:
        raise GrainfracError(f"--jobs {args.jobs}: fix: at least 1")
    test, rows = check_table(table, args.test)
    repo = Path(__file__).resolve().parents[2]
    log_dir = Path(args.log_dir or Path("results") / "logs" / table.stem).resolve()
    try:
        log_dir.mkdir(parents=True, exist_ok=True)
        for _, controls in rows.values():
            if not controls["out"]:
                Path("results", str(controls["study"])).mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise GrainfracError(f"cannot make the log and study folders ({exc.strerror}: {exc.filename}); fix: "
                             "give a writable --log-dir, run from a writable folder") from None
    print(f"{len(rows)} {test} rows of {table} checked; running {args.jobs} at a time, logs in {log_dir}", flush=True)
    done = {}

    def ended(line):
        if line in rows and line not in done:
            done[line] = row_outcomes(table, log_dir, [line], describe)[0]
            print(done[line], flush=True)

    run_batch(table.resolve(), repo / "yade_scripts" / SCRIPTS[test], args.jobs, log_dir, repo=Path.cwd(),
              on_row_end=ended)
    for line in rows:
        ended(line)
    failed = [o for o in done.values() if not o.ok and not o.numerical]
    numerical = [o for o in done.values() if o.numerical]
    if failed or numerical:
        said = [f"{len(failed)} of {len(rows)} rows failed: lines {_lines(failed)}"] if failed else []
        said += [f"{len(numerical)} of {len(rows)} rows ended as a numerical failure (no result): lines "
                 f"{_lines(numerical)}"] if numerical else []
        print("; ".join(said) + f" of {table}")
        return EXIT_ROWS_FAILED if failed else EXIT_NUMERICAL_FAILURE
    skipped = sum(o.skipped for o in done.values())
    print(f"all {len(rows)} rows finished with a result" + (f" ({skipped} skipped: finished before)" if skipped else ""))
    return 0


def _lines(outcomes) -> str:
    return ", ".join(str(o.line) for o in outcomes)
