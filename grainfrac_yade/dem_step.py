"""Critical DEM step of a specimen's scene, computed without YADE (pure numpy).

The YADE scene (:func:`grainfrac_yade.yade_adapter.scene.build_scene`) sets its masses and its step
with the functions of this module, so that :func:`critical_dem_step` (``specimen.json``'s
``critical_dem_step_s``: what a specimen will cost before it is run) equals the scene's
``dt_critical`` by construction.  The bound is the conservative one of each body on its own:

* rigid cells (one YADE body per cell): sqrt(m / K) and sqrt(I / K_rot), K summing k_n + k_s of the
  cell's bonds, K_rot (k_n + k_s) |r|^2 with r the lever arm from the body to the bond point
  (:func:`body_steps`);
* finite-element cells: sqrt(m / K) per sphere, K the Gershgorin bound of its stiffness row (elements
  and bonds, :func:`grainfrac_yade.elastic.node_stiffness`); a cell's mass is spread over its spheres
  in proportion to the area lumped on each (:func:`sphere_mass_inertia`);

masses are density x ``numerics.density_scale``, raised cell by cell to ``numerics.step_floor_quantile``
where that is on (:func:`lift_short_steps`).  The scene's DEM step is ``numerics.timestep_safety`` x
this critical step.
"""
from __future__ import annotations

import numpy as np

from .layout import BondProperties, ClumpLayout, bond_properties, cell_mass_inertia, layout_for, step_floor_factors
from .params import Parameters
from .specimen import Specimen

#: Blocked DOFs of the spheres of fem cells: in-plane translation only, the two-node springs and
#: plane elements that the static solve (:func:`grainfrac_yade.elastic.cluster_network`) assumes.
#: Measured on the retired spring lattice (4 x 8 mm, seed 1, 2 nodes per face, axial strain 3e-4):
#: "zXYZ" with plain kinematics (below) gave the static solve's E and nu (89.8 against 89.6 GPa,
#: 0.208 against 0.209); "zXY" (free spin, as rigid cells) with YADE's default kinematics gave
#: E 80.5 GPa, nu 0.255 and a DEM step 4.6 x shorter (the rotation of the smallest spheres sets it).
DEFORMABLE_BLOCKED_DOFS = "zXYZ"
#: ``Ig2_Sphere_Sphere_ScGeom.avoidGranularRatcheting`` in fem scenes.  YADE's default (True)
#: scales the relative translation of two spheres d apart by (r1 + r2)/d in the shear increment, so
#: a spring between non-touching spheres would act with k_s (r1 + r2)/d (measured: 1/2 at d = 2(r1 + r2)).
#: False: the plain relative displacement, k_s as given, the static solve's kinematics.  Rigid cells
#: keep YADE's default.
DEFORMABLE_RATCHETING_GUARD = False


def _oscillation_steps(n_bodies: int, ends: np.ndarray, k: np.ndarray, lever_sq: np.ndarray,
                       mass: np.ndarray, inertia: np.ndarray | None) -> np.ndarray:
    """(n_bodies,) the smaller of sqrt(m/K) and sqrt(I/K_rot) of each body, for springs of stiffness ``k``
    joining ``ends`` (c, 2).

    K sums k over a body's springs, K_rot sums k x ``lever_sq`` ((2c,): the first ends' squared
    lever arms, then the second ends').  ``inertia`` None: bodies that do not rotate, sqrt(m/K) only.
    """
    k_body = np.bincount(ends.ravel(), weights=np.repeat(k, 2), minlength=n_bodies)
    with np.errstate(divide="ignore"):
        t_trans = np.sqrt(mass / k_body)
        if inertia is None:
            return t_trans
        k_rot = np.bincount(np.concatenate([ends[:, 0], ends[:, 1]]), weights=np.tile(k, 2) * lever_sq,
                            minlength=n_bodies)
        t_rot = np.sqrt(inertia / k_rot)
    return np.minimum(t_trans, t_rot)


