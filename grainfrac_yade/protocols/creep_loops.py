"""The two creep clocks' loops over a held specimen (pure numpy; no YADE).

A *holder* is the creep run the loops drive (:class:`grainfrac_yade.protocols.creep.CreepRun`):
``relax(creep_time, safe_point=None, resume=None) -> bool`` (steps to equilibrium at the held load; ``safe_point(counters)`` is called between its checks, ``resume`` goes on from such counters), ``record_now``,
``mark_breaks``, ``check_failure``, ``unbalanced(mean_bond_force) -> (largest, relative)``,
``progress``, ``safe_point(phase, counters)`` (a checkpoint if one is due), ``platens``, ``servo``
(None without a stress servo), ``failed``, ``failure_reason`` and ``last_relaxation_steps``.  The
bonds are an engine's stress-corrosion bond writer (its ``stress_corrosion`` hook; YADE's
:class:`grainfrac_yade.engines.yade.corrosion_engine.StressCorrosion`, a
:class:`grainfrac_yade.kernel.corrosion.BondCorrosion`): its law, state, stresses and writes; its
``scene`` is an engine's :class:`grainfrac_yade.engines.Scene` (``run``, ``broken``, ``specimen``).  The law is not here: :func:`grainfrac_yade.law.creep_step`
(event clock) and the law's ``degrade`` (paper clock, through the engine).  The paper clock's
unbalanced force needs a dynamic engine (one with inertia).
"""
from __future__ import annotations

import numpy as np

from ..errors import NumericalFailure
from ..kernel.held_relaxation import collapse_watch, collapsing
from ..law import creep_step

#: Length of a UDEC 2D model's out-of-plane unit [m]: the paper's absolute F_u threshold (100 N)
#: is per metre of thickness; it is scaled by the layer thickness here.
UDEC_UNIT_THICKNESS = 1.0
#: Events between progress lines.
PROGRESS_EVERY = 20
#: Event clock: creep intervals of length 0 in a row that break no bond (a bond handed over at its
#: failure point that the contact law does not break) before the run ends as a numerical failure.
MAX_STALLED_INTERVALS = 10


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
    that, collapse (:class:`~grainfrac_yade.kernel.held_relaxation.CollapseWatch`, checked every
    ``engine_period`` DEM steps) ends the run when ``creep.collapse_strain_increment`` > 0 and the holder
    has a stress servo (``holder.servo`` not None).  ``sc``, ``cp``: the ``[stress_corrosion]`` and
    ``[creep]`` parameters.

    F_u is the largest resultant force on a free cell; ``absolute`` compares it, per metre of
    thickness as in UDEC 2D, with the threshold (100 N); ``relative`` uses the mean resultant over
    the mean bond force.  With ``engine_period`` k > 1 the k steps share the F_u of the last one.
    While F_u is at or above the threshold the law is applied every ``unbalanced_engine_period`` DEM
    steps instead (the step then sits at dt_min: the steps add k x dt_min of creep time).
    """
    scale = corr.scene.specimen.thickness / UDEC_UNIT_THICKNESS
    safe_point = holder.safe_point
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
    if servo is not None:
        watch = collapse_watch(cp, holder.platens.axial_strain(), (resume or {}).get("collapse"))
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
