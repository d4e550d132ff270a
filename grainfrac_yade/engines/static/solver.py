"""Static equilibrium at a platen closure: tangent assembly, SuperLU, the active-set iteration (pure scipy).

At fixed contact statuses (:mod:`.contacts`) the internal force is affine in the displacements,

    f_int(u) = K(s) u + G^T b(s),   K(s) = K_g + G_n^T A_nn C_n + G_t^T (A_sn C_n + A_ss C_t),

so the equilibrium f_int = f_ext on the free dofs, with the platen dofs at -d/2 and +d/2 (closure d), is one
linear solve.  The statuses themselves follow from the solution (open/closed, stick/slip by the return mapping
from the last converged state); the active-set iteration (a semi-smooth Newton method on the piecewise linear
law) solves, re-reads the statuses and repeats until they agree.  A consistent set is the exact solution (to
round-off): no residual tolerance enters the answer.  The status changes of one iteration are capped, the most
violated first (near-ties in canonical order, :func:`.ties.ranked`); the cap halves whenever an iteration does not
reduce the number of inconsistent contacts (what ends open/close and stick/slip cycling).

The SuperLU factor of the free block (:data:`DIRECT_FACTOR_OPTIONS`: COLAMD on the direct path; the fast path's
reference factors :data:`FAST_FACTOR_OPTIONS`) is kept while the tangent does not change (same statuses, same
free set), so the tangent response to the closure and a following solve cost one
back-substitution each.  Cells cut loose (their node group has no closed contact or bond to a platen's group)
carry no load: their dofs are held where they are and counted; a group held by the platens but free to slide
sideways gets one lateral dof pinned, as the intact specimen does (``elastic.solve_uniaxial``).  A singular
or ill-conditioned system (a mechanism in the loading path) raises :class:`NumericalFailure`, one line.  The kept
factor is :mod:`.factoring`'s (a mixin of :class:`Equilibrium`).  With ``numerics.static_condensation =
"cell_interiors"`` the fast path solves the system with the fem cells' interior nodes condensed out
(:mod:`.condensation`), the interiors recovered for each answer.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ...errors import NumericalFailure
from . import contacts as cl
from .condensation import cell_interiors
from .factoring import (DIRECT_FACTOR_OPTIONS, FAST_FACTOR_OPTIONS, ILL_CONDITIONED_RESIDUAL,  # noqa: F401
                        PIVOT_RATIO, KeptFactor)
from .network import StaticNetwork
from .tangent import MAX_LOW_RANK_CONTACTS, UPDATE_COLUMNS, TangentPattern
from .ties import ranked

#: Active-set iterations per equilibrium before giving up [1]: each is one factorisation; a consistent set is
#: normally found in a handful (measured on 10 x 20 mm, docs/studies/static_bench.md).
MAX_ACTIVE_SET_ITERATIONS = 200
#: Status changes allowed in the first iteration [1]: all of them; the cap halves when an iteration does not
#: reduce the number of inconsistent contacts (module doc).
STATUS_CHANGES_PER_ITERATION = 10**9


#: Stiffness to the ground on every dof, relative to that dof's own diagonal entry in the intact tangent [1], used
#: only where the plain factor is singular: a cell or group hinged at one node (a zero-energy rotation left when its
#: other bonds broke and opened) carries no load but makes the matrix singular; with 1e-12 SuperLU factorises and
#: forces move by ~1e-9 relative (measured on 4 x 8 mm), as ``elastic.ROLLING_REGULARISATION`` does for rolling.
GROUND_REGULARISATION = 1e-12
#: With the ground springs in, a solution whose ground forces exceed this fraction of the largest load on the free
#: dofs holds a mechanism against a load [1] (an unloaded hinge leaves them at round-off, ~1e-12).
LOADED_MECHANISM = 1e-6
#: Halvings of a step whose active set cycles [1]: at most 2**12 sub-steps before NumericalFailure.
MAX_SPLIT_DEPTH = 12


#: A status set that comes back (a cycle) is accepted when its largest inconsistency is below this fraction of the
#: largest contact normal force [1]: contacts hovering at their open/close or stick/slip point within round-off
#: of a path's sub-step (measured: 8e-4 N against forces of kN on 10 x 20 mm rigid cells).
CYCLE_ACCEPT_REL = 1e-6


#: Sets of fixed dofs (per set of closed contacts) kept [1]: a path meets a few; the cache is only emptied when full.
FIXED_CACHE = 256
#: Broken sets whose force rows are kept [1]: a break meets two (before and after it), a cascade a few more.
ROWS_CACHE = 4


class _Cycling(Exception):
    """The active set came back to a status set it had tried, or did not settle."""


@dataclass
class State:
    """A converged equilibrium (arrays over bonds in the network's canonical order)."""
    closure: float              # platen closure d [m]
    u: np.ndarray               # (ndof,) [m]
    broken: np.ndarray          # (m,) bool
    status: np.ndarray          # (m,) contacts.INTACT / OPEN / STICK / SLIP
    sign: np.ndarray            # (m,) slip direction
    s_p: np.ndarray             # (m,) shear reference of broken contacts [m]
    fn: np.ndarray              # (m,) [N], tension positive
    fs: np.ndarray              # (m,) [N]
    stress: float               # platen stress, compression positive [Pa]
    break_mode: np.ndarray = field(default=None)   # (m,) 0 intact, contacts.TENSION / SHEAR
    held: int = 0               # dofs of cells cut loose, held in place
    iterations: int = 0         # active-set iterations of the solve that made it

    def copy(self) -> "State":
        return replace(self, u=self.u.copy(), broken=self.broken.copy(), status=self.status.copy(),
                       sign=self.sign.copy(), s_p=self.s_p.copy(), fn=self.fn.copy(), fs=self.fs.copy(),
                       break_mode=self.break_mode.copy())


@dataclass
class Counters:
    """Work done, for the cost tables."""
    equilibria: int = 0
    iterations: int = 0
    factorisations: int = 0
    solves: int = 0
    factor_seconds: float = 0.0     # CPU
    solve_seconds: float = 0.0      # CPU
    splits: int = 0                 # steps split in two because the active set cycled
    grounded: int = 0               # factorisations that needed the ground springs (a hinge or sliding group)
    tangents: int = 0               # tangents assembled (status sets met)
    low_rank: int = 0               # tangents solved by a low-rank update of a kept factor (no factorisation)
    low_rank_refused: int = 0       # low-rank solves that did not reach the residual: factorised instead
    back_substitutions: int = 0     # on kept factors for the low-rank updates' columns and refinements
    assembly_seconds: float = 0.0   # CPU of assembling tangents and their free blocks


class Equilibrium(KeptFactor):
    """Equilibria of one network under a constant lateral traction ``confinement`` [Pa] (module doc)."""

    #: Whether the fast path may condense the cells' interiors out (:mod:`.condensation`): a subclass whose tangent
    #: adds stiffness on interior dofs (:class:`.damped.AnchoredEquilibrium`'s anchor) solves the full system.
    condensable = True

    def __init__(self, net: StaticNetwork, confinement: float = 0.0,
                 max_iterations: int = MAX_ACTIVE_SET_ITERATIONS,
                 changes_per_iteration: int = STATUS_CHANGES_PER_ITERATION, direction: float = 1.0,
                 reuse_factor: bool = True, max_low_rank_contacts: int = MAX_LOW_RANK_CONTACTS,
                 update_columns: str = "changes", condensation: str = "none"):
        """``direction`` +1: the platens close as the closure grows (compression); -1: they open (a pull).
        ``reuse_factor`` False: every tangent assembled by sparse products and factorised by SuperLU (the plain
        direct path, the fast path's reference); True: the cached assembly and low-rank updates of a kept factor
        (:mod:`.tangent`), at most ``max_low_rank_contacts`` changed contacts from it, their K^-1 U columns made as
        ``update_columns`` says (:data:`.tangent.UPDATE_COLUMNS`), on the system with the cells' interiors condensed
        out where ``condensation`` says so (:data:`.condensation.MODES`; the fast path of a :attr:`condensable`
        equilibrium only: the direct path is the reference)."""
        if max_iterations < 1 or changes_per_iteration < 1:
            raise ValueError("max_iterations and changes_per_iteration must be >= 1")
        self.net, self.max_iterations, self.changes_per_iteration = net, int(max_iterations), int(changes_per_iteration)
        self.f_ext = net.confinement_force(confinement)
        if direction not in (1.0, -1.0):
            raise ValueError(f"direction must be +1 (compression) or -1 (pull), got {direction!r}")
        self.e = direction * net.platen_vector()
        fixed = np.zeros(net.ndof, bool)
        fixed[net.dofs[net.top | net.bottom, 1]] = True
        rot = net.dofs[net.top | net.bottom, 2]
        fixed[rot[rot >= 0]] = True
        self.platen_fixed = fixed
        self.platen_nodes = net.top | net.bottom
        self.counters = Counters()
        self._ground = None
        #: the platen nodes' axial dofs, in node order (what :meth:`reaction_stress` sums)
        self._platen_y = (net.dofs[net.bottom, 1], net.dofs[net.top, 1])
        self._key, self._lu, self._k, self._b, self._fixed = None, None, None, None, None
        self._plain = None      # (status, sign) of the kept plain factor (_factor_now)
        ea, eb = net_tri_edges(net)
        nn = len(net.node_pos)
        self._n_cells, self._cell_of_node = connected_components(
            sp.coo_matrix((np.ones(len(ea)), (ea, eb)), shape=(nn, nn)), directed=False)
        order_pin = np.lexsort((net.node_pos[:, 0], net.node_pos[:, 1]))
        self._platen_order = order_pin[self.platen_nodes[order_pin]]
        self._rows_kinematic = all(g is c or (g.shape == c.shape and (g != c).nnz == 0)
                                   for g, c in ((net.gn, net.cn), (net.gt, net.ct)))
        self.reuse_factor, self.max_low_rank_contacts = bool(reuse_factor), int(max_low_rank_contacts)
        if max_low_rank_contacts < 1 or update_columns not in UPDATE_COLUMNS:
            raise ValueError(f"max_low_rank_contacts must be >= 1 and update_columns one of {UPDATE_COLUMNS}")
        self.update_columns = update_columns
        self._interiors = cell_interiors(net, condensation) if self.reuse_factor and self.condensable else None
        self._interior_free = None      # the interior dofs the kept factor's solves recover (None: not condensed)
        #: inside the active-set iteration the interior of a condensed solve is recovered only for the converged
        #: answer (the statuses read the boundary alone): (u, load, interior dofs) of the last solve, else None
        self._deferred, self._defer = None, False
        self._pattern = (TangentPattern(net if self._interiors is None else self._interiors.network) if self.reuse_factor
                         else None)
        self._lr, self._op, self._fixed_cache, self._rows_cache = None, None, {}, {}
        #: halvings of a step whose active set cycles before NumericalFailure (a caller with another way past a
        #: status cycle, :class:`.damped.RelaxingPath`, gives up sooner)
        self.max_split_depth = MAX_SPLIT_DEPTH

    # ------------------------------------------------------------------ assembly
    def force_rows(self, broken):
        """The network's force rows at this broken set (:meth:`.network.StaticNetwork.force_rows`), kept for the
        last few broken sets (the same matrices, so nothing changes but the work)."""
        key = broken.tobytes()
        hit = self._rows_cache.get(key)
        if hit is None:
            if len(self._rows_cache) >= ROWS_CACHE:
                self._rows_cache.pop(next(iter(self._rows_cache)))
            hit = self._rows_cache[key] = self.net.force_rows(broken)
        return hit

    def summed_rows(self, broken):
        """Force rows for sums over bonds (G^T f): the network's own where its force rows equal its kinematic rows
        in value (fem cells), as then :meth:`force_rows` differs from them only by stored zeros; else
        :meth:`force_rows`."""
        return (self.net.gn, self.net.gt) if self._rows_kinematic else self.force_rows(broken)

    def tangent(self, status, sign, s_p, ground=False):
        """Tangent stiffness (ndof x ndof) of the affine law at these statuses."""
        n = self.net
        a_nn, a_ns, a_sn, a_ss, b_n, b_s = cl.affine_law(status, sign, s_p, n.kn, n.ks, n.tan_residual)
        gn, gt = self.force_rows(status != cl.INTACT)
        k = n.k_grain + gn.T @ sp.diags(a_nn) @ n.cn + gt.T @ (sp.diags(a_sn) @ n.cn + sp.diags(a_ss) @ n.ct)
        if self._ground is None:      # each dof's own intact stiffness, once
            self._ground = sp.diags(GROUND_REGULARISATION * own_stiffness(k, n.dofs))
        return (k + self._ground).tocsc() if ground else k.tocsc()

    def fixed_dofs(self, status):
        """(fixed mask, number of dofs held because their group was cut loose, lateral pins)."""
        closed = status != cl.OPEN
        key = closed.tobytes()
        hit = self._fixed_cache.get(key)
        if hit is None:
            if len(self._fixed_cache) > FIXED_CACHE:
                self._fixed_cache.clear()
            hit = self._fixed_cache[key] = self._fixed_dofs(closed)
        return hit[0].copy(), hit[1], hit[2]

    def _fixed_dofs(self, closed):
        n = self.net
        label = self._groups(closed)
        anchored = np.zeros(label.max() + 1, bool)
        anchored[label[self.platen_nodes]] = True
        fixed = self.platen_fixed.copy()
        loose = ~anchored[label]
        held = n.dofs[loose]
        held = held[held >= 0]
        fixed[held] = True
        # one lateral pin per anchored group: its lowest (then leftmost) platen node, as elastic pins the specimen
        _, first = np.unique(label[self._platen_order], return_index=True)
        fixed[n.dofs[self._platen_order[first], 0]] = True
        return fixed, int(len(held)), len(first)

    def _groups(self, closed) -> np.ndarray:
        """(nodes,) the connected group of every node: its cell's nodes (held together by the grain stiffness,
        :func:`net_tri_edges`) joined by the ``closed`` contacts, solved on the graph of those cells."""
        n = self.net
        cell = self._cell_of_node
        a, b = cell[n.bond_nodes[closed, 0]], cell[n.bond_nodes[closed, 1]]
        nc = self._n_cells
        g = sp.coo_matrix((np.ones(len(a)), (a, b)), shape=(nc, nc))
        _, label = connected_components(g, directed=False)
        return label[cell]

    def displacements(self, closure, status, sign, s_p, held_u, extra=None):
        """u at ``closure`` under fixed statuses (held dofs at ``held_u``; ``extra``: a further dead load)."""
        def start_of(b, fixed):
            u = np.where(fixed, held_u, 0.0)
            plat = self.platen_fixed
            u[plat] = closure * self.e[plat]
            f = self.f_ext if extra is None else self.f_ext + extra
            return u, f - b
        return self._solve_state(status, sign, s_p, start_of)

    def _solve_state(self, status, sign, s_p, start_of):
        """Factor (or reuse), solve, and where the plain factor fails retry once with the ground springs; a
        mechanism the ground springs hold against a load is NumericalFailure.  ``start_of(b, fixed)``: (u with the
        fixed dofs' values, the load f_ext - b or None); the free dofs solve K_ff u_f = load_f - K_fc u_c, on the
        condensed system where the kept factor is (:mod:`.condensation`), its interior then recovered."""
        for attempt in range(2):
            lu, k, b, fixed = self._factor(status, sign, s_p)
            u, load = start_of(b, fixed)
            cells, interior = self._interiors, self._interior_free
            f = load if interior is None or load is None else cells.load(load)
            rhs = -(self._kfc @ u[fixed]) if f is None else f[~fixed] - self._kfc @ u[fixed]
            try:
                u[~fixed] = self._solve(lu, self._kff, rhs)
            except NumericalFailure:
                if self._grounded:
                    raise
                key = (status.tobytes(), np.where(status == cl.SLIP, sign, 0.0).tobytes())
                self._factor_now(key, status, sign, s_p, True)
                continue
            if interior is not None and self._defer:
                self._deferred = (u, load, interior)
            elif interior is not None:
                cells.recover(u, load, interior)
            if self._grounded:
                pull = np.abs(self._ground.diagonal() * u).max()
                if pull > LOADED_MECHANISM * max(np.abs(rhs).max(), 1e-300):
                    raise NumericalFailure(f"static equilibrium: a loaded mechanism (the ground springs carry "
                                           f"{pull:.3g} N): a cell or group free to move against a load")
            return u
        raise NumericalFailure("static equilibrium: no factor solves the system (a mechanism)")

    def response(self, state: State):
        """du/dd at ``state``'s statuses (the tangent response to the closure): (v, dF_n, dF_s, dstress)."""
        def start_of(b, fixed):
            v = np.zeros(self.net.ndof)
            v[self.platen_fixed] = self.e[self.platen_fixed]
            return v, None
        v = self._solve_state(state.status, state.sign, state.s_p, start_of)
        n = self.net
        a_nn, a_ns, a_sn, a_ss, _, _ = cl.affine_law(state.status, state.sign, state.s_p, n.kn, n.ks, n.tan_residual)
        dn, ds = n.cn @ v, n.ct @ v
        fn1, fs1 = a_nn * dn + a_ns * ds, a_sn * dn + a_ss * ds
        return v, fn1, fs1, self.platen_stress(v, fn1, fs1, state.status != cl.INTACT, constant=False)

    def platen_stress(self, u, fn, fs, broken, constant=True):
        """Platen stress [Pa, compression positive] of the internal forces (as ``elastic.solve_uniaxial``)."""
        n = self.net
        gn, gt = self.summed_rows(broken)
        r = n.k_grain @ u + gn.T @ fn + gt.T @ fs
        return self.reaction_stress(r - self.f_ext if constant else r)

    def reaction_stress(self, r: np.ndarray) -> float:
        """Platen stress [Pa, compression positive] of the force ``r`` (ndof,) [N] on the platen nodes: half the
        bottom's y sum less the top's, over width x thickness."""
        n = self.net
        bottom, top = self._platen_y
        return 0.5 * (r[bottom].sum() - r[top].sum()) / (n.width * n.thickness)

    # ------------------------------------------------------------------ the active-set iteration
    def solve(self, closure: float, base: State, release=None) -> State:
        """The equilibrium at ``closure`` from the last converged state ``base`` (its broken set, statuses as
        the first guess, shear references for the return mapping).  ``release``: the generalised force that the
        bonds broken since ``base`` carried beyond what they carry as broken contacts (:meth:`release_force`).

        Where the active set cycles or does not settle, the step is split in two halves (closure and release
        both halved), each solved from the converged state of the one before (a finer path, down to
        ``2**MAX_SPLIT_DEPTH`` sub-steps); only then NumericalFailure."""
        return self._split(closure, base, release, 0)

    def _split(self, closure, base, release, depth, lam0=0.0, lam1=1.0):
        try:
            return self._active_set(closure, base, None if release is None else (1.0 - lam1) * release)
        except _Cycling as exc:
            if depth >= self.max_split_depth:
                raise NumericalFailure(f"static equilibrium: contact statuses did not settle ({exc}) even in "
                                       f"{2 ** depth} sub-steps at closure {closure:.6g} m") from None
        self.counters.splits += 1
        mid = 0.5 * (base.closure + closure)
        lam = 0.5 * (lam0 + lam1)
        half = self._split(mid, base, release, depth + 1, lam0, lam)
        return self._split(closure, half, release, depth + 1, lam, lam1)

    def release_force(self, state: State, broken_now: State) -> np.ndarray:
        """(ndof,) what the bonds broken between ``state`` (intact there) and ``broken_now`` (the same displacement,
        those bonds broken) carried beyond their broken-contact forces, as a generalised force on the nodes.
        Summed over those bonds' rows alone: the other rows add exact zeros."""
        n = self.net
        new = np.flatnonzero(broken_now.broken & ~state.broken)
        dn, ds = n.cn[new] @ state.u, n.ct[new] @ state.u
        fn_b, fs_b = cl.forces(dn, ds, broken_now.status[new], broken_now.sign[new], broken_now.s_p[new], n.kn[new],
                               n.ks[new], n.tan_residual[new])
        gn, gt = (rows[new] for rows in self.summed_rows(state.broken))
        gnb, gtb = (rows[new] for rows in self.summed_rows(broken_now.broken))
        return -(gn.T @ state.fn[new] + gt.T @ state.fs[new] - gnb.T @ fn_b - gtb.T @ fs_b)

    def _converged(self, closure, base, status, sign, u, it) -> State:
        n = self.net
        if self._deferred is not None and self._deferred[0] is u:     # the interior of a condensed solve
            self._interiors.recover(*self._deferred)
        self._deferred = None
        dn, ds = n.cn @ u, n.ct @ u
        fn, fs = cl.forces(dn, ds, status, sign, base.s_p, n.kn, n.ks, n.tan_residual)
        s_p = np.where(base.broken, cl.converged_slip(ds, status, fs, n.ks), base.s_p)
        self.counters.equilibria += 1
        return State(closure, u, base.broken.copy(), status, sign, s_p, fn, fs,
                     self.platen_stress(u, fn, fs, base.broken), base.break_mode.copy(), self._held, it)

    def _active_set(self, closure, base, extra) -> State:
        self._defer = self._interiors is not None
        try:
            return self._iterate(closure, base, extra)
        finally:
            self._defer, self._deferred = False, None

    def _iterate(self, closure, base, extra) -> State:
        """The active-set iteration (module doc); a condensed solve's interior recovered for its answer alone."""
        n = self.net
        status, sign = base.status.copy(), base.sign.copy()
        cap, best, seen, last = self.changes_per_iteration, None, set(), np.zeros(0, int)
        for it in range(1, self.max_iterations + 1):
            key = (status.tobytes(), sign.tobytes())
            if key in seen and len(last) and worst <= CYCLE_ACCEPT_REL * scale:
                return self._converged(closure, base, status, sign, u_last, it)
            if key in seen:
                changes = ", ".join(f"contact {int(w)} to {cl.STATUS_NAMES[int(status[w])]} (off by {float(viol[w]):.3g} N)"
                                    for w in last[:4])
                raise _Cycling(f"a status set came back after {it - 1} iterations; last changes: {changes}")
            seen.add(key)
            u = self.displacements(closure, status, sign, base.s_p, base.u, extra)
            dn, ds = n.cn @ u, n.ct @ u
            new, new_sign, viol = cl.trial_status(dn, ds, base.broken, base.s_p, n.kn, n.ks, n.tan_residual,
                                                  status, sign)
            wrong = np.flatnonzero((new != status) | ((new == cl.SLIP) & (new_sign != sign)))
            self.counters.iterations += 1
            if not len(wrong):
                return self._converged(closure, base, status, sign, u, it)
            scale = float(np.abs(n.kn * dn).max())
            worst, u_last = float(viol[wrong].max()), u
            if best is not None and len(wrong) >= best:
                cap = max(1, cap // 2)
            best = len(wrong) if best is None else min(best, len(wrong))
            pick = ranked(viol, wrong)[:cap]
            last = pick
            status[pick], sign[pick] = new[pick], new_sign[pick]
        raise _Cycling(f"{len(wrong)} inconsistent after {self.max_iterations} iterations")

    def initial(self, closure: float = 0.0) -> State:
        """The intact specimen at ``closure`` (all bonds intact)."""
        m = self.net.n_bonds
        z = np.zeros(m)
        base = State(closure, np.zeros(self.net.ndof), np.zeros(m, bool), np.full(m, cl.INTACT), np.ones(m), z,
                     z, z, 0.0, np.zeros(m, int))
        return self.solve(closure, base)


def solver_options(params) -> dict:
    """The keyword arguments of :class:`Equilibrium` that the run's parameters set: the low-rank updates' contact limit
    (``numerics.static_low_rank_contacts``), how their columns are made (``numerics.static_update_columns``) and
    whether the cells' interiors are condensed out (``numerics.static_condensation``)."""
    return {"max_low_rank_contacts": params.numerics.static_low_rank_contacts,
            "update_columns": params.numerics.static_update_columns,
            "condensation": params.numerics.static_condensation}


def own_stiffness(k, dofs) -> np.ndarray:
    """(ndof,) each dof's own stiffness |K_ii| of the tangent ``k``, its kind's median (translations x, y,
    rotations: the columns of ``dofs``) where it has none."""
    d = np.abs(k.diagonal())
    for col in range(3):
        idx = dofs[:, col][dofs[:, col] >= 0]
        if len(idx) and (d[idx] > 0).any():
            d[idx] = np.where(d[idx] > 0, d[idx], np.median(d[idx][d[idx] > 0]))
    return d


def net_tri_edges(net: StaticNetwork):
    """(a, b) node pairs that hold a cell's nodes together (the grain stiffness's couplings)."""
    k = net.k_grain.tocoo()
    nodes_of = np.full(net.ndof, -1)
    for col in range(3):
        d = net.dofs[:, col]
        ok = d >= 0
        nodes_of[d[ok]] = np.flatnonzero(ok)
    a, b = nodes_of[k.row], nodes_of[k.col]
    keep = (a != b) & (k.data != 0)
    return a[keep], b[keep]
