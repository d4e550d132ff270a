"""Probe: the static UCS path where a broken face loses contact once its spheres slide apart (no YADE).

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.static_contact_loss_probe --params params/presets/fem.toml --seed 1

YADE's fem cells hold a broken face in contact through the smooth joint of its two corner spheres only while
they overlap: once the spheres' centres are farther apart than the sum of their radii
(:func:`grainfrac_yade.grains.fem.contact_radii`) the interaction ends, and the face carries nothing there
any more.  The static engine's contacts keep their rows for ever (small strain).  This probe follows the static
path and, after every converged state, drops the broken contacts whose spheres (initial centres plus the nodes'
displacements) no longer overlap (their stiffnesses set to zero, so they carry nothing from then on), re-solves
at the same closure and runs the cascade; new contacts between spheres that come together are not made.  The
question: does the loss of sliding contacts give the static path the peak that YADE's fem specimen shows?
"""
from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np

from grainfrac_yade.engines.static import contacts as cl
from grainfrac_yade.engines.static.cascade import Path
from grainfrac_yade.engines.static.solver import Equilibrium
from studies.static_engine_probe import specimen_arguments, specimen_layout
from grainfrac_yade.engines.static.ucs import ucs_path


class LossPath(Path):
    def __init__(self, eq, radius_sum, reach=1.0):
        super().__init__(eq)
        n = self.net
        self.a, self.b = n.bond_nodes[:, 0], n.bond_nodes[:, 1]
        self.reach = radius_sum * reach
        self.lost = np.zeros(n.n_bonds, bool)
        self.loss_log = []

    def _distance(self, u):
        n = self.net
        ux = np.where(n.dofs[:, 0] >= 0, u[n.dofs[:, 0]], 0.0)
        uy = np.where(n.dofs[:, 1] >= 0, u[n.dofs[:, 1]], 0.0)
        pos = n.node_pos + np.stack([ux, uy], axis=1)
        return np.linalg.norm(pos[self.b] - pos[self.a], axis=1)

    def _drop(self, state):
        n = self.net
        while True:
            new = state.broken & ~self.lost & (self._distance(state.u) > self.reach)
            if not new.any():
                return state
            self.lost |= new
            n.kn[new], n.ks[new] = 0.0, 0.0
            self.eq.forget_factor()
            base = state.copy()
            base.status[new] = cl.OPEN
            self.loss_log.append((state.closure / n.height, state.stress / 1e6, int(new.sum())))
            state = self.eq.solve(state.closure, base)
            state = super().cascade(state)

    def step(self, state, target=None, max_closure=math.inf):
        new, what = super().step(state, target, max_closure)
        if what == "none":
            return new, what
        return self._drop(new), what


def main(argv=None):
    ap = specimen_arguments(argparse.ArgumentParser())
    ap.add_argument("--reach", type=float, default=1.0, help="contact lost beyond this x the radii's sum")
    ap.add_argument("--max-strain", type=float, default=0.008)
    a = ap.parse_args(argv)
    p, s, lay, net = specimen_layout(a)
    rsum = lay.sphere_radius[net.bond_nodes[:, 0]] + lay.sphere_radius[net.bond_nodes[:, 1]]
    eq = Equilibrium(net)
    path = LossPath(eq, rsum, a.reach)
    t0 = time.process_time()
    r = ucs_path(eq, a.max_strain, p.ucs.stop_stress_ratio, path=path)
    print(json.dumps({"seed": a.seed, "reach": a.reach, "width": a.width, "height": a.height,
                      "peak_mpa": r.peak_stress / 1e6, "peak_strain": r.peak_strain, "end": r.end[:200],
                      "broken_at_peak": r.broken_at_peak, "broken_end": int(r.broken[-1]) if len(r.broken) else 0,
                      "bonds": net.n_bonds, "contacts_lost": int(path.lost.sum()),
                      "first_losses": path.loss_log[:5], "cpu_s": time.process_time() - t0}), flush=True)


if __name__ == "__main__":
    main()
