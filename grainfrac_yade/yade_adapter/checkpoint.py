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

import time

import numpy as np

from ..clocks import EventClock, PaperClock
from ..protocols.checkpoints import (ARRAYS_FILE, FORMAT, PHASES, SCENE_FILE, START_TABLE, Checkpointer,  # noqa: F401
                                     LoadingCheckpoints, base_state, history_arrays, inexact_note, platen_state, read,
                                     restore_platens, restore_scene, resume_record, scene_arrays)
from ..protocols.columns import history_as_today
from ..wave import HoldBudget
from .corrosion_engine import StressCorrosion, add_stiffness_restorer
from .platens import StressServo


def rebind_scene(scene):
    """After ``O.load``: fetch the scene's bond and link interactions and its law and integrator anew."""
    scene.rebind()


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


def restore(run, where, state: dict, arrays: dict):
    """Load the checkpoint ``where`` into creep run ``run``, freshly built from the same specimen and
    parameters.

    Returns (phase, loop counters) for the driver to go on from.
    """
    sc, pl = run.scene, run.platens
    restore_scene(sc, where, state, arrays, run.confinement)
    restore_platens(pl, state["platens"])
    r = state["run"]
    run.rows = [history_as_today(row) for row in r["rows"]]   # rows of older checkpoints: dem_steps
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
