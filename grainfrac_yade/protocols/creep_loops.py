"""The two creep clocks' loops over a held specimen (pure numpy; no YADE).

A *holder* is the creep run the loops drive (:class:`grainfrac_yade.protocols.creep.CreepRun`):
``relax(creep_time, safe_point=None, resume=None) -> bool`` (steps to equilibrium at the held load; ``safe_point(counters)`` is called between its checks, ``resume`` goes on from such counters), ``record_now``,
``mark_breaks``, ``check_failure``, ``unbalanced(mean_bond_force) -> (largest, relative)``,
``progress``, ``safe_point(phase, counters)`` (a checkpoint if one is due), ``platens``, ``servo``
(None without a stress servo), ``failed``, ``failure_reason`` and ``last_relaxation_steps``.  The
bonds are an engine's stress-corrosion bond writer (its ``stress_corrosion`` hook; YADE's
:class:`grainfrac_yade.engines.yade.corrosion_engine.StressCorrosion`, a :class:`.corrosion.BondCorrosion`):
its law, state, stresses and writes; its ``scene`` is an engine's :class:`grainfrac_yade.engines.Scene`
(``run``, ``broken``, ``specimen``).  The law is not here: :func:`grainfrac_yade.law.creep_step`
(event clock) and the law's ``degrade`` (paper clock, through the engine).  The paper clock's
unbalanced force needs a dynamic engine (one with inertia).
"""
from __future__ import annotations

import numpy as np

from ..errors import NumericalFailure
from ..law import creep_step

#: Length of a UDEC 2D model's out-of-plane unit [m]: the paper's absolute F_u threshold (100 N)
#: is per metre of thickness; it is scaled by the layer thickness here.
UDEC_UNIT_THICKNESS = 1.0
#: Events between progress lines.
PROGRESS_EVERY = 20
#: Event clock: creep intervals of length 0 in a row that break no bond (a bond handed over at its
#: failure point that the contact law does not break) before the run ends as a numerical failure.
MAX_STALLED_INTERVALS = 10


class CollapseWatch:
    """Collapse of a specimen under the held load, recognised from the stress servo.

    A servo saturated closing (its command clipped at +max speed) drives the platens together as
    fast as it may because the specimen carries less than the target stress; when that lasts while
    the axial strain grows by more than ``strain_increment``, the specimen is shortening without
    regaining the load: it has collapsed.  A transient stress drop after a break that the specimen
    recovers from ends the saturation before that, and any interruption starts the count again.

    Fed once per check with ``saturated`` (the servo was clipped closing on every DEM step since the
    previous check) and the axial strain at the check; :meth:`update` says whether collapse is
    reached.  A saturated stretch is measured from the strain at the check before its first
    saturated one (where the saturated DEM steps began).  ``strain_increment`` 0: criterion off.
    """

    def __init__(self, strain_increment: float, strain: float):
        self.strain_increment = float(strain_increment)
        #: axial strain at the previous check [1]
        self.previous = float(strain)
        #: axial strain where the current saturated stretch began [1]; None: not saturated
        self.start = None
        #: saturated checks in a row
        self.checks = 0

    @property
    def growth(self) -> float:
        """Axial strain gained in the current saturated stretch [1] (0 when not saturated)."""
        return 0.0 if self.start is None else self.previous - self.start

    def update(self, saturated: bool, strain: float) -> bool:
        """One check; True when the saturated stretch has gained more than ``strain_increment``."""
        if saturated:
            if self.start is None:
                self.start = self.previous
            self.checks += 1
        else:
            self.start, self.checks = None, 0
        self.previous = float(strain)
        return self.strain_increment > 0 and self.start is not None and self.growth > self.strain_increment

    def reason(self, steps_per_check: int) -> str:
        """The failure reason once collapse is reached."""
        return (f"collapse: servo at its closing speed limit for {self.checks * steps_per_check} DEM steps while "
                f"the axial strain grew by {self.growth:.6g} > collapse_strain_increment {self.strain_increment:g}")

    def state_dict(self) -> dict:
        return {"previous": self.previous, "start": self.start, "checks": self.checks}

    @classmethod
    def from_state(cls, strain_increment: float, state: dict) -> "CollapseWatch":
        watch = cls(strain_increment, state["previous"])
        watch.start, watch.checks = state["start"], int(state["checks"])
        return watch


