"""Deformable cells in YADE: sphere bodies held by unbreakable links, breakable bonds across faces.

The layouts here are made by hand (square cells, four spheres each, two bonds per shared face),
so the scene side is tested without the deformable-layout builder.
"""
import importlib.util
import math

import numpy as np
import pytest

from conftest import needs_yade
from grainfrac_yade.layout import ClumpLayout, build_layout, cell_mass_inertia
from grainfrac_yade.params import load_parameters
from grainfrac_yade.specimen import build_specimen, specimen_from_tessellation
from grainfrac_yade.tessellation import tessellate_seeds

pytestmark = [needs_yade, pytest.mark.yade]

PLAIN_ENGINES = ["ForceResetter", "InsertionSortCollider", "InteractionLoop", "NewtonIntegrator"]
SIZE = 1e-3          # side of a square cell [m]
THICKNESS = 1e-3     # layer thickness [m]
#: the four spheres of a cell, relative to its lower-left corner (in units of SIZE), radius SIZE/4
SPHERE_OFFSETS = np.array([[0.25, 0.25], [0.75, 0.25], [0.25, 0.75], [0.75, 0.75]])
#: links of a cell: the four sides and both diagonals of its sphere square
LINK_PAIRS = [(0, 1), (2, 3), (0, 2), (1, 3), (0, 3), (1, 2)]


def grid_specimen(params, nx, ny, mineral="quartz"):
    """nx x ny square cells of side SIZE."""
    seeds = [[(i + 0.5) * SIZE, (j + 0.5) * SIZE] for j in range(ny) for i in range(nx)]
    t = tessellate_seeds(seeds, [nx * SIZE, ny * SIZE], SIZE)
    names = params.minerals
    return specimen_from_tessellation(t, [names.index(mineral)] * t.n_cells, names, THICKNESS)


def grid_layout(specimen, params):
    """Deformable layout of square cells: four touching spheres per cell, six links, two bonds per face."""
    t = specimen.tessellation
    z = specimen.thickness / 2
    r = SIZE / 4
    corner = t.cell_centroid - SIZE / 2
    centers = np.concatenate([c + SPHERE_OFFSETS * SIZE for c in corner])
    sphere_cell = np.repeat(np.arange(t.n_cells), 4)
    links = np.array([(4 * c + a, 4 * c + b) for c in range(t.n_cells) for a, b in LINK_PAIRS])
    young = params.grains[specimen.mineral_names[specimen.mineral[0]]].young
    pairs, faces, points = [], [], []
    for f, (a, b) in enumerate(t.face_cells):
        n = t.face_normal[f]
        for i in range(4 * a, 4 * a + 4):
            j = np.flatnonzero(np.all(np.abs(centers[4 * b:4 * b + 4] - centers[i] - 2 * r * n) < 1e-12 * SIZE, axis=1))
            if len(j):
                pairs.append((i, 4 * b + int(j[0])))
                faces.append(f)
                points.append(centers[i] + r * n)
    faces = np.array(faces, dtype=np.int64)
    assert np.all(np.bincount(faces, minlength=t.n_faces) == 2)
    points = np.array(points).reshape(-1, 2)
    return ClumpLayout(
        sphere_cell=sphere_cell, sphere_center=np.column_stack([centers, np.full(len(centers), z)]),
        sphere_radius=np.full(len(centers), r), bond_spheres=np.array(pairs, dtype=np.int64).reshape(-1, 2),
        bond_face=faces,
        bond_area=specimen.face_area[faces] / 2, bond_point=np.column_stack([points, np.full(len(points), z)]),
        rigid_cells=False, link_spheres=links,
        link_normal_stiffness=np.full(len(links), young * specimen.thickness),
        link_shear_stiffness=np.full(len(links), 0.4 * young * specimen.thickness),
        sphere_area=np.repeat(t.cell_measure / 4, 4))


def deformable_scene(params, nx, ny):
    from grainfrac_yade.yade_adapter.scene import build_scene
    s = grid_specimen(params, nx, ny)
    return build_scene(s, params, grid_layout(s, params))


