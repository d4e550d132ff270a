"""Checkpoints of long runs (creep, UCS and Brazilian tests) and resuming from them (``--resume DIR``).

A checkpoint is the folder ``DIR/checkpoint/`` (:data:`grainfrac_yade.runs.runio.CHECKPOINT`):

* ``scene.yade.gz``: the YADE scene (``O.save``, YADE's binary archive, gzip'd: exact doubles);
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

from ..clocks import EventClock, PaperClock
from ..errors import GrainfracError
from ..grains import grain_model
from ..runs.runio import (ARRAYS_FILE, CHECKPOINT, CHECKPOINT_OLD, CHECKPOINT_STATE, CHECKPOINT_TMP, SCENE_FILE,
                          check_files, checkpoint_folder, code_version)
from ..wave import HoldBudget
from .corrosion_engine import StressCorrosion, add_stiffness_restorer
from .platens import StressServo

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
        #: a :class:`.vtk_output.StrainSeries` told of each row and of the end (it only reads the scene); None: no VTK
        self.snapshot = None

    def safe_point(self):
        """Before a history row's DEM steps: the state is complete; a checkpoint if one is due."""
        ck = self.checkpointer
        if ck is not None and self.scene.O.iter > 0 and ck.due():
            ck.write(self, "loading", {})


class Checkpointer:
    """Writes the checkpoints of one run into ``run_folder/checkpoint/``.

    ``interval``: wall time between checkpoints [s] (``numerics.checkpoint_interval``); 0: none but
    those the driver forces (a creep run's at the end of its ramp).  ``run_values``: what besides the
    parameters makes the run (seed, load), stored so that a batch rerun can tell whether the
    checkpoint continues its row.  ``capture(run, phase, loop, run_values, code_version)`` gives
    (state, arrays) of the run (default: a creep run's, :func:`capture`).
    """

    def __init__(self, run_folder, interval: float, run_values: dict, progress=None, capture=None):
        self.capture = capture or globals()["capture"]
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
            run.scene.O.save(str(tmp / SCENE_FILE))
            with open(tmp / ARRAYS_FILE, "wb") as fh:
                np.savez(fh, **arrays)
            text = json.dumps(state, indent=1, default=_json_value) + "\n"
            for name in (SCENE_FILE, ARRAYS_FILE):
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
            "dem_steps": int(sc.O.iter), "wall_s": time.time() - run.t0, "cpu_s": time.process_time() - run.c0,
            "scene": {"n_bodies": len(sc.O.bodies), "n_bonds": sc.n_bonds, "cracks_seen": sc._cracks_seen,
                      "tens_seen": sc._tens_seen, "erased_by_sliding": sc.erased_by_sliding}}


def scene_arrays(scene) -> dict:
    """The scene's bond bookkeeping for arrays.npz."""
    return {"broken": scene.broken, "break_mode": scene.break_mode, "break_step": scene.break_step}


def platen_state(platens) -> dict:
    return {"velocity": platens.velocity, "y0_top": float(platens.y0_top), "y0_bottom": float(platens.y0_bottom),
            "x0_gap": float(platens.x0_gap), "reaction_pa": float(platens.axial_stress())}


