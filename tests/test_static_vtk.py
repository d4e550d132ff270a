"""VTK series on the static engine: the same .vtp/.pvd series as YADE runs write, drawn from the solved displacements
(pure: numpy, scipy and VTK's Python modules; tiny specimens, about a second each)."""
import json

import numpy as np
import pandas as pd
import pytest

from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.params import load_parameters
from grainfrac_yade.kernel.cracks import bond_segments
from grainfrac_yade.vtkio import BOND_STATE_NAMES, read_vtp

pytest.importorskip("vtkmodules")

#: 3 x 6 mm, seed 1 (23 cells, 50 rigid bonds): the UCS path breaks 11 bonds in about 0.3 s.
TINY = ["specimen.width=3e-3", "specimen.height=6e-3", "numerics.engine=static"]
FEM = "params/presets/fem_coarse.toml"
#: The arrays a YADE run's series carry (tests/test_vtkio.py), which the static engine's must carry too.
CELL_ARRAYS = {"mineral", "mineral_name", "cell_id", "clump"}
UCS_BOND_ARRAYS = {"bond_id", "state", "state_name", "inter", "cell_a", "cell_b", "break_dem_step",
                   "normal_stress_pa", "shear_stress_pa", "tensile_strength_pa", "cohesion_pa"}
CREEP_BOND_ARRAYS = {"state", "state_name", "inter", "tensile_strength_pa", "cohesion_pa", "tensile_strength_fraction",
                     "normal_stress_pa", "shear_stress_pa", "break_time_s", "macro"}
#: 4 x 8 mm, seed 1, held at 160 MPa on the static engine: fails after a few events in about a second
#: (tests/test_static_engine.py's creep row).
CREEP_ROW = ["--engine", "static", "--width", "4e-3", "--height", "8e-3", "--stress", "160", "--seed", "1"]


def _root():
    from conftest import ROOT
    return ROOT


def _series(folder, name, n_items, time_name):
    """Every file of series ``name`` read back at its .pvd timestep (the YADE runs' check, tests/test_vtkio.py)."""
    from test_vtkio import _check_series
    return _check_series(folder, name, n_items, time_name)


def _ucs_with_series(tmp_path, every, *extra):
    """The UCS protocol on a tiny static scene with a VTK series every ``every`` rows: (history, scene, folder)."""
    from grainfrac_yade.protocols.snapshots import AXIAL_STRAIN, StrainSeries
    from grainfrac_yade.protocols.ucs import run_ucs
    p = load_parameters(extra_files=[_root() / f for f in extra if f.endswith(".toml")],
                        overrides=[*TINY, *[x for x in extra if not x.endswith(".toml")]])
    folder = tmp_path / "vtk"
    cols, _, scene, _ = run_ucs(build_specimen(p, 1), p, snapshot=StrainSeries(folder, every, AXIAL_STRAIN))
    return cols, scene, folder


def _node_displacements(scene):
    """(n_nodes, 2) node displacements and (n_nodes,) rotations [rad] read straight from the core's solved state."""
    net, u = scene.net, scene.state.u
    disp = np.zeros((len(net.node_pos), 2))
    for col in range(2):
        disp[:, col] = np.where(net.dofs[:, col] >= 0, u[np.maximum(net.dofs[:, col], 0)], 0.0)
    rot = np.where(net.dofs[:, 2] >= 0, u[np.maximum(net.dofs[:, 2], 0)], 0.0)
    return disp, rot


def _check_bond_states(data, scene):
    """The bonds' state codes: 0 intact, the break mode where broken, as the scene's bookkeeping."""
    state = data["cell_data"]["state"]
    assert np.array_equal(state > 0, scene.broken) and scene.broken.any()
    assert np.array_equal(state[scene.broken], scene.break_mode[scene.broken])
    assert [BOND_STATE_NAMES[k] for k in state] == data["cell_data"]["state_name"]