def collapsing(servo, steps: int, stress_ratio: float) -> bool:
    """One check of :class:`CollapseWatch`: the servo closed the platens at its speed limit on each of the
    last ``steps`` DEM steps and the held stress is below ``stress_ratio`` x its target (the specimen
    carries a fraction of the load; a cascade it arrests keeps more)."""
    return servo.closing_clipped_steps >= steps and servo.stress < stress_ratio * servo.target


def event_clock_loop(holder, corr, clock, resume=None) -> int:
    """Event clock (ours): at equilibrium, one :func:`~grainfrac_yade.law.creep_step` under the frozen
    stresses (to the next bond failure, or the law's loss cap); write, hand over, relax; repeat.

    ``holder`` (see module doc) relaxes the scene (``relax(creep_time) -> bool``), records rows
    (``record_now``) and reports progress. Returns the number of events (intervals that ended in a
    failure).  Each pass starts at a safe point (``holder.safe_point("event", counters)``, a checkpoint if due),
    and the relaxation after each creep step has safe points between its checks (phase ``relaxation``: the
    interval's counters with the relaxation's own under ``relaxation``), so that a long relaxation (a
    collapse at paper size takes hours) can be resumed inside.  ``resume``: the counters of such a point, to
    go on from it (scene and clock restored).
    """
    safe_point = holder.safe_point
    pending = None
    if resume is None:
        n_events = stalled = 0
        ok = holder.relax(0.0)
        holder.record_now(0.0)   # also when that first relaxation fails: its cracks belong to the run
        if not ok:
            return n_events
    else:
        n_events, stalled = int(resume["n_events"]), int(resume["stalled"])
        if "relaxation" in resume:   # inside the relaxation after a creep step: the step is done
            pending = resume
    while True:
        if pending is None:
            safe_point("event", {"n_events": n_events, "stalled": stalled})
            broken_before = int(corr.scene.broken.sum())
            idx = corr.intact()
            stresses = corr.stresses(idx)
            step = creep_step(corr.law, clock, corr.state, stresses)
            if step.stalled:
                break
            corr.state = step.state
            corr.write(idx)
            if len(step.failing):
                corr.hand_over_failures(step.failing, stresses.normal[step.positions], stresses.shear[step.positions],
                                        step.modes)
                n_events += 1
            clock.advance(step.dt, step.failing)
            corr.creep_time = clock.creep_time
            interval = {"n_events": n_events, "stalled": stalled, "broken_before": broken_before,
                        "broke": bool(len(step.failing)), "zero_step": bool(step.dt == 0)}
            relaxation = None
        else:
            interval = {k: pending[k] for k in ("n_events", "stalled", "broken_before", "broke", "zero_step")}
            relaxation, pending = pending["relaxation"], None

        def relaxation_point(counters, interval=interval):
            safe_point("relaxation", {**interval, "relaxation": counters})

        ok = holder.relax(clock.creep_time, safe_point=relaxation_point, resume=relaxation)
        holder.record_now(clock.creep_time)
        if n_events % PROGRESS_EVERY == 0 and interval["broke"]:
            holder.progress(f"t {clock.creep_time:.4g} s  events {n_events}  broken "
                            f"{int(corr.scene.broken.sum())}  relaxation {holder.last_relaxation_steps} steps")
        if not ok or clock.finished:
            break
        stalled = (stalled + 1 if interval["zero_step"] and int(corr.scene.broken.sum()) == interval["broken_before"]
                   else 0)
        if stalled >= MAX_STALLED_INTERVALS:
            raise NumericalFailure(f"{stalled} creep intervals of length 0 in a row broke no bond (creep time "
                                   f"{clock.creep_time:.6g} s): a bond at its failure point that the contact law "
                                   "does not break")
    return n_events



