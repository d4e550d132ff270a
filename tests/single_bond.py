"""One bond between two cells under a constant force: the closed-form check of the creep clocks.

Cell 0 is fixed; cell 1 carries a persistent force and may translate in the
plane (no rotation), so at equilibrium the bond carries exactly that force.
The cells are always rigid single spheres (one bond), whatever
``resolution.spheres_per_cell`` and ``resolution.grain_model`` say.
"""
from __future__ import annotations

import numpy as np

from grainfrac_yade.grains.rigid import build_layout
from grainfrac_yade.geometry.specimen import specimen_from_tessellation
from grainfrac_yade.geometry.tessellation import tessellate_seeds
from grainfrac_yade.engines.yade.corrosion_engine import StressCorrosion, add_stiffness_restorer
from grainfrac_yade.engines.yade.scene import build_scene

#: Relative unbalanced force on the loaded cell at which the pair counts as relaxed.
BOND_EQUILIBRIUM_TOLERANCE = 1e-9
MAX_RELAX_STEPS = 200000
#: The force is applied in this many equal increments, each followed by STEPS_PER_INCREMENT steps.
LOAD_INCREMENTS = 50
STEPS_PER_INCREMENT = 100


def two_cell_specimen(params, mineral="quartz", thickness=1e-3, size=1e-3):
    """Two square cells of side ``size`` side by side (face normal +x)."""
    t = tessellate_seeds([[0.5 * size, 0.5 * size], [1.5 * size, 0.5 * size]], [2 * size, size], size)
    names = params.minerals
    return specimen_from_tessellation(t, [names.index(mineral)] * 2, names, thickness)


class BondUnderForce:
    """Holder for the creep-clock loops (:mod:`grainfrac_yade.protocols.creep_loops`): constant force on cell 1,
    equilibrium by damped steps; no stress servo, no checkpoints."""

    servo = None

    def __init__(self, params, normal_stress, shear_stress, mineral="quartz"):
        """``normal_stress`` tension positive, ``shear_stress`` >= 0 [Pa] on the face."""
        self.params = params
        specimen = two_cell_specimen(params, mineral)
        self.scene = build_scene(specimen, params, build_layout(specimen, 1))
        O = self.scene.O
        area = float(self.scene.layout.bond_area[0])
        self.force = (normal_stress * area, shear_stress * area, 0.0)
        b0, b1 = (O.bodies[int(b)] for b in self.scene.cell_body)
        b0.state.blockedDOFs = "xyzXYZ"
        b1.state.blockedDOFs = "zXYZ"
        self._body = b1
        self.failed, self.failure_reason = False, ""
        self.last_relaxation_steps = 0
        self.lifetime = None
        self.rows = []
        for k in range(1, LOAD_INCREMENTS + 1):  # quasi-static loading: no dynamic overshoot
            O.forces.setPermF(b1.id, tuple(k / LOAD_INCREMENTS * f for f in self.force))
            self.scene.run(STEPS_PER_INCREMENT)
        self.corr = StressCorrosion(self.scene, params.stress_corrosion)
        self.relax(0.0)
        #: the bond's own stresses at equilibrium [Pa] (the face normal of the geometry has turned a
        #: little with the displacement, so they differ slightly from the applied ones)
        st = self.corr.stresses([0])
        self.sigma0, self.tau0 = float(st.normal[0]), float(st.shear[0])
        self.failed, self.failure_reason = False, ""
        self.scene.extras.append(self.corr)
        add_stiffness_restorer(self.scene, self.corr)   # a law that changes stiffness: broken bond, full contact

    def progress(self, msg):
        pass

    def safe_point(self, phase, counters):
        """No checkpoints."""

    def unbalanced(self, mean_bond_force):
        res = self.scene.O.forces.f(self._body.id).norm()
        return res, res / max(np.hypot(*self.force[:2]), 1e-300)

    def relax(self, creep_time, safe_point=None, resume=None):
        self.last_relaxation_steps = 0
        while self.last_relaxation_steps < MAX_RELAX_STEPS:
            self.scene.run(100)
            self.last_relaxation_steps += 100
            self.mark_breaks(creep_time)
            if self.failed:
                return False
            if self.unbalanced(0)[1] < BOND_EQUILIBRIUM_TOLERANCE:
                return True
        return False

    def mark_breaks(self, creep_time):
        if self.scene.broken[0] and not self.failed:
            self.failed, self.failure_reason = True, "bond broken"
            self.lifetime = creep_time

    def check_failure(self):
        return self.failed

    def record_now(self, creep_time):
        self.rows.append((creep_time, bool(self.scene.broken[0])))
