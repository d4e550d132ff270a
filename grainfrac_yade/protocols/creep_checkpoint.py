"""A creep run's own state beside the engine's scene at a checkpoint (:mod:`.checkpoints`): what :func:`capture`
writes of a :class:`grainfrac_yade.protocols.creep.CreepRun` at a safe point and :func:`restore` loads into a run
freshly built from the same specimen and parameters (:func:`grainfrac_yade.protocols.creep.resume_creep`)."""
from __future__ import annotations

import time

import numpy as np

from ..clocks import EventClock, PaperClock
from ..runs.columns import history_as_today
from ..wave import HoldBudget
from .checkpoints import START_TABLE, base_state, platen_state, restore_platens, restore_scene, scene_arrays


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
        servo = pl.resume_hold(s)
        run.servo = servo
        # checkpoints written before the hold budget had wave crossings held the fixed step counts
        run.hold_budget = (HoldBudget.from_dict(s["hold_budget"]) if "hold_budget" in s
                           else HoldBudget.fixed(run.params.creep))
    if state["corrosion"] is not None:
        run.corr = run.engine.stress_corrosion(
            sc, run.params.stress_corrosion,
            {"creep_time": state["corrosion"]["creep_time"], "restored": state["corrosion"].get("restored", []),
             **{k: arrays[k] for k in ("tensile_strength_pa", "cohesion_pa", "area_fraction")}})
    if state["clock"] is not None:
        kind = state["clock"].get("kind")
        run.clock = (EventClock if kind == EventClock.KIND else PaperClock).from_state(state["clock"])
    columns = state["start_table_columns"]
    run.initial_bond_stresses = None if columns is None else {k: arrays[START_TABLE + k] for k in columns}
    return state["phase"], state["loop"]
