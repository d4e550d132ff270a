"""Overdamped implicit relaxation where the static statuses do not settle (pure numpy and scipy).

Frictional contacts with a non-associated slip rule need not have a unique quasi-static equilibrium, and where the
active-set solve finds none (:mod:`.solver`: a status set comes back) the static path cannot go on.  Instead of
inertia, this module relaxes the specimen through *overdamped* motion, the backward-Euler step of

    C du/dt + f_int(u) = f_ext,      C = alpha h D,

with D the diagonal of the intact tangent (each dof's own stiffness) and h the pseudo-time step: each step solves

    f_int(u_{k+1}) + alpha D (u_{k+1} - u_k) = f_ext

(:class:`AnchoredEquilibrium`: the static equilibrium with a spring of alpha D on every free dof, anchored at the
last step's displacements).  The anchor makes the friction problem of one step strongly monotone for large enough
alpha (its contact statuses settle), and its force alpha D (u_{k+1} - u_k) is exactly the static problem's
unbalanced force at u_{k+1}.  A linear dof of stiffness k and anchor a = alpha D relaxes as
u_k - u_s = (a / (k + a))^k (u_0 - u_s): the closed form of backward Euler on a Kelvin-Voigt element
(tests/test_static_damped.py).  This is the relaxation of the paper's UDEC (each state relaxed to equilibrium with
heavy damping), without the inertia a creep hold does not call for.

:func:`relax_held` is pseudo-transient continuation on that flow: each step is a held-load regain along the
anchored path (bonds broken one at a time as in :mod:`.cascade`, the platen stress brought back to the target);
after a step whose statuses settle the anchor is halved (the steps grow towards the plain static solve, alpha -> 0),
after one whose statuses do not settle it is stiffened four-fold and the step taken again.  It ends

* **at rest**: the creep protocol's measure of a relaxed held load (the YADE engine's too,
  :func:`grainfrac_yade.kernel.equilibrium.relaxed`): the mean unbalanced force on the free nodes over the mean
  intact bond force, below :data:`REST_TOLERANCE` (1e-6; YADE's ``creep.equilibrium_tolerance`` of 1e-3 calls a
  sliding mechanism at rest).  The state is that anchored step's: its unbalanced force is what the measure read,
  its statuses consistent; the static path goes on from it;
* **failing**: the failure rule of :mod:`.failure` measured from where the regain began (collapse: the closure grew
  by more than ``creep.collapse_strain_increment`` of the height while the load was regained); or
* after ``max_steps`` steps, or with the anchor stiffened beyond :data:`MAX_ANCHOR_RATIO`, without either:
  :class:`~grainfrac_yade.errors.NumericalFailure` (a solver that gives out is never a failure of the specimen).

:class:`RelaxingPath` is the static path whose held-load regains relax so where the plain ones give out
(``numerics.static_relaxation = "overdamped"``, :mod:`.paths`; docs/studies/static_engine.md, "Overdamped
relaxation").
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ...errors import NumericalFailure
from . import contacts as cl
from .cascade import Path
from .failure import COLLAPSE, FailureRule
from .solver import Equilibrium, State, own_stiffness

#: Anchor stiffness alpha relative to each dof's own intact stiffness [1] in the first step of a relaxation: one
#: step then moves each dof half-way to its own static answer.  Starts of 1 and 10 reached the same accepted state
#: (the same broken set) on 10 x 20 mm (docs/studies/static_engine.md, "Overdamped relaxation").
ANCHOR_RATIO = 1.0
#: Factor the anchor is divided by after a step whose statuses settled [1] (pseudo-transient continuation).
ANCHOR_RELEASE = 2.0
#: Factor the anchor is multiplied by after a step whose statuses did not settle, before it is taken again [1].
ANCHOR_STIFFEN = 4.0
#: Smallest anchor ratio [1]: a spring of 1e-12 of each dof's stiffness is the solver's own ground regularisation
#: (:data:`.solver.GROUND_REGULARISATION`); below it the step is the plain static solve.
MIN_ANCHOR_RATIO = 1e-12
#: Largest anchor ratio [1]: statuses that do not settle even when every dof is held by 1e4 x its own stiffness
#: (steps of 1e-4 of the static answer) are a solver giving out.
MAX_ANCHOR_RATIO = 1e4
#: Halvings of an anchored step whose statuses cycle before the anchor is stiffened instead [1] (the plain solve's
#: 12 halvings cost seconds per failed step; a stiffer anchor settles them).
ANCHORED_SPLIT_DEPTH = 2
#: Active-set iterations of one anchored solve before it counts as unsettled [1] (the plain solve's 200 cost seconds
#: per failed step at 10 x 20 mm; settled anchored steps took 3-16, docs/studies/static_engine.md).
ANCHORED_MAX_ITERATIONS = 50
#: Halvings of a plain regain's step whose statuses cycle, and its active-set iterations, before the relaxation takes
#: over [1]: the plain solve alone tries 12 halvings of up to 200 iterations (:data:`.solver.MAX_SPLIT_DEPTH`,
#: :data:`.solver.MAX_ACTIVE_SET_ITERATIONS`), 5.7-6.7 CPU s per event that gives out at 10 x 20 mm, where a
#: relaxation costs 0.3-0.5 s (docs/studies/static_engine.md, "Overdamped relaxation").
PLAIN_SPLIT_DEPTH = 1
PLAIN_MAX_ITERATIONS = 50
#: Relative unbalanced force (:func:`relative_unbalanced`) below which a relaxation has come to rest [1].  A loaded
#: mechanism (frictional sliding under the held load) keeps it at 1e-5 to 1e-3 while the closure grows step after
#: step; an arrested flow falls through it (docs/studies/static_engine.md, "Overdamped relaxation"), so the
#: verdict does not hang on its value (tests/test_static_damped.py runs two).
REST_TOLERANCE = 1e-6
#: Pseudo-time steps of one relaxation before it gives up (NumericalFailure) [1] where no budget is given (a scene's
#: is ``numerics.static_relaxation_steps``): on 10 x 20 mm fem cells the criterion was met after 18-29 steps from a
#: status cycle, and a loaded mechanism reached the collapse rule after 640 (docs/studies/static_engine.md).
MAX_RELAXATION_STEPS = 1000


def intact_diagonal(eq: Equilibrium) -> np.ndarray:
    """(ndof,) each dof's own stiffness in the intact tangent [N/m or N m/rad] (:func:`.solver.own_stiffness`, as the
    solver's ground springs)."""
    m = eq.net.n_bonds
    return own_stiffness(Equilibrium.tangent(eq, np.full(m, cl.INTACT), np.ones(m), np.zeros(m)), eq.net.dofs)


