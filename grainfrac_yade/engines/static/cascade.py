"""Bonds broken one at a time: the sequentially linear path in the platen closure (pure).

Between breaks the equilibrium is piecewise linear in the closure d (:mod:`.solver`).  From a converged state
the tangent response gives every intact bond's force along the path, F = F0 + x dF/dd, and so the closure
increment x at which it reaches its strength (paper Eq. 4-5, :func:`.contacts.crossing_increment`); the engine
moves to the smallest one (or to the held load, if that comes first) and solves there.  If contact statuses
changed on the way (the path bent), the closure where the first bond reaches its strength (or the load its
target) is bracketed (Illinois) until the largest stress-to-strength ratio is 1 within ``bracket_tol``.

There the most overstressed bond breaks, alone, and the equilibrium is restored at the same closure; any bond
now at its strength (its ratio within :data:`.ties.DECISION_REL_TOL` of 1) breaks next, the most overstressed first,
until none is (the cascade).  Ties: ratios within :data:`.ties.DECISION_REL_TOL` of the largest count as equal, and the
first bond in the network's canonical order (by contact point, rounded) wins (:func:`.ties.first_of_largest`), so
nothing depends on how the input numbered the bonds nor on the CPU's round-off.

Control: the closure only grows (a stiff machine).  A snap-back (the load falling while the closure would have to
fall too) is not followed: the stress drops at fixed closure through the cascade, and the curve continues from
there; the UCS is the largest platen stress on the path (no loading rate enters).  A held load (creep) is
regained after each event by the same path (:meth:`Path.hold`), with the failure rule of :mod:`.failure`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import NumericalFailure
from . import contacts as cl
from .face_failure import BondFailure
from .failure import COLLAPSE, NO_EQUILIBRIUM, FailureRule
from .solver import Equilibrium, State
from .teeth import tooth_release
from .ties import DECISION_REL_TOL, first_of_largest

#: A bond whose ratio is within this of 1 has reached its strength [1]: the tie rule's tolerance
#: (:data:`.ties.DECISION_REL_TOL`), far above the round-off between two CPUs' answers.
BREAK_RATIO_TOL = DECISION_REL_TOL
#: Default bracketing tolerance on the largest ratio (and on stress / target) [1].
BRACKET_TOL = 1e-9
#: Bracketing iterations before the first state past the crossing is taken [1]; Illinois halves the bracket
#: at worst every other step, so 200 reach the float resolution of any closure.
MAX_BRACKET_ITERATIONS = 200
#: Path steps without a break before the path counts as stuck [1] (each step moves to a status change at least).
MAX_STEPS_WITHOUT_BREAK = 10_000


class LargeCascade(Exception):
    """A cascade broke more bonds at one closure than :attr:`Path.max_cascade` allows: ``state`` is the converged
    state after the last of them (bonds still at their strength left intact), for an engine with inertia to take
    over from (released energy may break more than the static cascade does)."""

    def __init__(self, state, bonds: int):
        super().__init__(f"static cascade: {bonds} bonds broken at closure {state.closure:.6g} m")
        self.state, self.bonds = state, int(bonds)


@dataclass
class Record:
    """One row of the path: after a break (or a reached target)."""
    closure: float
    stress_before: float        # platen stress where the bond reached its strength [Pa]
    stress_after: float         # after the cascade [Pa]
    bonds: list = field(default_factory=list)   # canonical numbers broken, in order
    modes: list = field(default_factory=list)


class Path:
    """The breaking path of one network (module doc); ``jt``, ``jc`` the current strengths [Pa] (creep lowers them)."""

    def __init__(self, eq: Equilibrium, bracket_tol: float = BRACKET_TOL):
        self.eq, self.net, self.bracket_tol = eq, eq.net, float(bracket_tol)
        self.jt, self.jc = eq.net.tensile_strength.copy(), eq.net.cohesion.copy()
        self.records: list[Record] = []
        self.steps = 0
        #: the state :meth:`run_closure` stood on before its last step (what a caller reports after a failure)
        self.last_state = None
        #: the last converged state a step or a break started from (a hand-over starts from it if a solve gives out)
        self.last_converged = None
        #: bonds one cascade may break before :class:`LargeCascade` is raised; None: no limit (the static engine)
        self.max_cascade = None
        #: the test's post-peak rule under displacement control, as the scene was given it
        #: (:meth:`.strategy.RelaxationHooks.lose_load_below`): a relaxation with the platens held loses the load
        #: below this ratio of the stress it started from; None: never (a path that does not relax ignores it)
        self.load_loss_ratio = None
        #: the bonds' saw-tooth softening (:class:`.teeth.BondTeeth`); None: a bond at its strength breaks
        self.teeth = None
        #: the failure criterion (:mod:`.face_failure`): each bond's own (the default) or each face's, whole
        self.failure = BondFailure(eq.net)

    # ------------------------------------------------------------------ ratios and the tie rule
    def ratios(self, state: State):
        """(ratio, mode) of every bond; -inf for broken ones."""
        r, mode = self.failure.overstress(state.fn, state.fs, self.jt, self.jc, state.broken)
        return np.where(state.broken, -np.inf, r), mode

    def over(self, state: State) -> np.ndarray:
        """Intact bonds at their strength (exact paper Eq. 4-5, or a ratio within BREAK_RATIO_TOL of 1)."""
        r, _ = self.ratios(state)
        hit = self.failure.failing(state.fn, state.fs, self.jt, self.jc, state.broken) | (r >= 1 - BREAK_RATIO_TOL)
        return hit & ~state.broken

    @staticmethod
    def pick(ratio: np.ndarray, candidates: np.ndarray) -> int:
        """The most overstressed of ``candidates``, ties to the first in canonical order
        (:func:`.ties.first_of_largest`)."""
        return first_of_largest(ratio, candidates)

    # ------------------------------------------------------------------ breaking
    def break_bond(self, state: State, bond: int, mode: int) -> State:
        """``state`` with ``bond`` broken, and with it the bonds its failure criterion breaks together
        (:meth:`.face_failure.BondFailure.group`: itself, or its face's intact bonds): :meth:`break_bonds`."""
        return self.break_bonds(state, self.failure.group(bond, state.broken), mode)

    def break_bonds(self, state: State, bonds: np.ndarray, mode: int) -> State:
        """``state`` with ``bonds`` broken at once (JCFpm's broken contact, :func:`.contacts.break_state`), re-solved at
        its closure (their intact forces released through :meth:`.solver.Equilibrium.release_force`)."""
        n = self.net
        base = state.copy()
        dn, ds = n.cn[bonds] @ state.u, n.ct[bonds] @ state.u
        st, sg, s_p = cl.break_state(dn, ds, state.fs[bonds], n.kn[bonds], n.ks[bonds], n.tan_residual[bonds])
        base.broken[bonds], base.status[bonds], base.sign[bonds], base.s_p[bonds] = True, st, sg, s_p
        base.break_mode[bonds] = mode
        return self.eq.solve(state.closure, base, self.eq.release_force(state, base))

    def soften_bond(self, state: State, bond: int) -> State:
        """``state`` with ``bond`` on its next saw-tooth (:mod:`.teeth`: lower stiffness and strengths, still intact),
        re-solved at its closure (the force it no longer carries released as for a break)."""
        n = self.net
        self.teeth.advance(bond, self.jt, self.jc)
        dn, ds = (rows[bond] @ state.u for rows in (n.cn, n.ct))
        release = tooth_release(self.eq, state, bond, n.kn[bond] * dn[0], n.ks[bond] * ds[0])
        return self.eq.solve(state.closure, state.copy(), release)

    def cascade(self, state: State, first: int | None = None, record: Record | None = None) -> State:
        """Break ``first`` (if given), then every bond at its strength, one at a time, the most overstressed first (a
        bond with a saw-tooth left takes it instead, :attr:`teeth`; with face failure its face's intact bonds break
        with it, :attr:`failure`); :class:`LargeCascade` after :attr:`max_cascade` broken bonds if that is set."""
        broken = 0
        while True:
            self.last_converged = state
            if self.max_cascade is not None and broken >= self.max_cascade and (first is not None or
                                                                               self.over(state).any()):
                raise LargeCascade(state, broken)
            ratio, mode = self.ratios(state)
            if first is not None:
                bond, first = first, None
            else:
                hit = np.flatnonzero(self.over(state))
                if not len(hit):
                    return state
                bond = self.pick(ratio, hit)
            if self.teeth is not None and self.teeth.softens(bond):
                state = self.soften_bond(state, bond)
                continue
            bonds = self.failure.group(bond, state.broken)
            state = self.break_bonds(state, bonds, int(mode[bond]))
            broken += len(bonds)
            if record is not None:
                record.bonds.extend(int(b) for b in bonds)
                record.modes.extend([int(mode[bond])] * len(bonds))

    # ------------------------------------------------------------------ the path
    def _h(self, state: State, target):
        r, _ = self.ratios(state)
        h = float(r.max()) - 1.0 if np.any(~state.broken) else -np.inf
        if target is not None:
            h = max(h, (state.stress - target) / target)
        return h

    def step(self, state: State, target=None, max_closure=math.inf):
        """One move along the path from ``state``: to the next bond crossing (then its cascade), to the target
        stress, or to ``max_closure``.  Returns (new state, what: "break" / "target" / "end" / "none");
        "none": nothing lies ahead (no crossing, no target reachable, no closure limit)."""
        self.last_converged = state
        v, fn1, fs1, p1 = self.eq.response(state)
        x = self.failure.crossing_increment(state.fn, state.fs, fn1, fs1, self.jt, self.jc, state.broken)
        x = np.where(state.broken, np.inf, x)
        x_break = float(x.min()) if len(x) else math.inf
        x_target = max(target - state.stress, 0.0) / p1 if target is not None and p1 > 0 else math.inf
        x_end = max_closure - state.closure
        dx = min(x_break, x_target, x_end)
        if not math.isfinite(dx):
            return state, "none"
        self.steps += 1
        trial = self.eq.solve(state.closure + dx, state)
        h = self._h(trial, target)
        if h > self.bracket_tol:
            trial = self._bracket(state, trial, target)
            h = self._h(trial, target)
        if h < -self.bracket_tol:        # the path bent away: neither reached yet
            return trial, "end" if trial.closure >= max_closure else "moved"
        r, _ = self.ratios(trial)
        if np.any(~trial.broken) and r.max() >= 1 - self.bracket_tol:
            rec = Record(trial.closure, trial.stress, trial.stress)
            bond = self.pick(r, np.flatnonzero(r >= 1 - self.bracket_tol))
            trial = self.cascade(trial, first=bond, record=rec)
            rec.stress_after = trial.stress
            self.records.append(rec)
            return trial, "break"
        if target is not None and trial.stress >= target * (1 - self.bracket_tol):
            return trial, "target"
        return trial, "end" if trial.closure >= max_closure else "moved"

    def _bracket(self, state: State, beyond: State, target):
        """Illinois on h(d) = max(largest ratio - 1, stress / target - 1) between ``state`` (h < 0) and
        ``beyond`` (h > 0), each trial solved from ``state`` (the last converged state)."""
        a, ha = state.closure, self._h(state, target)
        b, hb, sb = beyond.closure, self._h(beyond, target), beyond
        side = 0
        for _ in range(MAX_BRACKET_ITERATIONS):
            c = b - hb * (b - a) / (hb - ha) if hb != ha else 0.5 * (a + b)
            if not a < c < b:
                c = 0.5 * (a + b)
            if c == a or c == b:
                return sb
            sc = self.eq.solve(c, state)
            hc = self._h(sc, target)
            if abs(hc) <= self.bracket_tol:
                return sc
            if hc > 0:
                b, hb, sb = c, hc, sc
                if side == 1:
                    ha *= 0.5
                side = 1
            else:
                a, ha = c, hc
                if side == -1:
                    hb *= 0.5
                side = -1
        return sb

    def run_closure(self, state: State, max_closure: float, stop=None):
        """Follow the path until ``max_closure`` or until ``stop(state, records)`` says so; returns the last state."""
        quiet = 0
        while state.closure < max_closure:
            self.last_state = state
            state, what = self.step(state, None, max_closure)
            if what == "none":
                return state
            quiet = 0 if what == "break" else quiet + 1
            if quiet > MAX_STEPS_WITHOUT_BREAK:
                raise NumericalFailure(f"static path: {quiet} steps without a break at closure {state.closure:.6g} m")
            if stop is not None and stop(state, self.records):
                return state
        return state

    def summary_keys(self) -> dict:
        """What a run's summary records of the path beyond the engine's counters: the tooth events of saw-tooth
        softening (nothing for the plain path without it)."""
        return {} if self.teeth is None else self.teeth.summary_keys()

    def saved_arrays(self) -> dict:
        """Arrays a scene's save keeps of the path's own bookkeeping: the bonds' teeth (none for the plain path
        without softening)."""
        return {} if self.teeth is None else self.teeth.saved_arrays()

    def restore_arrays(self, arrays: dict) -> None:
        """Take back what :meth:`saved_arrays` gave."""
        if self.teeth is not None:
            self.teeth.restore_arrays(arrays)

    def hold(self, state: State, target: float, rule: FailureRule):
        """Regain the platen stress ``target`` [Pa] from ``state`` along the path: (state, failure reason or None)."""
        start, quiet = state.closure, 0
        while True:
            if state.stress >= target * (1 - self.bracket_tol) and not self.over(state).any():
                return state, None
            state, what = self.step(state, target)
            if what == "none":
                return state, NO_EQUILIBRIUM
            if rule.collapsed(start, state.closure, self.net.height):
                return state, COLLAPSE
            quiet = 0 if what == "break" else quiet + 1
            if quiet > MAX_STEPS_WITHOUT_BREAK:
                raise NumericalFailure(f"static hold: {quiet} steps without a break at closure {state.closure:.6g} m")
