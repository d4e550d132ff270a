"""The YADE side of finite-element cells (:mod:`grainfrac_yade.grains.fem`): a body per sphere.

Every layout sphere is a body of its own, translating in the plane only
(:data:`grainfrac_yade.grains.fem.BLOCKED_DOFS`), with its share of the cell's mass; YADE's
``Lin4NodeTetra`` elements hold a cell's spheres together (each triangle a tetrahedron whose fourth
node is lifted out of the plane, :func:`_append_fem_elements`), and ``FEInternalForceEngine`` applies
their forces before the integrator.  The contact geometry takes the plain relative displacement
(:data:`RATCHETING_GUARD`) and the bonds act on their faces' planes (YADE's
smooth joint, ``jointNormal`` the face normal): every bond is the two-node spring of the static
solve.  The spheres are larger than their bond gaps, so each cell has its own collision mask
(:func:`cell_mask`): spheres of one cell never touch.
"""
from __future__ import annotations

import ctypes
import os
import sys

import numpy as np

from ...errors import GrainfracError
from ...grains.fem import BLOCKED_DOFS, MODEL, element_apex
from ...vtkio import cluster_rigid_motion
from .cell_bodies import CellBodies, cell_spheres, set_mass_inertia, sphere_positions

#: ``Ig2_Sphere_Sphere_ScGeom.avoidGranularRatcheting`` in fem scenes.  YADE's default (True)
#: scales the relative translation of two spheres d apart by (r1 + r2)/d in the shear increment, so
#: a spring between non-touching spheres would act with k_s (r1 + r2)/d (measured: 1/2 at d = 2(r1 + r2)).
#: False: the plain relative displacement, k_s as given, the static solve's kinematics.
RATCHETING_GUARD = False

#: Collision mask bit shared by every sphere of a scene with per-cell masks (and the collider's
#: ``avoidSelfInteractionMask``): YADE makes no contact between two bodies of equal masks that
#: carry this bit, and lets bodies of different masks that share it meet.
CELL_MASK_BIT = 1
#: Largest cell index a per-cell mask can hold (YADE's masks are 32-bit signed integers).
MAX_MASKED_CELLS = 2**30 - 2


def cell_mask(cell: int) -> int:
    """Collision mask of the spheres of ``cell``: unique per cell, with ``CELL_MASK_BIT``, so that
    spheres of one cell never touch and spheres of different cells do."""
    if not 0 <= cell <= MAX_MASKED_CELLS:
        raise GrainfracError(f"cell_mask: cell {cell} beyond the {MAX_MASKED_CELLS} cells a YADE mask can tell "
                             "apart; fix: use a smaller specimen")
    return ((cell + 1) << 1) | CELL_MASK_BIT


#: Height of the lifted fourth node of finite-element cells over the cell's plane, in specimen
#: thicknesses [1]: 3, so that each tetrahedron's volume (area x height / 3) is the triangle's area
#: x the specimen's thickness, and its stiffness the plane-strain triangle's.
FEM_LIFT = 3.0



def configure_geometry(geometry):
    """The plain relative displacement in the shear increment (no ratcheting guard)."""
    geometry.avoidGranularRatcheting = RATCHETING_GUARD


def engines(w) -> list:
    """The elements' internal forces, before the integrator."""
    return [_without_native_stdout(lambda: w.FEInternalForceEngine([w.If2_Lin4NodeTetra_LinIsoRayleighDampElast()]))]


def collider_mask_bit() -> int:
    """Spheres of equal masks with this bit never meet (one mask per cell, :func:`cell_mask`)."""
    return CELL_MASK_BIT


