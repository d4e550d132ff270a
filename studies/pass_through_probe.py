"""Probe: how many contacts of the static fem UCS path are pressed past their spheres' initial gap (no YADE).

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.pass_through_probe --params params/presets/fem.toml --seed 1 \
        [--set resolution.contact_inset=0.01] [--max-strain 0.006]

YADE's smooth joint (the bonds of fem cells) measures a bond's normal displacement as D = initD - |(x1 - x2) . n|,
initD the initial distance of the two sphere centres along the face normal n (about the contact inset x the two
centroid-face distances: 1 um for 1 mm grains at ``resolution.contact_inset`` 0.001).  A pair pressed closer than
that has passed the face: its compression falls again, to zero at 2 initD and into tension beyond
(``studies.dynamics_ab_probe --pass-through``).  The static engine's law is linear in the displacement.  This probe
follows the static path and reports, at every 0.05 % of axial strain, the contacts whose compression du_n < 0 is
beyond initD (ratio -du_n / initD above 1): where YADE's law and the static one part.
"""
from __future__ import annotations

import argparse
import json
import math

import numpy as np

from grainfrac_yade.engines.static.cascade import Path
from grainfrac_yade.engines.static.scene import StaticScene
from grainfrac_yade.engines.static.solver import Equilibrium
from grainfrac_yade.engines.static.ucs import ucs_path
from studies.static_engine_probe import specimen_arguments, specimen_layout

#: Axial strain between two reports [1].
REPORT_EVERY = 5e-4


def initial_gap(scene) -> np.ndarray:
    """(bonds,) in the static network's order: each bond's stress-free normal gap [m], as the scene exports it for a
    dynamic engine (``bond_reference_gap``: for bonds on their face's plane the sphere centres' distance along the
    face normal, YADE's smooth-joint ``initD``)."""
    return scene.export_state().bond_reference_gap[scene.net.order]


class GapPath(Path):
    """The static path, reporting the contacts pressed past their initial gap every :data:`REPORT_EVERY`."""

    def __init__(self, eq, gap):
        super().__init__(eq)
        self.gap, self.rows, self.next = gap, [], REPORT_EVERY

    def step(self, state, target=None, max_closure=math.inf):
        new, what = super().step(state, target, max_closure)
        strain = new.closure / self.net.height
        if what != "none" and strain >= self.next:
            self.next = (math.floor(strain / REPORT_EVERY) + 1) * REPORT_EVERY
            ratio = -np.minimum(self.net.cn @ new.u, 0.0) / self.gap
            self.rows.append({"strain": strain, "stress_mpa": new.stress / 1e6, "broken": int(new.broken.sum()),
                              "ratio_p50": float(np.percentile(ratio, 50)), "ratio_p99": float(np.percentile(ratio, 99)),
                              "ratio_max": float(ratio.max()), "past_gap": int((ratio > 1).sum()),
                              "past_gap_intact": int(((ratio > 1) & ~new.broken).sum()),
                              "past_twice_gap": int((ratio > 2).sum())})
            print(json.dumps(self.rows[-1]), flush=True)
        return new, what


def main(argv=None):
    ap = specimen_arguments(argparse.ArgumentParser(description=__doc__.splitlines()[0]))
    ap.add_argument("--max-strain", type=float, default=0.006)
    a = ap.parse_args(argv)
    p, s, lay, _ = specimen_layout(a)
    scene = StaticScene(s, p, lay)
    gap = initial_gap(scene)
    print(json.dumps({"seed": a.seed, "contact_inset": p.resolution.contact_inset, "bonds": scene.n_bonds,
                      "gap_um_median": float(np.median(gap)) * 1e6, "gap_um_min": float(gap.min()) * 1e6}))
    eq = Equilibrium(scene.net)
    ucs_path(eq, a.max_strain, p.ucs.stop_stress_ratio, path=GapPath(eq, gap))


if __name__ == "__main__":
    main()
