"""The kept SuperLU factor of a static equilibrium's tangent (:class:`.solver.Equilibrium`'s factor methods).

Factorised once per status set and kept while the tangent does not change: on the direct path the plain factor
(:data:`DIRECT_FACTOR_OPTIONS`, with the ground springs where it is singular); on the fast path (:mod:`.tangent`)
a reference factor (:data:`FAST_FACTOR_OPTIONS`) solved by low-rank updates where the tangent is close to it.
A factor whose pivots spread beyond :data:`PIVOT_RATIO` is singular; a solve whose relative residual exceeds
:data:`ILL_CONDITIONED_RESIDUAL` is ill-conditioned: both raise :class:`NumericalFailure` (a mechanism).  The kept
state is saved and rebuilt bit for bit (:meth:`KeptFactor.factor_state`, :meth:`KeptFactor.restore_factor_state`).
"""
from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ...errors import NumericalFailure
from . import contacts as cl
from .tangent import LowRankSolver

#: Relative residual of a linear solve above which the system counts as ill-conditioned [1]: SuperLU with partial
#: pivoting leaves ~1e-12 on these matrices; 1e-6 means a (near) mechanism.
ILL_CONDITIONED_RESIDUAL = 1e-6

#: SuperLU options of the fast path's reference factors (``_refactor_fast``) [-]: minimum degree ordering on
#: A^T + A with SymmetricMode (the diagonal taken as pivot while it is at least ``diag_pivot_thresh`` of its
#: column's largest entry, else partial pivoting).  The tangent is symmetric but for slipping contacts; measured at
#: paper size (docs/studies/static_bench.md, "Cost at paper size"): fill 3.27e6 against 5.56e6 with COLAMD, one
#: back-substitution 0.0076 s against 0.0136 s; on the 160 MPa creep hold (150 events) solve CPU 33.2 s against
#: 47.4 s with the same break sequence, direct residuals 2.3e-14 (COLAMD 3.7e-14), no low-rank solve refused,
#: and the same factors at thresholds 0.0, 0.01 and 0.1.  Without SymmetricMode this ordering factorises in 5.4 s
#: (0.27 s with COLAMD).
FAST_FACTOR_OPTIONS = {"permc_spec": "MMD_AT_PLUS_A", "diag_pivot_thresh": 0.1, "options": {"SymmetricMode": True}}
#: SuperLU options of the direct path and of the ground-spring factors (``_factor_now``) [-]: the reference.
DIRECT_FACTOR_OPTIONS = {"permc_spec": "COLAMD"}

#: A factor whose smallest pivot is below this fraction of its largest is taken as singular [1] and made again
#: with the ground springs: float64 resolves 1e-16; intact 10 x 20 mm specimens have pivot ratios ~1e-6.
PIVOT_RATIO = 1e-13


class _PlainOp:
    """A SuperLU factor of the tangent itself (the direct path)."""
    fast = False

    def __init__(self, lu):
        self.lu = lu

    def solve(self, kff, rhs):
        return self.lu.solve(rhs)


class _FastOp:
    """The fast path's solve: the kept factor itself, or a low-rank update of it refined to FAST_RESIDUAL."""
    fast = True

    def __init__(self, op):
        self.op = op

    def solve(self, kff, rhs):
        if self.op.z is None:
            return self.op.direct(kff, rhs)
        return self.op.solve(kff, rhs)