def body_steps(layout: ClumpLayout, props: BondProperties, specimen: Specimen,
               mass: np.ndarray, inertia: np.ndarray, body_pos: np.ndarray | None = None,
               rotating: bool = True, ratcheting_guard: bool = True) -> np.ndarray:
    """Each body's own critical DEM step [s]: sqrt(m/K), and sqrt(I/K_rot) where it rotates.

    Rigid cells: the bodies are the cells (``mass``, ``inertia`` per cell; ``body_pos`` (n, 3)
    the cell bodies' positions).  K sums k_n + k_s of a cell's bonds; K_rot sums
    (k_n + k_s) |r|^2 with r the lever arm from the cell body to the bond point.

    Sphere bodies: the bodies are the spheres (``mass``, ``inertia`` per sphere).  K sums
    k_n + k_s of a sphere's bonds.  ``rotating=False`` (rotation blocked,
    ``DEFORMABLE_BLOCKED_DOFS``, the default): sqrt(m/K) only.  Otherwise K_rot sums
    (k_n + k_s) a l: l = max(r, (d + r - r_other)/2) the lever of the JCFpm torque (r for touching
    spheres; for spheres d apart the force acts half-way across the gap), a the lever of rotation
    in YADE's shear increment: the radius r with ``ratcheting_guard``
    (``avoidGranularRatcheting``, YADE's default), l without.
    """
    if layout.rigid_cells:
        cells = specimen.tessellation.face_cells[layout.bond_face]
        lever = np.concatenate([layout.bond_point - body_pos[cells[:, 0]],
                                layout.bond_point - body_pos[cells[:, 1]]])
        return _oscillation_steps(specimen.n_cells, cells, props.normal_stiffness + props.shear_stiffness,
                                  (lever**2).sum(1), mass, inertia)
    ends = layout.bond_spheres.astype(np.int64)
    k = props.normal_stiffness + props.shear_stiffness
    r = layout.sphere_radius[ends]
    d = np.linalg.norm(layout.sphere_center[ends[:, 0]] - layout.sphere_center[ends[:, 1]], axis=1)
    torque_lever = np.maximum(r, 0.5 * (d[:, None] + r - r[:, ::-1]))
    lever_sq = ((r if ratcheting_guard else torque_lever) * torque_lever).T.ravel()
    return _oscillation_steps(layout.n_spheres, ends, k, lever_sq, mass, inertia if rotating else None)


def critical_timestep(layout: ClumpLayout, props: BondProperties, specimen: Specimen,
                      mass: np.ndarray, inertia: np.ndarray, body_pos: np.ndarray | None = None,
                      rotating: bool = True, ratcheting_guard: bool = True) -> float:
    """Conservative critical DEM time step [s]: the smallest of the bodies' own steps (:func:`body_steps`)."""
    return float(body_steps(layout, props, specimen, mass, inertia, body_pos, rotating, ratcheting_guard).min())


def fem_node_stiffness(specimen: Specimen, params: Parameters, layout: ClumpLayout) -> np.ndarray:
    """(s,) Gershgorin bound of each sphere's stiffness row in finite-element cells [N/m] (elements and
    bonds, :func:`grainfrac_yade.elastic.node_stiffness`): a sphere's own step is sqrt(m / K)."""
    from .elastic import cluster_network, node_stiffness
    return node_stiffness(cluster_network(specimen, params, layout))


def cell_steps(body_step: np.ndarray, body_cell: np.ndarray, n_cells: int) -> np.ndarray:
    """(n_cells,) the smallest own step of each cell's bodies [s]."""
    steps = np.full(n_cells, np.inf)
    np.minimum.at(steps, body_cell, body_step)
    return steps


def lift_short_steps(quantile: float, body_step: np.ndarray, body_cell: np.ndarray, mass: np.ndarray,
                     inertia: np.ndarray) -> tuple:
    """Per-body ``mass`` and ``inertia`` with ``numerics.step_floor_quantile`` applied: every body of a cell
    whose smallest own step (``body_step``, bodies of cell ``body_cell``) lies below the quantile of the
    cells' steps is made heavier by the cell's :func:`grainfrac_yade.layout.step_floor_factors`."""
    n_cells = int(body_cell.max()) + 1
    f = step_floor_factors(cell_steps(body_step, body_cell, n_cells), quantile)[body_cell]
    return mass * f, inertia * f




def sphere_mass_inertia(specimen: Specimen, layout: ClumpLayout, cell_mass: np.ndarray):
    """Mass [kg] and inertia [kg m^2] of each sphere of deformable cells.

    Mass: the cell's areal mass (cell mass / cell area, i.e. density x density scale x thickness)
    times the area lumped on the sphere (``layout.sphere_area``), so a cell's spheres carry its
    mass.  Inertia: a disc's 0.5 m r^2 on all three axes (pseudo-2D).
    """
    areal = cell_mass / specimen.tessellation.cell_measure
    mass = areal[layout.sphere_cell] * layout.sphere_area
    return mass, 0.5 * mass * layout.sphere_radius**2




def kinematics(layout: ClumpLayout) -> tuple:
    """(rotating, ratcheting_guard) of the scene's bodies: rigid cells spin in the plane and keep YADE's
    ``avoidGranularRatcheting``; the spheres of deformable and fem cells translate only
    (:data:`DEFORMABLE_BLOCKED_DOFS`) with :data:`DEFORMABLE_RATCHETING_GUARD`."""
    if layout.rigid_cells:
        return True, True
    return "Z" not in DEFORMABLE_BLOCKED_DOFS, DEFORMABLE_RATCHETING_GUARD


