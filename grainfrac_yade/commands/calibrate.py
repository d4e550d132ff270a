"""``calibrate``: fit the strength and stiffness scale factors to the UCS and E targets (paper section 3.1, Tables 1-2).

A YADE packing of rigid cells is not UDEC's deformable blocks: with Table 1 and 2
as printed it is weaker and softer than the paper's model.  Two factors, the same
for every mineral pair so that Table 2's ratios stay, are fitted by fixed-point
iteration on the mean over seeds (UCS and E are close to proportional to them):

    strength_scale <- strength_scale * UCS_target / mean(UCS)
    stiffness_scale <- stiffness_scale * E_target / mean(E)

The result is written to ``params/calibration.toml`` with the measured values
before and after, and to ``OUT/calibration.csv`` (one row per seed and round).
"""
from __future__ import annotations

import dataclasses
import multiprocessing as mp
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from ..errors import GrainfracError
from ..params import load_parameters, require_plane
from ..protocols.ucs_output import run_ucs_to_folder
from ..runs.runio import commit_run_dir, prepare_run_dir, write_csv
from ._args import seed_type
from ._loads import positive_flag, stress_flag

#: UCS target [Pa]: the paper's simulated UCS, section 3.1 (shared/reference/paper_values.csv).
TARGET_UCS = 234.5e6
#: Young's modulus target [Pa]: LdB lab value 69 +- 5.8 GPa (shared/reference/ldb_lab_properties.csv).
TARGET_YOUNG = 69e9
CALIBRATION_FILE = Path(__file__).resolve().parents[2] / "params" / "calibration.toml"


#: Pa in one GPa (the unit of the modulus flags).
PA_PER_GPA = 1e9


def _gpa(text: str) -> float:
    """argparse type of a modulus flag: GPa, returned in Pa."""
    return positive_flag(text, "a modulus", "GPa", PA_PER_GPA, "69")


def register(sub, common):
    p = sub.add_parser("calibrate", help="fit strength/stiffness scale factors to UCS 234.5 MPa and E 69 GPa")
    common(p, geometry=True)
    p.add_argument("--seeds", type=seed_type, nargs="+", default=[1, 2, 3, 4, 5], help="specimen seeds (>= 0)")
    p.add_argument("--rounds", type=int, default=2, help="fixed-point rounds after the 'before' round")
    p.add_argument("--target-ucs", type=stress_flag, default=TARGET_UCS, metavar="MPA",
                   help=f"UCS target [MPa, like every stress flag] (default {TARGET_UCS / 1e6:g})")
    p.add_argument("--target-young", type=_gpa, default=TARGET_YOUNG, metavar="GPA",
                   help=f"Young's modulus target [GPa] (default {TARGET_YOUNG / 1e9:g})")
    p.add_argument("--jobs", type=int, default=1, help="seeds run in parallel (one process each)")
    p.add_argument("--write", default=str(CALIBRATION_FILE), help="calibration file to (over)write")
    p.set_defaults(func=cmd_calibrate, with_params=True)


def cmd_calibrate(args, params) -> int:
    base = list(args.resolved_overrides)   # the overrides of ``params``, for each round's parameter set
    require_plane(params, "calibrate")
    out = prepare_run_dir(args.out or "results/calibration", "calibrate", params, args.seeds,
                          overwrite=args.overwrite)
    strength, stiffness = params.calibration.strength_scale, params.calibration.stiffness_scale
    rows = []
    for rnd in range(args.rounds + 1):
        p = load_parameters(extra_files=args.params, overrides=base + [
            ("calibration.strength_scale", strength), ("calibration.stiffness_scale", stiffness)])
        folders = [out / f"round{rnd}_seed{seed}" for seed in args.seeds]
        for seed, s in zip(args.seeds, _run_seeds(p, args.seeds, folders, args.jobs)):
            if s["numerical_failure"]:
                raise GrainfracError(f"calibration round {rnd} seed {seed}: no UCS ({s['end_reason']}); fix: lower "
                                     "numerics.timestep_safety or check the specimen and parameters")
            rows.append({"round": rnd, "seed": seed, "strength_scale": strength, "stiffness_scale": stiffness,
                         "ucs_pa": s["ucs_pa"], "young_pa": s["young_pa"], "poisson": s["poisson"],
                         "crack_initiation_pa": s["crack_initiation_pa"], "crack_damage_pa": s["crack_damage_pa"],
                         "n_cells": s["n_cells"], "steps": s["steps"], "wall_s": s["wall_s"]})
            print(f"round {rnd} seed {seed}: UCS {s['ucs_pa'] / 1e6:.1f} MPa, E {s['young_pa'] / 1e9:.1f} GPa "
                  f"(strength x{strength:.4g}, stiffness x{stiffness:.4g})", flush=True)
        write_csv(out / "calibration.csv", rows)
        this = [r for r in rows if r["round"] == rnd]
        mean_ucs = np.mean([r["ucs_pa"] for r in this])
        mean_e = np.mean([r["young_pa"] for r in this])
        if rnd < args.rounds:
            strength *= args.target_ucs / mean_ucs
            stiffness *= args.target_young / mean_e
    out = commit_run_dir(out)   # a replacing run (--overwrite) takes the old one's place
    write_calibration_file(Path(args.write), rows, args, base, params.calibration)
    print(f"written {args.write} and {out / 'calibration.csv'}")
    return 0


