"""Command line: ``python3 -m grainfrac_yade <command> ...``.

The commands that build or run a model accept ``--params FILE`` (merged over the
shipped files in ``params/``) and repeated ``--set section.key=value`` overrides,
validated like the files (README.md lists them; tests/test_newcomer_inputs.py holds
the list equal to the parser's).  User errors print one line and exit with status 2.

Commands that run a model declare ``with_params=True`` (and optionally
``param_overrides``, a function of their arguments giving further overrides) in
``set_defaults``: :func:`main` loads the parameter set once and passes it in,
``func(args, params)``; the override list used is ``args.resolved_overrides``.
Command modules never import this module.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import re
import sys
import tempfile
import traceback
from pathlib import Path

from .commands import animate, register_all
from .errors import EXIT_NUMERICAL_FAILURE, GrainfracError  # noqa: F401  (the statuses, here)

#: Exit status for user errors (bad input), as argparse uses.
EXIT_USER_ERROR = 2
#: Exit status of an unexpected error (a bug or a failure of the machine, not bad input).
EXIT_INTERNAL_ERROR = 1
#: Flag (anywhere on the command line) that shows the traceback of an unexpected error instead of logging it.
DEBUG_FLAG = "--debug"
#: Folder of the traceback logs of unexpected errors (relative to the working folder; the temporary folder if
#: that is not writable).
ERROR_LOG_DIR = "results/logs"
#: Commands that take ``--engine NAME`` (a shortcut for ``--set numerics.engine=NAME``).
ENGINE_COMMANDS = ("ucs", "creep", "brazilian")
#: Help of ``--engine`` (the engines of :data:`grainfrac_yade.engines.registry.ENGINE_NAMES`).
ENGINE_HELP = ("mechanical engine (numerics.engine): yade (the default: explicit DEM), static (static equilibrium "
               "between bond failures) or hybrid (static, with YADE's dynamics where statics give out); given also "
               "as --set numerics.engine=... with another value: refused")
#: A negative number with an exponent (-10e-3): argparse takes it for an option ("expected one argument").
NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")


def check_out_flag(args):
    """``--out ''`` (or blanks) is refused: an empty folder name would silently mean the default folder."""
    out = getattr(args, "out", None)
    if out is not None and not str(out).strip():
        raise GrainfracError(f"--out {out!r}: an empty folder name; fix: give a folder (e.g. --out results/run1), "
                             "or leave --out out for the command's default folder")


class OneLineParser(argparse.ArgumentParser):
    """argparse with its errors in one line (no usage block): the flag, the problem, where the help is."""

    def error(self, message):
        self.exit(EXIT_USER_ERROR, f"error: {self.prog}: {message}; fix: see {self.prog} --help\n")


def _common(parser: argparse.ArgumentParser, geometry: bool = True):
    from .commands._args import seed_type   # not at module level: see main()
    parser.add_argument("--params", action="append", default=[], metavar="FILE",
                        help="TOML file merged over the shipped parameters (repeatable)")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="SECTION.KEY=VALUE",
                        help="override one parameter, e.g. --set stress_corrosion.beta1=0.002 (repeatable)")
    if geometry:
        parser.add_argument("--width", type=float, help="specimen width [m] (specimen.width)")
        parser.add_argument("--height", type=float, help="specimen height [m] (specimen.height)")
        parser.add_argument("--grain-size", type=float, help="grain size [m] (specimen.grain_size)")
        parser.add_argument("--spheres-per-cell", type=int, help="resolution.spheres_per_cell")
        parser.add_argument("--seed", type=seed_type, default=1, help="random seed of the specimen (>= 0)")
    parser.add_argument("--out", help="output folder")
    parser.add_argument("--overwrite", action="store_true", help="replace a run already in --out")


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
    parser = OneLineParser(prog="python3 -m grainfrac_yade",
                                     description="Grain-based DEM of time-dependent fracture of granite (YADE).")
    parser.add_argument(DEBUG_FLAG, action="store_true",
                        help="show the traceback of an unexpected error (else written to a log file whose path the "
                             "error line gives); accepted anywhere on the command line")
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("specimen", help="build a Voronoi grain specimen; write specimen.json and specimen.png")
    _common(p)
    p.add_argument("--bonds", action="store_true", help="draw the bond network on the picture")
    p.set_defaults(func=cmd_specimen, with_params=True)
    register_all(sub, _common)
    animate.register(sub, _common)
    for name in ENGINE_COMMANDS:
        if name in sub.choices:
            sub.choices[name].add_argument("--engine", metavar="NAME", help=ENGINE_HELP)
    return parser


def join_negative_values(argv: list) -> list:
    """``--width -10e-3`` as ``--width=-10e-3``: argparse reads a negative number with an exponent as an option
    and says only "expected one argument"; joined, the value reaches the parameter check, which names it."""
    out = []
    for token in argv:
        if out and out[-1].startswith("--") and "=" not in out[-1] and NEGATIVE_NUMBER.match(token):
            out[-1] = f"{out[-1]}={token}"
        else:
            out.append(token)
    return out


def _log_traceback(command: str) -> str:
    """Write the current exception's traceback to a new log file; its path (or a note if none could be written)."""
    stamp = _dt.datetime.now().strftime("%Y%m%d-%H%M%S")
    text = f"python3 -m grainfrac_yade {' '.join(sys.argv[1:])}\n\n{traceback.format_exc()}"
    for folder in (Path(ERROR_LOG_DIR), Path(tempfile.gettempdir())):
        try:
            folder.mkdir(parents=True, exist_ok=True)
            path = folder / f"error_{command}_{stamp}.log"
            path.write_text(text)
            return str(path.resolve())
        except OSError:
            continue
    return "(no log written: no writable folder)"


def main(argv=None) -> int:
    from .engines.yade import use_default_threads
    use_default_threads()   # before any command module loads the OpenMP runtime
    # this module's own imports load no numpy (nor OpenBLAS, which reads OMP_NUM_THREADS once) before this line
    from .commands._args import load_params_from_args
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = DEBUG_FLAG in argv
    argv = join_negative_values([a for a in argv if a != DEBUG_FLAG])
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        check_out_flag(args)
        if getattr(args, "with_params", False):
            return args.func(args, load_params_from_args(args))
        return args.func(args)
    except GrainfracError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print("interrupted: files already written are complete", file=sys.stderr)
        return 130
    except Exception as exc:   # noqa: BLE001  the general guard: one line, the traceback in a log
        if debug:
            raise
        where = _log_traceback(args.command)
        print(f"error: {args.command} failed unexpectedly: {type(exc).__name__}: {exc}; traceback in {where} "
              f"(or rerun with {DEBUG_FLAG} to see it)", file=sys.stderr)
        return EXIT_INTERNAL_ERROR
