"""The fast path of the equilibrium's linear algebra: cached assembly and factor reuse by low-rank updates (pure).

Assembly.  The tangent is K(s) = K_g + sum_i G_i^T A_i(s) C_i over contacts i (:mod:`.solver`), with A_i the 2 x 2
affine law of contact i (a_nn, a_sn, a_ss; a_ns = 0) and G_i its force rows (torque arms while intact, the
kinematic rows once broken).  Every contact's outer products g^T c are computed once on a fixed sparsity pattern
(the union over all statuses), so a tangent is the constant K_g plus six sparse matrix-vector products of the
coefficient vectors (:class:`TangentPattern`); the free block is a cached selection of the pattern's entries per
set of fixed dofs.

Factor reuse.  Between two status sets only the contacts whose (A_i, G_i) changed differ, each by a rank-2 term
U_i V_i^T (U_i = G_i'^T A_i' - G_i^T A_i columns, V_i = C_i^T): a tangent within ``max_contacts`` changed contacts
of a reference tangent whose SuperLU factor is kept is solved by the Sherman-Morrison-Woodbury formula on that
factor (:class:`LowRankSolver`), K^-1 U cached per contact and status, then refined against the assembled new
tangent until the relative residual is below :data:`FAST_RESIDUAL` (the level a direct SuperLU solve leaves).
Anything else (more changes, another set of fixed dofs, a refinement that does not get there) makes a new
reference factor: the caller falls back to the direct factorisation, which also does the singularity checks.
"""
from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ...params.schema import field_spec

#: A low-rank (Woodbury) solve is accepted when its relative residual max|K x - b| / max|b| on the assembled new
#: tangent is below RESIDUAL_MARGIN times the largest residual the direct solves on its reference factor left,
#: or below FAST_RESIDUAL, whichever is larger [1].  Direct SuperLU solves leave 6e-16 (median) to 1.2e-15 (max)
#: at 10 x 20 mm (392 solves of a fem path to 0.25 % strain) and 1.6e-14 to 2.0e-14 at paper size (the first 10
#: solves); the low-rank solves 7e-16 to 2.4e-15 unrefined at 10 x 20 mm.  An accepted solution is then as exact
#: as a direct one to within a factor 10 of round-off, far below what the bracketing and the tie rule look at (1e-9,
#: :data:`.ties.DECISION_REL_TOL`).  Whether an update is accepted is itself decided on round-off (one CPU's residual
#: 1.11e-14 against another's 1.19e-14 limit): harmless for a regular tangent, and a singular one is never solved by an
#: update (:data:`CAPACITANCE_PIVOT_RATIO`).
RESIDUAL_MARGIN = 10.0
FAST_RESIDUAL = 1e-14
#: A refinement step must at least halve the residual [1], else the low-rank solve is refused (it stagnates at
#: the capacitance's round-off) and the tangent factorised.
REFINEMENT_GAIN = 0.5
#: Refinement steps of a low-rank solve before giving up and refactorising [1]: each is one back-substitution on
#: the reference factor; with a well-conditioned capacitance one or two reach FAST_RESIDUAL.
MAX_REFINEMENT = 4
#: Changed contacts relative to the reference factor beyond which the tangent is factorised anew [1]: each adds
#: two back-substitutions (its K^-1 U columns) and two columns to every later solve, against one factorisation of
#: ~18 back-substitutions at paper size (0.18 s / 0.010 s).  Measured (docs/studies/static_bench.md, "Cost at
#: paper size"): 10 x 20 mm path to 0.8 % strain 18.4 / 15.8 / 16.0 CPU s at 16 / 48 / 128; paper-size creep at
#: 160 MPa, events 1-200: 132.8 s at 48, 101.5 s at 128 (12 factorisations for 2,727 tangents).
MAX_LOW_RANK_CONTACTS = 128
#: Contacts changed since the last assembly up to which only the pattern's entries they touch are summed again
#: (:meth:`TangentPattern.data`) [1]: an active-set iteration changes a few.  Measured at paper size (427,660 pattern
#: entries, 14,768 bonds, fem cells): 1.0-1.2 ms at 50 changed contacts, 2.3 ms at 300, 3.5-3.7 ms at 600, against
#: 3.7-4.0 ms for a full assembly; both give the same values.
INCREMENTAL_CONTACTS = 500
#: A capacitance I + V^T K^-1 U whose smallest LU pivot is below this fraction of its largest is taken as singular
#: [1]: the new tangent is then factorised (:meth:`.solver.Equilibrium._refactor_fast`), whose own pivot check decides
#: whether it is a mechanism (and the ground springs hold it), so that a singular tangent is never solved by an
#: update that happens to reach the residual on one CPU and not on another.  Measured on 4 x 8 mm (rigid and fem
#: cells, UCS and creep at 160 MPa, 1,174 low-rank tangents): singular tangents (their own factor's pivot ratio
#: <= 7.6e-15) had capacitance pivot ratios <= 6.6e-10, regular ones (>= 2.6e-11) >= 1.5e-7.
CAPACITANCE_PIVOT_RATIO = 1e-8
#: How the K^-1 U columns of a changed contact are made (``numerics.static_update_columns``): "changes" back-substitutes
#: its two U columns (the change of its force rows times its coefficients) for each status it takes; "rows"
#: back-substitutes each of its rows (c_n, c_t, and g_n, g_t where they differ from them) once per reference factor and
#: combines them with the change of its coefficients, skipping rows the change does not touch (a stick/slip change moves
#: the shear coefficients alone: one column).  The same solution to round-off (1e-16 relative per column).
UPDATE_COLUMNS = field_spec("numerics.static_update_columns")["choices"]