def paper_clock_loop(holder, corr, clock, sc, cp, resume=None):
    """Paper clock (Eq. 8): every ``engine_period`` DEM steps advance creep time by the doubled or
    reset step and degrade all intact bonds for it (the law's degrade, paper Eq. 7 by default).

    Each pass starts at a safe point (``holder.safe_point("paper", counters)``, a checkpoint if
    due); ``resume``: the counters of such a point, to go on from it (scene and clock restored).

    One notion of balance: F_u below the clock's threshold (:meth:`PaperClock.balanced`) both
    doubles the step and resets the count of DEM steps without balance; more than
    ``creep.max_relaxation_steps`` such steps in a row is the failure "no equilibrium".  Before
    that, collapse (:class:`CollapseWatch`, checked every ``engine_period`` DEM steps) ends the run
    when ``creep.collapse_strain_increment`` > 0 and the holder has a stress servo (``holder.servo``
    not None).  ``sc``, ``cp``: the ``[stress_corrosion]`` and ``[creep]`` parameters.

    F_u is the largest resultant force on a free cell; ``absolute`` compares it, per metre of
    thickness as in UDEC 2D, with the threshold (100 N); ``relative`` uses the mean resultant over
    the mean bond force.  With ``engine_period`` k > 1 the k steps share the F_u of the last one.
    While F_u is at or above the threshold the law is applied every ``unbalanced_engine_period`` DEM
    steps instead (the step then sits at dt_min: the steps add k x dt_min of creep time).
    """
    scale = corr.scene.specimen.thickness / UDEC_UNIT_THICKNESS
    safe_point = holder.safe_point
    increment = cp.collapse_strain_increment
    unbalanced_period = sc.unbalanced_engine_period
    servo = holder.servo
    if resume is None:
        holder.record_now(0.0)
        applications, not_balanced_steps = 0, 0
        period = sc.engine_period
    else:
        applications, not_balanced_steps = int(resume["applications"]), int(resume["not_balanced_steps"])
        period = int(resume.get("period", sc.engine_period))
    watch = None
    if increment > 0 and servo is not None:
        saved = (resume or {}).get("collapse")
        watch = (CollapseWatch.from_state(increment, saved) if saved
                 else CollapseWatch(increment, holder.platens.axial_strain()))
    while True:
        counters = {"applications": applications, "not_balanced_steps": not_balanced_steps}
        if period != sc.engine_period:
            counters["period"] = period
        if watch is not None:
            counters["collapse"] = watch.state_dict()
        safe_point("paper", counters)
        corr.scene.run(period)
        # a bond breaks in these DEM steps because the last creep step took it past its failure point
        # (or its neighbours' did): it broke at the creep time that step reached, not at the next one;
        # the steps run after the last creep step too, so no bond ends the run past its failure point
        holder.mark_breaks(clock.creep_time)
        idx = corr.intact()
        if not len(idx):   # nothing left to corrode, and no bond force for the relative F_u
            if not holder.check_failure():
                holder.failed, holder.failure_reason = True, "every bond broken"
            break
        if clock.creep_time >= sc.creep_time_limit:
            break
        stresses = corr.stresses(idx)
        mean_force = float(np.mean(np.hypot(stresses.normal, stresses.shear) * corr.area0[idx]))
        f_max, rel = holder.unbalanced(mean_force)
        f_u = f_max / scale if sc.unbalanced_force_reference == "absolute" else rel
        dt_b = clock.advance_many([f_u] * period)
        corr.degrade(dt_b, stresses)
        applications += 1
        balanced = clock.balanced(f_u)
        not_balanced_steps = 0 if balanced else not_balanced_steps + period
        if applications % cp.record_period == 0:
            holder.record_now(clock.creep_time)
        if applications % (PROGRESS_EVERY * 100) == 0:
            holder.progress(f"t {clock.creep_time:.4g} s  step {clock.dt:.3g} s  F_u {f_u:.3g}  broken "
                            f"{int(corr.scene.broken.sum())}  applications {applications}")
        collapsed = watch is not None and watch.update(collapsing(servo, period, cp.collapse_stress_ratio),
                                                       holder.platens.axial_strain())
        if not holder.check_failure() and collapsed:
            holder.failed, holder.failure_reason = True, watch.reason(period)
        elif not holder.failed and not_balanced_steps > cp.max_relaxation_steps:
            holder.failed, holder.failure_reason = True, (
                f"no equilibrium at the held load (strain runs away): F_u at or above the paper clock's "
                f"threshold {clock.unbalanced_force_threshold:g} for {not_balanced_steps} DEM steps")
        if holder.failed:
            break
        period = sc.engine_period if balanced else unbalanced_period
    holder.record_now(clock.creep_time)