class KeptFactor:
    """The factor methods of :class:`.solver.Equilibrium` (a mixin: it reads the equilibrium's network, caches
    and counters)."""

    def forget_factor(self):
        """Drop the kept factor (and with it the low-rank history): the next solve factorises afresh, as a new
        ``Equilibrium`` on the same network would.  The fast path's answers depend on which factor is kept at
        round-off (1e-12 relative), so a run that drops it goes on along another rounding than one that does not."""
        self._key, self._lr, self._op, self._lu, self._k, self._plain = None, None, None, None, None, None

    def stiffness_changed(self):
        """A bond's stiffness changed in place (a saw-tooth, :mod:`.teeth`): the tangent at the same statuses is
        another one, so the kept tangent's key is dropped and the next solve assembles it again; on the fast path
        that is a low-rank update of the kept reference factor (its K^-1 U columns are keyed by the coefficients),
        on the direct path a new factor."""
        self._key = None

    def factor_state(self) -> dict:
        """What rebuilds the solver's kept state bit for bit (:meth:`restore_factor_state`), as arrays: the ground
        springs (made from the first tangent that needed them); the fast path's reference factor as the statuses
        it was made at (its contacts' coefficients and fixed dofs), the largest residual of a direct solve on it and
        the K^-1 U columns it computed, in their blocks; or the plain factor's statuses (direct or grounded).
        Reading it changes nothing: a run that saves it goes on as one that does not."""
        out = {}
        if self._ground is not None:
            out["ground"] = self._ground.diagonal().copy()
        if self._lr is not None:
            a_nn, a_sn, a_ss, broken = self._lr.coef
            out.update(reference_a_nn=a_nn, reference_a_sn=a_sn, reference_a_ss=a_ss, reference_broken=broken,
                       reference_fixed=self._lr_fixed, reference_residual=np.float64(self._lr.direct_residual),
                       reference_columns=self._lr.column_table())
        elif self._plain is not None and self._key is not None:
            status, sign = self._plain
            out.update(plain_status=status, plain_sign=sign, plain_ground=np.bool_(self._grounded))
        return out

    def restore_factor_state(self, saved: dict) -> None:
        """Rebuild the kept state :meth:`factor_state` gave: the same matrices factorised with the same options and
        the same columns back-substituted in the same blocks give the same factor and columns, bit for bit (on one
        machine), so the next solve answers as the saved run's did.  An empty ``saved`` (a checkpoint written
        before these were kept) drops the factor instead."""
        self.forget_factor()
        if "ground" in saved:
            self._ground = sp.diags(np.asarray(saved["ground"], float))
        if "reference_fixed" in saved:
            coef = tuple(np.asarray(saved["reference_" + k], float) for k in ("a_nn", "a_sn", "a_ss")) + \
                (np.asarray(saved["reference_broken"], bool),)
            self._fixed = np.asarray(saved["reference_fixed"], bool)
            self._kff = self._pattern.free_block(self._pattern.data(*coef), self._fixed)
            self._coef = coef
            self._refactor_fast()
            self._lr.direct_residual = float(saved["reference_residual"])
            self._lr.replay(saved["reference_columns"])
        elif "plain_status" in saved:
            status, sign = np.asarray(saved["plain_status"]), np.asarray(saved["plain_sign"], float)
            key = (status.tobytes(), np.where(status == cl.SLIP, sign, 0.0).tobytes())
            self._factor_now(key, status, sign, np.zeros(self.net.n_bonds), bool(saved["plain_ground"]))

    def _factor(self, status, sign, s_p):
        key = (status.tobytes(), np.where(status == cl.SLIP, sign, 0.0).tobytes())
        if key != self._key:
            self._grounded = False
            try:
                if self.reuse_factor:
                    self._tangent_fast(key, status, sign, s_p)
                else:
                    self._factor_now(key, status, sign, s_p, False)
            except NumericalFailure:    # a hinge or a sliding group: once more with the ground springs
                self._factor_now(key, status, sign, s_p, True)
        n = self.net
        _, _, _, _, b_n, b_s = cl.affine_law(status, sign, s_p, n.kn, n.ks, n.tan_residual)
        # b_s is non-zero on broken (sticking) contacts only, whose force rows are their kinematic rows
        b = (n.ct.T @ b_s) if self.reuse_factor else self._gt.T @ b_s
        return self._lu, self._k, b, self._fixed

    def _tangent_fast(self, key, status, sign, s_p):
        """The fast path (:mod:`.tangent`): assemble on the cached pattern; solve by a low-rank update of the
        kept factor where the tangent is close to it, else factorise it as the new reference."""
        self._key = None
        n = self.net
        t0 = time.process_time()
        a_nn, _, a_sn, a_ss, _, _ = cl.affine_law(status, sign, s_p, n.kn, n.ks, n.tan_residual)
        coef = (a_nn, a_sn, a_ss, status != cl.INTACT)
        fixed, held, _ = self.fixed_dofs(status)
        interior = None
        if self._interiors is not None:         # the interiors condensed out: counted as fixed, recovered after a solve
            fixed, interior = self._interiors.split(fixed)
        data = self._pattern.data(*coef)
        kff = self._pattern.free_block(data, fixed)
        self._kfc = self._pattern.coupling(data, fixed)
        self.counters.assembly_seconds += time.process_time() - t0
        self.counters.tangents += 1
        op = None
        if self._lr is not None and np.array_equal(fixed, self._lr_fixed):
            op = self._lr.prepare(coef)
        self._fixed, self._held, self._kff, self._coef = fixed, held, kff, coef
        self._interior_free = interior
        if not kff.shape[0]:        # nothing free: nothing to solve
            self._op, self._key, self._k, self._lu, self._lr = _PlainOp(None), key, None, None, None
            return
        if op is None:
            op = self._refactor_fast()
        elif op.z is not None:
            self.counters.low_rank += 1
        self._op, self._key, self._k, self._lu = _FastOp(op), key, None, None

    def _refactor_fast(self):
        """Factorise the current tangent (fast path) and keep it as the reference of later low-rank updates."""
        kff = self._kff.copy()
        kff.eliminate_zeros()       # the pattern's structural zeros (open contacts) stay out of the factor
        t0 = time.process_time()
        self._lr = None
        try:
            lu = spla.splu(kff, **FAST_FACTOR_OPTIONS) if kff.shape[0] else None
        except RuntimeError:
            raise NumericalFailure("static equilibrium: the stiffness matrix is singular") from None
        finally:
            self.counters.factor_seconds += time.process_time() - t0
        self.counters.factorisations += 1
        d = np.abs(lu.U.diagonal())
        if d.min() <= PIVOT_RATIO * d.max():
            raise NumericalFailure("static equilibrium: a pivot of the factor vanishes (a mechanism)")
        self._lr = LowRankSolver(self.net, lu, self._coef, ~self._fixed, self.max_low_rank_contacts,
                                 self.update_columns, self._rows_kinematic)
        self._lr_fixed = self._fixed
        return self._lr.prepare(self._coef)

    def _factor_now(self, key, status, sign, s_p, ground):
        """Assemble and factorise the free block at these statuses (``ground``: with the ground springs)."""
        self._key = None
        fixed, held, _ = self.fixed_dofs(status)
        k = self.tangent(status, sign, s_p, ground)
        self._grounded = ground
        if ground:
            self.counters.grounded += 1
        self._gn, self._gt = self.force_rows(status != cl.INTACT)
        free = ~fixed
        kff = k[free][:, free].tocsc()
        t0 = time.process_time()
        try:
            lu = spla.splu(kff, **DIRECT_FACTOR_OPTIONS) if kff.shape[0] else None
        except RuntimeError as exc:
            raise NumericalFailure(f"static equilibrium: the stiffness matrix is singular ({exc}); a mechanism "
                                   "in the loading path (a cell or group held by one sliding contact)") from None
        self.counters.factor_seconds += time.process_time() - t0
        self.counters.factorisations += 1
        self._key, self._lu, self._k, self._fixed, self._held, self._kff = key, lu, k, fixed, held, kff
        self._interior_free = None          # the direct path solves the full system
        self._kfc = k[free][:, fixed].tocsr()
        self._op, self._lr, self._plain = _PlainOp(lu), None, (status.copy(), np.asarray(sign, float).copy())
        if lu is not None and not ground:     # a near-singular factor shows in its pivots' spread
            d = np.abs(lu.U.diagonal())
            if d.min() <= PIVOT_RATIO * d.max():
                self._key = None
                raise NumericalFailure("static equilibrium: a pivot of the factor vanishes (a mechanism)")

    def _solve(self, lu, kff, rhs):
        if not rhs.size:
            return rhs
        t0 = time.process_time()
        x = self._op.solve(kff, rhs)
        if x is None:       # the low-rank update did not reach the residual: factorise this tangent
            self.counters.low_rank_refused += 1
            self.counters.solve_seconds += time.process_time() - t0
            self._op = _FastOp(self._refactor_fast())
            t0 = time.process_time()
            x = self._op.solve(kff, rhs)
        self.counters.solve_seconds += time.process_time() - t0
        self.counters.solves += 1
        if self._lr is not None:
            self.counters.back_substitutions += self._lr.back_substitutions
            self._lr.back_substitutions = 0
        if not np.all(np.isfinite(x)):
            raise NumericalFailure("static equilibrium: the solution is NaN or infinite (a singular system: a "
                                   "mechanism in the loading path)")
        scale = max(np.abs(rhs).max(), 1e-300)
        res = np.abs(kff @ x - rhs).max() / scale
        if res > ILL_CONDITIONED_RESIDUAL:
            raise NumericalFailure(f"static equilibrium: ill-conditioned system (relative residual {res:.1e} > "
                                   f"{ILL_CONDITIONED_RESIDUAL:g}): a near mechanism in the loading path")
        return x
