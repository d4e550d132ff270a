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

:func:`relax_held` alternates such steps (each a held-load regain along the anchored path, bonds broken one at a
time as in :mod:`.cascade`) with attempts of the plain static regain from the state reached; it ends

* at the first plain static equilibrium at the held load (exact, to round-off: the static path goes on from it), or
* with the failure rule of :mod:`.failure` measured from where the relaxation began (collapse: the closure grew by
  more than ``creep.collapse_strain_increment`` of the height while the load was regained), or
* after ``max_steps`` steps without either: :class:`~grainfrac_yade.errors.NumericalFailure` (a solver that gives
  out is never a failure of the specimen).

:class:`RelaxingPath` is the static path whose held-load regains relax so where the plain ones give out.  Not yet
plugged into a scene (docs/studies/static_engine.md, "Overdamped relaxation").
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..errors import NumericalFailure
from . import contacts as cl
from .cascade import Path
from .failure import COLLAPSE, FailureRule
from .solver import Equilibrium, State, own_stiffness

#: Anchor stiffness alpha relative to each dof's own intact stiffness [1] in the first step of a relaxation.
ANCHOR_RATIO = 1.0
#: Pseudo-time steps of one relaxation before it gives up (NumericalFailure) [1].
MAX_RELAXATION_STEPS = 200


def intact_diagonal(eq: Equilibrium) -> np.ndarray:
    """(ndof,) each dof's own stiffness in the intact tangent [N/m or N m/rad] (:func:`.solver.own_stiffness`, as the
    solver's ground springs)."""
    m = eq.net.n_bonds
    return own_stiffness(Equilibrium.tangent(eq, np.full(m, cl.INTACT), np.ones(m), np.zeros(m)), eq.net.dofs)


class AnchoredEquilibrium(Equilibrium):
    """The equilibrium of :class:`.solver.Equilibrium` with a spring ``alpha`` D on every dof anchored at
    :attr:`u_ref` (module doc): one backward-Euler step of the overdamped motion.  ``alpha`` > 0 [1]."""

    def __init__(self, net, alpha: float = ANCHOR_RATIO, confinement: float = 0.0, **kw):
        if not alpha > 0:
            raise ValueError(f"alpha must be > 0 (got {alpha!r})")
        super().__init__(net, confinement, **kw)
        self.alpha = float(alpha)
        #: the anchor stiffness on every dof [N/m or N m/rad]
        self.anchor = self.alpha * intact_diagonal(self)
        #: where the anchor springs are anchored: the last step's displacements [m]
        self.u_ref = np.zeros(net.ndof)
        if self._pattern is not None:       # the fast path's constant part gains the anchor on its diagonal
            diag = np.flatnonzero(self._pattern.row == self._pattern.col)
            self._pattern.base = self._pattern.base.copy()
            self._pattern.base[diag] += self.anchor[self._pattern.row[diag]]

    def tangent(self, status, sign, s_p, ground=False):
        return (super().tangent(status, sign, s_p, ground) + sp.diags(self.anchor)).tocsc()

    def displacements(self, closure, status, sign, s_p, held_u, extra=None):
        pull = self.anchor * self.u_ref
        return super().displacements(closure, status, sign, s_p, held_u, pull if extra is None else extra + pull)

    def unbalanced(self, state: State) -> np.ndarray:
        """(ndof,) the static problem's unbalanced force at ``state``: the anchor's pull alpha D (u_ref - u)."""
        return self.anchor * (self.u_ref - state.u)


@dataclass
class Relaxation:
    """What one :func:`relax_held` did."""
    state: State                    # where it ended (a plain static equilibrium, or the failed state)
    failure: str | None             # the failure rule's reason, None when the load is held again
    steps: int = 0                  # pseudo-time steps
    static_attempts: int = 0        # plain static regains tried
    broken: int = 0                 # bonds broken during the relaxation
    unbalanced: list = field(default_factory=list)   # largest unbalanced force after each step [N]


def relax_held(path: Path, anchored: AnchoredEquilibrium, state: State, target: float, rule: FailureRule,
               max_steps: int = MAX_RELAXATION_STEPS) -> Relaxation:
    """Relax ``state`` (the last converged static state) under the held platen stress ``target`` [Pa] (module doc).
    ``path``: the static path (its strengths are used and lowered by nothing here); ``anchored``: an
    :class:`AnchoredEquilibrium` on the same network."""
    damped = Path(anchored, path.bracket_tol)
    damped.jt, damped.jc = path.jt, path.jc         # the same strengths, not copies
    start, broken0 = state.closure, int(state.broken.sum())
    out = Relaxation(state, None)
    for step in range(1, max_steps + 1):
        anchored.u_ref = state.u.copy()
        state, reason = damped.hold(state, target, FailureRule(0.0))
        out.steps, out.state, out.broken = step, state, int(state.broken.sum()) - broken0
        out.unbalanced.append(float(np.abs(anchored.unbalanced(state)).max()))
        if reason is not None or rule.collapsed(start, state.closure, path.net.height):
            out.failure = reason or COLLAPSE
            return out
        out.static_attempts += 1
        try:    # the plain static regain (Path's own, not a subclass's relaxing one)
            held, reason = Path.hold(path, Path.cascade(path, path.eq.solve(state.closure, state)), target, rule)
        except NumericalFailure:
            continue
        out.state, out.broken = held, int(held.broken.sum()) - broken0
        out.failure = reason or (COLLAPSE if rule.collapsed(start, held.closure, path.net.height) else None)
        return out
    raise NumericalFailure(f"overdamped relaxation: no static equilibrium at the held load after {max_steps} "
                           f"pseudo-time steps (closure {state.closure:.6g} m)")


class RelaxingPath(Path):
    """The static path whose held-load regain (:meth:`hold`, and a cascade before it) relaxes by
    :func:`relax_held` where the plain static solve gives out; every relaxation is kept in :attr:`relaxations`."""

    def __init__(self, eq: Equilibrium, anchored: AnchoredEquilibrium, bracket_tol=None,
                 max_steps: int = MAX_RELAXATION_STEPS):
        super().__init__(eq, *(() if bracket_tol is None else (bracket_tol,)))
        self.anchored, self.max_steps = anchored, int(max_steps)
        self.relaxations: list[Relaxation] = []
        self._unsettled = None      # the last converged state of a cascade that gave out, for the next hold
        self._in_hold = False       # inside a regain: a cascade that gives out is the regain's to handle

    def cascade(self, state, first=None, record=None):
        if self._in_hold:
            return super().cascade(state, first, record)
        try:
            return super().cascade(state, first, record)
        except NumericalFailure:
            self._unsettled = self.last_converged
            return self.last_converged

    def hold(self, state, target, rule):
        start, self._unsettled = self._unsettled, None
        self._in_hold = True
        try:
            if start is None:
                try:
                    return super().hold(state, target, rule)
                except NumericalFailure:
                    start = self.last_converged
            out = relax_held(self, self.anchored, start, target, rule, self.max_steps)
        finally:
            self._in_hold = False
        self.relaxations.append(out)
        return out.state, out.failure
