"""A creep run that times itself, for the ``bench`` command: its ramp, its relaxations and the clock's work
between them (wall time only; the DEM steps taken are the run's own)."""
from __future__ import annotations

import statistics
import time

from .creep import CreepRun


class TimedCreepRun(CreepRun):
    """A creep run that times its ramp and relaxations, stops after ``max_events`` event-clock intervals
    (None: runs to the end, as a creep run), then measures the held scene (``at_hold(run)``).

    Measuring after the events, not before, keeps the events independent of the timing: the
    timing windows' lengths follow the machine's speed and their DEM steps move the scene."""

    def __init__(self, specimen, params, target_stress, max_events=None, at_hold=None, progress=None):
        super().__init__(specimen, params, target_stress, progress=progress)
        self.max_events, self.at_hold = max_events, at_hold
        self.measured = None
        self.ramp_wall_s = self.hold_steps = None
        self.relaxations = []   # (DEM steps, wall s, reached equilibrium) after each event-clock interval
        self.clock_work = []    # wall s from the end of one relaxation to the start of the next (event clock)
        self._loop_calls = None  # relaxations inside the event-clock loop so far (None: not in it)
        self._last_end = None

    def ramp(self, resume=None):
        t = time.perf_counter()
        super().ramp(resume)
        self.ramp_wall_s = time.perf_counter() - t

    def run_event_clock(self, resume=None):
        self._loop_calls = 0
        super().run_event_clock(resume)
        if self.at_hold is not None:
            self.measured = self.at_hold(self)

    def relax(self, creep_time, safe_point=None, resume=None):
        start = time.perf_counter()
        ok = super().relax(creep_time, safe_point, resume)
        end = time.perf_counter()
        if self.hold_steps is None:
            self.hold_steps = self.last_relaxation_steps
        if self._loop_calls is None:
            return ok
        if self._loop_calls:   # the loop's first relaxation precedes its first interval
            self.clock_work.append(start - self._last_end)
            self.relaxations.append((self.last_relaxation_steps, end - start, ok))
        self._loop_calls += 1
        self._last_end = end
        if self.max_events is not None and len(self.relaxations) >= self.max_events:
            return False   # enough events timed (not a failure: ``failed`` stays as it is)
        return ok

    def event_costs(self) -> dict:
        """Relaxation DEM steps and wall time per event-clock interval that reached equilibrium, the
        clock's own work per interval, and the final wait of a run that failed."""
        done = [(steps, wall) for steps, wall, ok in self.relaxations if ok]
        out = {"n_events_timed": len(done)}
        if done:
            steps = [s for s, _ in done]
            out.update(relaxation_steps_median=statistics.median(steps), relaxation_steps_mean=statistics.mean(steps),
                       relaxation_steps_max=max(steps),
                       relaxation_wall_s_median=statistics.median(w for _, w in done),
                       clock_work_s_median=statistics.median(self.clock_work))
        failing = [steps for steps, _, ok in self.relaxations if not ok]
        if failing:
            out["final_relaxation_steps"] = failing[-1]
        return out
