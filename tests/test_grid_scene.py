"""YADE scenes of square cells on a grid: the rigid default scene's stiffness and time step by hand,
and the cell motion that the VTK output draws for finite-element cells.
"""
import math

import numpy as np
import pytest

from conftest import needs_yade
from grainfrac_yade.grains.rigid import build_layout
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen, specimen_from_tessellation
from grainfrac_yade.geometry.tessellation import tessellate_seeds

pytestmark = [needs_yade, pytest.mark.yade]

PLAIN_ENGINES = ["ForceResetter", "InsertionSortCollider", "InteractionLoop", "NewtonIntegrator"]
SIZE = 1e-3          # side of a square cell [m]
THICKNESS = 1e-3     # layer thickness [m]


def grid_specimen(params, nx, ny, mineral="quartz"):
    """nx x ny square cells of side SIZE."""
    seeds = [[(i + 0.5) * SIZE, (j + 0.5) * SIZE] for j in range(ny) for i in range(nx)]
    t = tessellate_seeds(seeds, [nx * SIZE, ny * SIZE], SIZE)
    names = params.minerals
    return specimen_from_tessellation(t, [names.index(mineral)] * t.n_cells, names, THICKNESS)


def test_vtk_cell_motion_follows_a_rotated_cell(params):
    from grainfrac_yade.engines.yade.scene import build_scene
    fem = load_parameters(overrides=["resolution.grain_model=fem"])
    s = grid_specimen(fem, 2, 1)
    sc = build_scene(s, fem)
    lay = sc.layout
    angle, shift = 0.1, np.array([1e-5, -2e-5])
    members = np.flatnonzero(lay.sphere_cell == 1)
    c = sc.specimen.tessellation.cell_centroid[1]
    rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    for m in members:
        p = (lay.sphere_center[m, :2] - c) @ rot.T + c + shift
        sc.O.bodies[int(sc.sphere_body[m])].state.pos = (p[0], p[1], lay.sphere_center[m, 2])
    pos, ang = sc.cell_motion()
    np.testing.assert_allclose(ang, [0.0, angle], atol=1e-12)
    np.testing.assert_allclose(pos[:, :2], sc.specimen.tessellation.cell_centroid + [[0, 0], shift], atol=1e-15)


def test_rigid_default_scene_is_unchanged(params):
    """Two square rigid cells (one sphere each): bond stiffness (series formula) and time step
    (min over cells of sqrt(m/K), sqrt(I/(K l^2)), l = SIZE/2 from centroid to face) as before."""
    from grainfrac_yade.engines.yade.scene import build_scene
    assert params.resolution.grain_model == "rigid"
    s = grid_specimen(params, 2, 1)
    sc = build_scene(s, params)
    assert sc.layout.model == "rigid" and len(sc.O.bodies) == 2
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
    from grainfrac_yade.engines.yade.scene import layout_for
    s = build_specimen(load_parameters(overrides=["specimen.width=4e-3", "specimen.height=8e-3"]), 1)
    a, b = layout_for(s, params), build_layout(s, params.resolution.spheres_per_cell)
    assert a.model == "rigid" and a.n_bonds == b.n_bonds
    np.testing.assert_array_equal(a.bond_spheres, b.bond_spheres)
