"""The held-load relaxation loop, written once for every engine (pure; no engine, no test protocol).

A specimen under a held load (the platens' stress servo, or the platens fixed where they are) is relaxed in DEM
steps until it rests, collapses or the budget runs out:

    while done < max_steps:
        (a safe point between chunks, the first excepted: the caller may checkpoint there)
        advance check_period DEM steps (the last chunk clipped to the budget where the engine asks so:
        a clipped chunk is not checked)
        the engine's bookkeeping of the chunk
        a failure of its own (a creep run's strain cap)          -> FAILED
        collapse (:class:`CollapseWatch`, the servo saturated)   -> COLLAPSE
        the load lost with the platens fixed (the UCS rule)      -> LOST_LOAD
        (after a take-back that gave out: wait 2^k checks)
        at rest (``balanced``), after ``min_steps``, and taken back (``settle``) -> EQUILIBRIUM
    -> BUDGET

The checks run in that order at the end of every chunk of ``creep.check_period`` DEM steps; each engine implements
:class:`HeldRelaxing` (the steps and what it measures): the creep hold and the isotropic stage on YADE's scene
(:mod:`grainfrac_yade.protocols.creep`, :mod:`grainfrac_yade.engines.yade.confinement`), the static engine's
inertial dynamics (:mod:`grainfrac_yade.engines.static.inertial`) and the hybrid engine's dynamic stints
(:mod:`grainfrac_yade.engines.hybrid.stints`).  What an outcome means (a failed creep run, a stint's take-back, a
relaxed static state) is the caller's.
"""
from __future__ import annotations

from dataclasses import dataclass

#: Outcomes of :func:`relax_held` (the hybrid engine's stint log names them).
EQUILIBRIUM, FAILED, COLLAPSE, LOST_LOAD, BUDGET = "equilibrium", "failed", "collapse", "lost load", "budget"


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


def collapse_watch(creep_params, strain: float, saved: dict | None = None):
    """The :class:`CollapseWatch` of a hold from the axial strain ``strain`` on (``saved``: its state at a
    checkpoint), or None where ``creep.collapse_strain_increment`` is 0 (criterion off)."""
    increment = creep_params.collapse_strain_increment
    if not increment > 0:
        return None
    return CollapseWatch.from_state(increment, saved) if saved else CollapseWatch(increment, strain)


def collapsing(servo, steps: int, stress_ratio: float) -> bool:
    """One check of :class:`CollapseWatch`: the servo closed the platens at its speed limit on each of the
    last ``steps`` DEM steps and the held stress is below ``stress_ratio`` x its target (the specimen
    carries a fraction of the load; a cascade it arrests keeps more)."""
    return servo.closing_clipped_steps >= steps and servo.stress < stress_ratio * servo.target


class HeldRelaxing:
    """What :func:`relax_held` drives: an engine's specimen under a held load.  ``advance`` is required; the rest
    default to a hold that only rests (no failure of its own, no lost load, every rest taken back)."""

    #: the stress servo that :func:`collapsing` reads (``stress``, ``target``, ``closing_clipped_steps``), where a
    #: collapse watch is given
    servo = None

    def advance(self, steps: int) -> None:
        """Run ``steps`` DEM steps."""
        raise NotImplementedError

    def checked(self, done: int) -> None:
        """Bookkeeping after a chunk, before its checks (``done``: DEM steps of the relaxation so far)."""

    def failure(self) -> str:
        """A failure of the engine's own ("" for none), checked first."""
        return ""

    def axial_strain(self) -> float:
        """The axial strain [1] (the collapse watch's measure)."""
        raise NotImplementedError

    def lost(self) -> bool:
        """The load lost with the platens fixed (no servo)."""
        return False

    def balanced(self) -> bool:
        """At rest under the held load."""
        raise NotImplementedError

    def settle(self) -> bool:
        """Take the rested state back (True), or not: the relaxation goes on (False: a take-back that gave out)."""
        return True


@dataclass
class HeldRelaxationEnd:
    """How :func:`relax_held` ended: ``outcome`` (:data:`EQUILIBRIUM`, :data:`FAILED`, :data:`COLLAPSE`,
    :data:`LOST_LOAD`, :data:`BUDGET`), the DEM steps of the relaxation (``steps``, a resumed one's included),
    ``reason`` (FAILED: the engine's; COLLAPSE: the watch's) and the take-backs that gave out (``gave_out``)."""

    outcome: str
    steps: int
    reason: str = ""
    gave_out: int = 0


def relax_held(relaxing: HeldRelaxing, max_steps: int, check_period: int, *, watch: CollapseWatch | None = None,
               collapse_stress_ratio: float = 0.0, min_steps: float = 0, done: int = 0, safe_point=None,
               clip_to_budget: bool = False) -> HeldRelaxationEnd:
    """Relax ``relaxing`` under its held load (module doc) in chunks of ``check_period`` DEM steps, at most
    ``max_steps`` (``clip_to_budget``: the last chunk ends at the budget, unchecked; else whole chunks).  ``watch``:
    the collapse criterion (None: off), fed with :func:`collapsing` of ``relaxing.servo`` below
    ``collapse_stress_ratio``; ``min_steps``: DEM steps before a rest may end it; ``done``: DEM steps already run
    (a resumed relaxation); ``safe_point(counters)``: called before each chunk but the first with the counters to
    resume from (``done``, the watch's state under ``collapse``).  After a rest not taken back (``settle`` False)
    the next rest is looked for 2^k checks later (the k-th in a row)."""
    gave_out, retry_at = 0, 0
    while done < max_steps:
        if safe_point is not None and done > 0:
            safe_point({"done": done, "collapse": None if watch is None else watch.state_dict()})
        chunk = min(check_period, max_steps - done) if clip_to_budget else check_period
        relaxing.advance(chunk)
        done += chunk
        if chunk < check_period:
            continue
        relaxing.checked(done)
        reason = relaxing.failure()
        if reason:
            return HeldRelaxationEnd(FAILED, done, reason, gave_out)
        if watch is not None and watch.update(collapsing(relaxing.servo, check_period, collapse_stress_ratio),
                                              relaxing.axial_strain()):
            return HeldRelaxationEnd(COLLAPSE, done, watch.reason(check_period), gave_out)
        if relaxing.lost():
            return HeldRelaxationEnd(LOST_LOAD, done, "", gave_out)
        if done < retry_at:
            continue
        if relaxing.balanced() and done >= min_steps:
            if relaxing.settle():
                return HeldRelaxationEnd(EQUILIBRIUM, done, "", gave_out)
            gave_out += 1
            retry_at = done + check_period * 2 ** gave_out
    return HeldRelaxationEnd(BUDGET, done, "", gave_out)
