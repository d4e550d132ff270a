"""``creep``: constant-load creep test to failure (paper section 4.1); history, cracks, summary, figures."""
from __future__ import annotations

import math

from ..errors import EXIT_NUMERICAL_FAILURE, GrainfracError
from ._loads import (CREEP_ROW_COLUMNS, PA_PER_MPA, add_confinement_option, check_stress_range, confinement_override,
                     creep_name_parts, positive_int, resolve_stress)
from ._outcome import numerical_failure_line, outcome, steps_phrase
from ..protocols.creep_output import UCS_FROM_CALIBRATION, resume_creep_folder, run_creep_to_folder, ucs_reference


#: Fractions of the lifetime that ``--vtk-fractions`` alone writes: the crack maps' (``analysis.figures.MAP_FRACTIONS``,
#: held equal by tests/test_newcomer_inputs.py; not imported here, which would load matplotlib to build the parser).
LIFE_FRACTIONS = (0.1, 0.5, 0.9, 1.0)


def register(sub, common):
    p = sub.add_parser("creep", help="constant-load creep test to failure with stress corrosion")
    common(p)
    load = p.add_mutually_exclusive_group()
    load.add_argument("--stress", type=float, metavar="MPA",
                      help="creep stress sigma_1 [MPa], e.g. 160 (every stress flag is in MPa; files and batch "
                           "columns are in Pa)")
    load.add_argument("--ratio", type=float, help="driving-stress ratio sigma/sigma_c (sigma_c: --ucs, else "
                                                  "calibration.reference_ucs, the calibrated mean UCS)")
    p.add_argument("--ucs", type=float, metavar="MPA", help="UCS [MPa] that --ratio refers to, e.g. 258")
    p.add_argument("--clock", choices=("event", "paper"), help="stress_corrosion.clock")
    add_confinement_option(p)
    p.add_argument("--vtk-times", type=_times, default=None, metavar="T1,T2,...",
                   help="write VTK files of cells and bonds (state, remaining strength) for ParaView at these "
                        "creep times [s] and at the end, into DIR/vtk/ (cells.pvd, bonds.pvd: time series in "
                        "creep time; e.g. --vtk-times 0,1e7)")
    p.add_argument("--vtk-every", type=positive_int, default=None, metavar="K",
                   help="also write VTK files at every K-th history row (one row per event of the event clock, "
                        "per creep step of the paper clock) and at the end, into DIR/vtk/")
    p.add_argument("--vtk-fractions", type=_fractions, nargs="?", const=list(LIFE_FRACTIONS), default=False,
                   metavar="F1,F2,...",
                   help="after the run, write the bond states at these fractions of the lifetime (of the run if "
                        "it did not fail; default the crack maps' 0.1,0.5,0.9,1) on the undeformed specimen, into "
                        "DIR/vtk/life_cells.pvd and life_bonds.pvd")
    p.add_argument("--resume", metavar="DIR",
                   help="go on with the interrupted creep run in DIR from its last checkpoint (DIR/checkpoint/, "
                        "written at the end of the ramp and every numerics.checkpoint_interval s); load, seed and "
                        "parameters come from DIR")
    p.set_defaults(func=cmd_creep, with_params=True, param_overrides=_clock_override)


def _clock_override(args) -> list:
    from ..params import FlagOverride
    return ([FlagOverride("stress_corrosion.clock", args.clock, "--clock")] if args.clock else []) + \
        confinement_override(args)


def _fractions(text: str) -> list:
    """Comma-separated fractions in (0, 1] (argparse type)."""
    import argparse
    try:
        values = [float(t) for t in text.split(",") if t.strip()]
    except ValueError:
        values = []
    if not values or any(not (0 < v <= 1) for v in values):
        raise argparse.ArgumentTypeError(f"{text!r}: give comma-separated fractions of the lifetime in (0, 1], "
                                         "e.g. 0.1,0.5,0.9,1")
    return sorted(values)


