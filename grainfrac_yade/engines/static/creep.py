"""A creep hold at constant platen stress on the static engine (pure).

The event clock of the YADE runs, fed by static stresses: the specimen is loaded along the path to the held
stress S (:meth:`.cascade.Path.hold`); then, repeatedly, the intact bonds' stresses (sigma = F_n / A0,
tau = |F_s| / A0) go to :func:`grainfrac_yade.law.creep_step` (paper Eq. 7 for the Hillig-Charles law: the
creep interval to the next bond failure under frozen stresses), the clock advances by it, the law's strengths
are written to the bonds, the failing bonds break one at a time with their cascade at the reached closure,
and the path regains S.  The specimen fails by the rule of :mod:`.failure`; the lifetime is the creep time then.

The ramp to S fails only by rule 1 of :mod:`.failure` (no equilibrium ahead: the path's peak lies below S);
the collapse strain applies to regaining S after an event, as in the YADE runs.

The paper's adaptive clock (Eq. 8) schedules dynamic relaxation steps; the static engine refuses it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...clocks import EventClock, PaperClock
from ...errors import GrainfracError, NumericalFailure
from ...law import Stresses, creep_step
from .cascade import Path
from .failure import FailureRule
from .solver import Equilibrium, State

PAPER_CLOCK_REFUSED = ("static engine: the paper's clock (Eq. 8) schedules dynamic relaxation steps; "
                       "fix: use the event clock (creep.clock = \"event\") or the YADE engine")


@dataclass
class CreepResult:
    failed: bool
    reason: str                 # failure reason, or why the hold ended without one
    lifetime: float             # creep time at the end [s]
    events: int
    broken: int
    times: list = field(default_factory=list)       # creep time of each event [s]
    strains: list = field(default_factory=list)     # axial strain after each event [1]
    broken_counts: list = field(default_factory=list)
    state: State | None = None
    numerical_failure: bool = False   # the solver gave up (never a failure of the specimen)


def creep_hold(eq: Equilibrium, law, clock, stress: float, rule: FailureRule, max_events: int = 10**6,
               path: Path | None = None) -> CreepResult:
    """Hold ``stress`` [Pa] on ``eq``'s network until it fails or the clock's time limit (module doc)."""
    if isinstance(clock, PaperClock) or not isinstance(clock, EventClock):
        raise GrainfracError(PAPER_CLOCK_REFUSED)
    res = CreepResult(False, "", clock.creep_time, 0, 0)
    try:
        return _hold(eq, law, clock, stress, rule, max_events, path or Path(eq), res)
    except NumericalFailure as exc:     # reported with what was reached; the lifetime is not a result
        res.numerical_failure, res.reason, res.lifetime = True, f"numerical failure: {exc}", clock.creep_time
        res.broken = int(res.state.broken.sum()) if res.state is not None else 0
        return res


def _hold(eq, law, clock, stress, rule, max_events, path, res):
    net = eq.net
    state, reason = path.hold(eq.initial(0.0), stress, FailureRule(0.0))   # the ramp: only "no equilibrium ahead"
    res.broken, res.state = int(state.broken.sum()), state
    if reason:
        res.failed, res.reason = True, "at load: " + reason
        return res
    bonds = law.initial_state(net.tensile_strength, net.cohesion, net.tan_friction)
    while res.events < max_events:
        intact = np.flatnonzero(~state.broken)
        if not len(intact):
            res.failed, res.reason = True, "every bond broken"
            break
        stresses = Stresses.of(intact, state.fn[intact] / net.area[intact], np.abs(state.fs[intact]) / net.area[intact])
        step = creep_step(law, clock, bonds, stresses)
        if step.stalled or not len(step.failing):
            if math.isfinite(step.dt) and step.dt > 0:
                clock.advance(step.dt)
            res.reason = "time limit" if clock.finished else "nothing can fail under the held stresses"
            break
        clock.advance(step.dt, step.failing)
        bonds = step.state
        jt, jc, _ = law.strengths(bonds)
        path.jt, path.jc = np.asarray(jt, float).copy(), np.asarray(jc, float).copy()
        state = path.cascade(state)
        state, reason = path.hold(state, stress, rule)
        res.events += 1
        res.state = state
        res.times.append(clock.creep_time)
        res.strains.append(state.closure / net.height)
        res.broken_counts.append(int(state.broken.sum()))
        if reason:
            res.failed, res.reason = True, reason
            break
    res.lifetime, res.broken, res.state = clock.creep_time, int(state.broken.sum()), state
    return res
