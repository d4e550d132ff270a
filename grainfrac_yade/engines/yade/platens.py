"""Rigid platens acting on the end cells of a specimen, and the specimen-scale measures.

The cells with a face on the top (bottom) wall form the top (bottom) platen:
their vertical motion is prescribed together, their rotation is blocked (the
platen face stays flat), and their lateral motion is free (smooth platen,
``platen_lateral = "free"``) or blocked (rough platen, ``"fixed"``).  The axial
stress is the platens' reaction over the specimen cross-section (width x
thickness); lateral strain comes from the cells on the side walls.  With
fem cells all bodies (spheres) of those cells take part: a platen cell's
spheres all move at the platen's speed, and the side-wall positions are the
means over the side cells' spheres.
"""
from __future__ import annotations

import numpy as np

from ...kernel.servo import ServoLaw


#: DOFs blocked on platen cells: y prescribed, z and all rotations blocked (pseudo-2D, flat platen).
PLATEN_BLOCKED = {"free": "yzXYZ", "fixed": "xyzXYZ"}


class Platens:
    """Top and bottom platen cells of a 2D scene; axial velocity control and measurements.

    Listed among the scene's engines; it needs no call per step (YADE keeps the
    velocity of blocked DOFs).
    """

    name = "Platens"

    def __init__(self, scene, lateral: str = "free"):
        t = scene.specimen.tessellation
        self.scene = scene
        self.top = t.cells_on_side("top")
        self.bottom = np.setdiff1d(t.cells_on_side("bottom"), self.top)
        self.left = t.cells_on_side("left")
        self.right = t.cells_on_side("right")
        self.width, self.height = float(t.box[0]), float(t.box[1])
        self.cross_section = self.width * scene.specimen.thickness
        O = scene.O
        self._top_bodies, self._bottom_bodies, self._left_bodies, self._right_bodies = (
            [O.bodies[int(b)] for b in scene.bodies_of(cells)]
            for cells in (self.top, self.bottom, self.left, self.right))
        for b in self._top_bodies + self._bottom_bodies:
            b.state.blockedDOFs = PLATEN_BLOCKED[lateral]
            b.state.vel = (0, 0, 0)
            b.state.angVel = (0, 0, 0)
        self._cache_handles()
        self.y0_top = np.mean([b.state.pos[1] for b in self._top_bodies])
        self.y0_bottom = np.mean([b.state.pos[1] for b in self._bottom_bodies])
        self.x0_gap = self._side_gap()
        self.velocity = 0.0
        #: (DEM step, axial stress [Pa]) restored from a checkpoint, read until that step has run
        self._restored_reaction = None

    def rebind(self, reaction: float):
        """After ``O.load`` of a checkpoint: fetch the platen and side bodies anew (handles of the
        replaced scene are stale), and read ``reaction`` [Pa], the axial stress saved with the
        checkpoint, until the next DEM step.  ``O.save`` keeps no forces: after ``O.load`` the force
        container reads zero until a step has run, and forces added from Python would act in that
        step, so the reaction of the last step before the checkpoint is restored here instead."""
        O = self.scene.O
        self._top_bodies, self._bottom_bodies, self._left_bodies, self._right_bodies = (
            [O.bodies[b.id] for b in bodies]
            for bodies in (self._top_bodies, self._bottom_bodies, self._left_bodies, self._right_bodies))
        self._cache_handles()
        self._restored_reaction = (O.iter, float(reaction))

    def state_dict(self) -> dict:
        """Speed, reference positions and the last reaction [Pa] (what a checkpoint keeps of the platens)."""
        return {"velocity": self.velocity, "y0_top": float(self.y0_top), "y0_bottom": float(self.y0_bottom),
                "x0_gap": float(self.x0_gap), "reaction_pa": float(self.axial_stress())}

    def restore_state(self, saved: dict) -> None:
        """After ``O.load`` of a checkpoint: the handles anew and the saved reaction (:meth:`rebind`), then the
        speed and the reference positions of :meth:`state_dict`."""
        self.rebind(saved["reaction_pa"])
        self.velocity, self.y0_top, self.y0_bottom, self.x0_gap = (saved["velocity"], saved["y0_top"],
                                                                   saved["y0_bottom"], saved["x0_gap"])

    def _cache_handles(self):
        """Body ids and state handles of the platen bodies, fetched once: the servo reads their forces
        and sets their velocities before every DEM step, and each ``body.state`` / ``body.id`` lookup
        from Python costs a wrapper (same values, same order of summation)."""
        self._top_ids = [b.id for b in self._top_bodies]
        self._bottom_ids = [b.id for b in self._bottom_bodies]
        self._top_states = [b.state for b in self._top_bodies]
        self._bottom_states = [b.state for b in self._bottom_bodies]

    def set_axial_velocity(self, closing_speed: float):
        """Platens approach each other at ``closing_speed`` [m/s] (half each)."""
        self.velocity = closing_speed
        down, up = -0.5 * closing_speed, 0.5 * closing_speed
        for st in self._top_states:
            st.vel = (st.vel[0], down, 0)
        for st in self._bottom_states:
            st.vel = (st.vel[0], up, 0)

    def shift(self, closing: float):
        """Move both platens towards each other by ``closing`` [m] in one jump (servo/creep hold)."""
        for b in self._top_bodies:
            p = b.state.pos
            b.state.pos = (p[0], p[1] - 0.5 * closing, p[2])
        for b in self._bottom_bodies:
            p = b.state.pos
            b.state.pos = (p[0], p[1] + 0.5 * closing, p[2])

    def axial_strain(self) -> float:
        """Platen closure over specimen height (shortening positive) [1]."""
        top = np.mean([b.state.pos[1] for b in self._top_bodies])
        bottom = np.mean([b.state.pos[1] for b in self._bottom_bodies])
        return ((self.y0_top - self.y0_bottom) - (top - bottom)) / self.height

    def _side_gap(self) -> float:
        return (np.mean([b.state.pos[0] for b in self._right_bodies])
                - np.mean([b.state.pos[0] for b in self._left_bodies]))

    def lateral_strain(self) -> float:
        """Change of the distance between the side cells over the width [1].

        Compression positive, as the axial strain: lateral expansion is negative.
        """
        return -(self._side_gap() - self.x0_gap) / self.width

    def axial_stress(self) -> float:
        """Mean reaction of the two platens over the cross-section (compression positive) [Pa]."""
        if self._restored_reaction is not None:
            if self._restored_reaction[0] == self.scene.O.iter:
                return self._restored_reaction[1]
            self._restored_reaction = None
        f = self.scene.O.forces.f
        top = sum(f(i)[1] for i in self._top_ids)
        bottom = sum(f(i)[1] for i in self._bottom_ids)
        return 0.5 * (top - bottom) / self.cross_section

    def hold_stress(self, target: float, young: float, response_steps: int, max_speed: float) -> "StressServo":
        """Force control from here on: a :class:`StressServo` holding the axial stress at ``target`` [Pa], added
        to the scene's drivers (its gain from the specimen's axial modulus ``young`` [Pa] and ``response_steps``,
        its speed within +-``max_speed`` [m/s])."""
        servo = StressServo(self, target, young, response_steps, max_speed)
        self.scene.drivers.append(servo)
        return servo

    def resume_hold(self, saved: dict) -> "StressServo":
        """:meth:`hold_stress` as a checkpoint saved it (``saved``: the servo's ``target``, ``gain``, ``max_speed``,
        ``stress``, and ``clipped``, ``closing_clipped_steps``, counted from 0 if the checkpoint has none)."""
        servo = StressServo.restored(self, saved["target"], saved["gain"], saved["max_speed"], saved["stress"],
                                     saved.get("clipped", 0), saved.get("closing_clipped_steps", 0))
        self.scene.drivers.append(servo)
        return servo