def test_every_sphere_is_a_body_and_links_are_not_bonds(params):
    sc = deformable_scene(params, 2, 2)
    O, lay = sc.O, sc.layout
    assert len(O.bodies) == lay.n_spheres == 16
    assert all(b.isStandalone for b in O.bodies)                 # no clumps
    assert len(sc.links) == lay.n_links == 24 and sc.n_bonds == len(sc.interactions) == 8
    assert O.interactions.countReal() == sc.n_bonds + len(sc.links)
    assert not {(i.id1, i.id2) for i in sc.links} & {(i.id1, i.id2) for i in sc.interactions}
    for i in sc.links:                                            # links stay inside a cell
        cells = {int(lay.sphere_cell[np.flatnonzero(sc.sphere_body == b)[0]]) for b in (i.id1, i.id2)}
        assert len(cells) == 1
        assert i.phys.isCohesive and i.phys.FnMax == i.phys.FsMax == 1e30
    assert sc.engine_names() == PLAIN_ENGINES
    assert [len(b) for b in sc.cell_bodies] == [4] * 4
    np.testing.assert_array_equal(sc.bodies_of([3, 1]), np.concatenate([sc.cell_bodies[3], sc.cell_bodies[1]]))
    for c in range(4):
        assert sc.cell_body[c] in sc.cell_bodies[c]               # the representative is one of its spheres
    assert all(O.bodies[int(b)].state.blockedDOFs == "zXYZ" for b in sc.sphere_body)   # translation only
    assert not O.engines[2].geomDispatcher.functors[0].avoidGranularRatcheting       # plain two-node springs


def test_sphere_masses_sum_to_the_polygon_masses(params):
    sc = deformable_scene(params, 2, 2)
    mass, _ = cell_mass_inertia(sc.specimen, params, params.numerics.density_scale)
    states = [sc.O.bodies[int(b)].state for b in sc.sphere_body]
    m = np.array([st.mass for st in states])
    per_cell = np.bincount(sc.layout.sphere_cell, weights=m)
    np.testing.assert_allclose(per_cell, mass, rtol=1e-12)
    rho = params.grains["quartz"].density * params.numerics.density_scale
    np.testing.assert_allclose(per_cell, rho * SIZE**2 * THICKNESS, rtol=1e-12)
    r = sc.layout.sphere_radius
    for st, mi, ri in zip(states, m, r):                            # a disc, on all three axes
        assert tuple(st.inertia) == pytest.approx((0.5 * mi * ri**2,) * 3, rel=1e-12)


def test_timestep_from_the_stiffest_sphere(params):
    """sqrt(m/K) per sphere, K the bonds' and links' k_n + k_s (rotation blocked); with rotation the
    step is also bounded by sqrt(I/K_rot), K_rot summing (k_n + k_s) a l: l = r for touching spheres
    and half the length for the diagonal links (the JCFpm torque lever), a = r with YADE's
    avoidGranularRatcheting, a = l without."""
    from grainfrac_yade.yade_adapter.scene import critical_timestep
    sc = deformable_scene(params, 2, 2)
    lay, p = sc.layout, sc.props
    m = sc.O.bodies[int(sc.sphere_body[0])].state.mass
    r = SIZE / 4
    # the stiffest: a sphere at the inner corner of its cell, two bonds and three links (two sides
    # and a diagonal of length 2 sqrt(2) r)
    k_bond = p.normal_stiffness[0] + p.shear_stiffness[0]
    k_link = lay.link_normal_stiffness[0] + lay.link_shear_stiffness[0]
    np.testing.assert_allclose(p.normal_stiffness, p.normal_stiffness[0], rtol=1e-14)   # all bonds alike
    safety = params.numerics.timestep_safety
    assert sc.O.dt == pytest.approx(safety * math.sqrt(m / (2 * k_bond + 3 * k_link)), rel=1e-12)
    mass = np.full(lay.n_spheres, m)
    for guard, diagonal_lever_sq in ((True, math.sqrt(2) * r**2), (False, 2 * r**2)):
        k_rot = 2 * k_bond * r**2 + 2 * k_link * r**2 + k_link * diagonal_lever_sq
        rotating = critical_timestep(lay, p, sc.specimen, mass, 0.5 * mass * r**2, rotating=True,
                                     ratcheting_guard=guard)
        assert rotating == pytest.approx(math.sqrt(0.5 * m * r**2 / k_rot), rel=1e-12)


