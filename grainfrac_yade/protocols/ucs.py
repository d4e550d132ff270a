"""Strain-controlled uniaxial compression between rigid platens (the UCS of paper section 3.1), or
confined (biaxial) compression with ``confinement.stress`` sigma_3 > 0 on the side walls
(the engine's ``consolidate``: isotropic stage to sigma_1 = sigma_3 first, then the same axial loading; the
post-peak stop rule then applies to the deviator sigma_1 - sigma_3).  Written against the scene interface
(:class:`grainfrac_yade.engines.Scene`): any engine runs it.

The test ends once the axial stress falls below ``ucs.stop_stress_ratio`` of its peak (past
``ucs.stop_min_strain`` of axial strain) with bonds
broken since the peak (post-peak; a drop without a break is elastic ringing, e.g. of a one-cell-wide
column set in motion from rest: measured 3.4 MPa then below 2.4 MPa, no bond broken), or at ``ucs.max_strain`` (then the largest stress so far is only a lower bound of the strength), or
on a numerical failure (NaN or infinite measures, a DEM step above the critical one): no result.
The result dict says which in ``end_reason`` (and ``peak_reached``, ``numerical_failure``).

Checkpoints (given a run folder, :mod:`.checkpoints`): every ``numerics.checkpoint_interval`` s of
wall time, before a history row's steps; :func:`resume_ucs` goes on from the last one and
computes what the uninterrupted test would have, bit for bit (one thread).
"""

from __future__ import annotations

import time

import numpy as np

from ..engines.registry import engine_for
from ..errors import NumericalFailure
from ..post_peak import softened_past_peak
from .checkpoints import (LoadingCheckpoints, base_state, history_arrays, inexact_note, platen_state, read,
                          restore_platens, restore_scene, resume_record, scene_arrays)
from ..kernel.confinement import broken_apart_reason
from ..kernel.cracks import broken_counts
from .loading import LoadingTest

#: Columns of a UCS history.
HISTORY_COLUMNS = ("step", "time_s", "axial_strain", "lateral_strain", "axial_stress_pa", "broken_total",
                   "broken_tensile", "broken_shear", "broken_inter", "broken_intra")
#: Prefix of the history columns in a checkpoint's arrays.npz.
HISTORY_ARRAY = "history_"


class UcsRun(LoadingCheckpoints, LoadingTest):
    """State of one compression test: scene, platens, history so far, peak so far."""

    strain_column = "axial_strain"

    def __init__(self, specimen, params, progress=None, scene=None, checkpoint_folder=None, run_values=None):
        self.t0, self.c0 = time.time(), time.process_time()
        self.params, self.progress = params, progress
        #: the engine of ``params`` (``numerics.engine``): builds the scene, brings a confined specimen to sigma_3
        self.engine = engine_for(params)
        self.scene = scene = scene or self.engine.build_scene(specimen, params)
        ucs = params.ucs
        self.platens = platens = scene.attach_platens(ucs.platen_lateral)
        # the post-peak rule is the test's: a relaxation with the platens held loses the load below it
        scene.lose_load_below(ucs.stop_stress_ratio)
        self.closing_speed = ucs.strain_rate * platens.height
        platens.set_axial_velocity(self.closing_speed)
        self.steps_per_row = max(1, int(round(ucs.record_strain_increment / (ucs.strain_rate * scene.dt))))
        self.cols = {k: [] for k in HISTORY_COLUMNS}
        self.peak, self.broken_at_peak = 0.0, 0
        self.peak_snapshot = (scene.broken.copy(), scene.break_mode.copy())
        self.confining = params.confinement.stress
        self.consolidation = {}
        #: side-wall forces of a confined test, made when the test starts (None: unconfined or not yet)
        self.confinement = None
        self.init_checkpoints(checkpoint_folder, params, run_values, progress, capture)
        #: True once restored from a checkpoint (:func:`resume_ucs`): loading goes on from it
        self.resumed = False

    def run(self):
        """Load to the end of the test; (history columns, result dict, scene, broken-at-peak snapshot)."""
        scene, platens, ucs, cols = self.scene, self.platens, self.params.ucs, self.cols
        confining = self.confining
        numerical, peak_reached = False, False
        broken_apart = ""   # why the specimen broke apart before the axial stage (confined tests), "" if not
        try:
            if confining > 0 and not self.resumed:
                self.confinement = scene.confine(confining)
                self.consolidation = self.engine.consolidate(scene, platens, confining, self.params)
                platens.set_axial_velocity(self.closing_speed)
                broken_apart = end = broken_apart_reason(scene, confining)
                if broken_apart and self.progress:
                    self.progress(end)
            while not broken_apart:
                self.safe_point()
                scene.run(self.steps_per_row)
                stress = platens.axial_stress()
                strain = platens.axial_strain()
                row = dict(step=scene.steps, time_s=scene.time, axial_strain=strain,
                           lateral_strain=platens.lateral_strain(), axial_stress_pa=stress, **broken_counts(scene))
                self.add_row(scene, row)
                if stress > self.peak:
                    self.peak, self.broken_at_peak = stress, row["broken_total"]
                    self.peak_snapshot = (scene.broken.copy(), scene.break_mode.copy())
                if self.progress and len(cols["step"]) % 50 == 0:
                    self.progress(f"strain {strain:.5f}  stress {stress / 1e6:7.1f} MPa  broken {row['broken_total']}")
                if softened_past_peak(stress - confining, self.peak - confining, row["broken_total"],
                                      self.broken_at_peak, ucs.stop_stress_ratio, strain, ucs.stop_min_strain):
                    peak_reached = True
                    end = (f"post-peak: the axial stress fell below {ucs.stop_stress_ratio:g} x its peak"
                           if confining == 0 else
                           f"post-peak: the deviator fell below {ucs.stop_stress_ratio:g} x its peak")
                    break
                if strain >= ucs.max_strain:
                    end = (f"axial strain reached ucs.max_strain = {ucs.max_strain:g} before the stress fell below "
                           f"{ucs.stop_stress_ratio:g} x its peak: the largest stress is a lower bound of the strength")
                    break
        except NumericalFailure as exc:
            numerical, end = True, self.numerical_end(exc)
        result = self.result(scene, broken_counts(scene), numerical, peak_reached, end,
                             failed_before_test=bool(broken_apart), confining_stress_pa=confining, **self.consolidation)
        return cols, result, scene, self.peak_snapshot