def inertia_about_bodies(specimen: Specimen, mass: np.ndarray, inertia: np.ndarray, body_pos: np.ndarray) -> np.ndarray:
    """Rigid cells: the polygon inertia about each cell body's reference point ``body_pos`` (n, >= dim)
    instead of the centroid (parallel-axis theorem)."""
    dim = specimen.tessellation.dim
    return inertia + mass * ((body_pos[:, :dim] - specimen.tessellation.cell_centroid) ** 2).sum(1)


def rigid_body_positions(layout: ClumpLayout, n_cells: int) -> np.ndarray:
    """(n_cells, 3) where YADE puts each rigid cell's body: its sphere's centre, or for a clump the mean
    of its members' centres weighted by their volumes (YADE's clump without discretisation: members'
    masses, one material per cell)."""
    w = layout.sphere_radius ** 3
    pos = np.zeros((n_cells, 3))
    total = np.bincount(layout.sphere_cell, weights=w, minlength=n_cells)
    for axis in range(3):
        pos[:, axis] = np.bincount(layout.sphere_cell, weights=w * layout.sphere_center[:, axis],
                                   minlength=n_cells) / total
    single = np.bincount(layout.sphere_cell, minlength=n_cells) == 1
    pos[layout.sphere_cell[single[layout.sphere_cell]]] = layout.sphere_center[single[layout.sphere_cell]]
    return pos


def rigid_masses_and_step(specimen: Specimen, layout: ClumpLayout, props: BondProperties, mass: np.ndarray,
                          inertia: np.ndarray, body_pos: np.ndarray, floor: float, rotating: bool = True,
                          ratcheting_guard: bool = True) -> tuple:
    """Rigid cells: (mass, inertia, critical step [s]) with the step floor ``floor`` applied; ``inertia``
    about the bodies (:func:`inertia_about_bodies`), ``body_pos`` (n, 3)."""
    if floor > 0:
        own = body_steps(layout, props, specimen, mass, inertia, body_pos, rotating, ratcheting_guard)
        mass, inertia = lift_short_steps(floor, own, np.arange(specimen.n_cells), mass, inertia)
    return mass, inertia, critical_timestep(layout, props, specimen, mass, inertia, body_pos, rotating=rotating,
                                            ratcheting_guard=ratcheting_guard)


def sphere_masses_and_step(specimen: Specimen, params: Parameters, layout: ClumpLayout, props: BondProperties,
                           cell_mass: np.ndarray, floor: float, rotating: bool = False,
                           ratcheting_guard: bool = False) -> tuple:
    """Deformable and fem cells: (sphere mass, sphere inertia, critical step [s], fem node stiffness or None)
    with the step floor ``floor`` applied."""
    fem_k = fem_node_stiffness(specimen, params, layout) if layout.n_elements else None
    mass, inertia = sphere_mass_inertia(specimen, layout, cell_mass)
    if floor > 0:
        own = (np.sqrt(mass / fem_k) if fem_k is not None else
               body_steps(layout, props, specimen, mass, inertia, None, rotating, ratcheting_guard))
        mass, inertia = lift_short_steps(floor, own, layout.sphere_cell, mass, inertia)
    if fem_k is not None:
        with np.errstate(divide="ignore"):
            dt = float(np.sqrt(mass / fem_k).min())
    else:
        dt = critical_timestep(layout, props, specimen, mass, inertia, None, rotating=rotating,
                               ratcheting_guard=ratcheting_guard)
    return mass, inertia, dt, fem_k


def critical_dem_step(specimen: Specimen, params: Parameters, layout: ClumpLayout | None = None) -> float:
    """Critical DEM step [s] of the scene ``build_scene(specimen, params)`` would build (its ``dt_critical``),
    for the grain model ``params.resolution.grain_model``; no YADE needed."""
    layout = layout or layout_for(specimen, params)
    props = bond_properties(specimen, layout, params)
    mass, inertia = cell_mass_inertia(specimen, params, params.numerics.density_scale)
    rotating, guard = kinematics(layout)
    floor = params.numerics.step_floor_quantile
    if layout.rigid_cells:
        pos = rigid_body_positions(layout, specimen.n_cells)
        inertia = inertia_about_bodies(specimen, mass, inertia, pos)
        return rigid_masses_and_step(specimen, layout, props, mass, inertia, pos, floor, rotating, guard)[2]
    return sphere_masses_and_step(specimen, params, layout, props, mass, floor, rotating, guard)[2]
