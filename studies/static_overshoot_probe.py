"""Probe: the static UCS path with the dynamic overshoot of a sudden break (no YADE).

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.static_overshoot_probe --params params/presets/fem.toml \
        --seed 1 --overshoot 0.816

A bond that breaks suddenly hands its force to its neighbours as a step load; a structure released so swings
past its new equilibrium.  For one degree of freedom with Cundall's non-viscous damping D the swing past the new
equilibrium is kappa = sqrt((1 - D) / (1 + D)) of the step (energy: (1 - D) k x_s^2 / 2 gained up to the new
equilibrium, (1 + D) k y^2 / 2 lost beyond it).  The probe checks every intact bond against its strength at the
forces F1 + kappa (F1 - F0), F0 and F1 the static forces before and after each break; bonds at their strength
there break next (the most overstressed at those forces first), each with its own overshoot.
"""
from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np

from grainfrac_yade.engines.static import contacts as cl
from grainfrac_yade.engines.static.cascade import BREAK_RATIO_TOL, LargeCascade, Path
from grainfrac_yade.engines.static.solver import Equilibrium
from studies.static_engine_probe import specimen_arguments, specimen_layout
from grainfrac_yade.engines.static.ucs import ucs_path


class OvershootPath(Path):
    def __init__(self, eq, overshoot):
        super().__init__(eq)
        self.overshoot = float(overshoot)
        self.dynamic_breaks = 0

    def cascade(self, state, first=None, record=None):
        broken, prev = 0, None
        n = self.net
        while True:
            self.last_converged = state
            if first is not None:
                ratio, mode = self.ratios(state)
                bond, first = first, None
            else:
                fn, fs = state.fn, state.fs
                if prev is not None and self.overshoot > 0:
                    fn = state.fn + self.overshoot * (state.fn - prev.fn)
                    fs = state.fs + self.overshoot * (state.fs - prev.fs)
                r, mode = cl.overstress(fn, fs, n.area, self.jt, self.jc, n.tan_friction)
                ratio = np.where(state.broken, -np.inf, r)
                hit = (cl.failing(fn, fs, n.area, self.jt, self.jc, n.tan_friction) | (ratio >= 1 - BREAK_RATIO_TOL))
                hit = np.flatnonzero(hit & ~state.broken)
                if not len(hit):
                    return state
                bond = self.pick(ratio, hit)
                if not self.over(state)[bond]:
                    self.dynamic_breaks += 1
            prev = state
            state = self.break_bond(state, bond, int(mode[bond]))
            broken += 1
            if record is not None:
                record.bonds.append(bond)
                record.modes.append(int(mode[bond]))


def main(argv=None):
    ap = specimen_arguments(argparse.ArgumentParser())
    ap.add_argument("--overshoot", type=float, default=0.0)
    ap.add_argument("--max-strain", type=float, default=0.01)
    a = ap.parse_args(argv)
    p, _, _, net = specimen_layout(a)
    eq = Equilibrium(net)
    path = OvershootPath(eq, a.overshoot)
    t0 = time.process_time()
    r = ucs_path(eq, a.max_strain, p.ucs.stop_stress_ratio, path=path)
    casc = [len(x.bonds) for x in path.records]
    print(json.dumps({"seed": a.seed, "overshoot": a.overshoot, "width": a.width, "height": a.height,
                      "peak_mpa": r.peak_stress / 1e6, "peak_strain": r.peak_strain, "end": r.end[:200],
                      "broken_at_peak": r.broken_at_peak, "broken_end": int(r.broken[-1]) if len(r.broken) else 0,
                      "bonds": net.n_bonds, "largest_cascade": max(casc) if casc else 0,
                      "dynamic_breaks": path.dynamic_breaks, "equilibria": eq.counters.equilibria,
                      "cpu_s": time.process_time() - t0}), flush=True)


if __name__ == "__main__":
    main()
