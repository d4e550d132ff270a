"""Run folders: plain files a person can open (JSON, CSV, PNG).

Every run folder records its resolved parameters, seed and code version.
Files are written to a temporary name and renamed, so an interrupted run never
leaves a half-written file; an existing run is never overwritten unless asked,
and a folder is never taken over by another kind of run or mixed with files of
something else.  ``summary.json`` marks a finished run: commands write it last.
A replacing run (``--overwrite``) is written beside the old one and swapped in
when it has finished, so a failed replacement leaves the old run intact.
"""
from __future__ import annotations

import datetime as _dt
import functools
import gzip
import hashlib
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import zipfile
import zlib
from pathlib import Path

import numpy as np

from .. import __version__
from ..atomic import write_atomically, write_text_atomically
from ..errors import GrainfracError
from ..params import flatten, load_parameters, migrate_tree
from ..repeatable import process_is_repeatable

#: Files whose presence marks a folder as holding a finished or running run.
RUN_MARKERS = ("run.json",)
#: The file that marks a run as finished (written last).
SUMMARY = "summary.json"
#: Parameter-tree entries that record provenance, not the model: never compared between runs.
PROVENANCE_KEYS = ("sources",)
#: Parameters that do not change what a run computes (how often it is checkpointed): never compared
#: between runs, and not part of :func:`run_digest`.
RESULT_NEUTRAL_KEYS = ("numerics.checkpoint_interval",)
#: Checkpoint of an unfinished run (creep ``--resume``): ``<run>/checkpoint/`` holds the DEM scene and
#: :data:`CHECKPOINT_STATE`, the driver's state, written last.  A new checkpoint is written into
#: ``checkpoint.tmp/`` and renamed; the previous one is moved aside to ``checkpoint.old/`` for the
#: instant between the two renames (:func:`checkpoint_folder` picks the complete one).
CHECKPOINT = "checkpoint"
CHECKPOINT_STATE = "state.json"
CHECKPOINT_TMP, CHECKPOINT_OLD = CHECKPOINT + ".tmp", CHECKPOINT + ".old"
#: The state.json key naming the file that holds a checkpoint's scene: the engine's own name for it
#: (:attr:`grainfrac_yade.engines.EngineModule.scene_file`).
SCENE_FILE_KEY = "scene_file"
#: The scene's file in a checkpoint whose state.json names none: code before each engine named its own kept every
#: engine's scene under YADE's name (a static or hybrid scene's npz too, told apart by its first bytes).
LEGACY_SCENE_FILE = "scene.yade.gz"
#: Per-bond arrays of the driver.
ARRAYS_FILE = "arrays.npz"
#: The first bytes of a zip archive (numpy's npz: the static engines' saved scene, also under the legacy name).
ZIP_MAGIC = b"PK\x03\x04"


@functools.lru_cache(maxsize=None)
def code_version() -> str:
    """Package version plus the git commit of the source tree (``+dirty`` if modified).

    Read once per process: a process runs the code it imported at its start, so a run's summary.json
    names that code even when the checkout changes while it runs (found: a 20-minute creep run whose
    summary named a commit made during the run)."""
    root = Path(__file__).resolve().parents[2]
    try:
        rev = subprocess.run(["git", "-C", str(root), "describe", "--always", "--dirty", "--abbrev=12"],
                             capture_output=True, text=True, timeout=10)
        if rev.returncode == 0 and rev.stdout.strip():
            return f"{__version__}+{rev.stdout.strip()}"
    except (OSError, subprocess.SubprocessError):
        pass
    return __version__


def summary_header(params, seed) -> dict:
    """summary.json keys shared by UCS and creep runs: seed, code version, all parameters, and at the
    top level how the cells are realised (``spheres_per_cell``, ``grain_model``, ``nodes_per_face``)."""
    r = params.resolution
    return {"seed": seed, "code_version": code_version(), "params": params.to_dict(),
            "spheres_per_cell": r.spheres_per_cell, "grain_model": r.grain_model, "nodes_per_face": r.nodes_per_face}


def _clean(value):
    """JSON-safe copy: NaN/inf become None, numpy scalars become Python numbers."""
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if hasattr(value, "item") and not isinstance(value, (str, bytes)):
        try:
            value = value.item()
        except (ValueError, AttributeError):
            value = value.tolist()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def write_json(path, data) -> Path:
    """Write ``data`` as indented JSON atomically."""
    text = json.dumps(_clean(data), indent=2, sort_keys=False) + "\n"
    return write_text_atomically(path, text)