def _outer_triplets(g: sp.csr_matrix, c: sp.csr_matrix):
    """(row, col, value, contact) of every contact's outer product g_i^T c_i (rows of equal length)."""
    g, c = g.tocsr(), c.tocsr()
    gi, ci = np.diff(g.indptr), np.diff(c.indptr)
    rows, cols, vals, who = [], [], [], []
    for ng in np.unique(gi):            # contacts grouped by their rows' lengths: vectorised per group
        for nc in np.unique(ci[gi == ng]):
            sel = np.flatnonzero((gi == ng) & (ci == nc))
            if not len(sel) or ng == 0 or nc == 0:
                continue
            gidx = g.indptr[sel][:, None] + np.arange(ng)
            cidx = c.indptr[sel][:, None] + np.arange(nc)
            r = np.repeat(g.indices[gidx], nc, axis=1)
            v1 = np.repeat(g.data[gidx], nc, axis=1)
            cc = np.tile(c.indices[cidx], (1, ng))
            v2 = np.tile(c.data[cidx], (1, ng))
            rows.append(r.ravel()), cols.append(cc.ravel()), vals.append((v1 * v2).ravel())
            who.append(np.repeat(sel, ng * nc))
    if not rows:
        z = np.zeros(0, int)
        return z, z, np.zeros(0), z
    return np.concatenate(rows), np.concatenate(cols), np.concatenate(vals), np.concatenate(who)


def _index_array(a: np.ndarray) -> np.ndarray:
    """``a`` (indices of a compressed sparse matrix) as 32-bit integers where they fit, as scipy would store them:
    a matrix built from them then skips scipy's scan of every index for the narrower type (the values and every
    product are the same)."""
    return a.astype(np.int32) if len(a) and a.max() < np.iinfo(np.int32).max else a