def _run_one(job):
    params, seed, folder = job
    return run_ucs_to_folder(params, seed, folder, overwrite=True)


def _run_seeds(params, seeds, folders, jobs):
    """UCS summaries of ``seeds`` (in order), ``jobs`` processes at a time (spawned, one YADE each)."""
    work = [(params, seed, folder) for seed, folder in zip(seeds, folders)]
    if jobs <= 1:
        return [_run_one(w) for w in work]
    with ProcessPoolExecutor(max_workers=jobs, mp_context=mp.get_context("spawn")) as pool:
        return list(pool.map(_run_one, work))


def _stats(rows, key):
    v = np.array([r[key] for r in rows])
    return v.mean(), v.std(ddof=1) if len(v) > 1 else 0.0


#: Keys of [calibration] this command fits or measures; the file it writes carries the others (the levers
#: on the contacts) at the values the calibration ran with.
FITTED_KEYS = ("strength_scale", "stiffness_scale", "reference_ucs")


def carried_lines(calibration) -> list:
    """``key = value  # unit, meaning`` lines of the [calibration] keys not fitted here, at ``calibration``'s values."""
    return [f"{f.name} = {getattr(calibration, f.name)!r}    # {f.metadata['unit']}, {f.metadata['doc']}"
            for f in dataclasses.fields(calibration) if f.name not in FITTED_KEYS]


def write_calibration_file(path: Path, rows, args, overrides, calibration):
    first = [r for r in rows if r["round"] == 0]
    last_round = max(r["round"] for r in rows)
    last = [r for r in rows if r["round"] == last_round]
    lines = ["# Calibration of the YADE packing to the paper's granite (UCS and E of paper section 3.1), written by",
             "#   python3 -m grainfrac_yade calibrate --seeds " + " ".join(map(str, args.seeds))
             + f" --rounds {args.rounds} " + " ".join(f"--set {k}={v}" for k, v in overrides).strip(),
             f"# seeds {args.seeds}; targets: UCS {args.target_ucs / 1e6:.1f} MPa"
             + (" (paper, simulated)," if args.target_ucs == TARGET_UCS else " (--target-ucs),"),
             f"# E {args.target_young / 1e9:.1f} GPa" + (" (LdB lab)." if args.target_young == TARGET_YOUNG
                                                        else " (--target-young).")
             + " Table 1 and 2 stay as printed; these factors scale",
             "# every bond alike. Why: rigid Voronoi cells bonded across faces are weaker and softer than",
             "# UDEC's deformable blocks with the same contact values (README, 'Calibration').",
             "#",
             "# measured (mean +- sd over seeds):  UCS [MPa]   E [GPa]   Poisson"]
    for label, rs in (("before (factors of round 0)", first), (f"after (round {last_round})", last)):
        u, su = _stats(rs, "ucs_pa")
        e, se = _stats(rs, "young_pa")
        n, sn = _stats(rs, "poisson")
        lines.append(f"#   {label:34s} {u / 1e6:6.1f} +- {su / 1e6:4.1f}  {e / 1e9:5.1f} +- {se / 1e9:3.1f}  "
                     f"{n:.3f} +- {sn:.3f}")
    lines += ["", "[calibration]",
              f"strength_scale = {last[0]['strength_scale']:.6g}    # 1, multiplies J^T and J^C of every contact pair",
              f"stiffness_scale = {last[0]['stiffness_scale']:.6g}   # 1, multiplies the series k_n and k_s of every bond",
              f"reference_ucs = {_stats(last, 'ucs_pa')[0]:.6g}     # Pa, calibrated mean UCS (round {last_round}): "
              "what a driving-stress ratio refers to, as in the lab",
              "# levers on the contacts, as this calibration ran with them",
              *carried_lines(calibration),
              ""]
    path.write_text("\n".join(lines))
