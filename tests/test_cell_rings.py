"""Radial rings of fem cells (``resolution.cell_rings``): the refined mesh holds a uniform strain with the
exact plane-strain energy, and rigid cells refuse rings."""
import dataclasses

import numpy as np
import pytest

from grainfrac_yade.elastic import cluster_network, plane_strain_matrix, stiffness_matrix
from grainfrac_yade.errors import ParameterError
from grainfrac_yade.geometry.grainmesh import ring_fractions
from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.grains.fem import build_fem_layout
from grainfrac_yade.params import load_parameters

SMALL = ["specimen.width=4e-3", "specimen.height=8e-3", "resolution.grain_model=fem"]
#: A uniform strain (Voigt: xx, yy, 2xy) with all three components, of elastic size.
STRAIN = np.array([1.0e-3, -4.0e-4, 2.5e-4])


def _grain_energy(net, displacement: np.ndarray) -> float:
    """0.5 u^T K u of the network's triangles alone (bond stiffnesses zeroed) [J]."""
    k, dofs = stiffness_matrix(dataclasses.replace(net, spring_kn=0 * net.spring_kn, spring_ks=0 * net.spring_ks))
    u = np.zeros(k.shape[0])
    u[dofs[:, 0]], u[dofs[:, 1]] = displacement[:, 0], displacement[:, 1]
    return 0.5 * u @ (k @ u)


@pytest.mark.parametrize("rings,growth", [(1, 1.0), (2, 1.0), (4, 1.0), (3, 2.0)])
def test_a_uniform_strain_stores_the_exact_plane_strain_energy_for_any_rings(rings, growth):
    """Constant-strain triangles reproduce a linear displacement field exactly, so the cells' triangles
    (however many rings) hold sum over cells of 0.5 t A' eps^T D eps, A' = (1 - inset)^2 A the shrunk
    cell's area and D its mineral's plane-strain matrix (Table 1): true only if the rings tile each cell
    without gap or overlap. Tolerance 1e-12 relative: a sum of a few thousand float64 terms."""
    grading = [f"resolution.cell_ring_growth={growth}"] if growth != 1.0 else []
    p = load_parameters(overrides=SMALL + [f"resolution.cell_rings={rings}"] + grading)
    s = build_specimen(p, 1)
    lay = build_fem_layout(s, p)
    net = cluster_network(s, p, lay)
    x = lay.sphere_center[:, :2]
    grad = np.array([[STRAIN[0], STRAIN[2] / 2], [STRAIN[2] / 2, STRAIN[1]]])
    energy = _grain_energy(net, x @ grad.T)
    d = plane_strain_matrix([p.grains[m].young for m in s.mineral_names],
                            [p.grains[m].poisson for m in s.mineral_names])[s.mineral]
    shrunk = (1 - p.resolution.contact_inset) ** 2 * s.tessellation.cell_measure
    expected = 0.5 * s.thickness * np.sum(shrunk * np.einsum("i,cij,j->c", STRAIN, d, STRAIN))
    assert energy == pytest.approx(expected, rel=1e-12)


def test_rings_refine_the_cells_interior_not_their_contacts():
    """Each ring adds one node per boundary node of a cell and two triangles per boundary segment; the bonds
    (their spheres, shares and faces) stay those of one fan."""
    fan, two = (build_fem_layout(build_specimen(q, 1), q) for q in
                (load_parameters(overrides=SMALL), load_parameters(overrides=SMALL + ["resolution.cell_rings=2"])))
    boundary = fan.n_spheres - fan.sphere_cell.max() - 1          # every node but the centroids
    assert two.n_spheres == fan.n_spheres + boundary
    assert len(two.element_spheres) == 3 * len(fan.element_spheres)
    assert np.array_equal(two.sphere_center[two.bond_spheres], fan.sphere_center[fan.bond_spheres])
    assert np.array_equal(two.bond_area, fan.bond_area) and np.array_equal(two.bond_face, fan.bond_face)


def test_graded_rings_thicken_inwards_in_the_given_ratio():
    """ring_fractions: layer thicknesses t_i = q^(i-1) / sum_j q^(j-1) from the boundary inwards (closed form:
    with 3 rings and q = 2 the layers are 1/7, 2/7 and 4/7 of the way, the rings at 6/7 and 4/7 from the
    centroid); q = 1 gives k / rings exactly, as every mesh before the grading. Tolerance 1e-15: two roundings."""
    assert ring_fractions(4) == [0.75, 0.5, 0.25] and ring_fractions(4, 1.0) == [3 / 4, 2 / 4, 1 / 4]
    assert ring_fractions(3, 2.0) == pytest.approx([6 / 7, 4 / 7], abs=1e-15)
    frac = [1.0] + ring_fractions(5, 1.5) + [0.0]
    layers = -np.diff(frac)
    assert layers[1:] / layers[:-1] == pytest.approx([1.5] * 4, rel=1e-12)
    assert ring_fractions(1, 2.0) == []


def test_graded_rings_move_only_the_inner_nodes():
    """The grading moves the inner rings; the boundary nodes, bonds and element count stay those of uniform rings."""
    uniform, graded = (build_fem_layout(build_specimen(q, 1), q) for q in
                       (load_parameters(overrides=SMALL + ["resolution.cell_rings=3"]),
                        load_parameters(overrides=SMALL + ["resolution.cell_rings=3", "resolution.cell_ring_growth=2"])))
    assert np.array_equal(graded.sphere_center[graded.bond_spheres], uniform.sphere_center[uniform.bond_spheres])
    assert np.array_equal(graded.element_spheres, uniform.element_spheres)
    assert not np.array_equal(graded.sphere_center, uniform.sphere_center)


def test_a_grading_without_rings_is_refused_in_one_line():
    with pytest.raises(ParameterError, match=r"resolution.cell_ring_growth: 2 with resolution.cell_rings = 1.*"
                                             r"; fix: set resolution.cell_rings >= 2"):
        load_parameters(overrides=SMALL + ["resolution.cell_ring_growth=2"])
    with pytest.raises(ParameterError, match=r"resolution.cell_ring_growth"):
        load_parameters(overrides=SMALL + ["resolution.cell_rings=2", "resolution.cell_ring_growth=0"])


def test_rigid_cells_refuse_rings_in_one_line():
    with pytest.raises(ParameterError, match=r"--set: resolution.cell_rings: 2 with resolution.grain_model = "
                                             r"'rigid'.*; fix: set resolution.cell_rings = 1, or "
                                             r"resolution.grain_model = \"fem\""):
        load_parameters(overrides=["resolution.cell_rings=2"])
    with pytest.raises(ParameterError, match=r"resolution.cell_rings: 0 must be >= 1"):
        load_parameters(overrides=SMALL + ["resolution.cell_rings=0"])
    assert load_parameters().resolution.cell_rings == 1
