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
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import GrainfracError
from ..layout import BondProperties, ClumpLayout, bond_properties, build_layout, cell_mass_inertia
from ..params import Parameters
from ..specimen import Specimen
from . import load_yade

#: Bond break modes, the codes of YADE's JCFpm crack file.
INTACT, TENSION, SHEAR = 0, 1, 2
#: Material type shared by all cells: JCFpm bonds only form between equal types.
COHESIVE_TYPE = 1


@dataclass
class GrainScene:
    """A built YADE scene plus the numpy bookkeeping of its bonds.

    Arrays are indexed by cell (``cell_body``) or bond (everything ``bond_*``).
    """
    specimen: Specimen
    layout: ClumpLayout
    props: BondProperties
    params: Parameters
    O: object
    cell_body: np.ndarray
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

    def engine_names(self) -> list:
        """YADE engines (class names), then the Python-side drivers and extras."""
        return [type(e).__name__ for e in self.O.engines] + [d.name for d in self.drivers + self.extras]

    # ------------------------------------------------------------------ stepping
    def run(self, n_steps: int):
        """Advance ``n_steps`` DEM steps; drivers act before each step, breaks are synced after."""
        O = self.O
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
                geom = self.interactions[k].geom
                mode = TENSION if geom.penetrationDepth - phys.initD < 0 else SHEAR
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

        Reads ``kn * (penetrationDepth - initD)`` (the law's own normal force,
        compression positive) and ``|shearForce|``; about 2-3 us per bond.
        """
        idx = np.arange(self.n_bonds) if indices is None else np.asarray(indices)
        fn = np.empty(len(idx))
        fs = np.empty(len(idx))
        inter = self.interactions
        for n, k in enumerate(idx):
            i = inter[k]
            phys = i.phys
            fn[n] = -phys.normalForce.dot(i.geom.normal)
            fs[n] = phys.shearForce.norm()
        return fn, fs

    def cell_positions(self, cells=None) -> np.ndarray:
        """(n, 3) current positions of cell bodies [m]."""
        ids = self.cell_body if cells is None else self.cell_body[np.asarray(cells)]
        return np.array([tuple(self.O.bodies[int(b)].state.pos) for b in ids])

    def cell_forces(self, cells) -> np.ndarray:
        """(n, 3) resultant interaction force on each cell body from the last step [N]."""
        f = self.O.forces.f
        return np.array([tuple(f(int(b))) for b in self.cell_body[np.asarray(cells)]])


def broken_counts(scene) -> dict:
    """Broken bonds by mode (tensile, shear) and kind (inter-, intra-granular)."""
    b, inter = scene.broken, scene.bond_is_inter
    return {"broken_total": int(b.sum()),
            "broken_tensile": int((scene.break_mode == TENSION).sum()),
            "broken_shear": int((scene.break_mode == SHEAR).sum()),
            "broken_inter": int((b & inter).sum()), "broken_intra": int((b & ~inter).sum())}


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


def critical_timestep(layout: ClumpLayout, props: BondProperties, specimen: Specimen,
                      mass: np.ndarray, inertia: np.ndarray, body_pos: np.ndarray) -> float:
    """Conservative critical DEM time step [s]: min over cells of sqrt(m/K) and sqrt(I/K_rot).

    K sums k_n + k_s of a cell's bonds; K_rot sums (k_n + k_s) |r|^2 with r the
    lever arm from the cell body to the bond point.
    """
    cells = specimen.tessellation.face_cells[layout.bond_face]
    k = props.normal_stiffness + props.shear_stiffness
    n = specimen.n_cells
    k_cell = np.bincount(cells.ravel(), weights=np.repeat(k, 2), minlength=n)
    lever = np.concatenate([layout.bond_point - body_pos[cells[:, 0]], layout.bond_point - body_pos[cells[:, 1]]])
    k_rot = np.bincount(np.concatenate([cells[:, 0], cells[:, 1]]),
                        weights=np.tile(k, 2) * (lever**2).sum(1), minlength=n)
    with np.errstate(divide="ignore"):
        t_trans = np.sqrt(mass / k_cell)
        t_rot = np.sqrt(inertia / k_rot)
    return float(min(t_trans.min(), t_rot.min()))


def build_scene(specimen: Specimen, params: Parameters, layout: ClumpLayout | None = None) -> GrainScene:
    """Build the plain mechanical YADE scene of ``specimen`` (replaces any current scene)."""
    yade = load_yade()
    from yade import O, utils, Vector3
    from yade import wrapper as w

    for pair, c in params.contacts.items():
        if c.residual_tensile_strength > 0 or c.residual_cohesion > 0:
            raise GrainfracError(f'contacts."{"/".join(pair)}": residual tensile strength and cohesion must be 0 '
                                 "with YADE's JCFpm law (it drops both to zero on a break); fix: set them to 0")
    layout = layout or build_layout(specimen, params.resolution.spheres_per_cell)
    props = bond_properties(specimen, layout, params)
    mass, inertia = cell_mass_inertia(specimen, params, params.numerics.density_scale)
    dim = specimen.tessellation.dim

    O.reset()
    mats = []
    for name in specimen.mineral_names:
        g, c = params.grains[name], params.contact(name, name)
        # Strengths of 1 Pa make the first-step bonds cohesive; every bond's values are written below.
        mats.append(O.materials.append(w.JCFpmMat(
            young=g.young, poisson=g.poisson, density=g.density, type=COHESIVE_TYPE,
            frictionAngle=c.friction_angle, residualFrictionAngle=c.residual_friction_angle,
            tensileStrength=1.0, cohesion=1.0)))
    law = w.Law2_ScGeom_JCFpmPhys_JointedCohesiveFrictionalPM(neverErase=True)
    newton = w.NewtonIntegrator(damping=params.numerics.damping, gravity=(0, 0, 0))
    O.engines = [
        w.ForceResetter(),
        w.InsertionSortCollider([w.Bo1_Sphere_Aabb()]),
        w.InteractionLoop([w.Ig2_Sphere_Sphere_ScGeom()],
                          [w.Ip2_JCFpmMat_JCFpmMat_JCFpmPhys(cohesiveTresholdIteration=1)], [law]),
        newton,
    ]
    blocked = _blocked_dofs(dim)
    n_cells = specimen.n_cells
    sphere_body = np.empty(layout.n_spheres, dtype=np.int64)
    cell_body = np.empty(n_cells, dtype=np.int64)
    order = np.argsort(layout.sphere_cell, kind="stable")
    bounds = np.searchsorted(layout.sphere_cell[order], np.arange(n_cells + 1))
    for cell in range(n_cells):
        members = order[bounds[cell]:bounds[cell + 1]]
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
    body_pos = body_pos3[:, :dim]
    centroid = specimen.tessellation.cell_centroid
    # polygon inertia about the body's reference point (parallel-axis theorem)
    inertia = inertia + mass * ((body_pos - centroid) ** 2).sum(1)
    for cell, body in enumerate(cell_body):
        st = O.bodies[int(body)].state
        st.mass = float(mass[cell])
        st.inertia = Vector3(*([float(inertia[cell])] * 3))
        st.blockedDOFs = blocked
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
        interactions.append(inter)
    dt_crit = critical_timestep(layout, props, specimen, mass, inertia, body_pos3)
    O.dt = params.numerics.timestep_safety * dt_crit
    return GrainScene(specimen=specimen, layout=layout, props=props, params=params, O=O,
                      cell_body=cell_body, sphere_body=sphere_body, interactions=interactions,
                      law=law, newton=newton)