def write_csv(path, frame) -> Path:
    """Write a pandas DataFrame (or dict of columns) as CSV atomically."""
    import pandas as pd
    frame = frame if isinstance(frame, pd.DataFrame) else pd.DataFrame(frame)
    return write_atomically(path, lambda tmp: frame.to_csv(tmp, index=False))


#: A run that replaces another (``--overwrite``) is written into ``.<name>.replacing`` beside the old one and
#: swapped in when it has finished (:func:`commit_run_dir`); the old run moves to ``.<name>.replaced`` for the
#: instant between the two renames.  A failure leaves the old run as it was.
REPLACING, REPLACED = ".replacing", ".replaced"


def _staging(out: Path, suffix: str) -> Path:
    return out.with_name(f".{out.name}{suffix}")


def _folder_error(out: Path, exc: OSError) -> GrainfracError:
    """One line for a run folder that cannot be made or written (read-only, immutable, /proc, ...)."""
    why = exc.strerror or type(exc).__name__
    return GrainfracError(f"{out}: cannot write the run folder here ({why}: {exc.filename or out}); fix: choose a "
                          "writable --out (batch column out)")


def run_command_of(out) -> str | None:
    """The command recorded in ``out/run.json`` ("" if unreadable), or None if the folder holds no run."""
    path = Path(out) / "run.json"
    if not path.exists():
        return None
    try:
        command = json.loads(path.read_text()).get("command")
    except (OSError, ValueError, AttributeError):
        return ""
    return command if isinstance(command, str) else ""


def prepare_run_dir(out, command: str, params, seed, overwrite: bool = False, argv=None) -> Path:
    """Create the run folder ``out`` and write ``run.json`` (command, seed, code version) and ``params.json``;
    return the folder to write the run into.

    Refuses, in one line: a folder that holds another kind of run (run.json of another command) or files of
    something else (no run.json), always; a folder that holds a run of ``command`` unless ``overwrite`` (naming
    ``--resume`` when that run is unfinished and has a checkpoint).  With ``overwrite`` the new run is written
    beside the old one (``.<name>.replacing``, the returned folder) and :func:`commit_run_dir` swaps it in once
    finished: until then, and after a failure, the old run is intact.
    """
    out = Path(out)
    old = _staging(out, REPLACED)
    try:
        if not out.exists() and old.is_dir():   # killed between the two renames of a swap: the old run is back
            os.replace(old, out)
        if out.exists() and not out.is_dir():
            raise GrainfracError(f"{out}: exists and is not a folder; fix: choose another --out")
        held = run_command_of(out) if out.is_dir() else None
        if held is None and out.is_dir() and any(out.iterdir()):
            names = sorted(p.name for p in out.iterdir())
            raise GrainfracError(f"{out}: holds files of something else than a run ({len(names)} entries, e.g. "
                                 f"{', '.join(names[:3])}; no run.json); fix: choose another --out, or an empty folder")
        if held is not None and held != command:
            kind = f"a {held!r} run" if held else "a run whose run.json is unreadable"
            raise GrainfracError(f"{out}: holds {kind}, not a {command!r} run; fix: choose another --out (a folder "
                                 "holds one kind of run; --overwrite replaces only a run of the same command)")
        if held is not None and not overwrite:
            if not (out / SUMMARY).exists() and checkpoint_folder(out) is not None:
                raise GrainfracError(f"{out}: holds an unfinished {command} run with a checkpoint; fix: "
                                     f"`python3 -m grainfrac_yade {command} --resume {out}` goes on with it "
                                     "(--overwrite would discard it), or choose another --out")
            raise GrainfracError(f"{out}: already holds a run (run.json); fix: choose another --out "
                                 "or pass --overwrite to replace it")
        where = out
        if held is not None:   # overwrite: the new run goes beside the old one
            where = _staging(out, REPLACING)
            shutil.rmtree(where, ignore_errors=True)   # a replacement that failed earlier
        where.mkdir(parents=True, exist_ok=True)
        write_json(where / "params.json", params.to_dict())
        write_json(where / "run.json", {
            "command": command, "argv": list(sys.argv if argv is None else argv), "seed": seed,
            "code_version": code_version(), "python": sys.version.split()[0], "platform": platform.platform(),
            "repeatable_process": process_is_repeatable(),
            "started": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        })
    except OSError as exc:
        raise _folder_error(out, exc) from None
    return where