def capture(run, phase: str, loop: dict, run_values: dict, version: str = "") -> tuple:
    """(state dict for state.json, arrays for arrays.npz) of creep run ``run`` at a safe point."""
    sc, pl = run.scene, run.platens
    state = {
        **base_state("creep", run, phase, loop, run_values, version),
        "creep_time_s": run.rows[-1]["creep_time_s"] if run.rows else 0.0,
        "run": {"rows": run.rows, "ramp_broken": run.ramp_broken, "failed": run.failed,
                "failure_reason": run.failure_reason, "failed_on_loading": run.failed_on_loading,
                "n_events": run.n_events, "vtk_times": run.vtk_times, "vtk_written": run.vtk_written,
                "vtk_merged": run.vtk_merged,
                "vtk_rows": run._vtk_rows, "vtk": run.vtk_folder is not None, "vtk_every": run.vtk_every,
                "last_relaxation_steps": run.last_relaxation_steps, "resumes": run.resumes,
                "consolidation": run.consolidation},
        "platens": platen_state(pl),
        "servo": None, "clock": None, "corrosion": None, "start_table_columns": None,
    }
    arrays = {**scene_arrays(sc), "break_time": run.break_time, "macro_time": run.macro_time}
    servo = run.servo
    if servo is not None:
        state["servo"] = {"target": servo.target, "gain": servo.gain, "max_speed": servo.max_speed,
                          "stress": float(servo.stress), "hold_budget": run.hold_budget.as_dict(),
                          "clipped": int(servo.clipped), "closing_clipped_steps": int(servo.closing_clipped_steps)}
    if run.corr is not None:
        corr = run.corr.state_dict()
        state["corrosion"] = {"creep_time": corr["creep_time"], "law": corr["law"], "restored": corr["restored"]}
        arrays.update(tensile_strength_pa=np.asarray(corr["tensile_strength_pa"]),
                      cohesion_pa=np.asarray(corr["cohesion_pa"]), area_fraction=np.asarray(corr["area_fraction"]))
    clock = run.clock
    if clock is not None:
        state["clock"] = clock.state_dict()
    if run.initial_bond_stresses is not None:
        state["start_table_columns"] = list(run.initial_bond_stresses)
        arrays.update({START_TABLE + k: np.asarray(v) for k, v in run.initial_bond_stresses.items()})
    return state, arrays


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


def rebind_scene(scene):
    """After ``O.load``: fetch the scene's bond and link interactions and its law and integrator anew."""
    from yade import wrapper as w
    O = scene.O
    body = scene.sphere_body

    def pairs(spheres):
        out = []
        for i, j in spheres:
            try:
                out.append(O.interactions[int(body[i]), int(body[j])])
            except (IndexError, KeyError, RuntimeError, ValueError):
                raise GrainfracError(f"checkpoint: no interaction between bodies {int(body[i])} and {int(body[j])} "
                                     "after O.load; fix: start the run again with --overwrite") from None
        return out

    scene.interactions = pairs(scene.layout.bond_spheres)
    loops = [e for e in O.engines if isinstance(e, w.InteractionLoop)]
    scene.law = next(f for f in loops[0].lawDispatcher.functors
                     if isinstance(f, w.Law2_ScGeom_JCFpmPhys_JointedCohesiveFrictionalPM))
    scene.newton = next(e for e in O.engines if isinstance(e, w.NewtonIntegrator))


def restore_scene(sc, where, state: dict, arrays: dict, confinement=None):
    """Replace scene ``sc`` (freshly built from the same specimen and parameters) by the checkpoint's
    (``O.load``), fetch its handles anew and restore its bond bookkeeping; ``confinement``: the
    :class:`.confinement.Confinement` whose permanent forces are set again (None: unconfined)."""
    O = sc.O
    n_bodies = len(O.bodies)
    if state["scene"]["n_bodies"] != n_bodies or state["scene"]["n_bonds"] != sc.n_bonds:
        raise GrainfracError(f"{where}: checkpoint of another scene ({state['scene']['n_bodies']} bodies, "
                             f"{state['scene']['n_bonds']} bonds; rebuilt: {n_bodies}, {sc.n_bonds}); fix: start the "
                             "run again with --overwrite")
    try:
        O.load(str(where / SCENE_FILE))
    except (RuntimeError, OSError, EOFError, ValueError) as exc:   # truncated or garbage: YADE's gzip/boost errors
        raise GrainfracError(f"{where / SCENE_FILE}: the checkpoint's scene is unreadable ({type(exc).__name__}: "
                             f"{exc}; truncated or not a YADE scene); fix: start the run again with --overwrite") from None
    rebind_scene(sc)
    if confinement is not None:
        confinement.apply()   # permanent forces are not saved with the scene
    sc.broken, sc.break_mode, sc.break_step = (np.array(arrays[k]) for k in ("broken", "break_mode", "break_step"))
    sc._cracks_seen, sc._tens_seen = state["scene"]["cracks_seen"], state["scene"]["tens_seen"]
    # checkpoints written before the count was kept: none was counted then
    sc.erased_by_sliding = state["scene"].get("erased_by_sliding", 0)
    if sc.law.nbTensCracks + sc.law.nbShearCracks != sc._cracks_seen:
        raise GrainfracError(f"{where}: the loaded scene's crack count ({sc.law.nbTensCracks + sc.law.nbShearCracks}) "
                             f"is not the checkpoint's ({sc._cracks_seen}); fix: start the run again with --overwrite")