class AnchoredEquilibrium(Equilibrium):
    """The equilibrium of :class:`.solver.Equilibrium` with a spring ``alpha`` D on every dof anchored at
    :attr:`u_ref` (module doc): one backward-Euler step of the overdamped motion.  ``alpha`` > 0 [1].  The anchor
    stiffens every dof, interiors too, by a ratio that changes step by step: the full system is solved
    (``numerics.static_condensation`` does not reach the anchored steps)."""

    condensable = False

    def __init__(self, net, alpha: float = ANCHOR_RATIO, confinement: float = 0.0, **kw):
        if not alpha > 0:
            raise ValueError(f"alpha must be > 0 (got {alpha!r})")
        super().__init__(net, confinement, **{"max_iterations": ANCHORED_MAX_ITERATIONS, **kw})
        self.max_split_depth = ANCHORED_SPLIT_DEPTH
        self.alpha = float(alpha)
        #: the anchor stiffness on every dof [N/m or N m/rad]
        self.anchor = self.alpha * intact_diagonal(self)
        #: where the anchor springs are anchored: the last step's displacements [m]
        self.u_ref = np.zeros(net.ndof)
        if self._pattern is not None:       # the fast path's constant part gains the anchor on its diagonal
            self._pattern.shift_diagonal(self.anchor)

    def set_alpha(self, alpha: float) -> None:
        """A new anchor ratio ``alpha`` > 0 [1]; the kept factor (and its low-rank history) is dropped."""
        if not alpha > 0:
            raise ValueError(f"alpha must be > 0 (got {alpha!r})")
        new = alpha * (self.anchor / self.alpha)
        if self._pattern is not None:
            self._pattern.shift_diagonal(new - self.anchor)
        self.alpha, self.anchor = float(alpha), new
        self.forget_factor()

    def tangent(self, status, sign, s_p, ground=False):
        return (super().tangent(status, sign, s_p, ground) + sp.diags(self.anchor)).tocsc()

    def displacements(self, closure, status, sign, s_p, held_u, extra=None):
        pull = self.anchor * self.u_ref
        return super().displacements(closure, status, sign, s_p, held_u, pull if extra is None else extra + pull)

    def unbalanced(self, state: State) -> np.ndarray:
        """(ndof,) the static problem's unbalanced force at ``state``: the anchor's pull alpha D (u_ref - u)."""
        return self.anchor * (self.u_ref - state.u)


