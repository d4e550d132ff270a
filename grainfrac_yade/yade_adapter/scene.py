"""Turn a :class:`~grainfrac_yade.specimen.Specimen` into a YADE scene and read bonds back.

The scene holds only what a test asks for (guide: "simulate only the effects a
scene calls for"): a plain mechanical scene has exactly ForceResetter,
InsertionSortCollider, InteractionLoop (sphere geometry, JCFpm physics and law)
and NewtonIntegrator, with no gravity.  Loading, recording and stress corrosion
are Python-side *drivers* called between DEM steps by :meth:`GrainScene.run`,
listed by :meth:`GrainScene.engine_names` beside the YADE engines.

Bonds are JCFpm interactions created explicitly, one per layout bond (so bonds
exist only across Voronoi faces), with ``neverErase=True`` so a broken bond
stays as a frictional contact that carries compression once its crack closes
back to the initial gap, and no tension.  On a break the law sets tensile
strength and cohesion to zero (Table 2's residual values); this module then
writes the residual friction phi_r itself (the law keeps phi).

Rigid cells (``layout.rigid_cells``, the default grain model) are one YADE body
each: a sphere, or a clump of spheres with the polygon's mass and inertia.
Finite-element cells are clusters of separate sphere bodies held together by
YADE's finite elements; only the breakable bonds are interactions
(:attr:`GrainScene.interactions`).  Code that acts on cells uses
:meth:`GrainScene.bodies_of`, which covers both models.  Their spheres translate
only (``DEFORMABLE_BLOCKED_DOFS``) and their contact geometry takes the plain
relative displacement (``DEFORMABLE_RATCHETING_GUARD``): every bond is a
two-node spring, the model that :func:`grainfrac_yade.elastic.cluster_network`
solves statically.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import GrainfracError, NumericalFailure
from ..law import check_finite
from ..dem_step import (DEFORMABLE_BLOCKED_DOFS, DEFORMABLE_RATCHETING_GUARD,  # noqa: F401 (re-exported)
                        body_steps, cell_steps, critical_timestep, fem_node_stiffness, inertia_about_bodies,
                        lift_short_steps, rigid_masses_and_step, sphere_mass_inertia, sphere_masses_and_step)
from ..layout import BondProperties, ClumpLayout, bond_properties, cell_mass_inertia, layout_for
from ..params import Parameters
from ..specimen import Specimen
from . import load_yade

#: Bond break modes, the codes of YADE's JCFpm crack file.
INTACT, TENSION, SHEAR = 0, 1, 2
#: Material type shared by all cells: JCFpm bonds only form between equal types.
COHESIVE_TYPE = 1
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


@dataclass
class GrainScene:
    """A built YADE scene plus the numpy bookkeeping of its bonds.

    Arrays are indexed by cell (``cell_body``, ``cell_bodies``), sphere (``sphere_body``) or
    breakable bond (``interactions`` and everything ``bond_*``).  ``cell_bodies[c]`` holds all
    body ids of cell c (one for rigid cells); ``cell_body[c]`` is the cell's body for rigid
    cells, and for deformable cells only a representative: the body of the cell's sphere
    nearest its centroid.
    """
    specimen: Specimen
    layout: ClumpLayout
    props: BondProperties
    params: Parameters
    O: object
    cell_body: np.ndarray
    cell_bodies: list
    sphere_body: np.ndarray
    interactions: list
    law: object
    newton: object
    drivers: list = field(default_factory=list)   # called before every DEM step
    extras: list = field(default_factory=list)    # listed engines acting between steps (platens, corrosion)
    broken: np.ndarray = None
    break_mode: np.ndarray = None
    break_step: np.ndarray = None
    tan_residual: np.ndarray = None
    #: conservative critical DEM step of the scene [s] (:func:`critical_timestep`); :meth:`run` refuses
    #: to step with a larger ``O.dt`` (an unstable step blows up or, before it does, gives nonsense)
    dt_critical: float = math.inf
    _cracks_seen: int = 0

    def __post_init__(self):
        nb = self.layout.n_bonds
        self.broken = np.zeros(nb, dtype=bool)
        self.break_mode = np.zeros(nb, dtype=np.int8)
        self.break_step = np.full(nb, -1, dtype=np.int64)
        self.tan_residual = np.tan(self.props.residual_friction_angle)

    # ------------------------------------------------------------------ structure
    @property
    def n_bonds(self) -> int:
        return self.layout.n_bonds

    @property
    def bond_cells(self) -> np.ndarray:
        """(n_bonds, 2) the two cells of each bond."""
        return self.specimen.tessellation.face_cells[self.layout.bond_face]

    @property
    def bond_is_inter(self) -> np.ndarray:
        """(n_bonds,) True for inter-granular bonds (two minerals)."""
        return self.specimen.face_is_inter[self.layout.bond_face]

    @property
    def bond_mineral_pair(self) -> np.ndarray:
        """(n_bonds, 2) mineral indices of the two cells."""
        return self.specimen.face_minerals[self.layout.bond_face]

    def bodies_of(self, cells) -> np.ndarray:
        """All body ids of ``cells``, cell by cell in the given order (one per rigid cell)."""
        cells = np.atleast_1d(np.asarray(cells, dtype=np.int64))
        if self.layout.rigid_cells:
            return self.cell_body[cells]
        parts = [self.cell_bodies[c] for c in cells]
        return np.concatenate(parts) if parts else np.empty(0, dtype=np.int64)

    def engine_names(self) -> list:
        """YADE engines (class names), then the Python-side drivers and extras."""
        return [type(e).__name__ for e in self.O.engines] + [d.name for d in self.drivers + self.extras]

    # ------------------------------------------------------------------ stepping
    def run(self, n_steps: int):
        """Advance ``n_steps`` DEM steps; drivers act before each step, breaks are synced after.

        NumericalFailure, before any step, if ``O.dt`` is not within (0, ``dt_critical``].
        """
        O = self.O
        if not 0 < O.dt <= self.dt_critical:
            raise NumericalFailure(f"DEM step {O.dt:.4g} s is not within (0, {self.dt_critical:.4g} s], the critical "
                                   "step of this scene (numerics.timestep_safety <= 1 keeps it there)")
        law = self.law
        drivers = self.drivers
        for _ in range(n_steps):
            for d in drivers:
                d.before_step(self)
            O.step()
            if law.nbTensCracks + law.nbShearCracks != self._cracks_seen:
                self.sync_breaks()

    def sync_breaks(self) -> np.ndarray:
        """Find bonds the law broke since the last call; set residual friction; return their indices."""
        law = self.law
        n_tens, n_shear = law.nbTensCracks, law.nbShearCracks
        if n_tens + n_shear == self._cracks_seen:
            return np.empty(0, dtype=np.int64)
        candidates = np.flatnonzero(~self.broken)
        new = [k for k in candidates if not self.interactions[k].phys.isCohesive]
        new = np.asarray(new, dtype=np.int64)
        prev_tens = getattr(self, "_tens_seen", 0)
        tens_new = n_tens - prev_tens
        for k in new:
            phys = self.interactions[k].phys
            if tens_new == len(new):
                mode = TENSION
            elif tens_new == 0:
                mode = SHEAR
            else:  # both kinds in one step: an opening bond broke in tension
                mode = TENSION if self.bond_separated([k])[0] else SHEAR
            self.break_mode[k] = mode
            phys.tanFrictionAngle = float(self.tan_residual[k])
        self.broken[new] = True
        self.break_step[new] = self.O.iter
        self._cracks_seen = n_tens + n_shear
        self._tens_seen = n_tens
        return new

    def break_bonds(self, indices, mode: int):
        """Break bonds ourselves (no JCFpm crack record): no cohesion or tension, residual friction.

        Used where the law cannot break a bond whose strength has gone, e.g. a compressed bond
        corroded to nothing while friction alone carries its shear (area mode, mode 3).
        """
        for k in np.atleast_1d(indices):
            ph = self.interactions[int(k)].phys
            ph.isCohesive = False
            ph.FnMax = ph.FsMax = 0.0
            ph.tanFrictionAngle = float(self.tan_residual[k])
            self.broken[k] = True
            self.break_mode[k] = mode
            self.break_step[k] = self.O.iter

    # ------------------------------------------------------------------ reading state
    def bond_forces(self, indices=None):
        """Normal force (tension positive) and shear force magnitude [N] of bonds.

        Reads the law's normal force (along the line of centres, or along the face normal for
        bonds on their face's plane) and ``|shearForce|``; about 2-3 us per bond.
        """
        idx = np.arange(self.n_bonds) if indices is None else np.asarray(indices)
        fn = np.empty(len(idx))
        fs = np.empty(len(idx))
        inter = self.interactions
        on_face = self.layout.bond_normal is not None
        for n, k in enumerate(idx):
            i = inter[k]
            phys = i.phys
            fn[n] = -phys.normalForce.dot(phys.jointNormal if on_face else i.geom.normal)
            fs[n] = phys.shearForce.norm()
        return fn, fs

    def bond_separated(self, indices) -> np.ndarray:
        """(n,) True where a bond's spheres are further apart than when it was made (an open crack):
        along the line of centres (penetration below its initial value), or across the face for bonds
        on their face's plane (YADE's smooth joint: |(x_b - x_a) . n| above its initial value)."""
        inter = self.interactions
        if self.layout.bond_normal is None:
            return np.array([inter[k].geom.penetrationDepth - inter[k].phys.initD < 0 for k in indices], dtype=bool)
        bodies = self.O.bodies
        out = []
        for k in indices:
            i = inter[k]
            gap = abs((bodies[i.id2].state.pos - bodies[i.id1].state.pos).dot(i.phys.jointNormal))
            out.append(i.phys.initD - gap < 0)
        return np.array(out, dtype=bool)

    def cell_positions(self, cells=None) -> np.ndarray:
        """(n, 3) current positions of cells [m]: the body (rigid), the mass centre of the spheres (deformable)."""
        cells = np.arange(self.specimen.n_cells) if cells is None else np.asarray(cells)
        bodies = self.O.bodies
        if self.layout.rigid_cells:
            return np.array([tuple(bodies[int(b)].state.pos) for b in self.cell_body[cells]])
        out = []
        for c in cells:
            states = [bodies[int(b)].state for b in self.cell_bodies[c]]
            m = np.array([st.mass for st in states])
            out.append(m @ np.array([tuple(st.pos) for st in states]) / m.sum())
        return np.array(out)

    def cell_forces(self, cells) -> np.ndarray:
        """(n, 3) resultant interaction force on each cell (summed over its bodies) from the last step [N]."""
        f = self.O.forces.f
        return np.array([np.sum([tuple(f(int(b))) for b in self.bodies_of([c])], axis=0) for c in cells])


def check_value(name, value, dem_step):
    """NumericalFailure if a measured value is NaN or infinite."""
    if not math.isfinite(value):
        raise NumericalFailure(f"{name} is {value} at DEM step {dem_step}")


def resultant_forces(scene, body_ids) -> tuple:
    """(largest, mean) resultant force on ``body_ids`` from the last DEM step [N]; NumericalFailure
    if one is NaN or infinite."""
    f = scene.O.forces.f
    res = np.array([f(b).norm() for b in body_ids])
    check_finite("resultant force", res, body_ids, item="body")
    return res.max(), res.mean()


#: Bonds sampled for the mean bond force (every k-th of the given ones, k = len // this).
BOND_FORCE_SAMPLE = 500


def mean_bond_force(scene, bonds) -> float:
    """Mean magnitude of the bond force [N] over a sample of ``bonds`` (about BOND_FORCE_SAMPLE of
    them), the scale that unbalanced forces are measured against; 0 if there are none."""
    sample = bonds[:: max(1, len(bonds) // BOND_FORCE_SAMPLE)]
    fn, fs = scene.bond_forces(sample)
    check_finite("bond force", np.hypot(fn, fs), sample)
    return float(np.mean(np.hypot(fn, fs))) if len(sample) else 0.0


def broken_counts(scene, broken=None) -> dict:
    """Broken bonds by mode (tensile, shear) and kind (inter-, intra-granular); ``broken``: a mask of
    the bonds to count (default: every broken bond; a mode is set only on broken bonds)."""
    b = scene.broken if broken is None else broken
    inter = scene.bond_is_inter
    return {"broken_total": int(b.sum()),
            "broken_tensile": int((b & (scene.break_mode == TENSION)).sum()),
            "broken_shear": int((b & (scene.break_mode == SHEAR)).sum()),
            "broken_inter": int((b & inter).sum()), "broken_intra": int((b & ~inter).sum())}


def softened_past_peak(value, peak, broken_now, broken_at_peak, stop_ratio) -> bool:
    """True once a strain-controlled test's measured ``value`` has fallen below ``stop_ratio`` x its
    ``peak`` with bonds broken since the peak.  This model softens only as bonds break: a drop with
    no break since the peak is the elastic ringing of a specimen set in motion from rest (measured on
    a one-cell-wide column: 3.4 MPa, then below 2.4 MPa, no bond broken), not a post-peak branch."""
    return peak > 0 and value < stop_ratio * peak and broken_now > broken_at_peak


def bond_segments(scene, indices) -> np.ndarray:
    """(c, 2, 2) face pieces of bonds [m]: centred on the bond point, as long as the bond's share."""
    lay, t = scene.layout, scene.specimen.tessellation
    idx = np.asarray(indices, dtype=np.int64)
    normal = t.face_normal[lay.bond_face[idx]]
    tangent = np.column_stack([-normal[:, 1], normal[:, 0]])
    half = 0.5 * lay.bond_area[idx] / scene.specimen.thickness
    p = lay.bond_point[idx, :2]
    return np.stack([p - half[:, None] * tangent, p + half[:, None] * tangent], axis=1)


