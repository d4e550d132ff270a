"""Probe: the static UCS path with the cascades relaxed by small-strain explicit dynamics in the core (no YADE).

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.static_dynamics_probe --params params/presets/fem.toml --seed 1 \
        [--damping 0.2] [--handover 1]

Between breaks the path is the static engine's.  Where a break's static cascade would break more than
``--handover`` bonds, the cascade is instead relaxed dynamically from the state just before that break: the bond
breaks suddenly and the network moves by central differences with lumped masses (fem nodes: density x thickness
x a third of each triangle's area), the platens held at the closure, Cundall's non-viscous damping D on every dof,
the same contact law step by step (intact bonds linear and broken at paper Eq. 4-5 as soon as they reach it;
broken contacts compression only, residual friction by the return mapping from the last step).  It ends when the
mean unbalanced force over the free dofs falls below ``--rest`` of the mean intact bond force (after at least one
wave crossing) or after ``--budget`` steps; the static equilibrium with the bonds broken so is then solved at the
closure, its own cascade run, and the path goes on.  The question: do small-strain dynamics alone give the fem
specimen the UCS peak that YADE shows (docs/studies/static_validation.md) and the static path does not?
"""
from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np

from grainfrac_yade.elastic import _triangle_b, build_network
from grainfrac_yade.engines.static import contacts as cl
from grainfrac_yade.engines.static.cascade import Path
from grainfrac_yade.engines.static.solver import Equilibrium
from studies.static_engine_probe import specimen_arguments, specimen_layout
from grainfrac_yade.engines.static.ucs import ucs_path

#: Fraction of the critical step (Gershgorin bound on M^-1 K) [1].
STEP_SAFETY = 0.8
#: Steps between equilibrium checks [1] (creep.check_period).
CHECK_PERIOD = 50


def node_masses(enet, s, p, ndof, dofs):
    bm, area = _triangle_b(enet)
    rho = np.array([p.grains[m].density for m in s.mineral_names])[s.mineral[enet.node_cell[enet.tri_nodes[:, 0]]]]
    m_node = np.zeros(len(enet.node_pos))
    np.add.at(m_node, enet.tri_nodes.ravel(), np.repeat(rho * area * s.thickness / 3.0, 3))
    m = np.zeros(ndof)
    for c in range(2):
        ok = dofs[:, c] >= 0
        m[dofs[ok, c]] = m_node[ok]
    return m


class DynamicStint:
    """Small-strain explicit dynamics of the static network at a fixed closure (module doc)."""

    def __init__(self, eq, masses, damping, rest, budget, min_steps_factor=1.0):
        self.eq, self.net = eq, eq.net
        n = self.net
        self.m = masses
        k_intact = eq.tangent(np.full(n.n_bonds, cl.INTACT), np.ones(n.n_bonds), np.zeros(n.n_bonds))
        gersh = np.asarray(abs(k_intact).sum(axis=1)).ravel()
        self.dt = STEP_SAFETY * 2.0 / math.sqrt((gersh / np.where(masses > 0, masses, np.inf)).max())
        self.damping, self.rest, self.budget = damping, rest, budget
        # steps for a P wave to cross the height: c = sqrt(E / rho)
        c = math.sqrt(70e9 / 2650.0)
        self.min_steps = int(min_steps_factor * n.height / c / self.dt)
        self.steps_total, self.stints = 0, 0

    def run(self, state, newly_broken, jt, jc):
        n, eq = self.net, self.eq
        fixed = eq.platen_fixed
        free = ~fixed
        u, v = state.u.copy(), np.zeros(n.ndof)
        broken, status, sign, s_p = state.broken.copy(), state.status.copy(), state.sign.copy(), state.s_p.copy()
        for b in newly_broken:
            dn, ds = n.cn[b] @ u, n.ct[b] @ u
            st, sg, sp_ = cl.break_state(np.atleast_1d(dn), np.atleast_1d(ds), np.atleast_1d(state.fs[b]),
                                         n.kn[b:b + 1], n.ks[b:b + 1], n.tan_residual[b:b + 1])
            broken[b], status[b], sign[b], s_p[b] = True, st[0], sg[0], sp_[0]
        mode = state.break_mode.copy()
        order = []
        gn, gt = eq.summed_rows(broken)
        inv_m = np.where(free & (self.m > 0), 1.0 / np.where(self.m > 0, self.m, 1.0), 0.0)
        steps = 0
        while steps < self.budget:
            dn, ds = n.cn @ u, n.ct @ u
            # intact bonds
            fn = np.where(broken, 0.0, n.kn * dn)
            fs = np.where(broken, 0.0, n.ks * ds)
            hit = cl.failing(fn, fs, n.area, jt, jc, n.tan_friction) & ~broken
            if hit.any():
                idx = np.flatnonzero(hit)
                r, md = cl.overstress(fn, fs, n.area, jt, jc, n.tan_friction)
                st, sg, sp_ = cl.break_state(dn[idx], ds[idx], fs[idx], n.kn[idx], n.ks[idx], n.tan_residual[idx])
                broken[idx], status[idx], sign[idx], s_p[idx], mode[idx] = True, st, sg, sp_, md[idx]
                order.extend(idx[np.argsort(-r[idx], kind="stable")].tolist())
                gn, gt = eq.summed_rows(broken)
            # broken contacts: compression only, friction by return mapping from the last step
            fnb = n.kn * np.minimum(dn, 0.0)
            trial = n.ks * (ds - s_p)
            cap = -fnb * n.tan_residual
            fsb = np.clip(trial, -cap, cap)
            openc = dn > 0
            fsb = np.where(openc, 0.0, fsb)
            s_p = np.where(broken, np.where(openc, ds, ds - fsb / n.ks), s_p)
            fn = np.where(broken, fnb, fn)
            fs = np.where(broken, fsb, fs)
            r_int = n.k_grain @ u + gn.T @ fn + gt.T @ fs
            f = eq.f_ext - r_int
            f[fixed] = 0.0
            fd = f * (1.0 - self.damping * np.sign(f * v))
            v += self.dt * fd * inv_m
            u += self.dt * v
            steps += 1
            if steps >= self.min_steps and steps % CHECK_PERIOD == 0:
                # the creep protocol's check: mean resultant force on the free nodes over the mean intact bond force
                fx = np.where(n.dofs[:, 0] >= 0, f[n.dofs[:, 0]], 0.0)
                fy = np.where(n.dofs[:, 1] >= 0, f[n.dofs[:, 1]], 0.0)
                moving = ~(n.top | n.bottom)
                unb = np.hypot(fx, fy)[moving].mean()
                ref = np.hypot(fn, fs)[~broken].mean() if (~broken).any() else 1.0
                if unb < self.rest * ref:
                    break
        status = np.where(broken, np.where(dn > 0, cl.OPEN, np.where(np.abs(trial) > cap, cl.SLIP, cl.STICK)),
                          cl.INTACT)
        sign = np.where(np.where(broken, trial, 1.0) >= 0, 1.0, -1.0)
        self.steps_total += steps
        self.stints += 1
        return broken, status, sign, s_p, mode, order, steps


