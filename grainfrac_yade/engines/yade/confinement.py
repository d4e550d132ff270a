"""Confining stress on the side walls of a plane specimen (biaxial compression and creep).

A flexible membrane: every boundary face of the cells on the left and right walls carries a
constant inward force sigma_3 x face length x thickness, normal to the original wall, on the
cell's body nearest the face's midpoint (the cell itself for rigid cells; a node sphere of a
finite-element cell).  The forces are YADE permanent forces: they act in every DEM
step with no Python call, and do not follow the cells as the specimen bulges or cracks open.  The
lateral stress is therefore sigma_3 by construction, over the specimen's original height.

Before axial loading the specimen is brought to the isotropic state sigma_1 = sigma_3 at
equilibrium (:func:`consolidate`), as in a triaxial cell; the test then loads axially.
"""
from __future__ import annotations

import numpy as np

from ...geometry.tessellation import SIDES
from ...wave import hold_budget, scene_density
from ...kernel.confinement import BROKEN_APART_FRACTION, broken_apart_reason  # noqa: F401
from ...kernel.equilibrium import held_at_equilibrium
from ...kernel.held_relaxation import EQUILIBRIUM, HeldRelaxing, relax_held
from .platens import StressServo


#: Walls that carry the confining stress and the inward direction (x) of their force.
CONFINED_WALLS = (("left", 1.0), ("right", -1.0))


class Confinement:
    """Permanent inward forces on the side-wall cells; listed among the scene's engines."""

    name = "Confinement"

    def __init__(self, scene, stress: float):
        """``stress``: confining stress sigma_3 [Pa], > 0."""
        self.scene, self.stress = scene, float(stress)
        t = scene.specimen.tessellation
        thickness = scene.specimen.thickness
        force = {}
        for side, direction in CONFINED_WALLS:
            on_wall = np.flatnonzero(t.boundary_side == SIDES.index(side))
            for face in on_wall:
                body = self._nearest_body(int(t.boundary_cell[face]), t.boundary_midpoint[face])
                force[body] = force.get(body, 0.0) + direction * self.stress * float(t.boundary_measure[face]) * thickness
        #: body id -> x force [N]
        self.body_force = force
        self.apply()

    def _nearest_body(self, cell: int, point) -> int:
        bodies = self.scene.bodies_of([cell])
        if len(bodies) == 1:
            return int(bodies[0])
        pos = np.array([tuple(self.scene.O.bodies[int(b)].state.pos)[:2] for b in bodies])
        return int(bodies[int(np.argmin(((pos - np.asarray(point)[:2]) ** 2).sum(1)))])

    def apply(self):
        """Set the permanent forces (again after ``O.load`` of a checkpoint: YADE does not save them)."""
        for body, fx in self.body_force.items():
            self.scene.O.forces.setPermF(body, (fx, 0.0, 0.0))

    def total_force(self) -> float:
        """Sum of the inward force magnitudes on both walls [N] (2 x sigma_3 x height x thickness)."""
        return float(sum(abs(f) for f in self.body_force.values()))


class IsotropicStage(HeldRelaxing):
    """The isotropic stage as the kernel's loop relaxes it: YADE's DEM steps, at rest where the servo holds its
    target at equilibrium over the intact bonds (:func:`grainfrac_yade.kernel.equilibrium.held_at_equilibrium`)."""

    def __init__(self, scene, servo, creep_params):
        self.scene, self.servo, self.creep_params = scene, servo, creep_params

    def advance(self, steps: int) -> None:
        self.scene.run(steps)

    def balanced(self) -> bool:
        return held_at_equilibrium(self.scene, self.servo, np.flatnonzero(~self.scene.broken), self.creep_params)


def young_estimate(params) -> float:
    """Area-weighted Young's modulus of the minerals (paper Table 1) [Pa]: the servo's gain estimate
    of the specimen's modulus (70 GPa for Table 1; measured specimens: 50.5 GPa raw, 69-72 GPa
    calibrated, i.e. 0.7-1.03 x this; the servo only needs its order)."""
    return float(sum(fraction * params.grains[m].young for m, fraction in params.composition.items()))


def consolidate(scene, platens, stress: float, params) -> dict:
    """Isotropic stage: with the confining forces on, a servo brings the axial stress to ``stress``
    [Pa] and holds it until equilibrium (mean resultant on free bodies / mean bond force below
    ``creep.equilibrium_tolerance`` and the axial stress within ``creep.stress_tolerance``,
    :func:`grainfrac_yade.kernel.equilibrium.held_at_equilibrium`), at most ``creep.max_relaxation_steps`` DEM
    steps: the kernel's held-load loop (:func:`grainfrac_yade.kernel.held_relaxation.relax_held`), as a creep
    run's hold.  The servo's gain uses :func:`young_estimate` of ``params``; with it and the scene's density
    (:func:`~grainfrac_yade.wave.scene_density`) the servo's response and the stage's step budget follow the
    creep hold's (:func:`~grainfrac_yade.wave.hold_budget`).
    The platens are left at rest.  Returns the stage's DEM steps, whether it
    reached equilibrium, and the axial stress at its end."""
    cp = params.creep
    young = young_estimate(params)
    budget = hold_budget(cp, platens.height, young, scene_density(params), scene.O.dt)
    servo = StressServo(platens, stress, young, budget.servo_response_steps, cp.servo_max_strain_rate * platens.height)
    scene.drivers.append(servo)
    try:
        end = relax_held(IsotropicStage(scene, servo, cp), budget.max_relaxation_steps, cp.check_period)
    finally:
        scene.drivers.remove(servo)
        platens.set_axial_velocity(0.0)
    return {"consolidation_steps": end.steps, "consolidated": end.outcome == EQUILIBRIUM,
            "consolidation_axial_stress_pa": servo.stress}