def final_run_dir(where) -> Path:
    """The folder a run written into ``where`` (:func:`prepare_run_dir`) ends in."""
    where = Path(where)
    if where.name.startswith(".") and where.name.endswith(REPLACING):
        return where.with_name(where.name[1:-len(REPLACING)])
    return where


def commit_run_dir(where) -> Path:
    """Swap a finished replacement run (``.<name>.replacing``) in for the old run; return the final folder.
    A run written straight into its folder (nothing replaced) is left as it is."""
    where = Path(where)
    out = final_run_dir(where)
    if out == where:
        return out
    old = _staging(out, REPLACED)
    shutil.rmtree(old, ignore_errors=True)
    if out.exists():
        os.replace(out, old)
    os.replace(where, out)
    shutil.rmtree(old, ignore_errors=True)
    return out


def remove_checkpoints(folder) -> None:
    """Delete a run folder's checkpoint folders (a finished or replaced run has nothing to resume)."""
    for name in (CHECKPOINT, CHECKPOINT_TMP, CHECKPOINT_OLD):
        shutil.rmtree(Path(folder) / name, ignore_errors=True)


def checkpoint_folder(folder) -> Path | None:
    """The complete checkpoint of run ``folder``, or None.

    ``checkpoint/`` if present (it only ever appears by renaming a complete one); else, after a
    kill between the two renames of a rewrite, ``checkpoint.tmp/`` if its state file (written last)
    is there, else ``checkpoint.old/``.
    """
    folder = Path(folder)
    for name in (CHECKPOINT, CHECKPOINT_TMP, CHECKPOINT_OLD):
        if (folder / name / CHECKPOINT_STATE).is_file():
            return folder / name
    return None


def read_checkpoint_state(folder) -> dict | None:
    """The driver state of run ``folder``'s checkpoint (JSON), or None if it has none or it is unreadable."""
    where = checkpoint_folder(folder)
    if where is None:
        return None
    try:
        state = json.loads((where / CHECKPOINT_STATE).read_text())
    except (OSError, ValueError):
        return None
    return state if isinstance(state, dict) else None


def checkpoint_differences(folder, params, run_values: dict) -> list | None:
    """What differs between the checkpoint in run ``folder`` and a run of ``params`` with ``run_values``.

    None if the folder holds no readable checkpoint; else "key: stored X, now Y" strings ([] if the
    checkpoint continues exactly this run: the folder's params.json and the checkpoint's run values
    equal the given ones). A key missing from an older params.json counts as the shipped default,
    as in :func:`stored_run_differences`.
    """
    state = read_checkpoint_state(folder)
    if state is None:
        return None
    try:
        stored = json.loads((Path(folder) / "params.json").read_text())
    except (OSError, ValueError) as exc:
        return [f"stored parameters unreadable ({type(exc).__name__}: {exc})"]
    pairs = _parameter_pairs(stored, params)
    stored_values = flatten_values(state.get("run_values", {}))
    pairs.update({key: (stored_values.get(key, MISSING), value) for key, value in flatten_values(run_values).items()})
    return _differences(pairs)


#: What a comparison shows for a key one side does not have.
MISSING = "(missing)"


def _parameter_pairs(stored_tree: dict, params) -> dict:
    """{dotted key: (stored value, value of ``params``)} over both parameter trees; a key missing
    from an older stored tree counts as the shipped default, as the analysis reads it."""
    stored = comparable_parameters(stored_tree)
    now = comparable_parameters(params.to_dict())
    defaults = comparable_parameters(load_parameters().to_dict())
    return {key: (stored.get(key, defaults.get(key, MISSING)), now.get(key, MISSING))
            for key in sorted(set(stored) | set(now))}


def _differences(pairs: dict) -> list:
    """"key: stored X, now Y" for each pair of unequal values."""
    return [f"{key}: stored {old!r}, now {new!r}" for key, (old, new) in pairs.items() if not _same(old, new)]


def flatten_values(values: dict) -> dict:
    """``run_values`` as JSON stores them, flattened to dotted keys."""
    return flatten(json.loads(json.dumps(_clean(values))))


def comparable_parameters(tree: dict) -> dict:
    """A parameter tree (``Parameters.to_dict()`` or a params.json) as {dotted key: value} as JSON
    stores it, without the provenance entries (:data:`PROVENANCE_KEYS`) and the parameters that do
    not change results (:data:`RESULT_NEUTRAL_KEYS`)."""
    tree = json.loads(json.dumps(_clean({k: v for k, v in tree.items() if k not in PROVENANCE_KEYS})))
    migrate_tree(tree)   # renamed keys of older params.json (stress_corrosion.mode -> law)
    return {k: v for k, v in flatten(tree).items() if k not in RESULT_NEUTRAL_KEYS}


