"""``analyze``: creep study folder(s) -> the paper's figures, lifetime fits and report.md."""
from __future__ import annotations

import argparse
import math


def _fractions(text: str) -> list:
    """Comma-separated fractions of the lifetime in [0, 1] (argparse type)."""
    try:
        values = [float(t) for t in text.split(",") if t.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a comma-separated list of numbers (e.g. 0.1,0.5,0.9,1)")
    if not values or any(not math.isfinite(v) or not 0 <= v <= 1 for v in values):
        raise argparse.ArgumentTypeError(f"{text!r}: fractions of the lifetime must lie in [0, 1]")
    return values


def register(sub, common):
    p = sub.add_parser("analyze", help="creep study: lifetime fits, strain/crack/damage figures and report.md",
                       description="Turn a study folder of creep runs into the paper's figures (Fig. 4-9), "
                                   "lifetime fits and a markdown report (default folder: FOLDER/report).")
    p.add_argument("folder", nargs="+", help="study folder holding run folders (e.g. results/lifetime_small); "
                                             "several folders: shown together, labelled by folder name, each "
                                             "fitted separately (needs --out)")
    p.add_argument("--lab", metavar="CSV", help="lab lifetimes: columns driving_stress_ratio,lifetime_s[,source]; "
                                                "without it the paper's UDEC value and the 1986 bound are drawn")
    p.add_argument("--out", help="report folder (default FOLDER/report)")
    p.add_argument("--reference", metavar="DIR", help="folder of paper_values.csv and lab_lifetimes_README.md "
                                                      "(default: params/reference: copies of the reference values the project ships)")
    p.add_argument("--focus-ratio", type=float, metavar="R",
                   help="driving-stress ratio of the run shown in the one-load figures (default: the paper's "
                        "160 MPa point's ratio)")
    p.add_argument("--map-fractions", type=_fractions, metavar="F1,F2,...",
                   help="fractions of the lifetime for the crack maps (default 0.1,0.5,0.9,1)")
    rate = p.add_mutually_exclusive_group()
    rate.add_argument("--beta1", type=float, metavar="PA_PER_S",
                      help="show every creep time at this stress-corrosion rate beta1 [Pa/s]: t' = t beta1_run / "
                           "beta1, exact for event-clock strength-mode runs (others are refused)")
    rate.add_argument("--beta1-file", metavar="TOML",
                      help="as --beta1, reading [stress_corrosion] beta1 from a TOML file "
                           "(e.g. params/stress_corrosion_calibrated.toml)")
    p.add_argument("--no-grains", action="store_true",
                   help="crack maps on the specimen outline only (default: the run's grains, rebuilt from "
                        "params.json and the seed)")
    p.set_defaults(func=cmd_analyze)


def cmd_analyze(args) -> int:
    from ..analysis.rescale import beta1_from_toml
    from ..analysis.figures import MAP_FRACTIONS
    from ..analysis.study import analyze_study
    beta1, source = args.beta1, "--beta1"
    if args.beta1_file is not None:
        beta1, source = beta1_from_toml(args.beta1_file), f"--beta1-file {args.beta1_file}"
    folders = args.folder if len(args.folder) > 1 else args.folder[0]
    report = analyze_study(folders, lab=args.lab, out=args.out, reference_dir=args.reference,
                           focus_ratio=args.focus_ratio, map_fractions=args.map_fractions or MAP_FRACTIONS,
                           beta1=beta1, beta1_source=source, grains=not args.no_grains)
    print(report)
    return 0