def _times(text: str) -> list:
    """Comma-separated creep times [s] (argparse type)."""
    import argparse
    try:
        times = [float(t) for t in text.split(",") if t.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a comma-separated list of times in s (e.g. 0,1e7)")
    if any(not math.isfinite(t) or t < 0 for t in times):
        raise argparse.ArgumentTypeError(f"{text!r}: creep times must be finite and >= 0 s")
    return times


def warn_reference(reference: dict) -> None:
    """A warning line (stderr) when the calibrated reference UCS was measured with other parameters."""
    import sys
    diffs = reference.get("ucs_reference_differences")
    if diffs:
        shown = "; ".join(diffs[:4]) + (f"; and {len(diffs) - 4} more" if len(diffs) > 4 else "")
        print(f"warning: the ratio refers to {UCS_FROM_CALIBRATION}, calibrated with other parameters than this "
              f"run's ({shown}); give the UCS of this specimen and model with --ucs (batch column ucs)",
              file=sys.stderr)


#: Options that shape a run: refused with --resume (the run folder holds them).
RESUME_CONFLICTS = (("stress", "--stress"), ("ratio", "--ratio"), ("ucs", "--ucs"), ("clock", "--clock"),
                    ("confinement", "--confinement"),
                    ("overrides", "--set"), ("params", "--params"), ("width", "--width"), ("height", "--height"),
                    ("grain_size", "--grain-size"), ("spheres_per_cell", "--spheres-per-cell"),
                    ("vtk_times", "--vtk-times"), ("vtk_every", "--vtk-every"), ("out", "--out"),
                    ("overwrite", "--overwrite"))


def cmd_creep(args, params) -> int:
    from ..analysis.figures import MAP_FRACTIONS
    from ..params import require_plane
    if args.resume:
        given = [flag for attr, flag in RESUME_CONFLICTS if getattr(args, attr, None) not in (None, [], False)]
        if args.vtk_fractions is not False:
            given.append("--vtk-fractions")
        if given:
            raise GrainfracError(f"--resume {args.resume} takes the load, seed and parameters from the run folder; "
                                 f"fix: drop {', '.join(given)}")
        s = resume_creep_folder(args.resume, progress=print)
        if s is None:
            print(f"creep run already finished (summary.json): {args.resume}; nothing to resume")
            return 0
        print(f"creep {s['stress_pa'] / 1e6:.1f} MPa (ratio {s['driving_stress_ratio']:.3f}), {s['clock']} clock, "
              f"resumed: {outcome(s)}, {s['n_events']} events, {s['broken_creep']} creep cracks, {steps_phrase(s)} "
              f"-> {args.resume}")
        return creep_exit_status(s, args.resume)
    require_plane(params, "creep")
    check_stress_range(params, "--confinement" if args.confinement is not None else "confinement.stress")
    stress, ratio, ref = resolve_stress(params, _pa(args.stress), args.ratio, _pa(args.ucs), cli=True)
    out = args.out or f"results/creep_{stress / 1e6:.0f}MPa_seed{args.seed}"
    source = "--ucs" if args.ucs is not None else UCS_FROM_CALIBRATION
    if args.ratio is not None:
        warn_reference(ucs_reference(params, source))
    s = run_creep_to_folder(params, args.seed, out, stress, ratio, ref, overwrite=args.overwrite, progress=print,
                            vtk_times=args.vtk_times, vtk_every=args.vtk_every,
                            vtk_fractions=None if args.vtk_fractions is False else
                            (args.vtk_fractions or list(MAP_FRACTIONS)), ucs_source=source)
    confined = f", confinement {params.confinement.stress / 1e6:g} MPa" if params.confinement.stress else ""
    if s["failed_before_test"]:
        print(f"creep {stress / 1e6:.1f} MPa (ratio {ratio:.3f}{confined}): {outcome(s)} -> {out}")
        return 1
    print(f"creep {stress / 1e6:.1f} MPa (ratio {ratio:.3f}{confined}), {s['clock']} clock: {outcome(s)}, {s['n_events']} events, "
          f"{s['broken_creep']} creep cracks, {steps_phrase(s)}, {s['wall_s']:.1f} s -> {out}")
    return creep_exit_status(s, out)


def creep_exit_status(summary: dict, out) -> int:
    """0 for a result (a lifetime, a survival, a failure on loading); :data:`~grainfrac_yade.errors.
    EXIT_NUMERICAL_FAILURE` with its one line on stderr for a numerical failure (no result)."""
    import sys
    if summary.get("numerical_failure"):
        print(numerical_failure_line(f"creep {summary['stress_pa'] / 1e6:.1f} MPa after {summary['n_events']} events",
                                     summary, out), file=sys.stderr)
        return EXIT_NUMERICAL_FAILURE
    return 0


def _pa(mpa):
    """A CLI stress [MPa] in Pa (None stays None)."""
    return None if mpa is None else mpa * PA_PER_MPA


def run_creep_in_yade(rows):
    """Entry of ``yade_scripts/creep.py``: one creep run per yade-batch row.

    Columns: ``ratio`` (driving-stress ratio) or ``stress`` [Pa], optional ``ucs`` [Pa] that the
    ratio refers to (default: calibration.reference_ucs), ``seed``, ``study``, ``out``, and any
    parameter path.  A row whose folder already holds a summary.json is skipped (a study can be
    rerun to complete it) if its stored parameters, seed and load equal the row's, else the row
    stops with one line (see :mod:`grainfrac_yade.engines.yade.batch`, column ``on_change``); an
    unfinished folder goes on from its checkpoint if that is of this row (same parameters, seed and
    load), else it is started again.
    """
    from ..params import load_parameters, require_plane
    read_table, row_errors, row_plan, run_folder_name = rows.read_table, rows.row_errors, rows.row_plan, rows.run_folder_name
    with row_errors():
        overrides, controls = read_table(CREEP_ROW_COLUMNS)
        params = load_parameters(overrides=overrides)
        require_plane(params, "creep")
        given = {k: (float(controls[k]) or None) for k in CREEP_ROW_COLUMNS}
        if given["ratio"] and given["stress"]:
            raise GrainfracError("batch row gives both ratio and stress; fix: keep one of the two columns per row "
                                 "(stress in Pa, ratio of the UCS)")
        check_stress_range(params)
        stress, ratio, ref = resolve_stress(params, given["stress"], given["ratio"], given["ucs"])
        name = run_folder_name(controls, creep_name_parts(controls) + overrides)
        out, action, note = row_plan(controls["out"] or f"results/{controls['study']}/{name}", params, controls,
                                     {"seed": int(controls["seed"]), "stress_pa": stress})
    if action == "skip":
        from ..runs.batchrun import ROW_SKIPPED
        print(f"creep {ROW_SKIPPED}: {out}")
        return
    if note:
        print(note)
    if action == "resume":
        print(f"creep row unfinished, resumed from its checkpoint: {out}")
    source = "batch column ucs" if given["ucs"] else UCS_FROM_CALIBRATION
    if given["ratio"]:
        warn_reference(ucs_reference(params, source))
    with row_errors():   # e.g. a folder of another kind of run: one line in the row's log
        s = run_creep_to_folder(params, int(controls["seed"]), out, stress, ratio, ref,
                                overwrite=(out / "run.json").exists(), progress=print, resume=action == "resume",
                                ucs_source=source)
    print(f"creep {stress / 1e6:.1f} MPa (ratio {ratio:.3f}): {outcome(s)} -> {out}")
    if s["failed_before_test"]:
        import sys
        sys.exit(1)
    if s["numerical_failure"]:   # the row's log and yade-batch's status say so; batch reads the summary
        import sys
        sys.exit(creep_exit_status(s, out))
