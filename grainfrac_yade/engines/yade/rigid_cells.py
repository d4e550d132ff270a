"""The YADE side of rigid cells (:mod:`grainfrac_yade.grains.rigid`): one body per cell.

A cell is a sphere, or a clump of its spheres, with the polygon's mass and inertia about where YADE
puts the body (:meth:`grainfrac_yade.grains.rigid.RigidCells.masses_and_step`); pseudo-2D: no
out-of-plane translation or rotation about x and y.  YADE's default contact kinematics
(``avoidGranularRatcheting``), no finite elements, one collision mask for all.
"""
from __future__ import annotations

import numpy as np

from ...grains.rigid import MODEL
from .cell_bodies import CellBodies, cell_spheres, set_mass_inertia


def _blocked_dofs(dim: int) -> str:
    """Pseudo-2D: no out-of-plane translation (z) or rotation about x, y."""
    return "zXY" if dim == 2 else ""


def configure_geometry(geometry):
    """YADE's default kinematics: nothing to change."""


def engines(w) -> list:
    """No engines beyond the plain scene's."""
    return []


def collider_mask_bit() -> int:
    """0: the collider's ``avoidSelfInteractionMask`` off (members of one clump never interact anyway)."""
    return 0


def append_bodies(O, utils, Vector3, specimen, params, layout, props, mats) -> CellBodies:
    """One body per cell (sphere or clump) with the polygon's mass and inertia about the body."""
    sphere_body = np.empty(layout.n_spheres, dtype=np.int64)
    cell_body = np.empty(specimen.n_cells, dtype=np.int64)
    for cell, members in enumerate(cell_spheres(layout, specimen.n_cells)):
        mat = mats[specimen.mineral[cell]]
        spheres = [utils.sphere(Vector3(*layout.sphere_center[m]), float(layout.sphere_radius[m]), material=mat)
                   for m in members]
        if len(spheres) == 1:
            body = O.bodies.append(spheres[0])
            sphere_body[members] = body
        else:
            body, ids = O.bodies.appendClumped(spheres)
            sphere_body[members] = ids
        cell_body[cell] = body
    body_pos = np.array([tuple(O.bodies[int(b)].state.pos) for b in cell_body])
    mass, inertia, dt = MODEL.masses_and_step(specimen, params, layout, props, body_pos)
    set_mass_inertia(O, Vector3, cell_body, mass, inertia, _blocked_dofs(specimen.tessellation.dim))
    return CellBodies(sphere_body, cell_body, [cell_body[c:c + 1] for c in range(specimen.n_cells)], mass, dt)


def bond_kinematics(phys, k: int, layout, Vector3):
    """Bonds along the line of the sphere centres: YADE's default."""


def finish(O, w, utils, Vector3, specimen, params, layout, bodies: CellBodies, mats) -> CellBodies:
    """Nothing after the bonds."""
    return bodies


def bodies_of(scene, cells) -> np.ndarray:
    """The body of each of ``cells``, in the given order."""
    return scene.cell_body[cells]


def cell_positions(scene, cells) -> np.ndarray:
    """(n, 3) current positions of the cell bodies [m]."""
    bodies = scene.O.bodies
    return np.array([tuple(bodies[int(b)].state.pos) for b in scene.cell_body[cells]])


def cell_motion(scene):
    """(n, 3) positions [m] and (n,) rotation angles about z [rad] of the cell bodies."""
    pos, angle = [], []
    for b in scene.cell_body:
        st = scene.O.bodies[int(b)].state
        axis, ang = st.ori.toAxisAngle()
        pos.append(tuple(st.pos))
        angle.append(float(ang) * float(axis[2]))
    return np.array(pos), np.array(angle)


def bond_shift(scene, pos) -> np.ndarray:
    """(b, 2) displacement [m] drawn for each bond: the mean of its two cells' displacements (``pos``: the
    cell positions of :func:`cell_motion`)."""
    tess = scene.specimen.tessellation
    cells_of_bond = scene.bond_cells
    return 0.5 * (pos[cells_of_bond[:, 0], :2] + pos[cells_of_bond[:, 1], :2]
                  - tess.cell_centroid[cells_of_bond[:, 0], :2] - tess.cell_centroid[cells_of_bond[:, 1], :2])
