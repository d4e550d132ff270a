"""``ucs``: uniaxial compression test (paper section 3.1); summary.json, history.csv, figures, crack map at peak."""
from __future__ import annotations

import sys

import numpy as np

from ..engines.registry import engine_for
from ..protocols import ucs as ucs_test
from ..protocols.cracks import bond_segments, crack_table
from .creep import add_confinement_option, check_stress_range, confinement_override
from .resume import add_resume_option, refuse_resume_conflicts, resumable_run


def add_vtk_every_option(parser, strain: str):
    """``--vtk-every K``: VTK series of a strain-controlled test, timestep the ``strain`` strain."""
    from .creep import _positive_int
    parser.add_argument("--vtk-every", type=_positive_int, default=None, metavar="K",
                        help=f"write VTK files of cells and bonds at every K-th history row and at the end into "
                             f"DIR/vtk/ (cells.pvd, bonds.pvd: time series whose timestep is the {strain} strain)")


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
        print(f"UCS: no result ({summary['end_reason']}) -> {out}")
        return 0
    confined = summary["confining_stress_pa"]
    label = f"peak axial stress at confinement {confined / 1e6:g} MPa:" if confined else "UCS"
    print(f"{label} {summary['ucs_pa'] / 1e6:.1f} MPa, E {_fmt(summary['young_pa'], 1e9)} GPa, "
          f"nu {_fmt(summary['poisson'], 1, 3)}, CI {_fmt(summary['crack_initiation_pa'])} MPa, "
          f"CD {_fmt(summary['crack_damage_pa'])} MPa, broken {summary['broken_total']} of {summary['n_bonds']} "
          f"({summary['steps']} steps, {summary['wall_s']:.1f} s; {summary['end_reason']}) -> {out}")
    return 0


def _fmt(value, unit=1e6, digits=1) -> str:
    """``value / unit`` with ``digits`` decimals (MPa by default); "-" if not measured (None or NaN)."""
    return "-" if value is None or not np.isfinite(value) else f"{value / unit:.{digits}f}"


#: summary.json keys measured from the stress-strain curve: null when a numerical failure ended the run.
MEASURES = ("ucs_pa", "peak_axial_strain", "young_pa", "young_method", "poisson", "crack_initiation_pa",
            "crack_damage_pa")


def run_ucs_to_folder(params, seed, out, overwrite=False, progress=None, resume=False, vtk_every=None) -> dict:
    """Run a UCS test into ``out``; summary.json is written last (it marks the run finished).

    Checkpoints go to ``out/checkpoint/`` every ``numerics.checkpoint_interval`` s of wall time and are
    removed once summary.json is written.  ``resume``: go on from the checkpoint in ``out`` instead of
    starting (``out`` keeps its run.json and params.json).  ``vtk_every``: VTK series in ``out/vtk/`` at
    every k-th history row and the end (None: none; not carried across a resume)."""
    from pathlib import Path
    from ..analysis.figures import run_stress_strain_figure
    from ..params import require_plane
    from ..analysis.plotting import crack_map
    from ..runs.runio import commit_run_dir, prepare_run_dir, remove_checkpoints, summary_header, write_csv, write_json
    from ..geometry.specimen import build_specimen
    from ..analysis.ucs_analysis import ucs_summary
    require_plane(params, "ucs")
    out = Path(out) if resume else prepare_run_dir(out, "ucs", params, seed, overwrite=overwrite)
    specimen = build_specimen(params, seed)
    outputs = {"checkpoint_folder": out, "run_values": {"seed": seed}}
    engine = engine_for(params)
    if resume:
        history, result, scene, (broken_peak, mode_peak) = ucs_test.resume_ucs(specimen, params, out, progress=progress)
    else:
        snapshot = engine.StrainSeries(out / "vtk", vtk_every, engine.AXIAL_STRAIN) if vtk_every else None
        history, result, scene, (broken_peak, mode_peak) = ucs_test.run_ucs(specimen, params, progress=progress,
                                                                            snapshot=snapshot, **outputs)
    # a numerical failure has no result: the curve before it is kept in history.csv, measured nothing
    no_result = result["numerical_failure"] or result.get("failed_before_test")
    summary = dict.fromkeys(MEASURES) if no_result else ucs_summary(history)
    summary.update(result)
    summary.update(summary_header(params, seed), n_cells=specimen.n_cells)
    write_csv(out / "history.csv", history)
    write_cracks(out / "cracks.csv", scene)
    if len(history["step"]):   # none when the specimen broke apart before the axial stage
        run_stress_strain_figure(history, summary, out / "stress_strain.png")
    idx = np.flatnonzero(broken_peak)
    at = ("the end of the isotropic stage" if result.get("failed_before_test") else
          "the largest stress before the numerical failure" if result["numerical_failure"] else
          f"peak ({summary['ucs_pa'] / 1e6:.0f} MPa)")
    crack_map(specimen, out / "crack_map_peak.png", bond_segments(scene, idx), mode_peak[idx],
              title=f"cracks at {at}, seed {seed}")
    write_json(out / "summary.json", summary)   # last: marks the run finished
    remove_checkpoints(out)                     # a finished run has nothing to resume
    commit_run_dir(out)                         # a replacing run (--overwrite) takes the old one's place
    return summary


def write_cracks(path, scene):
    """cracks.csv: one row per broken bond (step of its break, mode, kind, position, orientation)."""
    from ..runs.runio import write_csv
    idx = np.flatnonzero(scene.broken)
    table = crack_table(scene, idx)
    write_csv(path, {"bond": table.pop("bond"), "step": scene.break_step[idx], **table})


def run_ucs_in_yade(rows):
    """Entry of ``yade_scripts/ucs.py``: parameters from the batch row (or defaults); a finished row
    is skipped or stops as a creep row does, an unfinished one with a checkpoint of this row goes on
    from it.  ``rows``: the engine that reads the batch table (``read_table``, ``row_errors``,
    ``row_plan``, ``run_folder_name``: :mod:`grainfrac_yade.yade_adapter.batch`)."""
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
