"""``brazilian``: Brazilian disc test (diametral compression); summary.json, history.csv, cracks.csv,
load_strain.png, crack maps at the peak and at the end.

Tensile strength sigma_t = 2 P / (pi D t) (ISRM 1978 suggested method) at the peak load P of a
disc of diameter D (``brazilian.diameter``) and thickness t (``specimen.thickness``), the disc a
Voronoi tessellation clipped to the circle with the grain size and composition of the UCS
specimen (:mod:`grainfrac_yade.geometry.disc`), loaded by two rigid jaws
(:mod:`grainfrac_yade.protocols.brazilian`).
"""
from __future__ import annotations

import math
import sys

from ..errors import EXIT_NUMERICAL_FAILURE, GrainfracError
from ..protocols.brazilian_output import require_disc_model, run_brazilian_to_folder
from ..kernel.levers import Levers
from ._args import add_vtk_every_option
from ._outcome import numerical_failure_line, steps_phrase
from ._resume import add_resume_option, refuse_resume_conflicts, resumable_run


def register(sub, common):
    p = sub.add_parser("brazilian", help="strain-controlled Brazilian disc test (tensile strength 2P/(pi D t))")
    common(p, geometry=False)
    p.add_argument("--diameter", type=float, help="disc diameter [m] (brazilian.diameter)")
    p.add_argument("--grain-size", type=float, help="grain size [m] (specimen.grain_size)")
    p.add_argument("--spheres-per-cell", type=int, help="resolution.spheres_per_cell")
    from ._args import seed_type
    p.add_argument("--seed", type=seed_type, default=1, help="random seed of the specimen (>= 0)")
    p.add_argument("--tensile-scale", type=float, metavar="F",
                   help="multiply the tensile strength J^T of every contact row (Table 2) by F: the same as "
                        "--set contacts.<a>/<b>.tensile_strength=F x its value for each row (recorded so in "
                        "params.json)")
    lv = p.add_argument_group("levers on the bonds and cells (grainfrac_yade.kernel.levers; recorded in "
                              "summary.json under 'levers', not parameters: ucs and creep do not know them)")
    lv.add_argument("--slit-fraction", type=float, default=0.0, metavar="F",
                    help="share of faces unbonded before loading (slits: compression and friction, no tension)")
    lv.add_argument("--strength-cv", type=float, default=0.0, metavar="C",
                    help="coefficient of variation of a lognormal factor (mean 1) on each bond's J^T and J^C")
    lv.add_argument("--block-rotation", action="store_true", help="cells do not rotate (rigid cells)")
    add_resume_option(p, "Brazilian test")
    add_vtk_every_option(p, "diametral")
    p.set_defaults(func=cmd_brazilian)


def cmd_brazilian(args) -> int:
    from ._args import load_params_from_args
    if args.resume:
        refuse_resume_conflicts(args)
        found = resumable_run(args.resume, "brazilian")
        if found is None:
            print(f"Brazilian test already finished (summary.json): {args.resume}; nothing to resume")
            return 0
        params, state = found
        summary = run_brazilian_to_folder(params, int(state["run_values"]["seed"]), args.resume, progress=print,
                                          resume=True)
        print(format_result(summary, args.resume))
        return 0
    params = load_params_from_args(args)
    if args.diameter is not None or args.tensile_scale is not None:
        from ..params import FlagOverride
        extra = [] if args.diameter is None else [FlagOverride("brazilian.diameter", args.diameter, "--diameter")]
        if args.tensile_scale is not None:
            extra += tensile_scale_overrides(params, args.tensile_scale)
        params = _reload(args, extra, params, args.tensile_scale)
    levers = Levers(slit_fraction=args.slit_fraction, strength_cv=args.strength_cv, block_rotation=args.block_rotation)
    out = args.out or f"results/brazilian_seed{args.seed}"
    summary = run_brazilian_to_folder(params, args.seed, out, overwrite=args.overwrite, progress=print, levers=levers,
                                      vtk_every=args.vtk_every)
    if summary["numerical_failure"]:
        print(numerical_failure_line("Brazilian", summary, out), file=sys.stderr)
        return EXIT_NUMERICAL_FAILURE
    print(format_result(summary, out))
    return 0


def _reload(args, extra, base, factor):
    from ._args import overrides_from_args
    from ..params import load_parameters
    params = load_parameters(extra_files=args.params, overrides=overrides_from_args(args) + extra)
    if factor is not None:
        check_tensile_scale(base, params, factor)
    return params


