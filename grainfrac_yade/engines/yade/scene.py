"""Turn a :class:`~grainfrac_yade.geometry.specimen.Specimen` into a YADE scene and read bonds back.

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

The bodies come from the grain model of the layout (:mod:`grainfrac_yade.grains`),
whose YADE side is a module of this package: :mod:`.rigid_cells` (one body per
cell: a sphere, or a clump of spheres with the polygon's mass and inertia) and
:mod:`.fem_cells` (a body per sphere, held together by YADE's finite elements).
Only the breakable bonds are interactions (:attr:`GrainScene.interactions`).
Code that acts on cells uses :meth:`GrainScene.bodies_of`, which covers every model.  The scene's checkpoint and
its engine-neutral state are :mod:`.scene_state`'s (a mixin of :class:`GrainScene`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._interface import SceneState
from ...errors import GrainfracError, NumericalFailure
from ...grains import GrainModel, layout_for, model_of
from ...law import MODE_NEVER, MODE_SHEAR, MODE_TENSION
from ...layout import BondProperties, ClumpLayout, bond_properties
from ...params import Parameters
from ...kernel.cracks import bond_is_inter
from ...geometry.specimen import Specimen
from . import fem_cells, load_yade, rigid_cells
from .confinement import Confinement
from .jaws import DiscJaws
from .joints import IntactJointGuard
from .platens import Platens, free_bodies
from .scene_state import GrainSceneState
from .measures import BOND_FORCE_SAMPLE, check_value, mean_bond_force, resultant_forces  # noqa: F401

#: Bond break modes: the degradation laws' codes (:mod:`grainfrac_yade.law`), which are YADE's JCFpm crack file's.
INTACT, TENSION, SHEAR = MODE_NEVER, MODE_TENSION, MODE_SHEAR
#: Material type shared by all cells: JCFpm bonds only form between equal types.
COHESIVE_TYPE = 1
#: The YADE side of each grain model, by the name of the model it builds (its ``MODEL``, :mod:`grainfrac_yade.grains`).
YADE_CELLS = {cells.MODEL.name: cells for cells in (rigid_cells, fem_cells)}
@dataclass
class GrainScene(GrainSceneState):
    """A built YADE scene plus the numpy bookkeeping of its bonds.

    Arrays are indexed by cell (``cell_body``, ``cell_bodies``), sphere (``sphere_body``) or
    breakable bond (``interactions`` and everything ``bond_*``).  ``cell_bodies[c]`` holds all
    body ids of cell c (one for rigid cells); ``cell_body[c]`` is the cell's body for rigid
    cells, and for fem cells only a representative: the body that moves the cell's sphere
    nearest its centroid.  ``model`` is the layout's grain model, ``cells`` its YADE side
    (:data:`YADE_CELLS`).
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
    model: GrainModel
    cells: object
    drivers: list = field(default_factory=list)   # called before every DEM step
    extras: list = field(default_factory=list)    # listed engines acting between steps (platens, corrosion)
    broken: np.ndarray = None
    break_mode: np.ndarray = None
    break_step: np.ndarray = None
    tan_residual: np.ndarray = None
    #: conservative critical DEM step of the scene [s] (:func:`critical_timestep`); :meth:`run` refuses
    #: to step with a larger ``O.dt`` (an unstable step blows up or, before it does, gives nonsense)
    dt_critical: float = math.inf
    #: bonds YADE's smooth-joint law erased by their cumulative sliding path, not by a strength
    #: criterion (:mod:`.joints`), as far as synced; :meth:`sliding_erasures` adds those not synced yet
    erased_by_sliding: int = 0
    #: steps and time of the state a scene was built from (:func:`scene_from_state`), added to YADE's
    #: ``O.iter`` and ``O.time`` (which cannot be set); 0 for a scene built from the specimen
    step_offset: int = 0
    time_offset: float = 0.0
    #: (n_nodes, 3) where the nodes were built [m] (:meth:`node_bodies`), the origin of their displacements
    node_origin: np.ndarray = None
    #: each node body's orientation as built (a clump's principal frame, identity for a sphere): rotations are
    #: exported about z relative to it, and a state's rotation is applied on top of it
    node_orientation0: list = None
    _cracks_seen: int = 0
    _tens_seen: int = 0

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
        return bond_is_inter(self)

    @property
    def bond_mineral_pair(self) -> np.ndarray:
        """(n_bonds, 2) mineral indices of the two cells."""
        return self.specimen.face_minerals[self.layout.bond_face]

    def cell_motion(self) -> tuple:
        """(n, 2+) positions [m] of the cell centroids and (n,) rotation angles about z [rad]: the cell bodies'
        (rigid cells), or the least-squares rigid motion of each cell's spheres weighted by their lumped areas
        (fem cells)."""
        return self.cells.cell_motion(self)

    def bond_shift(self, positions) -> np.ndarray:
        """(b, 2) displacement [m] drawn for each bond: the mean of its two cells' (rigid) or two spheres' (fem)
        displacements; ``positions``: the cell positions of :meth:`cell_motion`."""
        return self.cells.bond_shift(self, positions)

    def bodies_of(self, cells) -> np.ndarray:
        """All body ids of ``cells``, cell by cell in the given order (one per rigid cell)."""
        return self.cells.bodies_of(self, np.atleast_1d(np.asarray(cells, dtype=np.int64)))

    def engine_names(self) -> list:
        """YADE engines (class names), then the Python-side drivers and extras."""
        return [type(e).__name__ for e in self.O.engines] + [d.name for d in self.drivers + self.extras]

    def counts(self) -> dict:
        """YADE's bodies, real interactions (and every interaction it lists, potential ones too) and the
        breakable bonds."""
        return {"n_bodies": len(self.O.bodies), "n_interactions": self.O.interactions.countReal(),
                "n_interactions_listed": len(self.O.interactions), "n_bonds": self.n_bonds}

    def summary_keys(self) -> dict:
        """Nothing beyond the common keys: YADE's summaries are as they were before engines could be chosen."""
        return {}

    # ------------------------------------------------------------------ counters
    @property
    def steps(self) -> int:
        """DEM steps so far (``O.iter``, from the state the scene was built from)."""
        return self.O.iter + self.step_offset

    @property
    def time(self) -> float:
        """DEM time so far [s] (``O.time``, from the state the scene was built from)."""
        return self.O.time + self.time_offset

    @property
    def dt(self) -> float:
        """The DEM step [s]."""
        return self.O.dt

    # ------------------------------------------------------------------ stepping
    def equilibrate(self, balanced, check_steps: int, max_steps: int):
        """Dynamic relaxation: DEM steps under the current loads, ``check_steps`` at a time, until
        ``balanced()``; the steps it took, None if it did not hold within ``max_steps``."""
        done = 0
        while done < max_steps:
            self.run(check_steps)
            done += check_steps
            if balanced():
                return done
        return None

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
        # the law counts its strength breaks; bonds beyond them lost cohesion by their sliding path
        self.erased_by_sliding += max(0, len(new) - (n_tens + n_shear - self._cracks_seen))
        prev_tens = self._tens_seen
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
        self.break_step[new] = self.steps
        self._cracks_seen = n_tens + n_shear
        self._tens_seen = n_tens
        return new

    def sliding_erasures(self) -> int:
        """Bonds erased by their sliding path so far (:mod:`.joints`): those synced as breaks, and the
        intact ones without cohesion that no strength break has synced yet; 0 without smooth joints."""
        if not self.model.bonds_on_faces:
            return 0
        pending = sum(1 for k in np.flatnonzero(~self.broken) if not self.interactions[k].phys.isCohesive)
        return self.erased_by_sliding + pending

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
            self.break_step[k] = self.steps

    def write_bond_strengths(self, indices, tensile, cohesion):
        """Intact bonds ``indices`` carry ``tensile`` strength and ``cohesion`` [Pa] per intact area from now on
        (JCFpm's ``FnMax``, ``FsMax``: strength x area); broken bonds keep none."""
        area = self.layout.bond_area
        for k, jt, jc in zip(np.atleast_1d(indices), np.atleast_1d(tensile), np.atleast_1d(cohesion)):
            ph = self.interactions[int(k)].phys
            if ph.isCohesive:
                ph.FnMax, ph.FsMax = float(jt * area[k]), float(jc * area[k])

    # ------------------------------------------------------------------ reading state
    def bond_stresses(self, indices=None):
        """(normal stress, tension positive; shear stress) [Pa] per intact area of bonds ``indices``."""
        idx = np.arange(self.n_bonds) if indices is None else np.asarray(indices, dtype=np.int64)
        fn, fs = self.bond_forces(idx)
        area = self.layout.bond_area[idx]
        return fn / area, fs / area

    def bond_strengths(self, indices=None):
        """(tensile strength, cohesion) [Pa] per intact area that bonds ``indices`` carry now (0 once broken)."""
        idx = np.arange(self.n_bonds) if indices is None else np.asarray(indices, dtype=np.int64)
        cap = np.array([(self.interactions[k].phys.FnMax, self.interactions[k].phys.FsMax) for k in idx]).reshape(-1, 2)
        area = self.layout.bond_area[idx]
        return cap[:, 0] / area, cap[:, 1] / area

    def bond_forces(self, indices=None):
        """Normal force (tension positive) and shear force magnitude [N] of bonds.

        Reads the law's normal force (along the line of centres, or along the face normal for
        bonds on their face's plane) and ``|shearForce|``; about 2-3 us per bond.  A broken bond whose
        contact YADE has erased (its cells apart) carries none: 0, 0.
        """
        idx = np.arange(self.n_bonds) if indices is None else np.asarray(indices)
        fn = np.empty(len(idx))
        fs = np.empty(len(idx))
        inter = self.interactions
        on_face = self.model.bonds_on_faces
        for n, k in enumerate(idx):
            i = inter[k]
            if not i.isReal:
                fn[n] = fs[n] = 0.0
                continue
            phys = i.phys
            fn[n] = -phys.normalForce.dot(phys.jointNormal if on_face else i.geom.normal)
            fs[n] = phys.shearForce.norm()
        return fn, fs

    def bond_separated(self, indices) -> np.ndarray:
        """(n,) True where a bond's spheres are further apart than when it was made (an open crack):
        along the line of centres (penetration below its initial value), or across the face for bonds
        on their face's plane (YADE's smooth joint: |(x_b - x_a) . n| above its initial value)."""
        inter = self.interactions
        if not self.model.bonds_on_faces:
            return np.array([inter[k].geom.penetrationDepth - inter[k].phys.initD < 0 for k in indices], dtype=bool)
        bodies = self.O.bodies
        out = []
        for k in indices:
            i = inter[k]
            gap = abs((bodies[i.id2].state.pos - bodies[i.id1].state.pos).dot(i.phys.jointNormal))
            out.append(i.phys.initD - gap < 0)
        return np.array(out, dtype=bool)

    def cell_positions(self, cells=None) -> np.ndarray:
        """(n, 3) current positions of cells [m]: the body (rigid), the mass centre of its bodies (fem)."""
        cells = np.arange(self.specimen.n_cells) if cells is None else np.asarray(cells)
        return self.cells.cell_positions(self, cells)

    # ------------------------------------------------------------------ platens and confinement
    def attach_platens(self, lateral: str = "free") -> Platens:
        """Rigid platens on the end cells (:class:`.platens.Platens`), listed among the scene's engines."""
        platens = Platens(self, lateral)
        self.extras.append(platens)
        self._platens, self._free_ids = platens, None
        return platens

    def free_bodies(self) -> list:
        """Body ids of the cells the platens do not drive (all cells' without platens), found once."""
        if getattr(self, "_free_ids", None) is None:
            platens = getattr(self, "_platens", None)
            self._free_ids = (free_bodies(self, platens) if platens is not None
                              else [int(b) for b in self.bodies_of(np.arange(self.specimen.n_cells))])
        return self._free_ids

    def unbalanced(self, reference: float) -> tuple:
        """(largest resultant force on a free body [N], mean resultant / ``reference``; inf if ``reference`` <= 0)
        from the last DEM step (free: not driven by the platens; bodies: cells, or the spheres of fem cells).
        NumericalFailure if a force is NaN or infinite."""
        largest, mean = resultant_forces(self, self.free_bodies())
        return largest, (mean / reference if reference > 0 else math.inf)

    def relaxation_damping(self, damping: float):
        """Cundall's non-viscous damping of the integrator from here on (``NewtonIntegrator.damping``)."""
        self.newton.damping = damping

    def lose_load_below(self, ratio) -> None:
        """Ignored: YADE's loading is dynamic throughout, and the protocol reads a post-peak drop off its rows."""

    def confine(self, stress: float) -> Confinement:
        """Confining stress sigma_3 [Pa] on the side walls (:class:`.confinement.Confinement`: permanent forces)."""
        confinement = Confinement(self, stress)
        self.extras.append(confinement)
        return confinement

    def attach_jaws(self, loading_arc: float, lateral: str = "fixed") -> DiscJaws:
        """The two jaws of a disc (:class:`.jaws.DiscJaws`: the cells whose rim arcs overlap ``loading_arc``
        [rad] about the ends of the vertical diameter), listed among the scene's engines."""
        jaws = DiscJaws(self, loading_arc, lateral)
        self.extras.append(jaws)
        return jaws

    def cell_forces(self, cells) -> np.ndarray:
        """(n, 3) resultant interaction force on each cell (summed over its bodies) from the last step [N]."""
        f = self.O.forces.f
        return np.array([np.sum([tuple(f(int(b))) for b in self.bodies_of([c])], axis=0) for c in cells])


