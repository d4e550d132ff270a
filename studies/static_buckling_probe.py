"""Probe: is the static path's equilibrium stable once the grains' stresses act on their rotations? (no YADE)

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.static_buckling_probe --params params/presets/fem.toml \
        --width 10e-3 --height 20e-3 --seed 1 --strains 0.001,0.002,0.003,0.004,0.005,0.006

Follows the static UCS path (:mod:`grainfrac_yade.engines.static.ucs`'s sequentially linear path, small strain) and, at
each strain asked, computes the critical load factor lambda of the linearised buckling problem

    (K_t + lambda K_sigma) phi = 0   on the free dofs,

K_t the path's tangent at that state (its contact statuses), K_sigma the geometric stiffness of the fem cells'
constant-strain triangles under their current stress (per triangle t A grad N_i . sigma . grad N_j on each of the
two displacement components).  lambda > 1: the state is stable; lambda <= 1: the load it carries buckles it (a
limit point of the path in large displacements).  The contacts' own geometric terms (their forces turning with
their faces) are left out: a face contact's two nodes sit at one point, so a rigid turn of the face moves no
moment through it.  Prints one JSON line per strain.
"""
from __future__ import annotations

import argparse
import json
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from grainfrac_yade.elastic import _triangle_b, build_network
from grainfrac_yade.engines.static.cascade import Path
from grainfrac_yade.engines.static.solver import Equilibrium
from studies.static_engine_probe import specimen_arguments, specimen_layout

#: Eigenvalues of K_t^-1 (-K_sigma) asked of ARPACK [1]: the largest few (the smallest load factors).
EIGENVALUES = 4


def geometric_stiffness(tri_nodes, bm, area, tri_stiffness, dofs, u, ndof):
    """(ndof, ndof) K_sigma of the triangles at displacements u (tension positive stresses x thickness)."""
    idx = dofs[tri_nodes][:, :, :2].reshape(-1, 6)
    ue = u[idx]                                          # (e, 6)
    st = np.einsum("eij,ejk,ek->ei", tri_stiffness, bm, ue)      # (e, 3): sxx t, syy t, sxy t [N/m]
    # grad N_i: from B's rows (B[0, 2i] = dN_i/dx, B[1, 2i+1] = dN_i/dy)
    gx, gy = bm[:, 0, 0::2], bm[:, 1, 1::2]              # (e, 3)
    sxx, syy, sxy = st[:, 0], st[:, 1], st[:, 2]
    kij = area[:, None, None] * (sxx[:, None, None] * gx[:, :, None] * gx[:, None, :]
                                 + syy[:, None, None] * gy[:, :, None] * gy[:, None, :]
                                 + sxy[:, None, None] * (gx[:, :, None] * gy[:, None, :] + gy[:, :, None] * gx[:, None, :]))
    rows, cols, vals = [], [], []
    for a in range(2):
        da = dofs[tri_nodes][:, :, a]                    # (e, 3)
        rows.append(np.repeat(da, 3, axis=1).ravel())
        cols.append(np.tile(da, (1, 3)).ravel())
        vals.append(kij.ravel())
    return sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(ndof, ndof)).tocsc()


def load_factor(eq, state, kg):
    """Smallest positive critical load factor of ``state`` (and the next ones) with K_sigma ``kg``."""
    fixed, _, _ = eq.fixed_dofs(state.status)
    free = ~fixed
    kt = eq.tangent(state.status, state.sign, state.s_p)[free][:, free].tocsc()
    ks = (-kg)[free][:, free].tocsc()
    lu = spla.splu(kt, permc_spec="COLAMD")
    op = spla.LinearOperator(kt.shape, matvec=lambda x: lu.solve(ks @ x), dtype=float)
    mu, vec = spla.eigs(op, k=EIGENVALUES, which="LR", tol=1e-8, maxiter=5000)
    order = np.argsort(-mu.real)
    mu, vec = mu[order], vec[:, order]
    lam = [float(1.0 / m.real) if m.real > 0 else float("inf") for m in mu]
    mode = np.abs(vec[:, 0].real)
    share = float((mode ** 2).max() / (mode ** 2).sum())
    participation = float((mode ** 2).sum() ** 2 / (mode ** 4).sum() / len(mode))
    return lam, share, participation


def main(argv=None):
    ap = specimen_arguments(argparse.ArgumentParser())
    ap.add_argument("--strains", default="0.001,0.002,0.003,0.004,0.005,0.006")
    a = ap.parse_args(argv)
    p, s, lay, net = specimen_layout(a)
    enet = build_network(s, p, lay.model, lay)
    if not len(enet.tri_nodes):
        raise SystemExit("static_buckling_probe: needs fem cells (--params params/presets/fem.toml)")
    bm, area = _triangle_b(enet)
    eq = Equilibrium(net)
    path = Path(eq)
    state = eq.initial(0.0)
    for strain in (float(x) for x in a.strains.split(",")):
        t0 = time.process_time()
        state = path.run_closure(state, strain * net.height)
        t1 = time.process_time()
        kg = geometric_stiffness(enet.tri_nodes, bm, area, enet.tri_stiffness, net.dofs, state.u, net.ndof)
        lam, share, part = load_factor(eq, state, kg)
        print(json.dumps({"seed": a.seed, "strain": state.closure / net.height, "stress_mpa": state.stress / 1e6,
                          "broken": int(state.broken.sum()), "bonds": net.n_bonds, "load_factors": lam,
                          "mode_largest_dof_share": share, "mode_participation": part,
                          "path_cpu_s": t1 - t0, "eigen_cpu_s": time.process_time() - t1}), flush=True)


if __name__ == "__main__":
    main()
