"""Static elastic reference: patch test, mesh bookkeeping, rigid solve against YADE, CLI output."""
import json

import numpy as np
import pytest

from conftest import needs_yade
from grainfrac_yade.elastic import (mesh_network, elastic_summary, plane_strain_matrix, rigid_network,
                                    solve_uniaxial)
from grainfrac_yade.errors import GrainfracError
from grainfrac_yade.geometry.grainmesh import face_node_positions, grain_mesh
from grainfrac_yade.grains.rigid import build_layout
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen, specimen_from_tessellation

SMALL = ["specimen.width=5e-3", "specimen.height=10e-3"]


def _one_mineral(p, seed=3):
    s = build_specimen(p, seed)
    return specimen_from_tessellation(s.tessellation, np.zeros(s.n_cells, int), s.mineral_names, s.thickness)


@pytest.mark.parametrize("nodes_per_face,rings", [(2, 1), (3, 2)])
def test_patch_test_one_mineral_with_stiff_contacts_gives_table_1(nodes_per_face, rings):
    """One mineral, contacts 1e4 x stiffer, platens on the walls: the specimen is the mineral itself,
    so E = E' = E/(1-nu^2) and nu = nu/(1-nu) (plane strain, Table 1) within 1 %."""
    p = load_parameters(overrides=SMALL + ["calibration.stiffness_scale=1e4"])
    s = _one_mineral(p)
    g = p.grains[s.mineral_names[0]]
    sol = solve_uniaxial(mesh_network(s, p, nodes_per_face, "corners", rings), s, platens="wall")
    assert sol.young == pytest.approx(g.young / (1 - g.poisson**2), rel=0.01)
    assert sol.poisson == pytest.approx(g.poisson / (1 - g.poisson), rel=0.01)


def test_plane_strain_matrix_is_hookes_law():
    """D eps with eps = (1, 0, 0) gives sigma_xx = E(1-nu)/((1+nu)(1-2nu)) and sigma_yy = E nu/(...)."""
    e, nu = 62e9, 0.27
    d = plane_strain_matrix([e], [nu])[0]
    f = e / ((1 + nu) * (1 - 2 * nu))
    assert d @ [1, 0, 0] == pytest.approx([f * (1 - nu), f * nu, 0])
    assert d[2, 2] == pytest.approx(e / (2 * (1 + nu)))


@pytest.mark.parametrize("contacts,k", [("corners", 2), ("corners", 4), ("midpoints", 1), ("midpoints", 3)])
def test_contact_shares_sum_to_each_face(small_params, contacts, k):
    """Every interior face is joined by k node pairs whose shares sum to 1; pairs sit at one point."""
    s = build_specimen(small_params, 1)
    mesh = grain_mesh(s, k, contacts)
    per_face = np.bincount(mesh.contact_face, weights=mesh.contact_share, minlength=s.tessellation.n_faces)
    assert per_face == pytest.approx(np.ones(s.tessellation.n_faces), abs=1e-12)
    a, b = mesh.node_pos[mesh.contact_nodes[:, 0]], mesh.node_pos[mesh.contact_nodes[:, 1]]
    assert np.abs(a - b).max() < 1e-12
    assert (mesh.node_cell[mesh.contact_nodes[:, 0]] != mesh.node_cell[mesh.contact_nodes[:, 1]]).all()


def test_mesh_covers_each_cell(small_params):
    """The triangles of a cell (any refinement) tile its polygon: areas sum to the cell area."""
    s = build_specimen(small_params, 2)
    for rings in (1, 3):
        mesh = grain_mesh(s, 3, "corners", rings)
        area = mesh.triangle_areas()
        assert (area > 0).all()
        per_cell = np.bincount(mesh.triangle_cell, weights=area, minlength=s.n_cells)
        assert per_cell == pytest.approx(s.tessellation.cell_measure, rel=1e-12)


def test_face_node_positions_refuse_one_corner_node():
    with pytest.raises(GrainfracError, match="nodes-per-face >= 2"):
        face_node_positions(1, "corners")