def relative_unbalanced(anchored: AnchoredEquilibrium, state: State) -> float:
    """The creep protocol's equilibrium measure at ``state`` (an anchored step's answer): :func:`relative_force` of
    the unbalanced force (:meth:`AnchoredEquilibrium.unbalanced`) [1]."""
    return relative_force(anchored.net, anchored.unbalanced(state), state.fn, state.fs, state.broken)


def relative_force(net, r: np.ndarray, fn: np.ndarray, fs: np.ndarray, broken: np.ndarray) -> float:
    """The creep protocol's equilibrium measure of the force ``r`` (ndof,) [N]: the mean magnitude of its
    translations on the nodes the platens do not drive, over the mean magnitude of the intact bonds' forces
    hypot(F_n, F_s) [1] (every intact bond: the static state has them all at no cost); infinite when no bond is
    intact."""
    dofs = net.dofs[~(net.top | net.bottom)][:, :2]
    force = np.hypot(*(np.where(dofs[:, k] >= 0, r[np.maximum(dofs[:, k], 0)], 0.0) for k in range(2)))
    intact = ~broken
    ref = float(np.hypot(fn[intact], fs[intact]).mean()) if intact.any() else 0.0
    return float(force.mean()) / ref if ref > 0 else math.inf


@dataclass
class Relaxation:
    """What one :func:`relax_held` did."""
    state: State                    # where it ended (the accepted anchored state, or the failed state)
    failure: str | None             # the failure rule's reason, None when the load is held again
    start_closure: float = 0.0      # closure where the regain began [m] (the collapse rule's origin)
    steps: int = 0                  # pseudo-time steps tried (unsettled ones included)
    unsettled: int = 0              # steps whose statuses did not settle (taken again with a stiffer anchor)
    broken: int = 0                 # bonds broken during the relaxation
    unbalanced: list = field(default_factory=list)   # relative unbalanced force after each settled step [1]
    alphas: list = field(default_factory=list)       # anchor ratio of each settled step [1]


def relax_held(path: Path, anchored: AnchoredEquilibrium, state: State, target: float, rule: FailureRule,
               tolerance: float, start_closure: float | None = None,
               max_steps: int = MAX_RELAXATION_STEPS) -> Relaxation:
    """Relax ``state`` (the last converged static state) under the held platen stress ``target`` [Pa] until the
    relative unbalanced force (:func:`relative_unbalanced`) is below ``tolerance`` [1] (module doc).  ``path``: the
    static path (its strengths are used, not changed); ``anchored``: an :class:`AnchoredEquilibrium` on the same
    network; ``start_closure``: where the regain began [m] (the collapse rule's origin; default ``state``'s)."""
    damped = Path(anchored, path.bracket_tol)
    damped.jt, damped.jc = path.jt, path.jc         # the same strengths, not copies
    damped.teeth = path.teeth                       # and the same teeth
    damped.failure = path.failure                   # and the same failure criterion
    start = state.closure if start_closure is None else float(start_closure)
    broken0 = int(state.broken.sum())
    out = Relaxation(state, None, start)
    alpha = ANCHOR_RATIO
    anchored.set_alpha(alpha)
    while out.steps < max_steps:
        out.steps += 1
        anchored.u_ref = state.u.copy()
        try:
            new, reason = damped.hold(damped.cascade(anchored.solve(state.closure, state)), target, FailureRule(0.0))
        except NumericalFailure:
            out.unsettled += 1
            alpha *= ANCHOR_STIFFEN
            if alpha > MAX_ANCHOR_RATIO:
                raise NumericalFailure(f"overdamped relaxation: contact statuses did not settle even with an "
                                       f"anchor of {MAX_ANCHOR_RATIO:g} x each dof's stiffness (closure "
                                       f"{state.closure:.6g} m)") from None
            anchored.set_alpha(alpha)
            continue
        state = new
        out.state, out.broken = state, int(state.broken.sum()) - broken0
        out.unbalanced.append(relative_unbalanced(anchored, state))
        out.alphas.append(alpha)
        if reason is not None or rule.collapsed(start, state.closure, path.net.height):
            out.failure = reason or COLLAPSE
            return out
        if out.unbalanced[-1] < tolerance:
            return out
        alpha = max(alpha / ANCHOR_RELEASE, MIN_ANCHOR_RATIO)
        anchored.set_alpha(alpha)
    raise NumericalFailure(f"overdamped relaxation: the held load not in equilibrium after {max_steps} "
                           f"pseudo-time steps (closure {state.closure:.6g} m, relative unbalanced force "
                           f"{out.unbalanced[-1] if out.unbalanced else math.inf:.3g})")