class DynamicPath(Path):
    def __init__(self, eq, stint, handover):
        super().__init__(eq)
        self.stint, self.handover = stint, handover
        self.log = []

    def cascade(self, state, first=None, record=None):
        if first is None:
            return super().cascade(state, None, record)
        pre = state
        ratio, mode = self.ratios(pre)
        s1 = self.break_bond(pre, first, int(mode[first]))
        if record is not None:
            record.bonds.append(first)
            record.modes.append(int(mode[first]))
        if not self.over(s1).any() or self.handover < 1:
            return super().cascade(s1, None, record)
        # more than one bond would break: relax dynamically from just before the first break
        broken, status, sign, s_p, bmode, order, steps = self.stint.run(pre, [first], self.jt, self.jc)
        base = s1.copy()
        base.broken, base.status, base.sign, base.s_p, base.break_mode = broken, status, sign, s_p, bmode
        new = [b for b in order if not s1.broken[b]]
        s2 = self.eq.solve(pre.closure, base, self.eq.release_force(s1, base))
        if record is not None:
            record.bonds.extend(new)
            record.modes.extend(int(bmode[b]) for b in new)
        self.log.append((pre.closure / self.net.height, pre.stress / 1e6, len(new) + 1, steps, s2.stress / 1e6))
        return super().cascade(s2, None, record)


def main(argv=None):
    ap = specimen_arguments(argparse.ArgumentParser())
    ap.add_argument("--damping", type=float, default=0.2)
    ap.add_argument("--handover", type=int, default=1)
    ap.add_argument("--rest", type=float, default=1e-3)
    ap.add_argument("--budget", type=int, default=200_000)
    ap.add_argument("--min-crossings", type=float, default=1.0)
    ap.add_argument("--max-strain", type=float, default=0.008)
    a = ap.parse_args(argv)
    p, s, lay, net = specimen_layout(a)
    enet = build_network(s, p, lay.model, lay)
    eq = Equilibrium(net)
    stint = DynamicStint(eq, node_masses(enet, s, p, net.ndof, net.dofs), a.damping, a.rest, a.budget,
                         a.min_crossings)
    path = DynamicPath(eq, stint, a.handover)
    t0 = time.process_time()
    r = ucs_path(eq, a.max_strain, p.ucs.stop_stress_ratio, path=path)
    big = sorted(path.log, key=lambda x: -x[2])[:8]
    print(json.dumps({"seed": a.seed, "damping": a.damping, "width": a.width, "height": a.height,
                      "peak_mpa": r.peak_stress / 1e6, "peak_strain": r.peak_strain, "end": r.end[:200],
                      "broken_at_peak": r.broken_at_peak, "broken_end": int(r.broken[-1]) if len(r.broken) else 0,
                      "bonds": net.n_bonds, "stints": stint.stints, "stint_steps": stint.steps_total,
                      "dt_s": stint.dt, "min_steps": stint.min_steps, "largest_stints": big,
                      "cpu_s": time.process_time() - t0}), flush=True)


if __name__ == "__main__":
    main()