def append_bodies(O, utils, Vector3, specimen, params, layout, props, mats) -> CellBodies:
    """One sphere body per layout sphere (not clumped), with its mass share; each cell's representative
    body is its sphere nearest its centroid."""
    mass, inertia, dt = MODEL.masses_and_step(specimen, params, layout, props)
    spheres = [utils.sphere(Vector3(*layout.sphere_center[m]), float(layout.sphere_radius[m]),
                            material=mats[specimen.mineral[layout.sphere_cell[m]]]) for m in range(layout.n_spheres)]
    sphere_body = np.asarray(O.bodies.append(spheres), dtype=np.int64)
    set_mass_inertia(O, Vector3, sphere_body, mass, inertia, BLOCKED_DOFS)
    members = cell_spheres(layout, specimen.n_cells)
    if any(len(m) == 0 for m in members):
        raise GrainfracError("fem layout: a cell has no sphere; fix: the layout builder must give every "
                             "cell at least one sphere")
    centroid = specimen.tessellation.cell_centroid
    nearest = [m[np.argmin(((layout.sphere_center[m, :2] - centroid[c, :2]) ** 2).sum(1))]
               for c, m in enumerate(members)]
    return CellBodies(sphere_body, sphere_body[nearest], [sphere_body[m] for m in members], mass, dt)


def bond_kinematics(phys, k: int, layout, Vector3):
    """Bond ``k`` acts on its face's plane (smooth joint along the face normal)."""
    phys.isOnJoint = True
    phys.jointNormal = Vector3(*layout.bond_normal[k], 0.0)


def finish(O, w, utils, Vector3, specimen, params, layout, bodies: CellBodies, mats) -> CellBodies:
    """Per-cell collision masks, then the elements; the bodies that move are a clump in place of each
    element apex sphere."""
    sphere_body = bodies.sphere_body
    for m, body in enumerate(sphere_body):
        O.bodies[int(body)].mask = cell_mask(int(layout.sphere_cell[m]))
    clump_of = _append_fem_elements(O, w, utils, Vector3, specimen, params, layout, sphere_body, mats, bodies.mass)
    moving = sphere_body.copy()
    for s, clump_id in clump_of.items():
        moving[s] = clump_id
    cell_body = np.array([moving[np.flatnonzero(sphere_body == b)[0]] for b in bodies.cell_body], dtype=np.int64)
    cell_bodies = [moving[m] for m in cell_spheres(layout, specimen.n_cells)]
    return CellBodies(sphere_body, cell_body, cell_bodies, bodies.mass, bodies.dt_critical)


def bodies_of(scene, cells) -> np.ndarray:
    """All bodies that move ``cells``, cell by cell in the given order."""
    parts = [scene.cell_bodies[c] for c in cells]
    return np.concatenate(parts) if parts else np.empty(0, dtype=np.int64)


def cell_positions(scene, cells) -> np.ndarray:
    """(n, 3) current positions of cells [m]: the mass centre of the bodies that move each."""
    bodies = scene.O.bodies
    out = []
    for c in cells:
        states = [bodies[int(b)].state for b in scene.cell_bodies[c]]
        m = np.array([st.mass for st in states])
        out.append(m @ np.array([tuple(st.pos) for st in states]) / m.sum())
    return np.array(out)


def cell_motion(scene):
    """(n, 2) positions [m] of the cell centroids and (n,) rotation angles about z [rad]: the least-squares
    rigid motion (translation + rotation) of each cell's spheres, weighted by their lumped areas."""
    lay = scene.layout
    return cluster_rigid_motion(lay.sphere_center, sphere_positions(scene), lay.sphere_cell, lay.sphere_area,
                                scene.specimen.tessellation.cell_centroid)


def bond_shift(scene, pos) -> np.ndarray:
    """(b, 2) displacement [m] drawn for each bond: the mean of its two spheres' displacements."""
    lay = scene.layout
    disp = sphere_positions(scene)[:, :2] - lay.sphere_center[:, :2]
    return 0.5 * (disp[lay.bond_spheres[:, 0]] + disp[lay.bond_spheres[:, 1]])


def _without_native_stdout(make):
    """``make()`` with the process's standard output sent to /dev/null (YADE's FEInternalForceEngine
    constructor prints two debugging lines from C++)."""
    libc = ctypes.CDLL(None)
    sys.stdout.flush()
    libc.fflush(None)
    saved, devnull = os.dup(1), os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    try:
        return make()
    finally:
        libc.fflush(None)
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)