class RelaxingPath(Path):
    """The static path whose held-load regain (:meth:`hold`, and a cascade before it) relaxes by
    :func:`relax_held` where the plain static solve gives out, to the relative unbalanced force ``tolerance`` [1];
    every relaxation is kept in :attr:`relaxations`."""

    def __init__(self, eq: Equilibrium, anchored: AnchoredEquilibrium, tolerance: float = REST_TOLERANCE,
                 bracket_tol=None,
                 max_steps: int = MAX_RELAXATION_STEPS):
        super().__init__(eq, *(() if bracket_tol is None else (bracket_tol,)))
        eq.max_split_depth = min(eq.max_split_depth, PLAIN_SPLIT_DEPTH)
        eq.max_iterations = min(eq.max_iterations, PLAIN_MAX_ITERATIONS)
        self.anchored, self.tolerance, self.max_steps = anchored, float(tolerance), int(max_steps)
        self.relaxations: list[Relaxation] = []
        #: (relaxations, steps, unsettled steps, bonds broken) since the run began (:data:`TALLY`)
        self.tally = np.zeros(len(self.TALLY), np.int64)
        self._unsettled = None      # the last converged state of a cascade that gave out, for the next hold
        self._in_hold = False       # inside a regain: a cascade that gives out is the regain's to handle

    #: Columns of :attr:`tally`: relaxations, pseudo-time steps, unsettled steps, bonds broken in them.
    TALLY = ("static_relaxations", "static_relaxation_steps", "static_relaxation_unsettled_steps",
             "static_relaxation_bonds_broken")

    def summary_keys(self) -> dict:
        """The relaxations of the whole run (a resumed run's included, :meth:`saved_arrays`)."""
        return {**super().summary_keys(), **{k: int(v) for k, v in zip(self.TALLY, self.tally)}}

    def saved_arrays(self) -> dict:
        return {**super().saved_arrays(), "relaxation_tally": self.tally.copy()}

    def restore_arrays(self, arrays: dict) -> None:
        super().restore_arrays(arrays)
        self.tally = np.asarray(arrays.get("relaxation_tally", np.zeros(len(self.TALLY))), np.int64).copy()

    def cascade(self, state, first=None, record=None):
        if self._in_hold:
            return super().cascade(state, first, record)
        try:
            return super().cascade(state, first, record)
        except NumericalFailure:
            self._unsettled = self.last_converged
            return self.last_converged

    def hold(self, state, target, rule):
        begin, (start, self._unsettled) = state.closure, (self._unsettled, None)
        self._in_hold = True
        try:
            if start is None:
                try:
                    return super().hold(state, target, rule)
                except NumericalFailure:
                    start = self.last_converged
            out = self._relax(start, target, rule, begin)
        finally:
            self._in_hold = False
        self.count(out)
        return out.state, out.failure

    def count(self, out: Relaxation) -> None:
        """Keep ``out`` in :attr:`relaxations` and add it to :attr:`tally`."""
        self.relaxations.append(out)
        self.tally += (1, out.steps, out.unsettled, out.broken)

    def _relax(self, start: State, target: float, rule: FailureRule, begin: float) -> Relaxation:
        """One relaxation of the converged state ``start`` under the held stress ``target`` [Pa], the regain having
        begun at closure ``begin`` [m] (the collapse rule's origin): :func:`relax_held`."""
        return relax_held(self, self.anchored, start, target, rule, self.tolerance, begin, self.max_steps)
