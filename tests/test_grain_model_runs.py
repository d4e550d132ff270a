"""Rigid and fem cells in the run records: every layout from ``layout_for``, the grain model in
summary.json, rigid, fem and retired-lattice runs kept apart in studies, batch rows naming the grain model.

No YADE run: the UCS and creep drivers are replaced by stand-ins returning a fixed history.
"""
import json
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from conftest import needs_yade
from grainfrac_yade.errors import GrainfracError
from grainfrac_yade.grains import layout_for
from grainfrac_yade.grains.rigid import build_layout
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen

SMALL = ["specimen.width=3e-3", "specimen.height=6e-3"]
FEM = ["resolution.grain_model=fem"]
SEED = 1


@pytest.fixture(scope="module")
def fem():
    """Parameters, specimen and layout of a small fem-cell run."""
    params = load_parameters(overrides=SMALL + FEM)
    specimen = build_specimen(params, SEED)
    return params, specimen, layout_for(specimen, params)


def test_scene_takes_its_layout_from_layout_for():
    from grainfrac_yade import grains
    from grainfrac_yade.engines.yade import scene
    assert scene.layout_for is grains.layout_for


def test_specimen_command_counts_and_draws_fem_bonds(tmp_path, fem):
    from grainfrac_yade.commands.specimen import run_specimen
    params, specimen, lay = fem
    assert lay.n_bonds == params.resolution.nodes_per_face * build_layout(specimen, 1).n_bonds
    record = run_specimen(params, SEED, tmp_path / "run", draw_bonds=True)
    written = json.loads((tmp_path / "run" / "specimen.json").read_text())
    for r in (record, written):
        assert r["n_bonds"] == lay.n_bonds and r["n_spheres"] == lay.n_spheres
        assert r["n_bonds_inter"] + r["n_bonds_intra"] == lay.n_bonds
        assert r["max_face_area_mismatch_rel"] < 1e-12
    assert (tmp_path / "run" / "specimen.png").stat().st_size > 0


def write_run_folder(folder, params, seed=SEED, command="ucs", summary=None, drop=(), older=()):
    """run.json, params.json (dotted keys in ``drop`` removed, as in files older than the key; ``older``
    (dotted key, value) pairs written as an older run wrote them), summary.json."""
    folder.mkdir(parents=True)
    (folder / "run.json").write_text(json.dumps({"command": command, "seed": seed}))
    tree = json.loads(json.dumps(params.to_dict()))
    for key in drop:
        section, name = key.split(".")
        del tree[section][name]
    for key, value in older:
        section, name = key.split(".")
        tree[section][name] = value
    (folder / "params.json").write_text(json.dumps(tree))
    if summary is not None:
        (folder / "summary.json").write_text(json.dumps(summary))
    return folder


def test_rebuild_checks_the_bonds_of_a_fem_run(tmp_path, fem):
    from grainfrac_yade.analysis.runparams import rebuild_specimen
    params, specimen, lay = fem
    d = write_run_folder(tmp_path / "fem_run", params, command="creep")
    bond = np.arange(0, lay.n_bonds, 7)
    cracks = pd.DataFrame({"bond": bond, "x_m": lay.bond_point[bond, 0], "y_m": lay.bond_point[bond, 1]})
    rebuilt = rebuild_specimen(d, SEED, n_bonds=lay.n_bonds, cracks=cracks)
    assert rebuilt.run_params.params.resolution.grain_model == "fem"
    assert np.array_equal(rebuilt.specimen.mineral, specimen.mineral)
    assert len(rebuilt.checks) == 2 and f"{lay.n_bonds} bonds" in rebuilt.checks[0]
    with pytest.raises(GrainfracError, match="bonds"):   # the rigid count is not this run's
        rebuild_specimen(d, SEED, n_bonds=build_layout(specimen, 1).n_bonds)


UCS_SUMMARY = {"ucs_pa": 300e6, "young_pa": 70e9, "poisson": 0.2, "crack_initiation_pa": 150e6,
               "crack_damage_pa": 280e6, "wall_s": 1.0, "dem_steps": 1000}


