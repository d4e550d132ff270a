"""The two jaws of a Brazilian disc in a YADE scene: cells at the ends of the vertical diameter, moved together
at a constant speed; the load, the diametral and horizontal strains (:mod:`grainfrac_yade.protocols.brazilian`
says what the test does with them)."""
from __future__ import annotations

import math

import numpy as np

from ...geometry.disc import DiscTessellation
from ...errors import GrainfracError

#: DOFs blocked on jaw cells: y prescribed, z and all rotations blocked; x too when fixed.
JAW_BLOCKED = {"free": "yzXYZ", "fixed": "xyzXYZ"}


class DiscJaws:
    """The two jaws of a disc scene: cells at the ends of the vertical diameter; velocity and measures."""

    name = "DiscJaws"

    def __init__(self, scene, loading_arc: float, lateral: str = "fixed"):
        t = scene.specimen.tessellation
        if not isinstance(t, DiscTessellation):
            raise GrainfracError("Brazilian test: the specimen is not a disc; fix: build it with "
                                 "grainfrac_yade.geometry.specimen.build_disc_specimen")
        self.scene = scene
        self.diameter, self.centre = t.diameter, t.centre
        half = 0.5 * loading_arc
        self.top = t.cells_in_arc(0.5 * math.pi, half)
        self.bottom = np.setdiff1d(t.cells_in_arc(-0.5 * math.pi, half), self.top)
        self.left = np.setdiff1d(t.cells_in_arc(math.pi, 0.0), np.concatenate([self.top, self.bottom]))
        self.right = np.setdiff1d(t.cells_in_arc(0.0, 0.0), np.concatenate([self.top, self.bottom, self.left]))
        if not (len(self.bottom) and len(self.left) and len(self.right)):
            raise GrainfracError(f"Brazilian test: a disc of {t.n_cells} cells has no separate cells at the two jaws "
                                 "and the ends of the horizontal diameter; fix: use a larger disc or smaller grains")
        self.loaded_arc_deg = [self._arc_deg(self.top, 0.5 * math.pi), self._arc_deg(self.bottom, -0.5 * math.pi)]
        O = scene.O
        self._top, self._bottom, self._left, self._right = (
            [O.bodies[int(b)] for b in scene.bodies_of(cells)] for cells in (self.top, self.bottom, self.left, self.right))
        for b in self._top + self._bottom:
            b.state.blockedDOFs = JAW_BLOCKED[lateral]
            b.state.vel = (0, 0, 0)
            b.state.angVel = (0, 0, 0)
        self.y0 = self._y(self._top) - self._y(self._bottom)
        self.x0 = self._x(self._right) - self._x(self._left)
        self.velocity = 0.0

    def rebind(self, state: dict):
        """After ``O.load`` of a checkpoint: the jaw and rim bodies anew (handles of the replaced scene are
        stale), the reference distances and the speed from ``state`` (:meth:`state_dict`).  No force is
        read before the next DEM step (the load is measured after the row's steps)."""
        O = self.scene.O
        self._top, self._bottom, self._left, self._right = (
            [O.bodies[b.id] for b in bodies] for bodies in (self._top, self._bottom, self._left, self._right))
        self.y0, self.x0, self.velocity = state["y0"], state["x0"], state["velocity"]

    def state_dict(self) -> dict:
        return {"y0": float(self.y0), "x0": float(self.x0), "velocity": self.velocity}

    def _arc_deg(self, cells, pole: float) -> float:
        """Angle [deg] the union of ``cells``' rim arcs spans (measured from the pole both ways)."""
        t = self.scene.specimen.tessellation
        arcs = t.boundary_arc[np.isin(t.boundary_cell, cells)]
        mid = (arcs.mean(axis=1) - pole + math.pi) % (2 * math.pi) - math.pi   # arc midpoints from the pole
        arcs = arcs[np.abs(mid) < 0.5 * math.pi] - (arcs.mean(axis=1) - mid)[np.abs(mid) < 0.5 * math.pi, None]
        return float(math.degrees(arcs[:, 1].max() - arcs[:, 0].min()))

    @staticmethod
    def _y(bodies) -> float:
        return float(np.mean([b.state.pos[1] for b in bodies]))

    @staticmethod
    def _x(bodies) -> float:
        return float(np.mean([b.state.pos[0] for b in bodies]))

    def set_closing_speed(self, speed: float):
        """Jaws approach each other at ``speed`` [m/s] (half each), along the vertical diameter."""
        self.velocity = speed
        for b in self._top:
            b.state.vel = (b.state.vel[0], -0.5 * speed, 0)
        for b in self._bottom:
            b.state.vel = (b.state.vel[0], 0.5 * speed, 0)

    def diametral_strain(self) -> float:
        """Jaw closure over the diameter (shortening positive) [1]."""
        return (self.y0 - (self._y(self._top) - self._y(self._bottom))) / self.diameter

    def horizontal_strain(self) -> float:
        """Change of the horizontal diameter's end-cell distance over D (compression positive) [1]."""
        return -((self._x(self._right) - self._x(self._left)) - self.x0) / self.diameter

    def load(self) -> float:
        """Mean reaction of the two jaws along the diameter (compression positive) [N]."""
        f = self.scene.O.forces.f
        top = sum(f(b.id)[1] for b in self._top)
        bottom = sum(f(b.id)[1] for b in self._bottom)
        return 0.5 * (top - bottom)
