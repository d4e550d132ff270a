"""``--resume DIR`` of the loading tests (``ucs``, ``brazilian``): the option, its conflicts, and the run
folder's parameters and checkpoint (``creep --resume`` has its own, :func:`grainfrac_yade.protocols.creep_output.resume_creep_folder`)."""
from __future__ import annotations

import json
from pathlib import Path

from ..analysis.runparams import load_run_parameters
from ..errors import GrainfracError
from ..runs.runio import CHECKPOINT, SUMMARY, check_files, checkpoint_folder, read_checkpoint_state

#: Options that shape a run: refused with --resume (the run folder holds them).
RESUME_CONFLICTS = (("overrides", "--set"), ("params", "--params"), ("width", "--width"), ("height", "--height"),
                    ("grain_size", "--grain-size"), ("spheres_per_cell", "--spheres-per-cell"),
                    ("confinement", "--confinement"), ("diameter", "--diameter"), ("tensile_scale", "--tensile-scale"),
                    ("slit_fraction", "--slit-fraction"), ("strength_cv", "--strength-cv"),
                    ("block_rotation", "--block-rotation"), ("out", "--out"), ("overwrite", "--overwrite"))


def add_resume_option(parser, what: str):
    parser.add_argument("--resume", metavar="DIR",
                        help=f"go on with the interrupted {what} in DIR from its last checkpoint (DIR/checkpoint/, "
                             "written every numerics.checkpoint_interval s of wall time); seed and parameters come "
                             "from DIR")


def refuse_resume_conflicts(args):
    """GrainfracError naming the options given with ``--resume`` that the run folder already fixes."""
    given = [flag for attr, flag in RESUME_CONFLICTS if getattr(args, attr, None) not in (None, [], False, 0.0)]
    if given:
        raise GrainfracError(f"--resume {args.resume} takes the seed and parameters from the run folder; "
                             f"fix: drop {', '.join(given)}")


def resumable_run(folder, command: str):
    """(parameters, checkpoint state) of the unfinished ``command`` run in ``folder``, or None if it is
    finished (summary.json).  GrainfracError (one line) if the folder holds no such run or no checkpoint."""
    folder = Path(folder)
    try:
        found = json.loads((folder / "run.json").read_text()).get("command")
    except (OSError, ValueError, AttributeError):
        raise GrainfracError(f"{folder}: no run here (run.json missing or unreadable); fix: give the --out folder "
                             f"of a {command} run") from None
    if found != command:
        raise GrainfracError(f"{folder}: holds a {found!r} run, not a {command} run; fix: resume it with "
                             f"`{found} --resume {folder}`, or give the folder of a {command} run")
    if (folder / SUMMARY).exists():
        return None
    if checkpoint_folder(folder) is not None:
        check_files(checkpoint_folder(folder))
    state = read_checkpoint_state(folder)
    if state is None:
        raise GrainfracError(f"{folder}: no checkpoint to resume from ({CHECKPOINT}/ missing: the run stopped before "
                             "its first checkpoint (numerics.checkpoint_interval), or was started by code without "
                             "checkpoints); fix: start it again with the same command (run.json) and --overwrite")
    if "seed" not in (state.get("run_values") or {}):
        raise GrainfracError(f"{folder}: the checkpoint lacks the run's seed; fix: start the run again with --overwrite")
    return load_run_parameters(folder).params, state