def _same(a, b) -> bool:
    """Equal values as JSON stores them (1 == 1.0, but true is not 1)."""
    return a == b and isinstance(a, bool) == isinstance(b, bool)


def stored_run_differences(folder, params, run_values: dict) -> list:
    """What differs between the finished run in ``folder`` and a run of ``params`` with ``run_values``.

    Compares the folder's params.json with ``params`` (every key; a key missing from an older
    params.json counts as the shipped default, as the analysis reads it) and its summary.json's
    ``run_values`` keys (e.g. seed, stress_pa). Returns "key: stored X, now Y" strings, [] if equal.
    """
    folder = Path(folder)
    try:
        stored = json.loads((folder / "params.json").read_text())
        summary = json.loads((folder / SUMMARY).read_text())
    except (OSError, ValueError) as exc:
        return [f"stored run unreadable ({type(exc).__name__}: {exc})"]
    pairs = _parameter_pairs(stored, params)
    pairs.update({key: (summary.get(key, MISSING), value) for key, value in flatten_values(run_values).items()})
    return _differences(pairs)


def run_digest(params, run_values: dict) -> str:
    """8 hex digits identifying the resolved parameters and run values (e.g. seed, load) of a run."""
    data = {"params": comparable_parameters(params.to_dict()), "run": _clean(run_values)}
    return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()[:8]


#: The fix a damaged checkpoint's one line names.
RESTART_FIX = "fix: start the run again with the same command (run.json) and --overwrite"


def scene_file_of(state: dict, where) -> str:
    """The name of the file that holds the scene of the checkpoint ``where`` whose state.json is ``state``: the one
    it names (:data:`SCENE_FILE_KEY`), else :data:`LEGACY_SCENE_FILE`; GrainfracError (one line) if what it names
    is not a file name."""
    name = state.get(SCENE_FILE_KEY, LEGACY_SCENE_FILE)
    if not isinstance(name, str) or not name or Path(name).name != name or name in (".", ".."):
        raise GrainfracError(f"{where}: the checkpoint's state file names no scene file ({SCENE_FILE_KEY} "
                             f"{name!r}); {RESTART_FIX}")
    return name


def check_files(where) -> None:
    """GrainfracError (one line naming the file) if checkpoint folder ``where`` has a state file that is not JSON,
    an arrays file that numpy cannot read whole, or a scene that is neither a complete gzip stream (YADE's) nor an npz
    numpy can read whole (the static engines'): checked
    before YADE is loaded and before anything is written.  Reads every file once (the scene's gzip stream to its
    end: about a second per 100 MB)."""
    where = Path(where)
    fix = RESTART_FIX
    try:
        state = json.loads((where / CHECKPOINT_STATE).read_text())
        if not isinstance(state, dict):
            raise ValueError("not a JSON object")
    except (OSError, ValueError) as exc:
        raise GrainfracError(f"{where}: the checkpoint's state file ({where.name}/{CHECKPOINT_STATE}) is unreadable "
                             f"(not the JSON this code writes: garbage or truncated; {type(exc).__name__}); "
                             f"{fix}") from None
    try:
        with np.load(where / ARRAYS_FILE) as data:
            for k in data.files:
                data[k]
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise GrainfracError(f"{where / ARRAYS_FILE}: the checkpoint's arrays are unreadable "
                             f"(truncated or not numpy's npz; {type(exc).__name__}: {exc}); {fix}") from None
    scene = where / scene_file_of(state, where)
    try:
        with open(scene, "rb") as fh:
            npz = fh.read(len(ZIP_MAGIC)) == ZIP_MAGIC
    except OSError:
        npz = False         # a missing or unreadable file: the check below names it
    if npz:                 # a static engine's scene: numpy's npz (zip), read whole as the arrays are
        try:
            with np.load(scene) as data:
                for k in data.files:
                    data[k]
        except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
            raise GrainfracError(f"{scene}: the checkpoint's static scene is unreadable (truncated npz; "
                                 f"{type(exc).__name__}: {exc}); {fix}") from None
        return
    try:
        with gzip.open(scene, "rb") as fh:
            while fh.read(1 << 24):
                pass
    except (OSError, EOFError, zlib.error) as exc:
        raise GrainfracError(f"{scene}: the checkpoint's scene is unreadable (truncated "
                             f"gzip or not a YADE scene; {type(exc).__name__}: {exc}); {fix}") from None