def verlet_distance(layout: ClumpLayout, numerics) -> float:
    """``InsertionSortCollider.verletDist``: ``numerics.verlet_fraction`` x the sphere radius at quantile
    ``numerics.verlet_radius_quantile``.  At quantile 0 it is YADE's own relative form (a negative value:
    that fraction of the smallest radius, which the collider finds itself), so the default scene is
    YADE's default; otherwise an absolute distance [m]."""
    if numerics.verlet_radius_quantile == 0:
        return -numerics.verlet_fraction
    return float(numerics.verlet_fraction * np.quantile(layout.sphere_radius, numerics.verlet_radius_quantile))


def scene_from_state(specimen: Specimen, params: Parameters, state: SceneState,
                     layout: ClumpLayout | None = None) -> GrainScene:
    """A YADE scene of ``specimen`` in ``state`` (:meth:`GrainScene.export_state` of this or another engine)."""
    scene = build_scene(specimen, params, layout)
    scene.apply_state(state)
    return scene


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
    model, cells = model_of(layout), YADE_CELLS[layout.model]
    props = bond_properties(specimen, layout, params)

    O.reset()
    mats = []
    for name in specimen.mineral_names:
        g, c = params.grains[name], params.contact(name, name)
        # Strengths of 1 Pa make the first-step bonds cohesive; every bond's values are written below.
        mats.append(O.materials.append(w.JCFpmMat(
            young=g.young, poisson=g.poisson, density=g.density, type=COHESIVE_TYPE,
            frictionAngle=c.friction_angle, residualFrictionAngle=c.residual_friction_angle,
            tensileStrength=1.0, cohesion=1.0)))
    law = w.Law2_ScGeom_JCFpmPhys_JointedCohesiveFrictionalPM(neverErase=True, smoothJoint=model.bonds_on_faces)
    geometry = w.Ig2_Sphere_Sphere_ScGeom()
    cells.configure_geometry(geometry)
    newton = w.NewtonIntegrator(damping=params.numerics.damping, gravity=(0, 0, 0))
    O.engines = [
        w.ForceResetter(),
        w.InsertionSortCollider([w.Bo1_Sphere_Aabb()], avoidSelfInteractionMask=cells.collider_mask_bit(),
                                verletDist=verlet_distance(layout, params.numerics)),
        w.InteractionLoop([geometry],
                          [w.Ip2_JCFpmMat_JCFpmMat_JCFpmPhys(cohesiveTresholdIteration=1)], [law]),
        *cells.engines(w),
        newton,
    ]
    # masses, inertias and the critical step: the grain model's arithmetic (grainfrac_yade.grains), which
    # specimen.json's critical_dem_step_s repeats without YADE
    bodies = cells.append_bodies(O, utils, Vector3, specimen, params, layout, props, mats)
    interactions = []
    tan_phi = np.tan(props.friction_angle)
    for k, (i, j) in enumerate(layout.bond_spheres):
        inter = utils.createInteraction(int(bodies.sphere_body[i]), int(bodies.sphere_body[j]))
        ph = inter.phys
        area = float(layout.bond_area[k])
        ph.kn = float(props.normal_stiffness[k])
        ph.ks = float(props.shear_stiffness[k])
        ph.FnMax = float(props.tensile_strength[k]) * area
        ph.FsMax = float(props.cohesion[k]) * area
        ph.tanFrictionAngle = float(tan_phi[k])
        ph.crossSection = area
        cells.bond_kinematics(ph, k, layout, Vector3)
        interactions.append(inter)
    bodies = cells.finish(O, w, utils, Vector3, specimen, params, layout, bodies, mats)
    dt_crit = bodies.dt_critical
    if not 0 < dt_crit < math.inf:
        raise GrainfracError(f"the scene's critical DEM step is {dt_crit:g} s (a cell without mass, or no bond "
                             "at all); fix: check the specimen's cells and faces")
    O.dt = params.numerics.timestep_safety * dt_crit
    scene = GrainScene(specimen=specimen, layout=layout, props=props, params=params, O=O,
                       cell_body=bodies.cell_body, cell_bodies=bodies.cell_bodies, sphere_body=bodies.sphere_body,
                       interactions=interactions, law=law, newton=newton, model=model, cells=cells,
                       dt_critical=dt_crit)
    scene.node_origin = scene.node_positions()
    scene.node_orientation0 = [O.bodies[int(b)].state.ori for b in scene.node_bodies()]
    if model.bonds_on_faces and params.numerics.keep_intact_joints:
        scene.drivers.append(IntactJointGuard(scene))
    return scene