def _blocked_dofs(dim: int) -> str:
    """Pseudo-2D: no out-of-plane translation (z) or rotation about x, y."""
    return "zXY" if dim == 2 else ""


def _cell_spheres(layout: ClumpLayout, n_cells: int) -> list:
    """Sphere indices of each cell, ascending."""
    order = np.argsort(layout.sphere_cell, kind="stable")
    bounds = np.searchsorted(layout.sphere_cell[order], np.arange(n_cells + 1))
    return [order[bounds[c]:bounds[c + 1]] for c in range(n_cells)]


def _append_rigid_cells(O, utils, Vector3, specimen, layout, mats, mass, inertia, blocked):
    """One body per cell (sphere or clump) with the polygon's mass and inertia.

    Returns (sphere_body, cell_body, body positions (n, 3), inertia about the bodies).
    """
    sphere_body = np.empty(layout.n_spheres, dtype=np.int64)
    cell_body = np.empty(specimen.n_cells, dtype=np.int64)
    for cell, members in enumerate(_cell_spheres(layout, specimen.n_cells)):
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
    body_pos3 = np.array([tuple(O.bodies[int(b)].state.pos) for b in cell_body])
    inertia = inertia_about_bodies(specimen, mass, inertia, body_pos3)
    _set_mass_inertia(O, Vector3, cell_body, mass, inertia, blocked)
    return sphere_body, cell_body, body_pos3, inertia


