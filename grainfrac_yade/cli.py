"""Command line: ``python3 -m grainfrac_yade <command> ...``.

Every command accepts ``--params FILE`` (merged over the shipped files in
``params/``) and repeated ``--set section.key=value`` overrides, validated like
the files.  User errors print one line and exit with status 2.

Commands that run a model declare ``with_params=True`` (and optionally
``param_overrides``, a function of their arguments giving further overrides) in
``set_defaults``: :func:`main` loads the parameter set once and passes it in,
``func(args, params)``; the override list used is ``args.resolved_overrides``.
Command modules never import this module.
"""
from __future__ import annotations

import argparse
import sys

from .errors import GrainfracError

#: Exit status for user errors (bad input), as argparse uses.
EXIT_USER_ERROR = 2


def _common(parser: argparse.ArgumentParser, geometry: bool = True):
    parser.add_argument("--params", action="append", default=[], metavar="FILE",
                        help="TOML file merged over the shipped parameters (repeatable)")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="SECTION.KEY=VALUE",
                        help="override one parameter, e.g. --set stress_corrosion.beta1=0.002 (repeatable)")
    if geometry:
        parser.add_argument("--width", type=float, help="specimen width [m] (specimen.width)")
        parser.add_argument("--height", type=float, help="specimen height [m] (specimen.height)")
        parser.add_argument("--grain-size", type=float, help="grain size [m] (specimen.grain_size)")
        parser.add_argument("--spheres-per-cell", type=int, help="resolution.spheres_per_cell")
        parser.add_argument("--seed", type=int, default=1, help="random seed of the specimen")
    parser.add_argument("--out", help="output folder")
    parser.add_argument("--overwrite", action="store_true", help="replace a run already in --out")


def overrides_from_args(args) -> list:
    """``--set`` strings plus the geometry shortcuts (--width etc.) and the command's own (``param_overrides``)."""
    out = list(args.overrides)
    extra = getattr(args, "param_overrides", None)
    if extra is not None:
        out += list(extra(args))
    for opt, key in (("width", "specimen.width"), ("height", "specimen.height"),
                     ("grain_size", "specimen.grain_size"), ("spheres_per_cell", "resolution.spheres_per_cell")):
        value = getattr(args, opt, None)
        if value is not None:
            out.append((key, value))
    return out


def load_params_from_args(args):
    """The parameter set of ``args`` (``--params``, ``--set``, shortcuts); sets ``args.resolved_overrides``."""
    from .params import load_parameters
    args.resolved_overrides = overrides_from_args(args)
    return load_parameters(extra_files=args.params, overrides=args.resolved_overrides)


def cmd_specimen(args, params) -> int:
    from .commands.specimen import run_specimen
    summary = run_specimen(params, args.seed, args.out or f"results/specimen_seed{args.seed}",
                           draw_bonds=args.bonds, overwrite=args.overwrite)
    print(_format_summary(summary))
    return 0


def _format_summary(summary: dict) -> str:
    fr = ", ".join(f"{k} {v * 100:.1f} %" for k, v in summary["mineral_area_fractions"].items())
    return (f"{summary['n_cells']} cells, {summary['n_faces']} faces, {summary['n_bonds']} bonds "
            f"({summary['n_bonds_inter']} inter-, {summary['n_bonds_intra']} intra-granular), "
            f"seed {summary['seed']}\nmineral area fractions: {fr}\nwritten: {summary['out']}")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python3 -m grainfrac_yade",
                                     description="Grain-based DEM of time-dependent fracture of granite (YADE).")
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("specimen", help="build a Voronoi grain specimen; write specimen.json and specimen.png")
    _common(p)
    p.add_argument("--bonds", action="store_true", help="draw the bond network on the picture")
    p.set_defaults(func=cmd_specimen, with_params=True)
    from .commands import register_all
    register_all(sub, _common)
    from .commands import animate
    animate.register(sub, _common)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        if getattr(args, "with_params", False):
            return args.func(args, load_params_from_args(args))
        return args.func(args)
    except GrainfracError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print("interrupted: files already written are complete", file=sys.stderr)
        return 130
