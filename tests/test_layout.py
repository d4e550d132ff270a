"""Sphere layout and bond properties (pure numpy)."""
import numpy as np
import pytest

from grainfrac_yade.grains.rigid import build_layout
from grainfrac_yade.layout import bond_properties, cell_mass_inertia
from grainfrac_yade.geometry.specimen import build_specimen, specimen_from_tessellation
from grainfrac_yade.geometry.tessellation import tessellate_seeds


@pytest.fixture(scope="module")
def specimen(small_params):
    return build_specimen(small_params, 5)


@pytest.mark.parametrize("n", [1, 6, 12])
def test_bonds_cross_faces_and_sum_to_face_area(specimen, n):
    lay = build_layout(specimen, n)
    cells = lay.sphere_cell[lay.bond_spheres]
    face_cells = specimen.tessellation.face_cells[lay.bond_face]
    np.testing.assert_array_equal(cells, face_cells)          # a bond joins the two cells of its face
    assert np.all(cells[:, 0] != cells[:, 1])                 # no bond inside a cell
    per_face = np.bincount(lay.bond_face, weights=lay.bond_area, minlength=specimen.tessellation.n_faces)
    np.testing.assert_allclose(per_face, specimen.face_area, rtol=1e-12)
    assert lay.n_bonds >= specimen.tessellation.n_faces


@pytest.mark.parametrize("n", [1, 8])
def test_spheres_of_different_cells_do_not_overlap(specimen, n):
    from scipy.spatial import cKDTree
    lay = build_layout(specimen, n)
    tree = cKDTree(lay.sphere_center)
    pairs = np.array(sorted(tree.query_pairs(2 * lay.sphere_radius.max())))
    other = lay.sphere_cell[pairs[:, 0]] != lay.sphere_cell[pairs[:, 1]]
    p = pairs[other]
    gap = np.linalg.norm(lay.sphere_center[p[:, 0]] - lay.sphere_center[p[:, 1]], axis=1) \
        - lay.sphere_radius[p[:, 0]] - lay.sphere_radius[p[:, 1]]
    assert gap.min() > -1e-12 * specimen.tessellation.box.max()


def test_face_lined_pairs_touch_on_the_face(specimen):
    lay = build_layout(specimen, 8)
    a, b = lay.bond_spheres.T
    d = np.linalg.norm(lay.sphere_center[a] - lay.sphere_center[b], axis=1)
    np.testing.assert_allclose(d, lay.sphere_radius[a] + lay.sphere_radius[b], rtol=1e-9)
    mid = 0.5 * (lay.sphere_center[a] + lay.sphere_center[b])
    np.testing.assert_allclose(mid, lay.bond_point, atol=1e-12)


def test_series_stiffness_formula(small_params):
    """Two cells of 1 mm: k = A / (1/k_n + l_a/E'_a + l_b/E'_b) with E' = E/(1-nu^2)."""
    t = tessellate_seeds([[0.5e-3, 0.5e-3], [1.5e-3, 0.5e-3]], [2e-3, 1e-3], 1e-3)
    names = small_params.minerals
    s = specimen_from_tessellation(t, [names.index("quartz"), names.index("biotite")], names, 1e-3)
    lay = build_layout(s, 1)
    bp = bond_properties(s, lay, small_params)
    c = small_params.contact("quartz", "biotite")
    q, b = small_params.grains["quartz"], small_params.grains["biotite"]
    area, l = 1e-3 * 1e-3, 0.5e-3
    kn = area / (1 / c.normal_stiffness + l / (q.young / (1 - q.poisson**2)) + l / (b.young / (1 - b.poisson**2)))
    ks = area / (1 / c.shear_stiffness + l / q.shear_modulus + l / b.shear_modulus)
    cal = small_params.calibration   # one factor on every bond's stiffness and strengths (the calibration of the packing)
    assert bp.normal_stiffness[0] == pytest.approx(kn * cal.stiffness_scale, rel=1e-12)
    assert bp.shear_stiffness[0] == pytest.approx(ks * cal.stiffness_scale, rel=1e-12)
    assert bp.tensile_strength[0] == pytest.approx(c.tensile_strength * cal.strength_scale, rel=1e-15)
    assert bp.cohesion[0] == pytest.approx(c.cohesion * cal.strength_scale, rel=1e-15)
    mass, inertia = cell_mass_inertia(s, small_params)
    rho = small_params.grains["quartz"].density
    assert mass[0] == pytest.approx(rho * 1e-3 * 1e-3 * 1e-3)
    assert inertia[0] == pytest.approx(mass[0] * (2 * (1e-3) ** 2) / 12)   # square plate: m (a^2+b^2)/12
