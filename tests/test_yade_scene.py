"""The YADE realisation: bonds only across faces, areas, engine list, residual friction."""
import math

import numpy as np
import pytest

from conftest import needs_yade
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen, specimen_from_tessellation
from grainfrac_yade.geometry.tessellation import tessellate_seeds

pytestmark = [needs_yade, pytest.mark.yade]

PLAIN_ENGINES = ["ForceResetter", "InsertionSortCollider", "InteractionLoop", "NewtonIntegrator"]


@pytest.mark.parametrize("spheres_per_cell", [1, 8])
def test_bonds_match_faces(small_params, spheres_per_cell):
    from grainfrac_yade.engines.yade.scene import build_scene
    p = load_parameters(overrides=["specimen.width=6e-3", "specimen.height=8e-3",
                                   f"resolution.spheres_per_cell={spheres_per_cell}"])
    s = build_specimen(p, 2)
    sc = build_scene(s, p)
    O = sc.O
    assert O.interactions.countReal() == sc.n_bonds == sc.layout.n_bonds
    body_cell = {}
    for k, b in enumerate(sc.sphere_body):
        body_cell[int(b)] = int(sc.layout.sphere_cell[k])
    faces = {tuple(f) for f in s.tessellation.face_cells}
    area_per_face = np.zeros(s.tessellation.n_faces)
    for k, inter in enumerate(sc.interactions):
        ca, cb = body_cell[inter.id1], body_cell[inter.id2]
        assert ca != cb                                     # no bond inside a cell
        assert (min(ca, cb), max(ca, cb)) in faces          # only across a shared face
        assert inter.phys.isCohesive
        area_per_face[sc.layout.bond_face[k]] += inter.phys.crossSection
    np.testing.assert_allclose(area_per_face, s.face_area, rtol=1e-12)
    assert sum(1 for i in O.interactions) == sc.n_bonds


def test_plain_scene_engine_list(small_params):
    from grainfrac_yade.engines.yade.scene import build_scene
    p = load_parameters(overrides=["specimen.width=4e-3", "specimen.height=4e-3"])
    sc = build_scene(build_specimen(p, 1), p)
    assert sc.engine_names() == PLAIN_ENGINES
    newton = sc.O.engines[-1]
    assert tuple(newton.gravity) == (0, 0, 0)
    assert all(type(e).__name__ != "PyRunner" for e in sc.O.engines)


def _two_cells(params, thickness=1e-3, minerals=("quartz", "quartz")):
    t = tessellate_seeds([[0.5e-3, 0.5e-3], [1.5e-3, 0.5e-3]], [2e-3, 1e-3], 1e-3)
    names = params.minerals
    return specimen_from_tessellation(t, [names.index(m) for m in minerals], names, thickness)


def _drive(sc, velocity, max_steps=200000):
    """Hold cell 0, move cell 1 at ``velocity`` until the bond breaks."""
    O = sc.O
    for cell in (0, 1):
        st = O.bodies[int(sc.cell_body[cell])].state
        st.blockedDOFs = "xyzXYZ"
        st.vel = (0, 0, 0)
    O.bodies[int(sc.cell_body[1])].state.vel = velocity
    for _ in range(max_steps // 100):
        sc.run(100)
        if sc.broken[0]:
            return
    raise AssertionError("bond did not break")


@pytest.mark.parametrize("velocity,mode", [((1e-3, 0, 0), 1), ((0, 1e-3, 0), 2)])
def test_broken_bond_switches_to_residual_friction(params, velocity, mode):
    from grainfrac_yade.engines.yade.scene import build_scene
    s = _two_cells(params)
    sc = build_scene(s, params)
    c = params.contact("quartz", "quartz")
    phys = sc.interactions[0].phys
    assert phys.tanFrictionAngle == pytest.approx(math.tan(c.friction_angle))
    _drive(sc, velocity)
    assert sc.break_mode[0] == mode
    assert phys.tanFrictionAngle == pytest.approx(math.tan(c.residual_friction_angle))
    assert phys.FnMax == 0 and phys.FsMax == 0          # Table 2: J^T_r = J^C_r = 0
    assert not phys.isCohesive


def test_bond_stress_does_not_depend_on_layer_thickness(params):
    """Same displacement, thickness 1 and 3 mm: force triples, stress F/A is the same."""
    from grainfrac_yade.engines.yade.scene import build_scene
    stresses = []
    for thickness in (1e-3, 3e-3):
        sc = build_scene(_two_cells(params, thickness), params)
        O = sc.O
        for cell in (0, 1):
            O.bodies[int(sc.cell_body[cell])].state.blockedDOFs = "xyzXYZ"
        O.bodies[int(sc.cell_body[1])].state.vel = (-1e-3, 0, 0)  # compress
        sc.run(50)
        fn, fs = sc.bond_forces()
        stresses.append(fn[0] / sc.layout.bond_area[0])
        assert fn[0] < 0                                      # compression is negative (tension positive)
    assert stresses[0] == pytest.approx(stresses[1], rel=1e-9)


def test_tensile_break_at_the_tensile_strength(params):
    """Pulling the bond apart breaks it when sigma = F_n/A reaches J^T (Table 2)."""
    from grainfrac_yade.engines.yade.scene import build_scene
    sc = build_scene(_two_cells(params), params)
    O = sc.O
    for cell in (0, 1):
        O.bodies[int(sc.cell_body[cell])].state.blockedDOFs = "xyzXYZ"
    O.bodies[int(sc.cell_body[1])].state.vel = (1e-4, 0, 0)
    peak = 0.0
    while not sc.broken[0]:
        fn, _ = sc.bond_forces()
        peak = max(peak, fn[0] / sc.layout.bond_area[0])
        sc.run(1)
    jt = params.contact("quartz", "quartz").tensile_strength * params.calibration.strength_scale
    # the last intact step is within one displacement increment of the limit
    step_stress = sc.props.normal_stiffness[0] * 1e-4 * O.dt / sc.layout.bond_area[0]
    assert jt - step_stress <= peak <= jt


def test_3d_box_scene_builds_with_one_sphere_per_cell():
    from grainfrac_yade.engines.yade.scene import build_scene
    p = load_parameters(overrides=["specimen.dimension=3", "specimen.width=3e-3", "specimen.height=4e-3",
                                   "specimen.thickness=3e-3"])
    s = build_specimen(p, 1)
    sc = build_scene(s, p)
    assert s.tessellation.dim == 3
    assert sc.O.interactions.countReal() == s.tessellation.n_faces == sc.n_bonds
    np.testing.assert_allclose([i.phys.crossSection for i in sc.interactions], s.face_area, rtol=1e-12)
    sc.run(20)
    assert sc.O.bodies[int(sc.cell_body[0])].state.blockedDOFs == ""
