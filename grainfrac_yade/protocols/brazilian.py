"""Strain-controlled Brazilian disc test: diametral compression between two rigid jaws.

ISRM (1978) suggested method: a disc of diameter D and thickness t is loaded along a diameter
until it splits; its tensile strength is sigma_t = 2 P / (pi D t) at the peak load P
(:mod:`grainfrac_yade.analysis.brazilian_analysis`).

The jaws are cells of the disc, as the UCS test's platens are (the scene's ``attach_jaws``; YADE's:
:mod:`grainfrac_yade.engines.yade.jaws`): the cells whose
rim arc overlaps an arc of ``brazilian.loading_arc_deg`` about the top (bottom) end of the
vertical diameter move together at a constant speed along it, their rotation blocked, and across
it fixed (``platen_lateral = "fixed"``, the default: rough steel jaws, and no rigid rotation of
the disc left free) or free (smooth).  Rigid jaw cells make curved jaws of the disc's own radius
that grip the rim over the loaded arc: the load goes in through the same bonds (Table 2, series
stiffness) as everywhere else.  Why not two YADE wall or box bodies: the cells are spheres at the
cells' centroids, inside the rim; a wall would touch them there, not at the rim, over one point
per cell, with a sphere-wall contact law and stiffness foreign to Table 2, and it would need a
contact model of its own.  The jaws' arc is reported as realised (``loaded_arc_deg``: the union
of the jaw cells' rim arcs, wider than the nominal arc by up to a cell on each side).

Measures: load P = mean of the two jaws' reactions along the diameter [N] (force on the layer of
thickness t); diametral strain = jaw closure / D; horizontal strain = change of the distance
between the rim cells at the two ends of the horizontal diameter / D (compression positive, so
the disc's widening is negative, as the UCS test's lateral strain).

The test ends once the load falls below ``brazilian.stop_load_ratio`` of its peak (past
``brazilian.stop_min_strain`` of diametral strain) with bonds
broken since the peak (the split), or at ``brazilian.max_strain`` (the peak is then a lower
bound), or on a numerical failure (no result); ``end_reason`` says which.

Written against the scene interface (:class:`grainfrac_yade.engines.Scene`): any engine runs it.

Checkpoints (given a run folder, :mod:`.checkpoints`): every ``numerics.checkpoint_interval`` s of
wall time, before a history row's steps; :func:`resume_brazilian` goes on from the last one and
computes what the uninterrupted test would have, bit for bit (one thread).
"""
from __future__ import annotations

import math
import time

import numpy as np

from ..analysis.brazilian_analysis import splits, tensile_stress
from ..engines.registry import engine_for
from ..errors import NumericalFailure
from ..post_peak import softened_past_peak
from .checkpoints import (LoadingCheckpoints, base_state, history_arrays, read, restore_scene, resume_record,
                          scene_arrays)
from ..kernel.cracks import broken_counts
from ..kernel.levers import Levers, new_breaks
from .loading import LoadingTest

def crack_counts(scene) -> dict:
    """Bonds broken during the test by mode and kind (:func:`grainfrac_yade.kernel.cracks.broken_counts` without the
    slits of :mod:`grainfrac_yade.kernel.levers`, which are broken before loading)."""
    return broken_counts(scene, new_breaks(scene))


#: Columns of a Brazilian history.
HISTORY_COLUMNS = ("step", "time_s", "diametral_strain", "horizontal_strain", "load_n", "tensile_stress_pa",
                   "broken_total", "broken_tensile", "broken_shear", "broken_inter", "broken_intra")
#: Prefix of the history columns in a checkpoint's arrays.npz.
HISTORY_ARRAY = "history_"


class BrazilianRun(LoadingCheckpoints, LoadingTest):
    """State of one Brazilian test: scene, jaws, history so far, peak and snapshots so far."""

    strain_column = "diametral_strain"

    def __init__(self, specimen, params, progress=None, scene=None, levers=None, checkpoint_folder=None,
                 run_values=None, apply=True):
        self.t0, self.c0 = time.time(), time.process_time()
        self.params, self.progress = params, progress
        #: the engine of ``params`` (``numerics.engine``): builds the scene, applies the levers
        self.engine = engine = engine_for(params)
        self.scene = scene = scene or engine.build_scene(specimen, params)
        #: what the levers did (the engine's ``apply_levers``); ``apply`` False: a resumed test, whose
        #: checkpoint holds the levers' bonds and counts
        self.applied = engine.apply_levers(scene, levers or Levers(), specimen.seed) if apply else {}
        bz = params.brazilian
        self.jaws = jaws = scene.attach_jaws(math.radians(bz.loading_arc_deg), bz.platen_lateral)
        jaws.set_closing_speed(bz.strain_rate * jaws.diameter)
        self.steps_per_row = max(1, int(round(bz.record_strain_increment / (bz.strain_rate * scene.dt))))
        self.thickness = specimen.thickness
        self.cols = {k: [] for k in HISTORY_COLUMNS}
        self.peak, self.broken_at_peak = 0.0, 0
        self.peak_snapshot = (new_breaks(scene), scene.break_mode.copy())
        self.split_snapshot = None
        self.init_checkpoints(checkpoint_folder, params, run_values, progress, capture)

    def run(self):
        """Load to the end of the test; (history columns, result dict, scene, snapshot at the failure load)."""
        scene, jaws, bz, cols = self.scene, self.jaws, self.params.brazilian, self.cols
        numerical, peak_reached = False, False
        try:
            while True:
                self.safe_point()
                scene.run(self.steps_per_row)
                load = jaws.load()
                strain = jaws.diametral_strain()
                row = dict(step=scene.steps, time_s=scene.time, diametral_strain=strain,
                           horizontal_strain=jaws.horizontal_strain(), load_n=load,
                           tensile_stress_pa=float(tensile_stress(load, jaws.diameter, self.thickness)),
                           **crack_counts(scene))
                self.add_row(scene, row)
                if self.split_snapshot is None and splits(load, self.peak, row["broken_total"], self.broken_at_peak,
                                                          strain, bz.stop_min_strain):   # the failure load is behind us
                    self.split_snapshot = self.peak_snapshot
                if load > self.peak:
                    self.peak, self.broken_at_peak = load, row["broken_total"]
                    if self.split_snapshot is None:
                        self.peak_snapshot = (new_breaks(scene), scene.break_mode.copy())
                if self.progress and len(cols["step"]) % 50 == 0:
                    self.progress(f"strain {strain:.6f}  sigma {row['tensile_stress_pa'] / 1e6:6.2f} MPa  "
                                  f"broken {row['broken_total']}")
                if softened_past_peak(load, self.peak, row["broken_total"], self.broken_at_peak, bz.stop_load_ratio,
                                      strain, bz.stop_min_strain):
                    peak_reached = True
                    end = f"post-peak: the load fell below {bz.stop_load_ratio:g} x its peak"
                    break
                if strain >= bz.max_strain:
                    end = (f"diametral strain reached brazilian.max_strain = {bz.max_strain:g} before the load "
                           f"fell below {bz.stop_load_ratio:g} x its peak: the largest load is a lower bound of the "
                           "strength")
                    break
        except NumericalFailure as exc:
            numerical, end = True, self.numerical_end(exc)
        result = self.result(scene, crack_counts(scene), numerical, peak_reached, end, cpu=False,
                             jaw_cells=[len(jaws.top), len(jaws.bottom)], loaded_arc_deg=jaws.loaded_arc_deg,
                             **self.applied)
        return cols, result, scene, self.split_snapshot or self.peak_snapshot


