"""What condensing each fem cell's interior nodes out of the static system would save: SuperLU's factor and one
back-substitution of the intact free block, in full and as the exact Schur complement on the nodes that bonds and
platens touch (each cell's interior is linear elastic and coupled only to its own boundary, so its complement is
made once, cell by cell).  One thread; prints what docs/studies/model_convergence.md ("Cost at the converged
discretisation") tabulates.  Built since as ``numerics.static_condensation = "cell_interiors"``
(grainfrac_yade/engines/static/condensation.py).

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.fem_condensation --width 10e-3 --height 20e-3 [--set KEY=VALUE ...]

Defaults: ``params/presets/fem.toml`` with K = 8 bonds a face and 4 rings graded 2, seed 1.  Times are CPU seconds
(``time.process_time``); the agreement line is the condensed solve against the full one on the boundary dofs.
"""
import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from grainfrac_yade.api import build_specimen, load_parameters
from grainfrac_yade.engines.static import contacts as cl
from grainfrac_yade.engines.static.factoring import FAST_FACTOR_OPTIONS
from grainfrac_yade.engines.static.network import build_static_network
from grainfrac_yade.engines.static.solver import Equilibrium
from grainfrac_yade.grains import layout_for

CONVERGED = [("resolution.nodes_per_face", 8), ("resolution.cell_rings", 4), ("resolution.cell_ring_growth", 2.0)]


def _timed(fn, repeat=1):
    t = time.process_time()
    for _ in range(repeat):
        out = fn()
    return out, (time.process_time() - t) / repeat


def condensed(k, boundary, interior, cell_of_interior):
    """The Schur complement K_bb - K_bi K_ii^-1 K_ib, cell by cell (K_ii is block-diagonal by cell)."""
    kbb, kbi, kii = k[boundary][:, boundary], k[boundary][:, interior].tocsc(), k[interior][:, interior].tocsc()
    rows, cols, vals = [], [], []
    for c in np.unique(cell_of_interior):
        e = np.flatnonzero(cell_of_interior == c)
        coupling = kbi[:, e]
        touched = np.unique(coupling.indices)
        x = spla.splu(kii[e][:, e].tocsc()).solve(coupling[touched].T.toarray())
        r, q = np.meshgrid(touched, touched, indexing="ij")
        rows.append(r.ravel()), cols.append(q.ravel()), vals.append(-np.asarray(coupling[touched] @ x).ravel())
    schur = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=kbb.shape)
    return (kbb + schur).tocsc()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--width", type=float, default=10e-3)
    ap.add_argument("--height", type=float, default=20e-3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--set", dest="overrides", action="append", default=[])
    a = ap.parse_args(argv)
    p = load_parameters(extra_files=["params/presets/fem.toml"],
                        overrides=[("specimen.width", a.width), ("specimen.height", a.height), *CONVERGED,
                                   *a.overrides])
    spec = build_specimen(p, a.seed)
    net = build_static_network(spec, p, layout_for(spec, p))
    eq, m = Equilibrium(net), net.n_bonds
    status = np.full(m, cl.INTACT)
    k = eq.tangent(status, np.ones(m), np.zeros(m)).tocsr()
    free = ~eq.fixed_dofs(status)[0]
    touched = np.zeros(len(net.node_pos), bool)
    touched[net.bond_nodes.ravel()] = True
    touched |= net.top | net.bottom
    node_of_dof = np.full(net.ndof, -1)
    for col in range(3):
        ok = net.dofs[:, col] >= 0
        node_of_dof[net.dofs[ok, col]] = np.flatnonzero(ok)
    boundary = np.flatnonzero(free & touched[node_of_dof])
    interior = np.flatnonzero(free & ~touched[node_of_dof])
    print(f"dofs {net.ndof}, free {free.sum()}, boundary {len(boundary)} ({len(boundary) / free.sum():.2f})")
    kff = k[free][:, free].tocsc()
    rhs = np.random.default_rng(0).standard_normal(kff.shape[0])
    lu, t_factor = _timed(lambda: spla.splu(kff, **FAST_FACTOR_OPTIONS))
    x_full, t_solve = _timed(lambda: lu.solve(rhs), 20)
    print(f"full: factor {t_factor:.3f} s, one back-substitution {1e3 * t_solve:.2f} ms, L+U {lu.L.nnz + lu.U.nnz}")
    kbb, t_condense = _timed(lambda: condensed(k, boundary, interior, net.node_cell[node_of_dof[interior]]))
    at = np.searchsorted(np.flatnonzero(free), boundary)
    b = np.zeros_like(rhs)
    b[at] = rhs[at]
    lub, t_factor = _timed(lambda: spla.splu(kbb, **FAST_FACTOR_OPTIONS))
    xb, t_solve = _timed(lambda: lub.solve(b[at]), 20)
    x_full = lu.solve(b)[at]
    print(f"condensed: factor {t_factor:.3f} s, one back-substitution {1e3 * t_solve:.2f} ms, L+U "
          f"{lub.L.nnz + lub.U.nnz}, condensation once {t_condense:.2f} s; agreement "
          f"{np.abs(xb - x_full).max() / np.abs(x_full).max():.1e}")


if __name__ == "__main__":
    main()
