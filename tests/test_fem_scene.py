"""Finite-element cells (``resolution.grain_model = "fem"``): static solve, YADE elements, scene.

The cluster of each cell is the reference's triangle mesh, shrunk by ``contact_inset``: the static
solve of that cluster must converge to the mesh reference as the inset goes to zero, and the YADE
scene must be that cluster (a slow elastic ramp agrees with the static solve, as for rigid cells).
"""
import dataclasses
from pathlib import Path

import numpy as np
import pytest

from conftest import needs_yade
from grainfrac_yade.grains.fem import build_fem_layout, element_apex
from grainfrac_yade.elastic import (cluster_network, contact_statistics, mesh_network, node_stiffness,
                                    solve_uniaxial, stiffness_matrix)
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen

FEM_PRESET = Path(__file__).resolve().parents[1] / "params" / "presets" / "fem_coarse.toml"
MEDIAN_VERLET = ["numerics.verlet_radius_quantile=0.5", "numerics.verlet_fraction=0.5"]
SMALL = ["specimen.width=4e-3", "specimen.height=8e-3", "resolution.grain_model=fem"]


def _with_inset(p, inset):
    return dataclasses.replace(p, resolution=dataclasses.replace(p.resolution, contact_inset=inset))


def _with_rings(p, rings):
    return dataclasses.replace(p, resolution=dataclasses.replace(p.resolution, cell_rings=rings))


def test_element_apex_covers_every_triangle_with_one_node_per_fan():
    p = load_parameters(overrides=SMALL)
    s = build_specimen(p, 1)
    lay = build_fem_layout(s, p)
    tri = lay.element_spheres
    apex = element_apex(tri)
    assert (tri == apex[:, None]).any(axis=1).all()          # every apex is a node of its triangle
    # a fan mesh (one ring): the centroid node of each cell is in all its triangles
    assert len(np.unique(apex)) == s.n_cells
    assert np.array_equal(np.unique(lay.sphere_cell[apex]), np.arange(s.n_cells))


@pytest.mark.parametrize("rings", [1, 2])
def test_fem_cluster_converges_to_the_mesh_reference_as_the_inset_vanishes(rings):
    """E and nu of the shrunk mesh approach the reference's (at the same ``resolution.cell_rings``) linearly
    in the inset (static solves, 10 x 20 mm seed 1: E -3.0 / -1.0 / -0.1 % at insets 0.03 / 0.01 / 0.001,
    nu within 0.3 %)."""
    p = _with_rings(load_parameters(overrides=SMALL), rings)
    s = build_specimen(p, 1)
    ref = solve_uniaxial(mesh_network(s, p, p.resolution.nodes_per_face, "corners", rings), s)
    errors = []
    for inset in (0.03, 0.01, 0.001):
        q = _with_inset(p, inset)
        sol = solve_uniaxial(cluster_network(s, q, build_fem_layout(s, q)), s)
        errors.append((abs(sol.young / ref.young - 1), abs(sol.poisson / ref.poisson - 1)))
    e_young, e_nu = np.array(errors).T
    assert e_young[0] > e_young[1] > e_young[2] and e_young[2] < 2e-3
    assert e_nu.max() < 1e-2


def test_contact_radii_leave_unbonded_spheres_of_different_cells_apart():
    from grainfrac_yade.grains.fem import CONTACT_RADIUS_FRACTION, contact_radii
    from scipy.spatial.distance import cdist
    p = load_parameters(overrides=SMALL)
    s = build_specimen(p, 1)
    lay = build_fem_layout(s, p)
    pos, r, cell = lay.sphere_center[:, :2], lay.sphere_radius, lay.sphere_cell
    assert np.array_equal(r, contact_radii(pos, cell, lay.bond_spheres))
    d = cdist(pos, pos)
    other = cell[:, None] != cell[None, :]
    other[lay.bond_spheres[:, 0], lay.bond_spheres[:, 1]] = False
    other[lay.bond_spheres[:, 1], lay.bond_spheres[:, 0]] = False
    gap = d - (r[:, None] + r[None, :])
    assert gap[other].min() >= (1 - CONTACT_RADIUS_FRACTION) * d[other].min() - 1e-15
    # each sphere's radius is set by one such neighbour: no sphere could be larger
    assert np.allclose((np.where(other, d, np.inf).min(axis=1)) * 0.5 * CONTACT_RADIUS_FRACTION, r)
    # bonds act on their faces' planes
    assert np.allclose(lay.bond_normal, s.tessellation.face_normal[lay.bond_face])