def _set_mass_inertia(O, Vector3, bodies, mass, inertia, blocked=None):
    """Body ``bodies[i]`` gets ``mass[i]`` and ``inertia[i]`` on all three axes (and ``blocked`` DOFs if given)."""
    for i, body in enumerate(bodies):
        st = O.bodies[int(body)].state
        st.mass = float(mass[i])
        st.inertia = Vector3(*([float(inertia[i])] * 3))
        if blocked is not None:
            st.blockedDOFs = blocked


def _append_deformable_cells(O, utils, Vector3, specimen, layout, mats, mass, inertia, blocked):
    """One sphere body per layout sphere (not clumped).

    Returns (sphere_body, cell_body (each cell's sphere nearest its centroid), cell_bodies).
    """
    spheres = [utils.sphere(Vector3(*layout.sphere_center[m]), float(layout.sphere_radius[m]),
                            material=mats[specimen.mineral[layout.sphere_cell[m]]]) for m in range(layout.n_spheres)]
    sphere_body = np.asarray(O.bodies.append(spheres), dtype=np.int64)
    _set_mass_inertia(O, Vector3, sphere_body, mass, inertia, blocked)
    members = _cell_spheres(layout, specimen.n_cells)
    if any(len(m) == 0 for m in members):
        raise GrainfracError("deformable layout: a cell has no sphere; fix: the layout builder must give every "
                             "cell at least one sphere")
    centroid = specimen.tessellation.cell_centroid
    nearest = [m[np.argmin(((layout.sphere_center[m, :2] - centroid[c, :2]) ** 2).sum(1))]
               for c, m in enumerate(members)]
    return sphere_body, sphere_body[nearest], [sphere_body[m] for m in members]