def free_bodies(scene, platens) -> list:
    """Body ids of the cells that are not platen cells (their resultant forces measure balance)."""
    free = np.setdiff1d(np.arange(scene.specimen.n_cells), np.union1d(platens.top, platens.bottom))
    return [int(b) for b in scene.bodies_of(free)]


class StressServo(ServoLaw):
    """Holds the axial stress at a target by moving the platens (a driver, called before each step): the servo law
    of :mod:`grainfrac_yade.kernel.servo` (its gain from the specimen's axial stiffness ``young`` x cross-section /
    height and ``response_steps``, its speed within +-``max_speed``; its saturation and clip counts) on YADE's
    platens, at YADE's DEM step."""

    name = "StressServo"

    def __init__(self, platens: Platens, target: float, young: float, response_steps: int, max_speed: float):
        super().__init__(target, platens.height / (young * response_steps), max_speed)
        self.platens = platens

    @classmethod
    def restored(cls, platens: Platens, target: float, gain: float, max_speed: float, stress: float,
                 clipped: int = 0, closing_clipped_steps: int = 0) -> "StressServo":
        """A servo as a checkpoint saved it: its own ``gain`` [m/Pa], last measured ``stress`` [Pa] and
        clip state (``clipped``, ``closing_clipped_steps``)."""
        servo = cls.__new__(cls)
        ServoLaw.__init__(servo, target, gain, max_speed)
        servo.platens = platens
        servo.stress, servo.clipped, servo.closing_clipped_steps = stress, int(clipped), int(closing_clipped_steps)
        return servo

    def before_step(self, scene):
        self.platens.set_axial_velocity(float(self.command(self.platens.axial_stress(), scene.O.dt)))