def _pull(sc, hold, pull, velocity, steps):
    """Block the bodies ``hold``, move the bodies ``pull`` at ``velocity``; the largest link tension [N]."""
    O = sc.O
    for b in np.concatenate([hold, pull]):
        st = O.bodies[int(b)].state
        st.blockedDOFs = "xyzXYZ"
        st.vel = (0, 0, 0)
    for b in pull:
        O.bodies[int(b)].state.vel = velocity
    peak = 0.0
    for _ in range(steps // 20):
        sc.run(20)
        peak = max(peak, max(-i.phys.normalForce.dot(i.geom.normal) for i in sc.links))
        if sc.n_bonds and sc.broken.all():
            break
    return peak


def test_links_never_break_when_the_bonds_do(params):
    """Hold the far spheres of the left cell, pull the far spheres of the right cell: the load goes
    through the links of both cells into the two bonds of the face; the bonds break, the links do not."""
    sc = deformable_scene(params, 2, 1)
    lay = sc.layout
    x = lay.sphere_center[:, 0]
    hold = sc.sphere_body[np.isclose(x, 0.25 * SIZE)]
    pull = sc.sphere_body[np.isclose(x, 1.75 * SIZE)]
    peak = _pull(sc, hold, pull, (1e-2, 0, 0), 100000)
    assert sc.broken.all() and set(sc.break_mode) == {1}
    assert sc.law.nbTensCracks + sc.law.nbShearCracks == sc.n_bonds == 2
    bond_strength = sc.interactions[0].phys.crossSection * sc.props.tensile_strength[0]
    assert peak > 0.5 * bond_strength                      # each link carried a bond-breaking share
    for i in sc.links:
        assert i.phys.isCohesive and i.phys.FnMax == 1e30 and i.phys.FsMax == 1e30
    # pull the far upper sphere out of the right cell (it has no bond), all other spheres held: its
    # links stretch far beyond any bond's strength and never break
    sc2 = deformable_scene(params, 2, 1)
    peak = _pull(sc2, sc2.sphere_body[:7], sc2.sphere_body[7:], (0.2, 0.2, 0), 2000)
    assert peak > 10 * bond_strength
    assert sc2.law.nbTensCracks + sc2.law.nbShearCracks == 0 and not sc2.broken.any()
    assert all(i.phys.isCohesive for i in sc2.links)


def test_platens_drive_all_spheres_of_the_end_cells(params):
    from grainfrac_yade.yade_adapter.platens import PLATEN_BLOCKED, Platens
    sc = deformable_scene(params, 2, 4)
    pl = Platens(sc)
    sc.extras.append(pl)
    top = sc.bodies_of(pl.top)
    assert len(pl._top_bodies) == len(top) == 8 and len(pl._left_bodies) == 16
    assert all(b.state.blockedDOFs == PLATEN_BLOCKED["free"] for b in pl._top_bodies + pl._bottom_bodies)
    pl.set_axial_velocity(1.0 * pl.height)
    sc.run(2000)
    vy = {b.state.vel[1] for b in pl._top_bodies}
    assert len(vy) == 1 and vy.pop() < 0                     # driven together
    assert pl.axial_strain() > 0 and pl.axial_stress() > 0
    assert pl.lateral_strain() < 0                           # the specimen bulges
    assert not sc.broken.any()
    forces = sc.cell_forces(pl.top)
    assert forces.shape == (2, 3)


def test_vtk_cell_motion_follows_a_rotated_cell(params):
    from grainfrac_yade.yade_adapter.vtk_output import cell_motion
    sc = deformable_scene(params, 2, 1)
    lay = sc.layout
    angle, shift = 0.1, np.array([1e-5, -2e-5])
    members = np.flatnonzero(lay.sphere_cell == 1)
    c = sc.specimen.tessellation.cell_centroid[1]
    rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    for m in members:
        p = (lay.sphere_center[m, :2] - c) @ rot.T + c + shift
        sc.O.bodies[int(sc.sphere_body[m])].state.pos = (p[0], p[1], lay.sphere_center[m, 2])
    pos, ang = cell_motion(sc)
    np.testing.assert_allclose(ang, [0.0, angle], atol=1e-12)
    np.testing.assert_allclose(pos[:, :2], sc.specimen.tessellation.cell_centroid + [[0, 0], shift], atol=1e-15)
    np.testing.assert_allclose(sc.cell_positions([1])[0, :2], c + shift, atol=1e-15)


def test_rigid_default_scene_is_unchanged(params):
    """Two square rigid cells (one sphere each): bond stiffness (series formula) and time step
    (min over cells of sqrt(m/K), sqrt(I/(K l^2)), l = SIZE/2 from centroid to face) as before."""
    from grainfrac_yade.yade_adapter.scene import build_scene
    assert params.resolution.grain_model == "rigid"
    s = grid_specimen(params, 2, 1)
    sc = build_scene(s, params)
    assert sc.layout.rigid_cells and len(sc.O.bodies) == 2 and not sc.links
    g, c = params.grains["quartz"], params.contact("quartz", "quartz")
    e_plane, area, half = g.young / (1 - g.poisson**2), SIZE * THICKNESS, SIZE / 2
    scale = params.calibration.stiffness_scale
    kn = area / (1 / c.normal_stiffness + 2 * half / e_plane) * scale
    ks = area / (1 / c.shear_stiffness + 2 * half / g.shear_modulus) * scale
    assert sc.interactions[0].phys.kn == pytest.approx(kn, rel=1e-14)
    assert sc.interactions[0].phys.ks == pytest.approx(ks, rel=1e-14)
    mass = g.density * params.numerics.density_scale * SIZE**2 * THICKNESS
    inertia = mass * SIZE**2 / 6                              # square about its centre
    dt = min(math.sqrt(mass / (kn + ks)), math.sqrt(inertia / ((kn + ks) * half**2)))
    assert sc.O.dt == pytest.approx(params.numerics.timestep_safety * dt, rel=1e-14)
    np.testing.assert_array_equal(sc.bodies_of([1, 0]), sc.cell_body[[1, 0]])
    assert [list(b) for b in sc.cell_bodies] == [[sc.cell_body[0]], [sc.cell_body[1]]]


def test_rigid_layout_comes_from_layout_for(params):
    from grainfrac_yade.yade_adapter.scene import layout_for
    s = build_specimen(load_parameters(overrides=["specimen.width=4e-3", "specimen.height=8e-3"]), 1)
    a, b = layout_for(s, params), build_layout(s, params.resolution.spheres_per_cell)
    assert a.rigid_cells and a.n_bonds == b.n_bonds
    np.testing.assert_array_equal(a.bond_spheres, b.bond_spheres)


NO_BUILDER = importlib.util.find_spec("grainfrac_yade.deformable") is None
NO_BUILDER_REASON = "grainfrac_yade.deformable (the deformable-layout builder) does not exist yet"


@pytest.mark.skipif(NO_BUILDER, reason=NO_BUILDER_REASON)
def test_short_compression_of_a_deformable_specimen():
    """4 x 8 mm, deformable cells from layout_for: platens load it, stress rises, links hold."""
    from grainfrac_yade.yade_adapter.platens import Platens
    from grainfrac_yade.yade_adapter.scene import build_scene
    p = load_parameters(overrides=["specimen.width=4e-3", "specimen.height=8e-3",
                                   'resolution.grain_model="deformable"'])
    s = build_specimen(p, 1)
    sc = build_scene(s, p)
    assert not sc.layout.rigid_cells and len(sc.O.bodies) == sc.layout.n_spheres
    assert sc.engine_names() == PLAIN_ENGINES
    pl = Platens(sc, p.ucs.platen_lateral)
    sc.extras.append(pl)
    pl.set_axial_velocity(p.ucs.strain_rate * pl.height)
    stresses = []
    for _ in range(5):
        sc.run(400)
        stresses.append(pl.axial_stress())
    assert np.all(np.isfinite(stresses)) and stresses[-1] > stresses[0] > 0
    assert pl.axial_strain() > 0
    assert all(i.phys.isCohesive for i in sc.links)


@pytest.mark.skipif(NO_BUILDER, reason=NO_BUILDER_REASON)
def test_deformable_dem_matches_the_static_lattice_solve():
    """Slow compression to 3e-4 axial strain (5x the UCS rate; 1x gives the same within 0.4 %): E and
    Poisson's ratio of the DEM are those of the static solve of the same springs."""
    from grainfrac_yade.elastic import elastic_summary
    from grainfrac_yade.yade_adapter.platens import Platens
    from grainfrac_yade.yade_adapter.scene import build_scene
    p = load_parameters(overrides=["specimen.width=4e-3", "specimen.height=8e-3",
                                   'resolution.grain_model="deformable"'])
    s = build_specimen(p, 1)
    static, _, _ = elastic_summary(s, p, "lattice")
    sc = build_scene(s, p)
    pl = Platens(sc, "free")
    sc.extras.append(pl)
    pl.set_axial_velocity(5 * p.ucs.strain_rate * pl.height)
    while pl.axial_strain() < 3e-4:
        sc.run(200)
    strain = pl.axial_strain()
    assert pl.axial_stress() / strain == pytest.approx(static["young_pa"], rel=0.02)
    assert -pl.lateral_strain() / strain == pytest.approx(static["poisson"], abs=0.01)
    assert not sc.broken.any()
