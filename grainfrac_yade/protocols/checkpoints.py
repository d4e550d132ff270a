"""Checkpoints of long runs (creep, UCS and Brazilian tests) and resuming from them (``--resume DIR``), for
any engine: the engine saves and restores its scene (:meth:`grainfrac_yade.engines.Scene.save`,
``restore_checkpoint``), this module writes and reads the rest.

A checkpoint is the folder ``DIR/checkpoint/`` (:data:`grainfrac_yade.runs.runio.CHECKPOINT`):

* the engine's scene, in the file the engine names (:attr:`grainfrac_yade.engines.EngineModule.scene_file`,
  recorded in ``state.json``): ``scene.yade.gz`` for YADE (``O.save``, YADE's binary archive, gzip'd: exact
  doubles), ``scene.npz`` for the static and hybrid engines; a checkpoint written before the engines named theirs
  has its scene in ``scene.yade.gz`` whatever the engine (:data:`grainfrac_yade.runs.runio.LEGACY_SCENE_FILE`);
* ``arrays.npz``: the driver's per-bond arrays (bookkeeping of breaks; creep: the degradation law's
  state: strengths J^T, J^C of paper Eq. 7 or area fractions, break and macrocrack times, the bond
  stresses at the start of creep; UCS and Brazilian: the history so far and the snapshot at the peak);
* ``state.json``: everything else (test, phase, clock state, servo and platen state, history rows so
  far, run values), written last.

It is written into ``checkpoint.tmp/``, each file flushed to disk, then renamed into place
(:meth:`Checkpointer.write`), so a kill at any moment leaves the previous checkpoint or the new
one, never a half-written one.

A checkpoint is taken only at a *safe point* of a driver, between DEM steps, where what the driver
does next depends on the saved state alone: creep: in the loading ramp (phase ``loading``, every
``numerics.checkpoint_interval`` s of wall time), at its end (``ramp``, always) and at the top of
each pass of the creep clock loops (``event``, ``paper``); UCS and Brazilian tests: before each
history row's DEM steps (``loading``).  Checking the wall clock and ``O.save`` change nothing in
the scene, so a checkpointed run computes what an unchecked one does (tested bit for bit).

What ``O.save`` / ``O.load`` keep, measured on YADE 2023.02a with one thread:

* kept: bodies (positions, velocities, orientations, blocked DOFs, masses), the real interactions
  with their geometry and JCFpm physics in their container order, the engines with their
  attributes (the law's crack counters), ``O.iter``, ``O.dt``, ``O.time``.  5000 DEM steps after
  ``O.load`` equal 5000 steps without it to the last bit;
* not kept: the force container (it reads zero after ``O.load`` until a step has run; forces
  put back with ``O.forces.addF`` act in the next step and change it: 1 step later the forces
  were about twice the uninterrupted run's), permanent forces (``setPermF``: the confinement's,
  set again), the collider's potential (not real) interactions (6 x 12 mm after the ramp: 242
  interactions before ``O.save``, 241 real ones after ``O.load``; they carry no force), and every
  Python handle: bodies, interactions and engines are new objects after ``O.load``.

So after ``O.load`` (:func:`restore_scene`) the bond, link and engine handles of the
:class:`~.scene.GrainScene` and the platens' (jaws') body handles are fetched anew, and the one
force the creep driver reads before the next step, the platens' reaction (the servo's input), is
restored from the state (:meth:`~.platens.Platens.rebind`); the Python-side state (servo, stress
corrosion, clock, history, loop counters) comes from ``state.json`` and ``arrays.npz``.
"""
from __future__ import annotations

import datetime as _dt
import json
import os
import shutil
import time
import zipfile
from pathlib import Path

import numpy as np

from ..errors import GrainfracError
from ..grains import grain_model
from ..runs.runio import (ARRAYS_FILE, CHECKPOINT, CHECKPOINT_OLD, CHECKPOINT_STATE, CHECKPOINT_TMP,  # noqa: F401
                          SCENE_FILE_KEY, check_files, checkpoint_folder, code_version, scene_file_of)
from ..runs.columns import HISTORY_RENAMED