def test_mesh_cells_concentrate_shear_more_than_rigid_cells(small_params):
    """The reason deformable grains matter: at the same load the contact shear tail is higher."""
    s = build_specimen(small_params, 1)
    rigid, _, _ = elastic_summary(s, small_params, "rigid", build_layout(s, 1))
    mesh, _, _ = elastic_summary(s, small_params, "mesh")
    assert mesh["shear_stress_ratio_p99"] > 1.3 * rigid["shear_stress_ratio_p99"]
    assert mesh["young_pa"] > rigid["young_pa"]


def test_ratios_do_not_depend_on_the_applied_strain(small_params):
    s = build_specimen(small_params, 1)
    a, _, _ = elastic_summary(s, small_params, "mesh", strain=1e-4)
    b, _, _ = elastic_summary(s, small_params, "mesh", strain=3e-3)
    for key in ("young_pa", "poisson", "shear_stress_ratio_p99", "tension_stress_ratio_max"):
        assert a[key] == pytest.approx(b[key], rel=1e-9)


def test_elastic_command_writes_summary_and_histogram(tmp_path):
    from grainfrac_yade.cli import main
    out = tmp_path / "el"
    assert main(["elastic", "--width", "5e-3", "--height", "10e-3", "--seed", "2", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    for key in ("young_pa", "poisson", "shear_stress_ratio_p50", "shear_stress_ratio_p99", "shear_stress_ratio_max",
                "tension_stress_ratio_p50", "tension_stress_ratio_p99", "tension_stress_ratio_max"):
        assert np.isfinite(summary[key])
        assert np.isfinite(summary["models"]["rigid"][key])
    assert summary["grains"] == "mesh"
    assert (out / "contact_stress_histogram.png").stat().st_size > 10_000
    assert (out / "params.json").exists() and (out / "run.json").exists()


@needs_yade
@pytest.mark.yade
def test_rigid_solve_agrees_with_yade_after_a_small_elastic_ramp():
    """Same specimen, same bonds: YADE compressed slowly to a strain of 2e-4 (no bond breaks) and
    relaxed to rest gives the static solve's platen stress and every bond's normal and shear
    force.  Measured on this 4 x 8 mm specimen (seed 1): 6e-5 relative on the stress, 1.5e-4 of
    the largest bond force.  The solve needs YADE's exact shear kinematics to get there: without
    the ratcheting guard's factor (r_a + r_b)/d on the relative translation the gap was 2.8 % and
    3.2 %."""
    p = load_parameters(overrides=["specimen.width=4e-3", "specimen.height=8e-3", "numerics.damping=0.7"])
    _assert_yade_ramp_matches_static_solve(p, rigid_network, relax_steps=20000)


def _assert_yade_ramp_matches_static_solve(p, network, relax_steps):
    """Ramp seed 1 of ``p`` in YADE slowly to a strain of 2e-4, relax, compare with ``network``'s solve."""
    from grainfrac_yade.engines.yade.platens import Platens
    from grainfrac_yade.engines.yade.scene import build_scene
    s = build_specimen(p, 1)
    scene = build_scene(s, p)
    net = network(s, p, scene.layout)
    platens = Platens(scene)
    scene.extras.append(platens)
    strain, steps = 2e-4, 4000
    platens.set_axial_velocity(strain * platens.height / (steps * scene.O.dt))
    scene.run(steps)
    platens.set_axial_velocity(0.0)
    scene.run(relax_steps)
    assert not scene.broken.any()
    sol = solve_uniaxial(net, s, platens.axial_strain())
    fn, fs = scene.bond_forces()
    nb = scene.n_bonds
    scale = np.abs(sol.normal_force[:nb]).max()
    assert platens.axial_stress() == pytest.approx(sol.applied_stress, rel=1e-3)
    assert np.abs(fn - sol.normal_force[:nb]).max() < 1e-3 * scale
    assert np.abs(fs - np.abs(sol.shear_force[:nb])).max() < 1e-3 * scale
