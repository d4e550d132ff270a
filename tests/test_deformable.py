"""Deformable cells (pure numpy core): link springs, stiffness matching, masses, layout bookkeeping."""
import numpy as np
import pytest

from grainfrac_yade.deformable import build_deformable_layout, edge_springs, link_scale, stiffness_lumped_area
from grainfrac_yade.elastic import elastic_summary, cluster_network, plane_strain_matrix, solve_uniaxial
from grainfrac_yade.params import load_parameters
from grainfrac_yade.specimen import build_specimen

SMALL = ["specimen.width=5e-3", "specimen.height=10e-3", "resolution.grain_model=deformable"]


def _edge_energy(corners, springs, eps):
    """Energy of edge springs under the uniform strain eps (Voigt xx, yy, 2xy)."""
    ends = np.roll(corners, -1, axis=0) - corners
    length = np.linalg.norm(ends, axis=1)
    n = ends / length[:, None]
    strain = np.array([[eps[0], eps[2] / 2], [eps[2] / 2, eps[1]]])
    delta = length * np.einsum("ei,ij,ej->e", n, strain, n)
    return 0.5 * (springs * delta**2).sum()


def test_edge_springs_are_exact_for_an_equilateral_triangle_with_nu_one_third():
    """Plane nu' = 1/3 (nu = 1/4 in plane strain) on an equilateral triangle: the edge stiffness
    has no coupling terms, so three springs store the triangle's strain energy for every strain."""
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, np.sqrt(3) / 2]]) * 1e-3
    area = np.sqrt(3) / 4 * 1e-6
    d = plane_strain_matrix([60e9], [0.25])[0] * 1e-3
    k = edge_springs(corners, area * d)
    for eps in ([1e-4, 0, 0], [0, 1e-4, 0], [0, 0, 1e-4], [3e-5, -2e-5, 5e-5]):
        eps = np.array(eps)
        assert _edge_energy(corners, k, eps) == pytest.approx(0.5 * area * eps @ d @ eps, rel=1e-10)
    assert k == pytest.approx(np.full(3, k[0]), rel=1e-10)


def test_edge_springs_are_positive_for_any_triangle(rng):
    d = plane_strain_matrix([91e9], [0.2])[0]
    for _ in range(200):
        corners = rng.random((3, 2))
        d1, d2 = corners[1] - corners[0], corners[2] - corners[0]
        area = 0.5 * (d1[0] * d2[1] - d1[1] * d2[0])
        if abs(area) < 1e-3:
            continue
        assert (edge_springs(corners, abs(area) * d) > 0).all()


def test_link_scale_matches_the_young_modulus_of_the_reference():
    p = load_parameters(overrides=SMALL)
    s = build_specimen(p, 2)
    layout = build_deformable_layout(s, p)
    lattice = solve_uniaxial(cluster_network(s, p, layout), s)
    reference, _, _ = elastic_summary(s, p, "deformable", p.resolution.nodes_per_face)
    assert lattice.young == pytest.approx(reference["young_pa"], rel=1e-3)
    assert 0 < link_scale(s, p, p.resolution.contact_inset) < 1     # dropping the coupling terms stiffens a cluster


def test_layout_bookkeeping():
    """Bonds carry the faces' areas; each cell keeps its area as mass share; no sphere overlaps
    another at the start; links join spheres of one cell, bonds spheres of two cells."""
    p = load_parameters(overrides=SMALL)
    s = build_specimen(p, 1)
    lay = build_deformable_layout(s, p)
    assert not lay.rigid_cells
    per_face = np.bincount(lay.bond_face, weights=lay.bond_area, minlength=s.tessellation.n_faces)
    assert per_face == pytest.approx(s.face_area, rel=1e-12)
    per_cell = np.bincount(lay.sphere_cell, weights=lay.sphere_area, minlength=s.n_cells)
    assert per_cell == pytest.approx(s.tessellation.cell_measure, rel=1e-12)
    c = lay.sphere_center[:, :2]
    gap = np.linalg.norm(c[:, None] - c[None], axis=-1) - lay.sphere_radius[:, None] - lay.sphere_radius[None]
    np.fill_diagonal(gap, np.inf)
    assert gap.min() > -1e-15
    assert (lay.sphere_cell[lay.link_spheres[:, 0]] == lay.sphere_cell[lay.link_spheres[:, 1]]).all()
    assert (lay.sphere_cell[lay.bond_spheres[:, 0]] != lay.sphere_cell[lay.bond_spheres[:, 1]]).all()
    assert (lay.link_normal_stiffness > 0).all() and (lay.link_shear_stiffness == 0).all()
    assert stiffness_lumped_area(s, p, lay) == pytest.approx(lay.sphere_area)