def _without_native_stdout(make):
    """``make()`` with the process's standard output sent to /dev/null (YADE's FEInternalForceEngine
    constructor prints two debugging lines from C++)."""
    import ctypes
    import os
    import sys
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
    ``FEM_LIFT`` x thickness above its apex a (:func:`grainfrac_yade.deformable.element_apex`) and
    clumped with a, so that a' moves with a in the plane: the tetrahedron's displacement field is
    then the triangle's, constant in z, its strain the triangle's (plane strain, the z motion of
    every sphere being blocked), its volume area x thickness.  The lifted node has no bound (no
    contact); the clump of a and a' is the body that moves, with a's mass.
    """
    from ..deformable import element_apex
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
        clump.state.blockedDOFs = DEFORMABLE_BLOCKED_DOFS
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


def verlet_distance(layout: ClumpLayout, numerics) -> float:
    """``InsertionSortCollider.verletDist``: ``numerics.verlet_fraction`` x the sphere radius at quantile
    ``numerics.verlet_radius_quantile``.  At quantile 0 it is YADE's own relative form (a negative value:
    that fraction of the smallest radius, which the collider finds itself), so the default scene is
    YADE's default; otherwise an absolute distance [m]."""
    if numerics.verlet_radius_quantile == 0:
        return -numerics.verlet_fraction
    return float(numerics.verlet_fraction * np.quantile(layout.sphere_radius, numerics.verlet_radius_quantile))


