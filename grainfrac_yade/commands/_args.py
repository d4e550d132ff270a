"""Argument helpers that the CLI (``cli.py``) and the command modules share: the seed type, the parameter
overrides a command line gives, and the parameter set they load.  Here, not in ``cli.py``, because
command modules never import ``cli.py`` (it loads them)."""
from __future__ import annotations

import argparse
import sys

from ..engines.registry import engine_for, require_dynamic
from ..errors import GrainfracError
from ..failure_criterion import reading_refusal
from ..params import FlagOverride, check_conflicting_overrides, load_parameters, override_origin
from ..geometry.specimen import MAX_SEED, check_cell_count
from ..geometry.tessellation import n_cells_for
from ._loads import positive_int


def seed_type(text: str, example: str = "1") -> int:
    """argparse type of a specimen seed: a whole number in [0, MAX_SEED] (numpy's generators take no negative
    seed; :data:`~grainfrac_yade.geometry.specimen.MAX_SEED` is the range of a 32-bit seed)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number (e.g. {example})") from None
    if value < 0 or value > MAX_SEED:
        raise argparse.ArgumentTypeError(f"{value}: a seed is a whole number from 0 to {MAX_SEED} (the range of a "
                                         f"32-bit seed; e.g. {example})")
    return value


def seed_list_type(text: str) -> list:
    """argparse type of a list of specimen seeds separated by commas, e.g. 1,2: each as :func:`seed_type`."""
    return [seed_type(x, example="1,2") for x in text.split(",") if x.strip()]


def float_list_type(text: str) -> list:
    """argparse type of a list of numbers separated by commas, e.g. 0.7,0.8."""
    return [float(x) for x in text.split(",") if x.strip()]


def overrides_from_args(args) -> list:
    """``--set`` strings plus the geometry shortcuts (--width etc.) and the command's own (``param_overrides``);
    a shortcut's override is a :class:`~grainfrac_yade.params.FlagOverride` (its errors name the flag)."""
    out = list(args.overrides)
    extra = getattr(args, "param_overrides", None)
    if extra is not None:
        out += list(extra(args))
    for opt, key in (("width", "specimen.width"), ("height", "specimen.height"),
                     ("grain_size", "specimen.grain_size"), ("spheres_per_cell", "resolution.spheres_per_cell"),
                   ("engine", "numerics.engine")):
        value = getattr(args, opt, None)
        if value is not None:
            out.append(FlagOverride(key, value, "--" + opt.replace("_", "-")))
    return out


def load_params_from_args(args):
    """The parameter set of ``args`` (``--params``, ``--set``, shortcuts); sets ``args.resolved_overrides``."""
    args.resolved_overrides = overrides_from_args(args)
    params = load_parameters(extra_files=args.params, overrides=args.resolved_overrides)
    check_conflicting_overrides(args.resolved_overrides)   # after each value's own check (a NaN named as such)
    sp = params.specimen   # refused before any folder is made or anything allocated
    box = [sp.width, sp.height] if sp.dimension == 2 else [sp.width, sp.height, sp.thickness]
    flags = ", ".join(override_origin(o) for o in args.resolved_overrides
                      if override_origin(o) != "--set" and o[0].startswith("specimen."))
    check_cell_count(n_cells_for(box, sp.grain_size), f"the {' x '.join(f'{b * 1e3:g}' for b in box)} mm specimen",
                     sp.grain_size, flags)
    check_engine(getattr(args, "command", ""), params, args.resolved_overrides, bool(getattr(args, "vtk_every", None)))
    return params


def check_engine(command: str, params, overrides=(), vtk: bool = False) -> None:
    """Before a run folder is made: refuse what the engine of ``params`` cannot run (one line: the paper clock
    without dynamics, a test the engine does not have yet, a VTK series ``vtk`` it does not write), and warn
    once per line of a dynamic-only setting given in ``overrides`` to an engine without dynamics; a creep test with face
    failure whose corrosion does not read the face (:func:`grainfrac_yade.failure_criterion.reading_refusal`).  A dynamic engine
    (YADE) refuses only settings it has no model of; an engine says what it refuses in its
    :class:`~grainfrac_yade.engines.EngineModule` (``unsupported``, ``refused_settings``, ``vtk_refused``, ``warn_dynamic_only``:
    docs/maintainers.md, adding an engine)."""
    module = engine_for(params)
    refusal = module.refusal(command, params) or (reading_refusal(params) if command == "creep" else "")
    if refusal:
        raise GrainfracError(refusal)
    if module.dynamic:
        return
    if command == "creep" and params.stress_corrosion.clock == "paper":
        require_dynamic(params, "the paper clock (its unbalanced force, Eq. 8)")
    if vtk and module.vtk_refused:
        raise GrainfracError(module.vtk_refused)
    for line in module.warn_dynamic_only([o for o in overrides if override_origin(o) == "--set"], params):
        print(line, file=sys.stderr)


def add_vtk_every_option(parser, strain: str):
    """``--vtk-every K``: VTK series of a strain-controlled test, timestep the ``strain`` strain."""
    parser.add_argument("--vtk-every", type=positive_int, default=None, metavar="K",
                        help=f"write VTK files of cells and bonds at every K-th history row and at the end into "
                             f"DIR/vtk/ (cells.pvd, bonds.pvd: time series whose timestep is the {strain} strain)")