def restore_platens(pl, p: dict):
    """After :func:`restore_scene`: the platens' body handles anew, their reference positions and speed."""
    pl.rebind(p["reaction_pa"])
    pl.velocity, pl.y0_top, pl.y0_bottom, pl.x0_gap = p["velocity"], p["y0_top"], p["y0_bottom"], p["x0_gap"]



def inexact_note(params) -> str:
    """"" if a resume of a run with ``params`` is bit-identical to the uninterrupted run (one thread), else why not."""
    return grain_model(params.resolution.grain_model).resume_note


def resume_record(state: dict) -> dict:
    """What a summary's ``resumed_from`` lists for the checkpoint ``state``."""
    out = {"dem_steps": state["dem_steps"], "phase": state["phase"], "checkpoint_written": state["written"]}
    if "creep_time_s" in state:
        out["creep_time_s"] = state["creep_time_s"]
    return out


def restore(run, where, state: dict, arrays: dict):
    """Load the checkpoint ``where`` into creep run ``run``, freshly built from the same specimen and
    parameters.

    Returns (phase, loop counters) for the driver to go on from.
    """
    sc, pl = run.scene, run.platens
    restore_scene(sc, where, state, arrays, run.confinement)
    restore_platens(pl, state["platens"])
    r = state["run"]
    run.rows = r["rows"]
    run.ramp_broken, run.failed, run.failure_reason = r["ramp_broken"], r["failed"], r["failure_reason"]
    run.failed_on_loading, run.n_events = r["failed_on_loading"], r["n_events"]
    run.vtk_times, run.vtk_written, run._vtk_rows = r["vtk_times"], r["vtk_written"], r["vtk_rows"]
    run.vtk_every = int(r.get("vtk_every", 0))   # older checkpoints: times only
    run.vtk_merged = r.get("vtk_merged", [])   # older checkpoints: none recorded
    run.last_relaxation_steps = r["last_relaxation_steps"]
    run.consolidation = r.get("consolidation", {})
    run.resumes = r["resumes"] + [{"dem_steps": state["dem_steps"], "creep_time_s": state["creep_time_s"],
                                   "phase": state["phase"], "checkpoint_written": state["written"]}]
    run.break_time, run.macro_time = np.array(arrays["break_time"]), np.array(arrays["macro_time"])
    run.t0 = time.time() - state["wall_s"]
    run.c0 = time.process_time() - state.get("cpu_s", 0.0)
    if state["servo"] is not None:
        s = state["servo"]
        # checkpoints written before the clip count was kept: counted from 0 again
        servo = StressServo.restored(pl, s["target"], s["gain"], s["max_speed"], s["stress"],
                                     s.get("clipped", 0), s.get("closing_clipped_steps", 0))
        run.servo = servo
        # checkpoints written before the hold budget had wave crossings held the fixed step counts
        run.hold_budget = (HoldBudget.from_dict(s["hold_budget"]) if "hold_budget" in s
                           else HoldBudget.fixed(run.params.creep))
        sc.drivers.append(servo)
    if state["corrosion"] is not None:
        corr = StressCorrosion(sc, run.params.stress_corrosion)
        corr.load_state({"creep_time": state["corrosion"]["creep_time"],
                         "restored": state["corrosion"].get("restored", []),
                         **{k: arrays[k] for k in ("tensile_strength_pa", "cohesion_pa", "area_fraction")}},
                        write=False)
        run.corr = corr
        sc.extras.append(corr)
        add_stiffness_restorer(sc, corr)
    if state["clock"] is not None:
        kind = state["clock"].get("kind")
        run.clock = (EventClock if kind == EventClock.KIND else PaperClock).from_state(state["clock"])
    columns = state["start_table_columns"]
    run.initial_bond_stresses = None if columns is None else {k: arrays[START_TABLE + k] for k in columns}
    return state["phase"], state["loop"]