def build_scene(specimen: Specimen, params: Parameters, layout: ClumpLayout | None = None) -> GrainScene:
    """Build the plain mechanical YADE scene of ``specimen`` (replaces any current scene)."""
    yade = load_yade()
    from yade import O, utils, Vector3
    from yade import wrapper as w

    for pair, c in params.contacts.items():
        if c.residual_tensile_strength > 0 or c.residual_cohesion > 0:
            raise GrainfracError(f'contacts."{"/".join(pair)}": residual tensile strength and cohesion must be 0 '
                                 "with YADE's JCFpm law (it drops both to zero on a break); fix: set them to 0")
    layout = layout or layout_for(specimen, params)
    dim = specimen.tessellation.dim
    if not layout.rigid_cells and dim != 2:
        raise GrainfracError("resolution.grain_model: deformable cells are built for 2D specimens only; fix: use "
                             'grain_model = "rigid" with specimen.dimension = 3')
    props = bond_properties(specimen, layout, params)
    mass, inertia = cell_mass_inertia(specimen, params, params.numerics.density_scale)

    O.reset()
    mats = []
    for name in specimen.mineral_names:
        g, c = params.grains[name], params.contact(name, name)
        # Strengths of 1 Pa make the first-step bonds cohesive; every bond's values are written below.
        mats.append(O.materials.append(w.JCFpmMat(
            young=g.young, poisson=g.poisson, density=g.density, type=COHESIVE_TYPE,
            frictionAngle=c.friction_angle, residualFrictionAngle=c.residual_friction_angle,
            tensileStrength=1.0, cohesion=1.0)))
    law = w.Law2_ScGeom_JCFpmPhys_JointedCohesiveFrictionalPM(neverErase=True,
                                                               smoothJoint=layout.bond_normal is not None)
    geometry = w.Ig2_Sphere_Sphere_ScGeom()
    if not layout.rigid_cells:
        geometry.avoidGranularRatcheting = DEFORMABLE_RATCHETING_GUARD
    newton = w.NewtonIntegrator(damping=params.numerics.damping, gravity=(0, 0, 0))
    # spheres larger than their bond gaps (bonds on face planes): one collision mask per cell
    per_cell_masks = layout.bond_normal is not None
    # finite-element cells: their elements' internal forces, before the integrator
    elements = ([_without_native_stdout(lambda: w.FEInternalForceEngine([w.If2_Lin4NodeTetra_LinIsoRayleighDampElast()]))]
                if layout.n_elements else [])
    O.engines = [
        w.ForceResetter(),
        w.InsertionSortCollider([w.Bo1_Sphere_Aabb()], avoidSelfInteractionMask=CELL_MASK_BIT if per_cell_masks else 0,
                                verletDist=verlet_distance(layout, params.numerics)),
        w.InteractionLoop([geometry],
                          [w.Ip2_JCFpmMat_JCFpmMat_JCFpmPhys(cohesiveTresholdIteration=1)], [law]),
        *elements,
        newton,
    ]
    blocked = _blocked_dofs(dim) if layout.rigid_cells else DEFORMABLE_BLOCKED_DOFS
    rotating = "Z" not in blocked
    floor = params.numerics.step_floor_quantile
    guard = geometry.avoidGranularRatcheting
    # masses, inertias and the critical step: the core's arithmetic (grainfrac_yade.dem_step), which
    # specimen.json's critical_dem_step_s repeats without YADE
    if layout.rigid_cells:
        sphere_body, cell_body, body_pos3, inertia = _append_rigid_cells(
            O, utils, Vector3, specimen, layout, mats, mass, inertia, blocked)
        cell_bodies = [cell_body[c:c + 1] for c in range(specimen.n_cells)]
        mass, inertia, dt_crit = rigid_masses_and_step(specimen, layout, props, mass, inertia, body_pos3, floor,
                                                       rotating, guard)
        if floor > 0:
            _set_mass_inertia(O, Vector3, cell_body, mass, inertia)
    else:
        mass, inertia, dt_crit, _ = sphere_masses_and_step(specimen, params, layout, props, mass, floor,
                                                           rotating, guard)
        sphere_body, cell_body, cell_bodies = _append_deformable_cells(
            O, utils, Vector3, specimen, layout, mats, mass, inertia, blocked)
    interactions = []
    tan_phi = np.tan(props.friction_angle)
    for k, (i, j) in enumerate(layout.bond_spheres):
        inter = utils.createInteraction(int(sphere_body[i]), int(sphere_body[j]))
        ph = inter.phys
        area = float(layout.bond_area[k])
        ph.kn = float(props.normal_stiffness[k])
        ph.ks = float(props.shear_stiffness[k])
        ph.FnMax = float(props.tensile_strength[k]) * area
        ph.FsMax = float(props.cohesion[k]) * area
        ph.tanFrictionAngle = float(tan_phi[k])
        ph.crossSection = area
        if layout.bond_normal is not None:
            ph.isOnJoint = True
            ph.jointNormal = Vector3(*layout.bond_normal[k], 0.0)
        interactions.append(inter)
    if per_cell_masks:
        for m, body in enumerate(sphere_body):
            O.bodies[int(body)].mask = cell_mask(int(layout.sphere_cell[m]))
    if layout.n_elements:
        clump_of = _append_fem_elements(O, w, utils, Vector3, specimen, params, layout, sphere_body, mats, mass)
        # the bodies that move: a clump in place of each apex sphere
        moving = sphere_body.copy()
        for s, clump_id in clump_of.items():
            moving[s] = clump_id
        cell_body = np.array([moving[np.flatnonzero(sphere_body == b)[0]] for b in cell_body], dtype=np.int64)
        cell_bodies = [moving[m] for m in _cell_spheres(layout, specimen.n_cells)]
    if not 0 < dt_crit < math.inf:
        raise GrainfracError(f"the scene's critical DEM step is {dt_crit:g} s (a cell without mass, or no bond "
                             "at all); fix: check the specimen's cells and faces")
    O.dt = params.numerics.timestep_safety * dt_crit
    return GrainScene(specimen=specimen, layout=layout, props=props, params=params, O=O,
                      cell_body=cell_body, cell_bodies=cell_bodies, sphere_body=sphere_body,
                      interactions=interactions, law=law, newton=newton, dt_critical=dt_crit)