def test_fem_masses_keep_each_cell_whole_and_equalise_the_sphere_periods():
    p = load_parameters(overrides=SMALL)
    s = build_specimen(p, 1)
    lay = build_fem_layout(s, p)
    per_cell = np.bincount(lay.sphere_cell, weights=lay.sphere_area, minlength=s.n_cells)
    assert np.allclose(per_cell, s.tessellation.cell_measure, rtol=1e-12)
    k = node_stiffness(cluster_network(s, p, lay))
    ratio = lay.sphere_area / k                              # m / K up to the areal density
    for c in range(3):
        r = ratio[lay.sphere_cell == c]
        assert np.allclose(r, r[0], rtol=1e-12)


def test_node_stiffness_bounds_the_fastest_mode():
    """Gershgorin: the largest eigenvalue of K (unit masses) is at most the largest row sum."""
    p = load_parameters(overrides=SMALL)
    s = build_specimen(p, 1)
    net = cluster_network(s, p, build_fem_layout(s, p))
    k, _ = stiffness_matrix(net)
    from scipy.sparse.linalg import eigsh
    lam = eigsh(k, k=1, which="LA", return_eigenvectors=False)[0]
    bound = node_stiffness(net).max()
    assert 0.2 * bound < lam <= bound


@needs_yade
@pytest.mark.yade
def test_yade_element_material_gives_an_exact_linear_tetrahedron():
    """One Lin4NodeTetra with :func:`fem_element_material`: nodal forces = -K u of a tetrahedron
    built by hand from the shape-function gradients and the 3D isotropic elasticity matrix."""
    from grainfrac_yade.engines.yade import load_yade
    from grainfrac_yade.engines.yade.fem_cells import fem_element_material
    load_yade()
    from yade import O, utils, Vector3
    from yade import wrapper as w
    young, nu = 50e9, 0.3
    pos = np.array([[0, 0, 0], [1e-3, 0, 0], [0.2e-3, 0.9e-3, 0], [0.3e-3, 0.2e-3, 0.8e-3]])
    O.reset()
    ids = [O.bodies.append(utils.sphere(Vector3(*x), 1e-5)) for x in pos]
    element = w.Lin4NodeTetra()
    body = w.Body(shape=element, material=w.LinIsoRayleighDampElastMat(**fem_element_material(young, nu)))
    body.dynamic, body.bounded = False, False
    O.bodies.append(body)
    for i in ids:
        element.addNode(O.bodies[i])
    u = np.random.default_rng(1).normal(size=(4, 3)) * 1e-6
    for i, du in zip(ids, u):
        O.bodies[i].state.pos = Vector3(*(pos[i] + du))
    O.engines = [w.ForceResetter(), w.FEInternalForceEngine([w.If2_Lin4NodeTetra_LinIsoRayleighDampElast()])]
    O.dt = 1e-12
    O.step()
    force = np.array([tuple(O.forces.f(i)) for i in ids])
    grad = np.linalg.inv(np.c_[np.ones(4), pos])[1:, :]          # (3, 4) shape-function gradients
    b = np.zeros((6, 12))
    for a in range(4):
        gx, gy, gz = grad[:, a]
        b[:, 3 * a:3 * a + 3] = [[gx, 0, 0], [0, gy, 0], [0, 0, gz], [gy, gx, 0], [0, gz, gy], [gz, 0, gx]]
    lam, mu = young * nu / ((1 + nu) * (1 - 2 * nu)), young / (2 * (1 + nu))
    d = np.zeros((6, 6))
    d[:3, :3] = lam
    d[range(3), range(3)] += 2 * mu
    d[3:, 3:] = mu * np.eye(3)
    volume = abs(np.linalg.det(np.c_[np.ones(4), pos])) / 6
    expected = -(volume * b.T @ d @ b @ u.ravel()).reshape(4, 3)
    assert np.abs(force - expected).max() < 1e-6 * np.abs(expected).max()


@needs_yade
@pytest.mark.yade
@pytest.mark.parametrize("rings", [1, 2])
def test_fem_scene_agrees_with_the_static_solve_after_a_small_elastic_ramp(rings):
    """The YADE scene of finite-element cells is the shrunk mesh that the static solve models, bonds
    acting along their faces' normals (smooth joints), at one fan of triangles per cell or with a radial
    ring (``resolution.cell_rings``): platen stress and every bond's forces agree (measured on 4 x 8 mm
    seed 1: 8e-10 on the stress, 5e-9 of the largest bond force; with the bonds along the lines of
    sphere centres and the static solve along the face normals, 6 %)."""
    from test_elastic import _assert_yade_ramp_matches_static_solve
    p = load_parameters(overrides=SMALL + ["numerics.damping=0.7", f"resolution.cell_rings={rings}"])
    _assert_yade_ramp_matches_static_solve(p, cluster_network, relax_steps=20000)