def fem_element_material(young: float, poisson: float) -> dict:
    """Arguments of YADE's ``LinIsoRayleighDampElastMat`` that make ``Lin4NodeTetra`` an exact linear
    tetrahedron of Young's modulus ``young`` [Pa] and Poisson's ratio ``poisson`` (3D isotropic).

    YADE 2023.02a's ``If2_Lin4NodeTetra_LinIsoRayleighDampElast`` applies the force
    -(M^-1 K) u, M its consistent mass matrix 0.05 x density x (material Poisson's ratio) x
    (I_4 + 1 1^T) (x) I_3, and builds K with the elasticity matrix E/((1+nu)(1-nu)) [[1-nu, nu, nu], ...;
    shear (1-2nu)/2] instead of E/((1+nu)(1-2nu)) [...].  K has the rigid translations in its null
    space, so M^-1 K = 20 / (density x nu) K: density 20/nu makes the force -K u, and
    E (1-nu)/(1-2nu) restores the elasticity matrix.  No damping (alpha = beta = 0): the scene's
    NewtonIntegrator damps.  Tested against a hand-built tetrahedron (tests/test_fem_scene.py).
    """
    return {"youngmodulus": young * (1 - poisson) / (1 - 2 * poisson), "poissonratio": poisson,
            "density": 20.0 / poisson, "alpha": 0.0, "beta": 0.0}


def _append_fem_elements(O, w, utils, Vector3, specimen, params, layout, sphere_body, mats, mass) -> dict:
    """YADE finite elements for the triangles of ``layout.element_spheres``; returns {sphere: clump id}.

    A triangle (a, b, c) of the plane becomes the tetrahedron (a, b, c, a'), a' a node lifted by
    ``FEM_LIFT`` x thickness above its apex a (:func:`grainfrac_yade.grains.fem.element_apex`) and
    clumped with a, so that a' moves with a in the plane: the tetrahedron's displacement field is
    then the triangle's, constant in z, its strain the triangle's (plane strain, the z motion of
    every sphere being blocked), its volume area x thickness.  The lifted node has no bound (no
    contact); the clump of a and a' is the body that moves, with a's mass.
    """
    tri = layout.element_spheres
    apex = element_apex(tri)
    lift = FEM_LIFT * specimen.thickness
    clump_of = {}
    clump_material = w.ElastMat()   # YADE's FEM engine asserts that every body has a material
    for s in np.unique(apex):
        sphere = O.bodies[int(sphere_body[s])]
        ghost = utils.sphere(sphere.state.pos + Vector3(0, 0, lift), float(layout.sphere_radius[s]),
                             material=sphere.material)
        ghost.bounded = False
        ghost_id = O.bodies.append(ghost)
        clump_id = O.bodies.clump([int(sphere_body[s]), ghost_id])
        clump = O.bodies[clump_id]
        clump.material = clump_material
        clump.state.mass = float(mass[s])
        clump.state.inertia = sphere.state.inertia
        clump.state.blockedDOFs = BLOCKED_DOFS
        clump_of[int(s)] = (clump_id, ghost_id)
    fem_mats = [w.LinIsoRayleighDampElastMat(**fem_element_material(params.grains[m].young, params.grains[m].poisson))
                for m in specimen.mineral_names]
    for (a, b, c), top in zip(tri, apex):
        element = w.Lin4NodeTetra()
        body = w.Body(shape=element, material=fem_mats[specimen.mineral[layout.sphere_cell[a]]])
        body.dynamic, body.bounded = False, False
        O.bodies.append(body)
        for node in (a, b, c):
            element.addNode(O.bodies[int(sphere_body[node])])
        element.addNode(O.bodies[clump_of[int(top)][1]])
    return {s: ids[0] for s, ids in clump_of.items()}