def test_analyze_ucs_keeps_rigid_fem_and_retired_lattice_runs_apart(tmp_path):
    """An older run of the retired spring lattice (grain_model "deformable" in its params.json) still
    shows in the study's table, as its own group."""
    from grainfrac_yade.analysis import collect_runs
    from grainfrac_yade.cli import main
    rigid = load_parameters(overrides=SMALL)
    fem = load_parameters(overrides=SMALL + FEM)
    study = tmp_path / "study"
    write_run_folder(study / "rigid", rigid, summary=dict(UCS_SUMMARY, ucs_pa=300e6))
    write_run_folder(study / "fem", fem, summary=dict(UCS_SUMMARY, ucs_pa=500e6))
    write_run_folder(study / "lattice", fem, summary=dict(UCS_SUMMARY, ucs_pa=700e6),
                     older=[("resolution.grain_model", "deformable")])
    runs = collect_runs(study)
    assert set(runs["resolution.grain_model"]) == {"rigid", "fem", "deformable"}
    assert list(runs["resolution.nodes_per_face"]) == [2, 2, 2]
    # a rigid run whose params.json predates the grain model keys joins the rigid group
    write_run_folder(study / "older_rigid", rigid, summary=dict(UCS_SUMMARY, ucs_pa=310e6),
                     drop=("resolution.grain_model", "resolution.nodes_per_face"))
    assert main(["analyze-ucs", str(study)]) == 0
    stats = pd.read_csv(study / "report" / "ucs_stats.csv").set_index("resolution.grain_model")
    assert len(stats) == 3
    assert stats.loc["rigid", "ucs_pa_count"] == 2 and stats.loc["rigid", "ucs_pa_mean"] == pytest.approx(305e6)
    assert stats.loc["fem", "ucs_pa_count"] == 1 and stats.loc["fem", "ucs_pa_mean"] == 500e6
    assert stats.loc["deformable", "ucs_pa_count"] == 1 and stats.loc["deformable", "ucs_pa_mean"] == 700e6
    table = (study / "report" / "ucs_stats.md").read_text()
    assert "| rigid | 1 |" in table and "| fem, 2/face | 1 |" in table and "| lattice (retired), 2/face | 1 |" in table


def test_a_retired_lattice_run_cannot_be_rebuilt_and_says_why(tmp_path):
    from grainfrac_yade.analysis.runparams import rebuild_specimen
    d = write_run_folder(tmp_path / "lattice", load_parameters(overrides=SMALL), command="creep",
                         older=[("resolution.grain_model", "deformable")])
    with pytest.raises(GrainfracError) as err:
        rebuild_specimen(d, SEED)
    msg = str(err.value)
    assert "\n" not in msg and "params.json" in msg and "resolution.grain_model" in msg
    assert "retired" in msg and '"fem"' in msg


def test_analyze_ucs_keeps_runs_older_than_the_grain_model(tmp_path):
    """A study whose params.json files all lack the keys: one group, not an empty table."""
    from grainfrac_yade.cli import main
    rigid = load_parameters(overrides=SMALL)
    old = ("resolution.grain_model", "resolution.nodes_per_face")
    for seed in (1, 2):
        write_run_folder(tmp_path / f"seed{seed}", rigid, seed=seed, summary=UCS_SUMMARY, drop=old)
    assert main(["analyze-ucs", str(tmp_path)]) == 0
    stats = pd.read_csv(tmp_path / "report" / "ucs_stats.csv")
    assert len(stats) == 1 and stats["ucs_pa_count"].iloc[0] == 2
    assert "| rigid | 1 |" in (tmp_path / "report" / "ucs_stats.md").read_text()


def fake_scene(specimen, layout):
    n = layout.n_bonds
    return SimpleNamespace(specimen=specimen, layout=layout, n_bonds=n, broken=np.zeros(n, bool),
                           break_step=np.full(n, -1), break_mode=np.zeros(n, int), bond_is_inter=np.zeros(n, bool),
                           steps=1000, sliding_erasures=lambda: 0, summary_keys=lambda: {})