#: Layout of state.json and arrays.npz; a checkpoint of another layout is refused.
FORMAT = 1
#: Safe points of each test's driver at which a checkpoint can be taken (the phase it resumes in);
#: a checkpoint without a ``test`` key is a creep run's (written before the other tests had any).
PHASES = {"creep": ("loading", "ramp", "event", "relaxation", "paper"), "ucs": ("loading",), "brazilian": ("loading",)}
#: Prefix of the initial bond-stress table's columns in arrays.npz.
START_TABLE = "start_"


def _json_value(value):
    """numpy scalars and arrays as JSON numbers and lists (floats keep every bit: JSON writes repr)."""
    if isinstance(value, (np.generic, np.ndarray)):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")


def _fsync(path):
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


class LoadingCheckpoints:
    """Checkpoints of a strain-controlled test (UCS, Brazilian): one is due before a history row's DEM
    steps (its :meth:`safe_point`), when the state is complete.  The test's runner calls
    :meth:`init_checkpoints` in its constructor; ``capture`` is the test's (state, arrays) writer."""

    def init_checkpoints(self, checkpoint_folder, params, run_values, progress, capture):
        self.checkpointer = None if checkpoint_folder is None else Checkpointer(
            checkpoint_folder, params.numerics.checkpoint_interval, run_values or {}, progress, capture=capture)
        #: the checkpoints this run went on from (DEM step, phase, when written)
        self.resumes = []
        #: a VTK series (:class:`.snapshots.StrainSeries`) told of each row and of the end (it only reads the scene); None: no VTK
        self.snapshot = None

    def safe_point(self):
        """Before a history row's DEM steps: the state is complete; a checkpoint if one is due."""
        ck = self.checkpointer
        if ck is not None and self.scene.steps > 0 and ck.due():
            ck.write(self, "loading", {})


class Checkpointer:
    """Writes the checkpoints of one run into ``run_folder/checkpoint/``.

    ``interval``: wall time between checkpoints [s] (``numerics.checkpoint_interval``); 0: none but
    those the driver forces (a creep run's at the end of its ramp).  ``run_values``: what besides the
    parameters makes the run (seed, load), stored so that a batch rerun can tell whether the
    checkpoint continues its row.  ``capture(run, phase, loop, run_values, code_version)`` gives
    (state, arrays) of the run (each test has its own).
    """

    def __init__(self, run_folder, interval: float, run_values: dict, progress=None, capture=None):
        self.capture = capture
        self.folder = Path(run_folder)
        self.interval = float(interval)
        self.run_values = dict(run_values)
        self.progress = progress or (lambda msg: None)
        self.code_version = code_version()
        self.last = time.monotonic()
        #: wall time [s] and size [bytes] of each checkpoint written
        self.write_s, self.sizes = [], []

    def due(self) -> bool:
        return self.interval > 0 and time.monotonic() - self.last >= self.interval

    def write(self, run, phase: str, loop: dict):
        """Checkpoint ``run`` at a safe point of ``phase`` with the loop's counters ``loop``."""
        t0 = time.monotonic()
        tmp, final, old = (self.folder / n for n in (CHECKPOINT_TMP, CHECKPOINT, CHECKPOINT_OLD))
        try:
            shutil.rmtree(tmp, ignore_errors=True)
            tmp.mkdir(parents=True)
            state, arrays = self.capture(run, phase, loop, self.run_values, self.code_version)
            scene_file = state[SCENE_FILE_KEY] = run.engine.scene_file   # the engine's name for its scene's file
            run.scene.save(tmp / scene_file)
            with open(tmp / ARRAYS_FILE, "wb") as fh:
                np.savez(fh, **arrays)
            text = json.dumps(state, indent=1, default=_json_value) + "\n"
            for name in (scene_file, ARRAYS_FILE):
                _fsync(tmp / name)
            (tmp / CHECKPOINT_STATE).write_text(text)   # last, once the rest is on disk: marks it complete
            _fsync(tmp / CHECKPOINT_STATE)
            _fsync(tmp)
            shutil.rmtree(old, ignore_errors=True)
            if final.exists():
                os.replace(final, old)
            os.replace(tmp, final)
            _fsync(self.folder)
            shutil.rmtree(old, ignore_errors=True)
        except (OSError, RuntimeError, TypeError, ValueError) as exc:   # an aid: the run goes on without it
            self.progress(f"checkpoint not written ({type(exc).__name__}: {exc}); the run goes on")
            return
        finally:
            self.last = time.monotonic()
        self.write_s.append(time.monotonic() - t0)
        self.sizes.append(sum(p.stat().st_size for p in final.iterdir()))