class TangentPattern:
    """The tangent K(s) of a network on one sparsity pattern (CSC, column-major), assembled from coefficients."""

    #: The six (force row, kinematic row, coefficient) terms: intact bonds through G, broken contacts through C.
    TERMS = (("gn", "cn", "nn"), ("gt", "cn", "sn"), ("gt", "ct", "ss"),
             ("cn", "cn", "nn"), ("ct", "cn", "sn"), ("ct", "ct", "ss"))

    def __init__(self, net):
        self.net, n = net, net.ndof
        kg = net.k_grain.tocoo()
        parts = [(kg.row, kg.col, kg.data, None)]
        trip = []
        for gname, cname, _ in self.TERMS:
            r, c, v, w = _outer_triplets(getattr(net, gname), getattr(net, cname))
            trip.append((r, c, v, w))
            parts.append((r, c, v, w))
        diag = np.arange(n)
        keys = np.concatenate([p[1].astype(np.int64) * n + p[0] for p in parts] + [diag * n + diag])
        uniq, inv = np.unique(keys, return_inverse=True)
        self.row, self.col = (uniq % n).astype(np.int64), (uniq // n).astype(np.int64)
        self.nnz = len(uniq)
        self.indptr = np.searchsorted(self.col, np.arange(n + 1))
        off = len(kg.row)
        self.base = np.bincount(inv[:off], weights=kg.data.astype(float), minlength=self.nnz).astype(float)
        self.maps = []
        for r, c, v, w in trip:
            pos = inv[off:off + len(r)]
            off += len(r)
            self.maps.append(sp.csr_matrix((v.astype(float), (pos, w)), shape=(self.nnz, net.n_bonds)))
        # the pattern's entries each contact touches (in any term): a contact's column of the union of the maps
        touch = sum(abs(mp) for mp in self.maps).tocsc()
        self._touch = (touch.indptr, touch.indices)
        self._free_cache = {}
        self._last = None       # (coefficients, values) of the last assembly

    def shift_diagonal(self, delta: np.ndarray) -> None:
        """Add ``delta`` (ndof,) to the diagonal of the constant part (every later assembly's values); the last
        assembly, which :meth:`data` would otherwise update from, is forgotten."""
        diag = np.flatnonzero(self.row == self.col)
        self.base = self.base.copy()
        self.base[diag] += delta[self.row[diag]]
        self._last = None

    def data(self, a_nn, a_sn, a_ss, broken):
        """The pattern's values at these per-contact coefficients (``broken``: rows C instead of G).

        Every entry is base + sum over the six terms of (map row . its coefficients), in that order.  Where at
        most :data:`INCREMENTAL_CONTACTS` contacts differ from the last assembly (the base changes only through
        :meth:`shift_diagonal`, which forgets it) only the entries
        they touch are summed again, by the same rows in the same order: the values are those of a full
        assembly, bit for bit."""
        coef = (a_nn, a_sn, a_ss, broken)
        last = self._last
        changed = None
        if last is not None:
            changed = np.flatnonzero(np.any([x != y for x, y in zip(coef, last[0])], axis=0))
        if changed is None or len(changed) > INCREMENTAL_CONTACTS:
            d = self._sum(None, *coef)
        else:
            d = last[1].copy()
            indptr, indices = self._touch
            rows = np.unique(np.concatenate([indices[indptr[i]:indptr[i + 1]] for i in changed] + [indices[:0]]))
            d[rows] = self._sum(rows, *coef)
        self._last = (tuple(np.array(x, copy=True) for x in coef), d)
        return d

    def _sum(self, rows, a_nn, a_sn, a_ss, broken):
        """The values of the pattern's entries ``rows`` (sorted; None: all of them): base, then each term's rows
        times its coefficients (intact bonds through G, broken contacts through C)."""
        full = rows is None
        intact = ~broken
        coef = {"nn": a_nn, "sn": a_sn, "ss": a_ss}
        d = self.base.copy() if full else self.base[rows]
        for (g, _, name), mp in zip(self.TERMS, self.maps):
            w = np.where(broken, coef[name], 0.0) if g in ("cn", "ct") else np.where(intact, coef[name], 0.0)
            d += (mp if full else mp[rows]) @ w
        return d

    def full(self, data) -> sp.csc_matrix:
        n = self.net.ndof
        return sp.csc_matrix((data, self.row, self.indptr), shape=(n, n))

    def free_block(self, data, fixed) -> sp.csc_matrix:
        """The free x free block (CSC) of the tangent with these values."""
        key = fixed.tobytes()
        sel = self._free_cache.get(key)
        if sel is None:
            free = ~fixed
            fmap = np.cumsum(free) - 1
            take = np.flatnonzero(free[self.row] & free[self.col])
            nf = int(free.sum())
            indptr = np.searchsorted(fmap[self.col[take]], np.arange(nf + 1))
            sel = (take, _index_array(fmap[self.row[take]]), _index_array(indptr), nf)
            if len(self._free_cache) > 64:
                self._free_cache.clear()
            self._free_cache[key] = sel
        take, rows, indptr, nf = sel
        return sp.csc_matrix((data[take], rows, indptr), shape=(nf, nf))

    def coupling(self, data, fixed) -> sp.csc_matrix:
        """The free x fixed block (CSC) of the tangent with these values."""
        key = b"c" + fixed.tobytes()
        sel = self._free_cache.get(key)
        if sel is None:
            free = ~fixed
            fmap, xmap = np.cumsum(free) - 1, np.cumsum(fixed) - 1
            take = np.flatnonzero(free[self.row] & fixed[self.col])
            nx = int(fixed.sum())
            indptr = np.searchsorted(xmap[self.col[take]], np.arange(nx + 1))
            sel = (take, _index_array(fmap[self.row[take]]), _index_array(indptr), (int(free.sum()), nx))
            self._free_cache[key] = sel
        take, rows, indptr, shape = sel
        return sp.csc_matrix((data[take], rows, indptr), shape=shape)


class LowRankSolver:
    """Solves with a tangent K' = K + U V^T on the reference factor of K (Woodbury), refined against K' (module doc).
    ``coef`` per contact: (a_nn, a_sn, a_ss, broken) of the reference; ``free`` its free dofs.

    The K^-1 U columns are kept per contact and status as n x 2 blocks and never concatenated into one n x 2r
    array: the capacitance I + V^T Z reads only the rows of Z that V^T touches (a few per contact), and Z s in a
    solve is a sum over the blocks.  The columns of the contacts met for the first time in a :meth:`prepare` are
    computed by one back-substitution of all their U columns together."""

    def __init__(self, net, lu, coef, free, max_contacts=MAX_LOW_RANK_CONTACTS, columns="changes",
                 rows_kinematic=False):
        self.net, self.lu, self.coef, self.free, self.max_contacts = net, lu, coef, free, max_contacts
        #: :data:`UPDATE_COLUMNS`; ``rows_kinematic``: the force rows equal the kinematic rows (fem cells)
        self.columns, self.rows_kinematic = columns, bool(rows_kinematic)
        self._z = {}            # (contact, coefficients) -> K^-1 U columns (n x 2, free dofs)
        self._y = {}            # columns "rows": (contact, row kind 0 c_n, 1 c_t, 2 g_n, 3 g_t) -> K^-1 of that row
        #: the keys of every back-substitution of U columns, in the order and blocks they were computed (what
        #: :meth:`replay` repeats to rebuild :attr:`_z` bit for bit: a block's columns are solved together)
        self.blocks = []
        #: Columns back-substituted on the reference factor (each U column counts one, whether solved alone or
        #: in a block with others; each solve of a right-hand side counts one).
        self.back_substitutions = 0
        self.direct_residual = 0.0  # the largest relative residual of a direct solve on this factor
        cols = np.flatnonzero(free)
        m = net.n_bonds
        # rows restricted to the free dofs, once per reference: 0..m-1 c_n, m..2m-1 c_t, then g_n, g_t
        self._rows = sp.vstack([net.cn, net.ct, net.gn, net.gt]).tocsc()[:, cols].tocsr()
        self._m = m

    @staticmethod
    def _key(i, new):
        return (int(i),) + tuple(float(x) for x in new[:3]) + (bool(new[3]),)

    def _u(self, i, new):
        """The two U columns (w_n, w_t) of contact i going from its reference coefficients to ``new``."""
        old = tuple(c[i] for c in self.coef)
        m = self._m
        dense = self._rows[[i, m + i, 2 * m + i, 3 * m + i]].toarray()

        def rows(broken):
            return (dense[0], dense[1]) if broken else (dense[2], dense[3])
        gn1, gt1 = rows(new[3])
        gn0, gt0 = rows(old[3])
        wn = new[0] * gn1 + new[1] * gt1 - old[0] * gn0 - old[1] * gt0
        wt = new[2] * gt1 - old[2] * gt0
        return wn, wt

    def _columns(self, contacts, coefs):
        """The K^-1 U blocks (n x 2) of these contacts at these coefficients: cached ones as they are, the others
        by one back-substitution of all their U columns (n x 2k) on the reference factor, then cached."""
        keys = [self._key(i, c) for i, c in zip(contacts, coefs)]
        miss = [j for j, k in enumerate(keys) if k not in self._z]
        if miss and self.columns == "rows":
            self._columns_from_rows([contacts[j] for j in miss], [coefs[j] for j in miss], [keys[j] for j in miss])
        elif miss:
            u = np.empty((self.lu.shape[0], 2 * len(miss)), order="F")
            for q, j in enumerate(miss):
                u[:, 2 * q], u[:, 2 * q + 1] = self._u(contacts[j], coefs[j])
            z = self.lu.solve(u)
            self.back_substitutions += u.shape[1]
            for q, j in enumerate(miss):
                self._z[keys[j]] = z[:, 2 * q:2 * q + 2]
        if miss:
            self.blocks.append([keys[j] for j in miss])
        return [self._z[k] for k in keys]

    def _row_terms(self, i, new):
        """{row kind: (coefficient in w_n, coefficient in w_t)} of contact i going from its reference coefficients to
        ``new`` (:meth:`_u` by rows: w_n = a_nn' g_n' + a_sn' g_t' - a_nn g_n - a_sn g_t, w_t = a_ss' g_t' - a_ss g_t,
        g the kinematic rows once broken); rows with both coefficients zero left out."""
        old = tuple(c[i] for c in self.coef)
        terms = {}

        def add(kind, cn, ct):
            if self.rows_kinematic:
                kind %= 2
            a, b = terms.get(kind, (0.0, 0.0))
            terms[kind] = (a + cn, b + ct)
        for sign, (a_nn, a_sn, a_ss, broken) in ((1.0, new), (-1.0, old)):
            n_kind, t_kind = (0, 1) if broken else (2, 3)
            add(n_kind, sign * a_nn, 0.0)
            add(t_kind, sign * a_sn, sign * a_ss)
        return {k: v for k, v in sorted(terms.items()) if v[0] != 0.0 or v[1] != 0.0}

    def _columns_from_rows(self, contacts, coefs, keys):
        """The K^-1 U blocks of these contacts (columns "rows", :data:`UPDATE_COLUMNS`): the rows not yet solved on
        this factor by one back-substitution together, then each block combined from its contact's rows."""
        terms = [self._row_terms(i, c) for i, c in zip(contacts, coefs)]
        need = list(dict.fromkeys((int(i), kind) for i, t in zip(contacts, terms) for kind in t
                                  if (int(i), kind) not in self._y))
        if need:
            m, n = self._m, self.lu.shape[0]
            u = np.empty((n, len(need)), order="F")
            for q, (i, kind) in enumerate(need):
                u[:, q] = self._rows[kind * m + i].toarray().ravel()
            y = self.lu.solve(u)
            self.back_substitutions += len(need)
            for q, key in enumerate(need):
                self._y[key] = y[:, q]
        for i, t, key in zip(contacts, terms, keys):
            z = np.zeros((self.lu.shape[0], 2), order="F")
            for kind, (cn, ct) in t.items():
                y = self._y[(int(i), kind)]
                if cn != 0.0:
                    z[:, 0] += cn * y
                if ct != 0.0:
                    z[:, 1] += ct * y
            self._z[key] = z

    def column_table(self) -> np.ndarray:
        """(k, 6) the keys of :attr:`blocks` as rows (block, contact, a_nn, a_sn, a_ss, broken): exact doubles."""
        rows = [(b,) + key for b, keys in enumerate(self.blocks) for key in keys]
        return np.array(rows, float).reshape(-1, 6)

    def replay(self, table: np.ndarray) -> None:
        """Compute the K^-1 U columns of :meth:`column_table`'s rows block by block, as they were first computed:
        the same right-hand sides in the same blocks on the same factor give the same columns, bit for bit."""
        table = np.asarray(table, float).reshape(-1, 6)
        for b in np.unique(table[:, 0]):
            rows = table[table[:, 0] == b]
            self._columns([int(r[1]) for r in rows], [(r[2], r[3], r[4], bool(r[5])) for r in rows])

    def prepare(self, coef_new):
        """The low-rank operator for the new coefficients, or None where it is not worth it (too many changes)."""
        old_nn, old_sn, old_ss, old_b = self.coef
        a_nn, a_sn, a_ss, b = coef_new
        changed = np.flatnonzero((a_nn != old_nn) | (a_sn != old_sn) | (a_ss != old_ss) | (b != old_b))
        if len(changed) > self.max_contacts:
            return None
        if not len(changed):
            return _Woodbury(self, None, None, None)
        blocks = self._columns(changed, [(a_nn[i], a_sn[i], a_ss[i], b[i]) for i in changed])
        # V's columns per contact are (c_n, c_t), interleaved to match U's (w_n, w_t) per contact
        r = len(changed)
        order = np.empty(2 * r, int)
        order[0::2], order[1::2] = changed, self._m + changed
        vt = self._rows[order]
        # V^T Z on the rows of Z that V^T touches: the same stored entries in the same order, so the same sums
        used, local = np.unique(vt.indices, return_inverse=True)
        zg = np.empty((len(used), 2 * r))
        for j, zj in enumerate(blocks):     # column by column: each a contiguous array (twice as fast as rows)
            zg[:, 2 * j] = zj[:, 0][used]
            zg[:, 2 * j + 1] = zj[:, 1][used]
        vt_used = sp.csr_matrix((vt.data, local.reshape(-1).astype(vt.indices.dtype), vt.indptr),
                                shape=(2 * r, len(used)))
        cap = np.eye(2 * r) + vt_used @ zg
        try:
            with warnings.catch_warnings():     # a singular capacitance (a mechanism) is refused just below
                warnings.simplefilter("ignore", sla.LinAlgWarning)
                lu_cap = sla.lu_factor(cap, check_finite=True)
        except (ValueError, np.linalg.LinAlgError):
            return None
        pivots = np.abs(np.diag(lu_cap[0]))
        if not np.all(np.isfinite(lu_cap[0])) or pivots.min() <= CAPACITANCE_PIVOT_RATIO * pivots.max():
            return None
        return _Woodbury(self, blocks, vt, lu_cap)


class _Woodbury:
    def __init__(self, owner, z, vt, lu_cap):
        self.owner, self.z, self.vt, self.lu_cap = owner, z, vt, lu_cap    # z: the K^-1 U blocks (n x 2 each)

    def apply(self, rhs):
        y = self.owner.lu.solve(rhs)
        self.owner.back_substitutions += 1
        if self.z is None:
            return y
        s = sla.lu_solve(self.lu_cap, self.vt @ y)
        for j, zj in enumerate(self.z):     # y - Z s, block by block (no n x 2r copy)
            y -= zj @ s[2 * j:2 * j + 2]
        return y

    def direct(self, kff, rhs):
        """The plain solve on the reference factor (``kff`` is its tangent); its residual is recorded."""
        x = self.apply(rhs)
        scale = np.abs(rhs).max()
        if scale > 0 and np.all(np.isfinite(x)):
            res = np.abs(kff @ x - rhs).max() / scale
            self.owner.direct_residual = max(self.owner.direct_residual, res)
        return x

    def solve(self, kff, rhs):
        """x with a relative residual within the accepted level (module constants), or None."""
        scale = max(np.abs(rhs).max(), 1e-300)
        accept = max(FAST_RESIDUAL, RESIDUAL_MARGIN * self.owner.direct_residual) * scale
        x = self.apply(rhs)
        last = np.inf
        for _ in range(MAX_REFINEMENT + 1):
            if not np.all(np.isfinite(x)):
                return None
            res = rhs - kff @ x
            r = np.abs(res).max()
            if r <= accept:
                return x
            if r > REFINEMENT_GAIN * last:
                return None
            last = r
            x = x + self.apply(res)
        return None