def format_result(summary, out) -> str:
    if summary["numerical_failure"]:
        return f"Brazilian: no result ({summary['end_reason']}) -> {out}"
    ratio = summary["reference_ucs_over_tensile_strength"]
    return (f"Brazilian tensile strength {summary['tensile_strength_pa'] / 1e6:.2f} MPa "
            f"(P/t {summary['peak_load_per_thickness_n_per_m'] / 1e3:.1f} kN/m, D {summary['diameter_m'] * 1e3:g} mm), "
            f"calibration.reference_ucs / sigma_t {'-' if ratio is None else f'{ratio:.1f}'}; central band "
            f"{summary['central_band_fraction']:.2f} of {summary['broken_total']} broken bonds "
            f"({steps_phrase(summary)}, {summary['wall_s']:.1f} s; {summary['end_reason']}) -> {out}")


def tensile_scale_overrides(params, factor: float) -> list:
    """(key, value) overrides that multiply J^T of every contact row the parameter files give by ``factor``.

    The rows are the pure-mineral pairs and any mixed pair a file in ``params.sources`` gives; the
    other mixed pairs are averages of pure pairs (paper section 3.1), so they scale with them.
    Effect on every bond: J^T x ``factor`` x ``calibration.strength_scale``; cohesion, friction and
    stiffness stay.  1.0 changes nothing.
    """
    from ..params import pair_key, read_toml
    if not (isinstance(factor, (int, float)) and math.isfinite(factor) and factor > 0):
        raise GrainfracError(f"--tensile-scale {factor!r}: not a positive number; fix: give a factor > 0, e.g. 0.5")
    rows = {pair_key(m, m) for m in params.minerals}
    for source in params.sources:
        for name in read_toml(source).get("contacts", {}):
            rows.add(pair_key(*name.split("/")))
    return [(f"contacts.{a}/{b}.tensile_strength", params.contact(a, b).tensile_strength * factor)
            for a, b in sorted(rows)]


def check_tensile_scale(base, scaled, factor: float):
    """GrainfracError unless every pair's J^T in ``scaled`` is ``factor`` x that in ``base`` (1e-12)."""
    for key, c in base.contacts.items():
        got = scaled.contacts[key].tensile_strength
        if abs(got / (c.tensile_strength * factor) - 1) > 1e-12:
            raise GrainfracError(f"--tensile-scale: contact {'/'.join(key)} ended with J^T {got:g} Pa, not "
                                 f"{factor:g} x {c.tensile_strength:g} Pa (a mixed pair given by --set only?); fix: "
                                 "give that pair in a --params file or set its tensile_strength yourself")


def run_brazilian_in_yade(rows):
    """Entry of ``yade_scripts/brazilian.py``: parameters from the batch row (or defaults); a finished row
    is skipped or stops as a UCS row does, an unfinished one with a checkpoint of this row (no levers)
    goes on from it.  ``rows``: the engine's reader of the batch table
    (its ``batch_rows``: ``read_table``, ``row_errors``, ``row_plan``, ``run_folder_name``;
    :mod:`grainfrac_yade.engines.yade.batch`)."""
    from ..params import load_parameters
    from ..runs.runio import read_checkpoint_state
    read_table, row_errors, row_plan, run_folder_name = rows.read_table, rows.row_errors, rows.row_plan, rows.run_folder_name
    with row_errors():
        overrides, controls = read_table()
        params = load_parameters(overrides=overrides)
        require_disc_model(params)
        out, action, note = row_plan(controls["out"] or f"results/{controls['study']}/"
                                     f"{run_folder_name(controls, overrides)}",
                                     params, controls, {"seed": int(controls["seed"])})
    if action == "resume" and (read_checkpoint_state(out) or {}).get("run_values", {}).get("levers") != \
            Levers().to_dict():   # a CLI test with levers in this folder: not this row's (rows have none)
        action, note = "run", f"{out}: its checkpoint is of a test with levers (brazilian --slit-fraction ...): started again"
    if action == "skip":
        from ..runs.batchrun import ROW_SKIPPED
        print(f"Brazilian {ROW_SKIPPED}: {out}")
        return
    if note:
        print(note)
    if action == "resume":
        print(f"Brazilian row unfinished, resumed from its checkpoint: {out}")
    with row_errors():
        summary = run_brazilian_to_folder(params, int(controls["seed"]), out,
                                          overwrite=(out / "run.json").exists(), resume=action == "resume")
    print(format_result(summary, out))
    if summary["numerical_failure"]:   # the row's log and yade-batch's status say so; batch reads the summary
        sys.exit(EXIT_NUMERICAL_FAILURE)