def capture(run, phase, loop, run_values, version="") -> tuple:
    """(state.json, arrays.npz) of UCS test ``run`` at a safe point."""
    state = {**base_state("ucs", run, phase, loop, run_values, version),
             "run": {"peak": run.peak, "broken_at_peak": run.broken_at_peak, "consolidation": run.consolidation,
                     "confined": run.confinement is not None, "rows": len(run.cols["step"]),
                     "resumes": run.resumes},
             "platens": platen_state(run.platens)}
    arrays = {**scene_arrays(run.scene), "peak_broken": run.peak_snapshot[0], "peak_break_mode": run.peak_snapshot[1]}
    arrays.update({HISTORY_ARRAY + k: np.asarray(v) for k, v in run.cols.items()})
    return state, arrays


def restore(run, where, state, arrays):
    """Load the checkpoint ``where`` into ``run`` (a :class:`UcsRun` freshly built from the same specimen
    and parameters)."""
    r = state["run"]
    if r["confined"]:
        run.confinement = run.scene.confine(run.confining)   # its forces, set again after the scene is restored
    restore_scene(run.scene, where, state, arrays, run.confinement)
    restore_platens(run.platens, state["platens"])
    run.peak, run.broken_at_peak, run.consolidation = r["peak"], r["broken_at_peak"], r["consolidation"]
    run.peak_snapshot = (np.array(arrays["peak_broken"]), np.array(arrays["peak_break_mode"]))
    run.cols = history_arrays(arrays, HISTORY_ARRAY, HISTORY_COLUMNS)
    run.t0 = time.time() - state["wall_s"]
    run.c0 = time.process_time() - state["cpu_s"]
    run.resumes = r["resumes"] + [resume_record(state)]
    run.resumed = True


def run_ucs(specimen, params, progress=None, scene=None, checkpoint_folder=None, run_values=None, snapshot=None):
    """Run the test; return (history columns, result dict, scene, broken-at-peak snapshot).

    The history holds only finite rows (a row with a NaN or infinite value ends the run as a
    numerical failure instead).  ``checkpoint_folder``: the run folder, checkpoints go to its
    ``checkpoint/`` (None: none); ``run_values``: stored with them (seed).  ``snapshot``: a
    :class:`.snapshots.StrainSeries` (VTK files, timestep the axial strain), None: no VTK output.
    """
    run = UcsRun(specimen, params, progress, scene, checkpoint_folder, run_values)
    run.snapshot = snapshot
    return run.run()


def resume_ucs(specimen, params, run_folder, progress=None, run_values=None):
    """Go on with the UCS test whose checkpoint is in ``run_folder`` (same specimen and parameters as the
    test that wrote it); returns what :func:`run_ucs` returns.  GrainfracError if there is no usable
    checkpoint."""
    where, state, arrays = read(run_folder, "ucs")
    run = UcsRun(specimen, params, progress, checkpoint_folder=run_folder,
                 run_values=run_values if run_values is not None else state.get("run_values"))
    restore(run, where, state, arrays)
    if progress:
        progress(f"resumed from the checkpoint at DEM step {state['dem_steps']} ({len(run.cols['step'])} "
                 "history rows)")
        if inexact_note(params):
            progress(f"note: not bit-identical: {inexact_note(params)}")
    return run.run()