def capture(run, phase, loop, run_values, version="") -> tuple:
    """(state.json, arrays.npz) of Brazilian test ``run`` at a safe point."""
    state = {**base_state("brazilian", run, phase, loop, run_values, version),
             "run": {"peak": run.peak, "broken_at_peak": run.broken_at_peak, "applied": run.applied,
                     "split": run.split_snapshot is not None, "rows": len(run.cols["step"]),
                     "resumes": run.resumes},
             "jaws": run.jaws.state_dict()}
    arrays = {**scene_arrays(run.scene), "peak_broken": run.peak_snapshot[0], "peak_break_mode": run.peak_snapshot[1]}
    if run.split_snapshot is not None:
        arrays.update(split_broken=run.split_snapshot[0], split_break_mode=run.split_snapshot[1])
    arrays.update({HISTORY_ARRAY + k: np.asarray(v) for k, v in run.cols.items()})
    return state, arrays


def restore(run, where, state, arrays):
    """Load the checkpoint ``where`` into ``run`` (a :class:`BrazilianRun` freshly built from the same
    specimen and parameters, levers not applied: the checkpoint's scene holds them)."""
    restore_scene(run.scene, where, state, arrays)
    run.jaws.rebind(state["jaws"])
    r = state["run"]
    run.peak, run.broken_at_peak, run.applied = r["peak"], r["broken_at_peak"], r["applied"]
    run.peak_snapshot = (np.array(arrays["peak_broken"]), np.array(arrays["peak_break_mode"]))
    run.split_snapshot = ((np.array(arrays["split_broken"]), np.array(arrays["split_break_mode"])) if r["split"]
                          else None)
    if r["split"] and all(np.array_equal(a, b) for a, b in zip(run.split_snapshot, run.peak_snapshot)):
        run.split_snapshot = run.peak_snapshot   # the same snapshot, as in the uninterrupted run
    run.cols = history_arrays(arrays, HISTORY_ARRAY, HISTORY_COLUMNS)
    run.t0 = time.time() - state["wall_s"]
    run.c0 = time.process_time() - state["cpu_s"]
    run.resumes = r["resumes"] + [resume_record(state)]


def run_brazilian(specimen, params, progress=None, scene=None, levers=None, checkpoint_folder=None, run_values=None,
                  snapshot=None):
    """Run the test; return (history columns, result dict, scene, snapshot at the failure load).

    The snapshot (bonds broken, their modes) is taken at the failure load: the peak before the split
    (:func:`grainfrac_yade.analysis.brazilian_analysis.split_peak_index`, the same rows), else at the largest
    load.  ``levers``: :class:`grainfrac_yade.kernel.levers.Levers` applied to the scene before loading (None: none).
    Broken counts and the snapshot leave out slits.  ``checkpoint_folder``: the run folder,
    checkpoints go to its ``checkpoint/`` (None: none); ``run_values``: stored with them (seed, levers).
    ``snapshot``: a :class:`.snapshots.StrainSeries` (VTK files, timestep the diametral strain; it only
    reads the scene), None: no VTK output.
    """
    run = BrazilianRun(specimen, params, progress, scene, levers, checkpoint_folder, run_values)
    run.snapshot = snapshot
    return run.run()


def resume_brazilian(specimen, params, run_folder, progress=None):
    """Go on with the Brazilian test whose checkpoint is in ``run_folder`` (same specimen and parameters as
    the test that wrote it); returns what :func:`run_brazilian` returns.  GrainfracError if there is no
    usable checkpoint."""
    where, state, arrays = read(run_folder, "brazilian")
    run = BrazilianRun(specimen, params, progress, checkpoint_folder=run_folder, run_values=state.get("run_values"),
                       apply=False)
    restore(run, where, state, arrays)
    if progress:
        progress(f"resumed from the checkpoint at DEM step {state['dem_steps']} ({len(run.cols['step'])} "
                 "history rows)")
    return run.run()
