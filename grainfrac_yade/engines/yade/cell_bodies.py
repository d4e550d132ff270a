"""What the YADE side of every grain model shares: the bodies a model appended, and how they get their masses.

Each grain model of :mod:`grainfrac_yade.grains` has its YADE side in a module of this package
(:mod:`.rigid_cells`, :mod:`.fem_cells`) with the same functions: ``configure_geometry``,
``engines``, ``collider_mask_bit``, ``append_bodies`` (returning :class:`CellBodies`),
``bond_kinematics``, ``finish``, and the readers ``bodies_of``, ``cell_positions``, ``cell_motion``
and ``bond_shift``, and the grain model it builds (``MODEL``, whose name selects the module and whose
``bonds_on_faces`` says whether the bonds act on their face's plane, YADE's smooth joint, rather than along the
line of the sphere centres).  :func:`grainfrac_yade.engines.yade.scene.build_scene` calls them.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class CellBodies:
    """The YADE bodies of a scene's cells.

    ``sphere_body[s]``: the body of layout sphere s; ``cell_body[c]``: the body of cell c (rigid
    cells) or a representative (the body that moves the cell's sphere nearest its centroid);
    ``cell_bodies[c]``: every body that moves cell c; ``mass``: what each moving body weighs [kg];
    ``dt_critical``: the scene's critical DEM step [s] (:meth:`GrainModel.masses_and_step`).
    """
    sphere_body: np.ndarray
    cell_body: np.ndarray
    cell_bodies: list
    mass: np.ndarray
    dt_critical: float


def cell_spheres(layout, n_cells: int) -> list:
    """Sphere indices of each cell, ascending."""
    order = np.argsort(layout.sphere_cell, kind="stable")
    bounds = np.searchsorted(layout.sphere_cell[order], np.arange(n_cells + 1))
    return [order[bounds[c]:bounds[c + 1]] for c in range(n_cells)]


def set_mass_inertia(O, Vector3, bodies, mass, inertia, blocked=None):
    """Body ``bodies[i]`` gets ``mass[i]`` and ``inertia[i]`` on all three axes (and ``blocked`` DOFs if given)."""
    for i, body in enumerate(bodies):
        st = O.bodies[int(body)].state
        st.mass = float(mass[i])
        st.inertia = Vector3(*([float(inertia[i])] * 3))
        if blocked is not None:
            st.blockedDOFs = blocked


def sphere_positions(scene) -> np.ndarray:
    """(s, 3) current positions of the layout's spheres [m]."""
    return np.array([tuple(scene.O.bodies[int(b)].state.pos) for b in scene.sphere_body])
