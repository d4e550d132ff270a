"""What every strain-controlled test (UCS, Brazilian) does with a history row and at its end, written once.

A test's runner keeps its history as columns (``cols``), an optional VTK series (``snapshot``: told of
each row and of the end; it only reads the scene) and the checkpoints it went on from (``resumes``).
Each row is refused whole if one of its values is NaN or infinite (a DEM that blew up): the run then
ends as a numerical failure, with the rows before it kept and no result measured.
"""
from __future__ import annotations

import math
import time

import numpy as np

from ..errors import NumericalFailure
from ..law import check_finite
from ..runs.columns import STEP, STEPS, STEPS_COUNTED_KEY, steps_counted

#: Bonds sampled for the mean bond force (every k-th of the given ones, k = len // this).
BOND_FORCE_SAMPLE = 500


def check_value(name, value, step):
    """NumericalFailure if a measured value is NaN or infinite."""
    if not math.isfinite(value):
        raise NumericalFailure(f"{name} is {value} at DEM step {step}")


def mean_bond_force(scene, bonds) -> float:
    """Mean magnitude of the bond force [N] over a sample of ``bonds`` (about BOND_FORCE_SAMPLE of
    them), the scale that unbalanced forces are measured against; 0 if there are none."""
    sample = bonds[:: max(1, len(bonds) // BOND_FORCE_SAMPLE)]
    fn, fs = scene.bond_forces(sample)
    check_finite("bond force", np.hypot(fn, fs), sample)
    return float(np.mean(np.hypot(fn, fs))) if len(sample) else 0.0


def relaxed(scene, bonds, creep_params) -> bool:
    """The scene's unbalanced force (:meth:`~grainfrac_yade.engines.Scene.unbalanced`: mean resultant force on the
    bodies the platens do not drive) over the mean force of ``bonds`` is below ``creep.equilibrium_tolerance``."""
    _, rel = scene.unbalanced(mean_bond_force(scene, bonds))
    return rel < creep_params.equilibrium_tolerance


def held_at_equilibrium(scene, servo, bonds, creep_params) -> bool:
    """A stress servo (the platens' ``hold_stress``) holds its target at equilibrium: the scene :func:`relaxed`,
    and the held stress within ``creep.stress_tolerance`` x the target.  NumericalFailure if a force or the stress
    is not finite."""
    balanced = relaxed(scene, bonds, creep_params)
    check_value("held axial stress", servo.stress, scene.steps)
    return balanced and abs(servo.stress - servo.target) < creep_params.stress_tolerance * servo.target


class LoadingTest:
    """The rows and the end of a strain-controlled test; ``strain_column``: the history column of its strain;
    ``engine``: the engine module that runs it (set by the test)."""

    strain_column = ""

    def add_row(self, scene, row: dict):
        """Append ``row`` to the history (NumericalFailure, and no row, if a value is not finite) and tell the
        VTK series."""
        for k, v in row.items():
            check_value(k, v, scene.steps)
        for k, v in row.items():
            self.cols[k].append(v)
        if self.snapshot is not None:
            self.snapshot.row(scene, len(self.cols[STEP]), row[self.strain_column])

    def numerical_end(self, exc: NumericalFailure) -> str:
        """The end reason of a numerical failure (told to the progress callback)."""
        end = f"numerical failure: {exc}"
        if self.progress:
            self.progress(end)
        return end

    def result(self, scene, counts: dict, numerical: bool, peak_reached: bool, end: str, cpu: bool = True,
               **extra) -> dict:
        """The result dict of the test (after the VTK series' last snapshot, unless it ended in a numerical
        failure): steps and what they count (``steps_counted``), the engine, wall (and CPU) time, the DEM step
        (``dem_timestep_s``; a static engine's load increment ``load_increment_s`` instead), bonds and ``counts``
        of broken ones, how it ended, then ``extra``, and the checkpoints it went on from."""
        cols = self.cols
        if self.snapshot is not None and cols[STEP] and not numerical:
            self.snapshot.write(scene, len(cols[STEP]), cols[self.strain_column][-1])
        result = {STEPS: int(scene.steps), "wall_s": time.time() - self.t0}
        if cpu:
            result["cpu_s"] = time.process_time() - self.c0
        engine = self.engine   # the engine of the run (an EngineModule: its name, whether it is dynamic)
        step = "dem_timestep_s" if engine.dynamic else "load_increment_s"
        result.update({STEPS_COUNTED_KEY: steps_counted(engine), "engine": engine.name,
                       step: scene.dt, "n_bonds": scene.n_bonds, **counts,
                       "numerical_failure": numerical, "bonds_erased_by_sliding": scene.sliding_erasures(),
                       "peak_reached": peak_reached, "end_reason": end, **extra})
        result.update(scene.summary_keys())
        if self.resumes:
            result["resumed_from"] = self.resumes
        return result