def base_state(test: str, run, phase: str, loop: dict, run_values: dict, version: str) -> dict:
    """The keys of state.json every test writes (``run``: has ``scene``, ``t0`` and ``c0``)."""
    sc = run.scene
    return {"format": FORMAT, "test": test, "phase": phase, "loop": dict(loop), "run_values": run_values,
            "code_version": version, "written": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
            "dem_steps": int(sc.steps), "wall_s": time.time() - run.t0, "cpu_s": time.process_time() - run.c0,
            "scene": sc.checkpoint_state()}


def scene_arrays(scene) -> dict:
    """The scene's bond bookkeeping for arrays.npz."""
    return {"broken": scene.broken, "break_mode": scene.break_mode, "break_step": scene.break_step}


def platen_state(platens) -> dict:
    return platens.state_dict()


def read(run_folder, test: str = "creep") -> tuple:
    """(checkpoint folder, state, arrays) of the ``test`` run in ``run_folder``; GrainfracError if it has
    none or it is bad."""
    where = checkpoint_folder(run_folder)
    if where is None:
        raise GrainfracError(f"{run_folder}: no checkpoint to resume from ({CHECKPOINT}/ missing: the run stopped "
                             "before its first checkpoint, or was started by code without checkpoints); fix: start "
                             "it again with --overwrite")
    try:
        state = json.loads((where / CHECKPOINT_STATE).read_text())
        with np.load(where / ARRAYS_FILE) as data:
            arrays = {k: data[k] for k in data.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise GrainfracError(f"{where}: checkpoint unreadable ({type(exc).__name__}: {exc}); fix: start the run "
                             "again with --overwrite") from None
    if state.get("format") != FORMAT or state.get("phase") not in PHASES.get(state.get("test", "creep"), ()):
        raise GrainfracError(f"{where}: checkpoint of another layout (format {state.get('format')!r}, this code "
                             f"reads {FORMAT}); fix: resume it with the code that wrote it, or start the run again "
                             "with --overwrite")
    if state.get("test", "creep") != test:
        raise GrainfracError(f"{where}: checkpoint of a {state.get('test', 'creep')} run, not of a {test} run; fix: "
                             f"resume it with the {state.get('test', 'creep')} command")
    return where, state, arrays


def history_arrays(arrays: dict, prefix: str, columns) -> dict:
    """The history columns a checkpoint's arrays.npz holds under ``prefix``, by today's names (older checkpoints
    hold some under their old names, :data:`grainfrac_yade.runs.columns.HISTORY_RENAMED`)."""
    old = {new: name for name, new in HISTORY_RENAMED.items() if prefix + name in arrays}
    return {k: arrays[prefix + (k if prefix + k in arrays else old[k])].tolist() for k in columns}


def restore_scene(sc, where, state: dict, arrays: dict, confinement=None):
    """Replace scene ``sc`` (freshly built from the same specimen and parameters) by the checkpoint's
    (:meth:`Scene.restore_checkpoint`) with its bond bookkeeping; ``confinement``: the side-wall forces
    set again (None: unconfined)."""
    sc.restore_checkpoint(where, where / scene_file_of(state, where), state["scene"], arrays, confinement)


def restore_platens(pl, p: dict):
    """After :func:`restore_scene`: the platens (:class:`grainfrac_yade.engines.PlatenDrive`) as the checkpoint
    saved them (:meth:`~grainfrac_yade.engines.PlatenDrive.restore_state`)."""
    pl.restore_state(p)



def inexact_note(params) -> str:
    """"" if a resume of a run with ``params`` is bit-identical to the uninterrupted run (one thread), else why not."""
    return grain_model(params.resolution.grain_model).resume_note


def resume_record(state: dict) -> dict:
    """What a summary's ``resumed_from`` lists for the checkpoint ``state``."""
    out = {"dem_steps": state["dem_steps"], "phase": state["phase"], "checkpoint_written": state["written"]}
    if "creep_time_s" in state:
        out["creep_time_s"] = state["creep_time_s"]
    return out