def test_ucs_series_rigid_cells_move_by_the_solved_displacements(tmp_path):
    """Rigid cells: every polygon is its cell translated and rotated by its node's solved dofs, every bond segment
    shifted by the mean of its two cells' translations; the last snapshot is the scene's final state."""
    cols, scene, folder = _ucs_with_series(tmp_path, 25)
    spec, tess = scene.specimen, scene.specimen.tessellation
    cells = _series(folder, "cells", spec.n_cells, "axial_strain")
    bonds = _series(folder, "bonds", scene.n_bonds, "axial_strain")
    strain = list(cols["axial_strain"])
    assert [t for t, _ in bonds] == strain[24::25] + ([strain[-1]] if len(strain) % 25 else [])
    disp, rot = _node_displacements(scene)
    assert np.abs(disp).max() > 1e-6   # the specimen was shortened by about 0.4 %
    last = cells[-1][1]
    assert set(last["cell_data"]) >= CELL_ARRAYS
    for c, ids in enumerate(last["cells"]):
        v0 = np.asarray(tess.cell_vertices[c])[:, :2] - tess.cell_centroid[c, :2]
        a = rot[c]
        moved = v0 @ np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]).T + tess.cell_centroid[c, :2] + disp[c]
        np.testing.assert_allclose(last["points"][ids, :2], moved, rtol=0, atol=1e-15)
    b = bonds[-1][1]
    assert set(b["cell_data"]) >= UCS_BOND_ARRAYS
    cell_of = scene.layout.sphere_cell[scene.layout.bond_spheres]
    shift = 0.5 * (disp[cell_of[:, 0]] + disp[cell_of[:, 1]])
    seg = bond_segments(scene, np.arange(scene.n_bonds)) + shift[:, None, :]
    pts = np.array([b["points"][ids, :2] for ids in b["cells"]])
    np.testing.assert_allclose(pts, seg, rtol=0, atol=1e-15)
    _check_bond_states(b, scene)
    fn, fs = scene.bond_forces()
    np.testing.assert_allclose(b["cell_data"]["normal_stress_pa"], fn / scene.layout.bond_area, rtol=1e-15)
    np.testing.assert_allclose(b["cell_data"]["shear_stress_pa"], fs / scene.layout.bond_area, rtol=1e-15)
    steps = b["cell_data"]["break_dem_step"]
    assert np.array_equal(steps[scene.broken], scene.break_step[scene.broken]) and np.isnan(steps[~scene.broken]).all()


def test_ucs_series_fem_cells_follow_their_spheres(tmp_path):
    """Fem cells: each polygon is moved by the least-squares rigid motion of its spheres (their lumped areas as
    weights; closed form here: the weighted mean translation and the angle atan2(sum w r0 x r, sum w r0 . r) of the
    centred positions), bonds by the mean of their two spheres' displacements."""
    _, scene, folder = _ucs_with_series(tmp_path, 40, FEM, "ucs.max_strain=0.006")
    lay, tess = scene.layout, scene.specimen.tessellation
    disp, _ = _node_displacements(scene)
    assert len(disp) == lay.n_spheres and np.abs(disp).max() > 1e-6
    last = _series(folder, "cells", scene.specimen.n_cells, "axial_strain")[-1][1]
    x0, w, cell = lay.sphere_center[:, :2], lay.sphere_area, lay.sphere_cell
    x = x0 + disp
    for c, ids in enumerate(last["cells"]):
        k = cell == c
        m0, m = (np.average(y[k], axis=0, weights=w[k]) for y in (x0, x))
        r0, r = x0[k] - m0, x[k] - m
        a = np.arctan2((w[k] * (r0[:, 0] * r[:, 1] - r0[:, 1] * r[:, 0])).sum(), (w[k] * (r0 * r).sum(1)).sum())
        rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
        moved = (np.asarray(tess.cell_vertices[c])[:, :2] - m0) @ rot.T + m
        np.testing.assert_allclose(last["points"][ids, :2], moved, rtol=0, atol=1e-15)
    b = _series(folder, "bonds", scene.n_bonds, "axial_strain")[-1][1]
    s = lay.bond_spheres
    seg = bond_segments(scene, np.arange(scene.n_bonds)) + 0.5 * (disp[s[:, 0]] + disp[s[:, 1]])[:, None, :]
    np.testing.assert_allclose(np.array([b["points"][ids, :2] for ids in b["cells"]]), seg, rtol=0, atol=1e-15)
    _check_bond_states(b, scene)


