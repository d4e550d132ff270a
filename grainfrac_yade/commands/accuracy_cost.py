"""``accuracy-cost [--quick]``: what accuracy costs in time, in one command.

Reads the study's plan (``params/accuracy_cost.toml``, :mod:`grainfrac_yade.analysis.accuracy_study`), writes its
yade-batch tables into the study folder (``ucs.table``, ``creep.table``; ``--tables-only`` stops there,
for ``yade-batch`` or ``submit`` by hand), runs them ``--jobs`` rows at a time (finished rows with the
same parameters are kept, unfinished creep rows go on from their checkpoints), then writes
``accuracy_cost.csv``, ``accuracy_cost.md`` and ``accuracy_cost.png`` into the folder
(:mod:`grainfrac_yade.analysis.accuracy`).  ``--analyze-only`` skips the runs (a partial study gives a
partial table: missing runs are counted in its ``note`` column).
"""
from __future__ import annotations

import os
import time
from dataclasses import replace
from pathlib import Path

from ..analysis.accuracy_study import creep_rows, load_study, ucs_rows
from ..errors import GrainfracError
from ..runs.batchrun import run_batch, write_table
from ..runs.runio import write_csv

REPO = Path(__file__).resolve().parents[2]
STUDY_FILE = REPO / "params" / "accuracy_cost.toml"


def register(sub, common):
    p = sub.add_parser("accuracy-cost", help="what accuracy costs in time: one knob at a time against its "
                                             "reference (params/accuracy_cost.toml), table and Pareto figure")
    p.add_argument("--study", default=str(STUDY_FILE), help="study plan (TOML), default params/accuracy_cost.toml")
    p.add_argument("--quick", action="store_true", help="the plan's [quick] subset: a smoke run, not a measurement")
    p.add_argument("--out", help="study folder (default: the plan's folder)")
    p.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="runs at a time (default: cores)")
    group = p.add_mutually_exclusive_group()
    group.add_argument("--tables-only", action="store_true", help="write the yade-batch tables, run nothing")
    group.add_argument("--analyze-only", action="store_true", help="summarise the runs already in the folder")
    p.set_defaults(func=cmd_accuracy_cost)


def cmd_accuracy_cost(args) -> int:
    study = load_study(args.study, quick=args.quick, repo=REPO)
    study = replace(study, folder=Path(args.out or study.folder).resolve())
    folder = study.folder
    folder.mkdir(parents=True, exist_ok=True)
    tables = []
    for name, rows, script in (("ucs", ucs_rows(study, REPO), "ucs.py"), ("creep", creep_rows(study, REPO), "creep.py")):
        if rows:
            comment = (f"accuracy-cost {name} rows ({'quick, ' if args.quick else ''}plan {args.study}); "
                       "written by python3 -m grainfrac_yade accuracy-cost")
            tables.append((write_table(folder / f"{name}.table", rows, comment), script, len(rows)))
    print(f"accuracy-cost: {len(study.settings)} settings, seeds {list(study.seeds)}, ratios {list(study.ratios)}; "
          + ", ".join(f"{n} rows in {t}" for t, _, n in tables), flush=True)
    if args.tables_only:
        return 0
    if not args.analyze_only:
        logs = folder / "logs" / time.strftime("%Y%m%d-%H%M%S")   # one folder per call: a rerun keeps earlier logs
        for table, script, n in tables:
            print(f"running {table.name}: {n} rows, {args.jobs} at a time (logs in {logs})", flush=True)
            run_batch(table, REPO / "yade_scripts" / script, args.jobs, logs / table.stem, repo=REPO,
                      watch=[], progress=None)
    return summarise(study)


def summarise(study) -> int:
    """Write the study's table (CSV, markdown) and Pareto figure from the runs in its folder."""
    from ..analysis.accuracy import history_measures, label_runs, markdown_table, pareto_figure, setting_rows
    from ..analysis.collect import code_version_note, collect_runs
    from ..analysis.study import read_history
    folder = study.folder
    runs = collect_runs(folder)
    labelled = label_runs(study, runs) if not runs.empty else runs
    if labelled.empty:
        raise GrainfracError(f"{folder}: no run of the study yet; fix: run python3 -m grainfrac_yade accuracy-cost "
                             "without --analyze-only")
    measures = {}
    for r in labelled[(labelled["test"] == "creep") & (labelled["outcome"] == "failed")].itertuples():
        measures[(r.setting, float(r.ratio_planned), int(r.seed_planned))] = history_measures(
            read_history(r.folder), getattr(r, "tertiary_start_s", None), getattr(r, "clock", ""))
    table = setting_rows(study, labelled, measures)
    write_csv(folder / "accuracy_cost.csv", table)
    note = code_version_note(labelled)
    text = markdown_table(table, study.ratios) + (f"\n{note}\n" if note else "")
    (folder / "accuracy_cost.md").write_text(text)
    pareto_figure(table, folder / "accuracy_cost.png")
    print(text)
    print(f"written {folder / 'accuracy_cost.csv'}, {folder / 'accuracy_cost.md'}, {folder / 'accuracy_cost.png'}")
    return 0