def test_ucs_and_creep_summaries_name_the_grain_model(tmp_path, monkeypatch, fem):
    from grainfrac_yade.protocols.creep_output import run_creep_to_folder
    from grainfrac_yade.protocols.ucs_output import run_ucs_to_folder
    from grainfrac_yade.protocols import ucs as ucs_test
    from grainfrac_yade.protocols import creep as creep_test
    params, specimen, lay = fem
    scene = fake_scene(specimen, lay)
    strain = np.linspace(0.0, 5e-3, 26)
    stress = np.where(strain <= 4e-3, 70e9 * strain, 0.5 * 280e6)
    zeros = np.zeros(len(strain), int)
    history = {"step": np.arange(len(strain)), "time_s": strain, "axial_strain": strain,
               "lateral_strain": -0.2 * strain, "axial_stress_pa": stress, "broken_total": np.arange(len(strain)),
               "broken_tensile": zeros, "broken_shear": zeros, "broken_inter": zeros, "broken_intra": zeros}
    result = {"steps": 1000, "wall_s": 0.1, "dem_timestep_s": 1e-9, "n_bonds": lay.n_bonds,
              "numerical_failure": False, "peak_reached": True, "end_reason": "post-peak"}
    monkeypatch.setattr(ucs_test, "run_ucs", lambda specimen, params, progress=None, **outputs:
                        (history, result, scene, (scene.broken, scene.break_mode)))
    rows = [{"creep_time_s": t, "axial_strain": 2e-3 + 1e-9 * t, "lateral_strain": -4e-4, "axial_stress_pa": 200e6,
             "broken_total": 3, "macrocracks": 0, "step": 1000, "wall_s": 0.1} for t in (0.0, 10.0, 20.0)]
    run = SimpleNamespace(rows=rows, ramp_broken=3, failed=False, failure_reason="", failed_on_loading=False,
                          failed_before_test=False,
                          numerical_failure=False, n_events=2, scene=scene, vtk_written=[], initial_bond_stresses=None,
                          break_time=np.full(lay.n_bonds, np.nan), macro_time=np.full(lay.n_bonds, np.nan), vtk_folder=None, vtk_times=[], vtk_merged=[])
    monkeypatch.setattr(creep_test, "run_creep", lambda specimen, params, stress, progress=None, **outputs: run)
    run_ucs_to_folder(params, SEED, tmp_path / "ucs")
    run_creep_to_folder(params, SEED, tmp_path / "creep", 200e6, 0.7, 285e6)
    for name in ("ucs", "creep"):
        s = json.loads((tmp_path / name / "summary.json").read_text())
        assert (s["spheres_per_cell"], s["grain_model"], s["nodes_per_face"]) == (1, "fem", 2), name
        assert s["seed"] == SEED and s["params"]["resolution"]["grain_model"] == "fem"


@needs_yade
@pytest.mark.yade
def test_batch_row_sets_the_grain_model(tmp_path, monkeypatch):
    """YADE's table reader (no simulation): a quoted text cell and an integer cell become overrides."""
    from grainfrac_yade.runs.batchrun import write_table
    from grainfrac_yade.engines.yade.batch import read_table, run_folder_name
    table = write_table(tmp_path / "grains.table", [
        {"resolution.grain_model": "rigid", "resolution.nodes_per_face": 2, "seed": 1},
        {"resolution.grain_model": "fem", "resolution.nodes_per_face": 3, "seed": 2}])
    assert table.read_text().splitlines()[2] == "'fem' 3 2"
    monkeypatch.setenv("YADE_BATCH", f"{table}:2")
    overrides, controls = read_table()
    assert overrides == [] and controls["seed"] == 1     # the defaults: no override
    monkeypatch.setenv("YADE_BATCH", f"{table}:3")
    overrides, controls = read_table()
    assert overrides == [("resolution.grain_model", "fem"), ("resolution.nodes_per_face", 3)]
    assert controls["seed"] == 2
    res = load_parameters(overrides=overrides).resolution
    assert (res.grain_model, res.nodes_per_face) == ("fem", 3)
    assert run_folder_name(controls, overrides) == "grain_model=fem_nodes_per_face=3_seed2"
    bare = tmp_path / "bare.table"
    bare.write_text("resolution.grain_model seed\nfem 1\n")   # text without quotes
    monkeypatch.setenv("YADE_BATCH", f"{bare}:2")
    with pytest.raises(GrainfracError, match="quoted") as err:
        read_table()
    assert "\n" not in str(err.value)
