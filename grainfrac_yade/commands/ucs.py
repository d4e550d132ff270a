"""``ucs``: uniaxial compression test (paper section 3.1); summary.json, history.csv, figures, crack map at peak."""
from __future__ import annotations

import sys

import numpy as np

from ..protocols.ucs_output import run_ucs_to_folder
from ..errors import EXIT_NUMERICAL_FAILURE
from ._loads import add_confinement_option, check_stress_range, confinement_override
from ._outcome import numerical_failure_line, steps_phrase
from ._args import add_vtk_every_option
from ._resume import add_resume_option, refuse_resume_conflicts, resumable_run


def register(sub, common):
    p = sub.add_parser("ucs", help="strain-controlled uniaxial compression test")
    common(p)
    add_confinement_option(p)
    add_resume_option(p, "UCS test")
    add_vtk_every_option(p, "axial")
    p.set_defaults(func=cmd_ucs, with_params=True, param_overrides=confinement_override)


def cmd_ucs(args, params) -> int:
    from ..params import require_plane
    if args.resume:
        refuse_resume_conflicts(args)
        found = resumable_run(args.resume, "ucs")
        if found is None:
            print(f"UCS test already finished (summary.json): {args.resume}; nothing to resume")
            return 0
        params, state = found
        out = args.resume
        summary = run_ucs_to_folder(params, int(state["run_values"]["seed"]), out, progress=print, resume=True)
    else:
        require_plane(params, "ucs")
        check_stress_range(params, "--confinement" if args.confinement is not None else "confinement.stress")
        out = args.out or f"results/ucs_seed{args.seed}"
        summary = run_ucs_to_folder(params, args.seed, out, overwrite=args.overwrite, progress=print,
                                    vtk_every=args.vtk_every)
    if summary.get("failed_before_test"):
        print(f"UCS: failed before the test ({summary['end_reason']}) -> {out}")
        return 1
    if summary["numerical_failure"]:
        print(numerical_failure_line("UCS", summary, out), file=sys.stderr)
        return EXIT_NUMERICAL_FAILURE
    confined = summary["confining_stress_pa"]
    label = f"peak axial stress at confinement {confined / 1e6:g} MPa:" if confined else "UCS"
    # a test stopped at ucs.max_strain before its peak: the largest stress is a lower bound (end_reason says why)
    bound = "" if summary.get("peak_reached", True) else "at least "
    print(f"{label} {bound}{summary['ucs_pa'] / 1e6:.1f} MPa, E {_fmt(summary['young_pa'], 1e9)} GPa, "
          f"nu {_fmt(summary['poisson'], 1, 3)}, CI {_fmt(summary['crack_initiation_pa'])} MPa, "
          f"CD {_fmt(summary['crack_damage_pa'])} MPa, broken {summary['broken_total']} of {summary['n_bonds']} "
          f"({steps_phrase(summary)}, {summary['wall_s']:.1f} s; {summary['end_reason']}) -> {out}")
    return 0


def _fmt(value, unit=1e6, digits=1) -> str:
    """``value / unit`` with ``digits`` decimals (MPa by default); "-" if not measured (None or NaN)."""
    return "-" if value is None or not np.isfinite(value) else f"{value / unit:.{digits}f}"


def run_ucs_in_yade(rows):
    """Entry of ``yade_scripts/ucs.py``: parameters from the batch row (or defaults); a finished row
    is skipped or stops as a creep row does, an unfinished one with a checkpoint of this row goes on
    from it.  ``rows``: the engine's reader of the batch table
    (its ``batch_rows``: ``read_table``, ``row_errors``, ``row_plan``, ``run_folder_name``;
    :mod:`grainfrac_yade.engines.yade.batch`)."""
    from ..params import load_parameters, require_plane
    read_table, row_errors, row_plan, run_folder_name = rows.read_table, rows.row_errors, rows.row_plan, rows.run_folder_name
    with row_errors():
        overrides, controls = read_table()
        params = load_parameters(overrides=overrides)
        require_plane(params, "ucs")
        check_stress_range(params)
        out, action, note = row_plan(controls["out"] or f"results/{controls['study']}/"
                                     f"{run_folder_name(controls, overrides)}",
                                     params, controls, {"seed": int(controls["seed"])})
    if action == "skip":
        from ..runs.batchrun import ROW_SKIPPED
        print(f"UCS {ROW_SKIPPED}: {out}")
        return
    if note:
        print(note)
    if action == "resume":
        print(f"UCS row unfinished, resumed from its checkpoint: {out}")
    with row_errors():   # e.g. a folder of another kind of run: one line in the row's log
        s = run_ucs_to_folder(params, int(controls["seed"]), out, overwrite=(out / "run.json").exists(),
                              resume=action == "resume")
    if s.get("failed_before_test"):
        print(f"UCS: failed before the test ({s['end_reason']}) -> {out}")
        sys.exit(1)
    print(f"UCS: no result ({s['end_reason']}) -> {out}" if s["numerical_failure"] else
          f"UCS {s['ucs_pa'] / 1e6:.1f} MPa, E {_fmt(s['young_pa'], 1e9)} GPa -> {out}")
    if s["numerical_failure"]:   # the row's log and yade-batch's status say so; batch reads the summary
        sys.exit(EXIT_NUMERICAL_FAILURE)