@needs_yade
@pytest.mark.yade
def test_a_verlet_distance_of_the_median_sphere_keeps_the_static_solve():
    """The collider's Verlet distance only decides how often it sorts and which pairs it hands over as
    possible contacts, never a force: with 0.5 x the median sphere radius the slow elastic ramp still
    equals the static solve, with the tolerances of the default scene's test."""
    from test_elastic import _assert_yade_ramp_matches_static_solve
    p = load_parameters(overrides=SMALL + ["numerics.damping=0.7", *MEDIAN_VERLET])
    _assert_yade_ramp_matches_static_solve(p, cluster_network, relax_steps=20000)


@needs_yade
@pytest.mark.yade
@pytest.mark.slow
def test_a_verlet_distance_of_the_median_sphere_stops_the_resorting():
    """The collider holds the distance asked for, and over 1,000 DEM steps of a UCS ramp it sorts far less
    often than with YADE's rule (0.5 x the smallest sphere, which fem cells make tiny next to sliver
    faces).  10 x 20 mm seed 3 with the fem preset (smallest sphere 2.7e-3 of the median): 543 sorts
    in 1,000 steps after 200 warm-up steps with YADE's rule, 1 with the median's."""
    from grainfrac_yade.engines.yade.platens import Platens
    from grainfrac_yade.engines.yade.scene import build_scene
    sorts = {}
    for name, extra in (("yade_rule", ["numerics.verlet_radius_quantile=0"]), ("median", MEDIAN_VERLET)):
        q = load_parameters(extra_files=[FEM_PRESET], overrides=["specimen.width=10e-3", "specimen.height=20e-3",
                                                                  *extra])
        scene = build_scene(build_specimen(q, 3), q)
        collider = next(e for e in scene.O.engines if type(e).__name__ == "InsertionSortCollider")
        if name == "median":
            assert collider.verletDist == pytest.approx(0.5 * np.median(scene.layout.sphere_radius), rel=1e-15)
        else:
            assert collider.verletDist == -0.5
        platens = Platens(scene)
        scene.extras.append(platens)
        platens.set_axial_velocity(q.ucs.strain_rate * platens.height)
        scene.run(1200)
        sorts[name] = collider.numAction
    assert sorts["median"] * 10 < sorts["yade_rule"]


@needs_yade
@pytest.mark.yade
def test_fem_scene_lists_the_element_engine_and_moves_clumped_apexes():
    from grainfrac_yade.engines.yade.scene import build_scene
    p = load_parameters(overrides=SMALL)
    s = build_specimen(p, 1)
    scene = build_scene(s, p)
    assert scene.engine_names() == ["ForceResetter", "InsertionSortCollider", "InteractionLoop",
                                    "FEInternalForceEngine", "NewtonIntegrator", "IntactJointGuard"]
    O = scene.O
    # each cell's bodies: its spheres, the apex sphere replaced by the clump that moves it
    clumps = [b for c in range(s.n_cells) for b in scene.bodies_of([c]) if O.bodies[int(b)].isClump]
    assert len(clumps) == s.n_cells
    assert 0 < O.dt <= scene.dt_critical
    # bonds on their faces' planes: none open at the start, and the law uses smooth joints
    scene.run(1)
    assert scene.law.smoothJoint and not scene.bond_separated(range(scene.n_bonds)).any()
    assert all(i.phys.isOnJoint for i in scene.interactions)
    # rigid scenes carry no element engine
    q = load_parameters(overrides=SMALL[:2] + ["resolution.grain_model=rigid"])
    assert "FEInternalForceEngine" not in build_scene(build_specimen(q, 1), q).engine_names()


@needs_yade
@pytest.mark.yade
@pytest.mark.parametrize("command", [["ucs"], pytest.param(["creep", "--ratio", "0.8", "--set",
                                                              "stress_corrosion.creep_time_limit=1e13"],
                                                             marks=pytest.mark.slow)])
def test_fem_cells_run_the_commands_end_to_end(tmp_path, command):
    """The preset runs a UCS and a creep test on a tiny specimen: a clean end, the grain model in
    the summary, cracks recorded, no numerical failure."""
    import json
    import subprocess
    import sys
    from pathlib import Path
    root = Path(__file__).resolve().parents[1]
    out = tmp_path / command[0]
    res = subprocess.run([sys.executable, "-m", "grainfrac_yade", *command, "--params", "params/presets/fem_coarse.toml",
                          "--width", "4e-3", "--height", "8e-3", "--seed", "1", "--out", str(out)],
                         capture_output=True, text=True, cwd=root)
    assert res.returncode == 0, res.stderr[-2000:]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["numerical_failure"] is False and summary["end_reason"]
    assert json.loads((out / "params.json").read_text())["resolution"]["grain_model"] == "fem"
    assert (out / "cracks.csv").exists() and (out / "history.csv").exists()
    if command[0] == "creep":
        assert summary["failed"] is True or summary["lifetime_s"] is None
        assert summary["broken_total"] > 0
    else:
        assert 0 < summary["ucs_pa"] < 1e9 and 50e9 < summary["young_pa"] < 100e9
