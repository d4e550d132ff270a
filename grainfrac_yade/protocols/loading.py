"""What every strain-controlled test (UCS, Brazilian) does with a history row and at its end, written once.

A test's runner keeps its history as columns (``cols``), an optional VTK series (``snapshot``: told of
each row and of the end; it only reads the scene) and the checkpoints it went on from (``resumes``).
Each row is refused whole if one of its values is NaN or infinite (a DEM that blew up): the run then
ends as a numerical failure, with the rows before it kept and no result measured.
"""
from __future__ import annotations

import time

from ..errors import NumericalFailure
from ..kernel.equilibrium import check_value
from ..runs.columns import STEP, STEPS, STEPS_COUNTED_KEY, steps_counted


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
