"""Static condensation of the fem cells' interior nodes out of the static equilibrium (pure numpy/scipy).

A fem cell's nodes that no bond touches and that do not move with a platen (the inner rings and the centroid of a
cell away from the platens; ``numerics.static_condensation = "cell_interiors"``) carry only the cell's own
constant-strain triangles, which are linear elastic and never break.  With the free dofs split into the boundary b
(every other free dof) and the interior i, the equilibrium at fixed contact statuses s

    [K_bb(s)  K_bi] [u_b]   [r_b]
    [K_ib     K_ii] [u_i] = [r_i]

has K_bi, K_ib and K_ii constant (the grain stiffness alone) and K_ii block-diagonal by cell, so

    (K_bb(s) - K_bi K_ii^-1 K_ib) u_b = r_b - K_bi K_ii^-1 r_i,      u_i = K_ii^-1 (r_i - K_ib u_b):

the exact Schur complement on the boundary dofs (static condensation).  Its constant part -K_bi K_ii^-1 K_ib is made
once, cell by cell, as -W^T W with W = L^-1 K_ib and L the Cholesky factor of the cell's K_ii (symmetric to the
last bit), and added to the grain stiffness of a condensed network (:attr:`CellInteriors.network`: the interior's
rows and columns empty).  The solver's fast path (:mod:`.tangent`: the assembled tangent, its kept SuperLU factor,
the low-rank updates of changed contacts, the refinement) then works on that network with the interior dofs
counted as fixed (:meth:`CellInteriors.split`): every factor and back-substitution is on the boundary dofs alone.
After each converged equilibrium and tangent response (not after each active-set iteration: the statuses read the
boundary alone) the interior displacements are recovered (:meth:`CellInteriors.recover`), so every reader of
the displacement vector (forces, the platen stress, outputs, the inertial relaxation, checkpoints) sees the full
one.  The answers equal the uncondensed ones to round-off (another elimination order; tests/test_static_condensation.py).

A cell cut loose is held whole (:meth:`.solver.Equilibrium.fixed_dofs`): its interior is fixed with it and its Schur
part couples only its own (fixed) boundary dofs, so it changes nothing.  Every prescribed dof (platens, jaws, lateral
pins) is on a boundary node; a fixed set that holds part of a cell's interior cannot be condensed and is refused
(:meth:`CellInteriors.split`).  Rigid cells have no interior node (every node is a bond
node): the parameter check refuses the option with them (:func:`grainfrac_yade.params.fem_only.check_fem_only`).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ...params.schema import field_spec
from .factoring import FAST_FACTOR_OPTIONS

#: ``numerics.static_condensation`` (the schema's choices): "none" = the full free system (every run before the key);
#: "cell_interiors" = the fem cells' interior nodes condensed out of it (module doc).
MODES = field_spec("numerics.static_condensation")["choices"]


def cell_interiors(net, mode: str):
    """The condensation of ``net`` that ``mode`` (:data:`MODES`) asks for: a :class:`CellInteriors`, or None for
    "none" and where no cell has an interior node."""
    if mode not in MODES:
        raise ValueError(f"static condensation must be one of {MODES}, got {mode!r}")
    if mode == "none":
        return None
    cells = CellInteriors(net)
    return cells if len(cells.interior_dofs) else None


class CellInteriors:
    """The exact static condensation of every cell's interior nodes (module doc)."""

    def __init__(self, net):
        self.net = net
        touched = np.zeros(len(net.node_pos), bool)
        touched[net.bond_nodes.ravel()] = True
        touched |= net.top | net.bottom | (net.dofs[:, 2] >= 0)
        inner = np.flatnonzero(~touched)
        dof_ok = net.dofs[inner, :2] >= 0
        #: the interior dofs (sorted) and the cell of each
        self.interior_dofs = net.dofs[inner, :2][dof_ok]
        order = np.argsort(self.interior_dofs)
        self.interior_dofs = self.interior_dofs[order]
        self.interior_cell = np.repeat(net.node_cell[inner], 2)[dof_ok.ravel()][order]
        #: (ndof,) True on the interior dofs
        self.interior = np.zeros(net.ndof, bool)
        self.interior[self.interior_dofs] = True
        k = net.k_grain.tocsr()
        i = self.interior_dofs
        self._k_ib = k[i][:, ~self.interior].tocsr() if len(i) else None    # interior x boundary (all of it)
        self._boundary_dofs = np.flatnonzero(~self.interior)
        self._split_cache = {}
        if not len(i):
            self.network = net
            return
        # block-diagonal by cell (no fill between cells), symmetric positive definite: the fast path's ordering
        # (minimum degree on A^T + A, diagonal pivots) leaves half COLAMD's fill (5 x 10 mm: 0.35 M against 0.69 M
        # entries, one solve 0.9 against 1.2 ms)
        self._lu_ii = spla.splu(k[i][:, i].tocsc(), **FAST_FACTOR_OPTIONS)
        self.network = replace(net, k_grain=self._condensed_grain_stiffness(k))

    def _condensed_grain_stiffness(self, k) -> sp.csr_matrix:
        """K_g on the boundary dofs plus every cell's -K_bi K_ii^-1 K_ib (-W^T W, W = L^-1 K_ib); nothing on the
        interior's rows and columns."""
        kc = k.tocoo()
        keep = ~self.interior[kc.row] & ~self.interior[kc.col]
        rows, cols, vals = [kc.row[keep]], [kc.col[keep]], [kc.data[keep]]
        kr = k[self.interior_dofs].tocsr()
        for c in np.unique(self.interior_cell):
            at = np.flatnonzero(self.interior_cell == c)
            e = self.interior_dofs[at]
            block = kr[at]
            touched = np.unique(block.indices)
            bnd = touched[~self.interior[touched]]
            if not len(bnd):
                continue
            chol = sla.cholesky(block[:, e].toarray(), lower=True)
            w = sla.solve_triangular(chol, block[:, bnd].toarray(), lower=True)
            r, q = np.meshgrid(bnd, bnd, indexing="ij")
            rows.append(r.ravel()), cols.append(q.ravel()), vals.append(-(w.T @ w).ravel())
        n = self.net.ndof
        return sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(n, n)).tocsr()

    def split(self, fixed: np.ndarray):
        """(fixed dofs of the condensed system: ``fixed`` and the interior, the interior dofs to recover: those
        not in ``fixed``).  A cell's interior must be wholly fixed (a cell held whole) or wholly free."""
        key = fixed.tobytes()
        hit = self._split_cache.get(key)
        if hit is None:
            held = fixed[self.interior_dofs]
            part = np.unique(self.interior_cell[held])
            if np.isin(self.interior_cell[~held], part).any():
                raise ValueError("static condensation: a fixed set holds part of a cell's interior; the interior "
                                 "is condensed out whole (numerics.static_condensation = \"none\" solves it)")
            if len(self._split_cache) > 64:
                self._split_cache.clear()
            hit = self._split_cache[key] = (fixed | self.interior, ~held)
        return hit[0].copy(), hit[1]

    def load(self, f: np.ndarray) -> np.ndarray:
        """(ndof,) the condensed load: ``f`` on the boundary less K_bi K_ii^-1 f_i, nothing on the interior."""
        fi = f[self.interior_dofs]
        if not fi.any():
            return f
        out = f.copy()
        out[self._boundary_dofs] -= self._k_ib.T @ self._lu_ii.solve(fi)
        out[self.interior_dofs] = 0.0
        return out

    def recover(self, u: np.ndarray, f, free: np.ndarray) -> None:
        """Write u_i = K_ii^-1 (f_i - K_ib u_b) into ``u`` (ndof,) on the interior dofs marked ``free`` (the
        :meth:`split`'s second answer); ``f``: the load of the solve (None: no load)."""
        r = -(self._k_ib @ u[self._boundary_dofs])
        if f is not None:
            r += f[self.interior_dofs]
        u[self.interior_dofs[free]] = self._lu_ii.solve(r)[free]