def test_ucs_command_writes_the_series(tmp_path, capsys):
    """ucs --engine static --vtk-every K: no longer refused; every K-th history row and the end, the last snapshot's
    broken bonds those of the run."""
    from grainfrac_yade.cli import main
    out = tmp_path / "ucs"
    rc = main(["ucs", "--engine", "static", "--width", "3e-3", "--height", "6e-3", "--seed", "1", "--vtk-every", "30",
               "--out", str(out)])
    assert rc == 0, capsys.readouterr().err
    s = json.loads((out / "summary.json").read_text())
    hist = pd.read_csv(out / "history.csv", float_precision="round_trip")
    bonds = _series(out / "vtk", "bonds", s["n_bonds"], "axial_strain")
    strain = list(hist["axial_strain"])
    assert [t for t, _ in bonds] == strain[29::30] + ([strain[-1]] if len(strain) % 30 else [])
    assert int((bonds[-1][1]["cell_data"]["state"] > 0).sum()) == s["broken_total"] > 0
    _series(out / "vtk", "cells", 23, "axial_strain")


def test_creep_command_writes_the_series_in_creep_time(tmp_path, capsys):
    """creep --engine static with --vtk-times, --vtk-every and --vtk-fractions: the regular series (each snapshot's
    broken bonds those of cracks.csv by then, the last at the lifetime) and the life series."""
    from grainfrac_yade.cli import main
    out = tmp_path / "creep"
    rc = main(["creep", *CREEP_ROW, "--vtk-times", "0", "--vtk-every", "1", "--vtk-fractions", "--out", str(out)])
    assert rc == 0, capsys.readouterr().err
    s = json.loads((out / "summary.json").read_text())
    assert s["failed"] is True
    cracks = pd.read_csv(out / "cracks.csv", float_precision="round_trip")
    hist = pd.read_csv(out / "history.csv", float_precision="round_trip")
    bonds = _series(out / "vtk", "bonds", s["n_bonds"], "creep_time")
    cells = _series(out / "vtk", "cells", len(read_vtp(out / "vtk" / "cells_0000.vtp")["cells"]), "creep_time")
    assert [t for t, _ in bonds] == sorted(set(hist["creep_time_s"])) and bonds[-1][0] == s["lifetime_s"]
    assert set(cells[-1][1]["cell_data"]) >= CELL_ARRAYS
    first, last = cells[0][1]["points"], cells[-1][1]["points"]
    assert np.abs(last - first).max() > 0   # the cells moved during the hold (creep strain)
    for t, b in bonds:
        data = b["cell_data"]
        assert set(data) >= CREEP_BOND_ARRAYS
        broken = data["state"] > 0
        assert int(broken.sum()) == int(((cracks["phase"] == "ramp") | (cracks["creep_time_s"] <= t)).sum())
        assert np.all(data["tensile_strength_pa"][broken] == 0) and np.all(np.isnan(data["break_time_s"][~broken]))
    np.testing.assert_array_equal(np.flatnonzero(bonds[-1][1]["cell_data"]["state"] > 0), np.sort(cracks["bond"]))
    life = _series(out / "vtk", "life_bonds", s["n_bonds"], "creep_time")
    assert len(life) >= 2 and life[-1][0] == pytest.approx(s["lifetime_s"], rel=1e-15)
