"""The hybrid engine: the static scene with YADE's dynamic stints where statics give out (tiny specimens)."""
import json

import numpy as np
import pytest

from conftest import needs_yade
from static_tiny import assert_resumed_as_whole, run_killed_and_resumed

from grainfrac_yade.engines import Scene
from grainfrac_yade.engines.registry import ENGINE_NAMES, engine, engine_for
from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.params import load_parameters
from grainfrac_yade.params.schema import NumericsParams
from grainfrac_yade.wave import steps_for

TINY = ["specimen.width=3e-3", "specimen.height=6e-3"]
FEM = "params/presets/fem_coarse.toml"


def _params(engine_name, *extra, fem=False):
    return load_parameters(extra_files=[FEM] if fem else (), overrides=[*TINY, f"numerics.engine={engine_name}", *extra])


def test_hybrid_engine_module():
    """Registered (and a choice of numerics.engine), no dynamics between stints, its refusals in one line."""
    import dataclasses
    choices = next(f for f in dataclasses.fields(NumericsParams) if f.name == "engine").metadata["choices"]
    assert "hybrid" in ENGINE_NAMES and tuple(choices) == ENGINE_NAMES
    module = engine("hybrid")
    assert module.name == "hybrid" and module.dynamic is False
    assert module.refusal("brazilian") and module.warn_dynamic_only(["numerics.damping=0.7"], None) == []


def test_without_a_stint_the_hybrid_path_is_the_static_one():
    """Where statics never give out, the hybrid scene is the static scene, bit for bit."""
    paths = {}
    for name in ("static", "hybrid"):
        p = _params(name)
        scene = engine_for(p).build_scene(build_specimen(p, 1), p)
        assert isinstance(scene, Scene)
        pl = scene.attach_platens("free")
        pl.set_axial_velocity(p.ucs.strain_rate * pl.height)
        stress = []
        for _ in range(60):
            scene.run(2)
            stress.append(pl.axial_stress())
        paths[name] = (np.array(stress), scene.broken.copy(), scene.state.u.copy())
        if name == "hybrid":
            assert scene.strategy.stints == [] and scene.summary_keys()["dynamic_stints"] == 0
    (sa, ba, ua), (sb, bb, ub) = paths["static"], paths["hybrid"]
    assert np.array_equal(sa, sb) and np.array_equal(ba, bb) and np.array_equal(ua, ub)


def _static_state_in_yade(fem: bool, increments: int):
    p = _params("static", fem=fem)
    specimen = build_specimen(p, 1)
    static = engine("static").build_scene(specimen, p)
    pl = static.attach_platens("free")
    pl.set_axial_velocity(p.ucs.strain_rate * pl.height)
    static.run(increments)
    dyn = engine("yade").scene_from_state(specimen, p, static.export_state(pl))
    ypl = dyn.attach_platens("free")
    ypl.set_axial_velocity(0.0)
    return static, pl, dyn, ypl


@needs_yade
@pytest.mark.parametrize("fem, rel_stress, rel_unbalanced", [(False, 1e-3, 1e-2), (True, 1e-8, 1e-6)])
def test_a_static_state_stays_in_equilibrium_in_yade(fem, rel_stress, rel_unbalanced):
    """The hand-over itself: YADE started from a loaded static state (0.2 % strain, about 170 MPa) with the platens
    fixed keeps its stress and its broken set for 2,000 DEM steps.  Fem cells: the same nodes, elements and
    springs, so the static equilibrium is YADE's to round-off (measured 2e-10 of the mean bond force unbalanced;
    stated 1e-6, stress 1e-8).  Rigid cells: YADE's torque arms and rotations differ from the static rows at
    second order (measured 0.02 % of the stress; stated 0.1 %, unbalanced below 1 % once relaxed)."""
    static, pl, dyn, ypl = _static_state_in_yade(fem, 100)
    dyn.run(2000)
    assert ypl.axial_stress() == pytest.approx(pl.axial_stress(), rel=rel_stress)
    assert np.array_equal(dyn.broken, static.broken)
    assert dyn.unbalanced(float(np.abs(static.bond_forces()[0]).mean()))[1] < rel_unbalanced


@needs_yade
def test_a_fem_yade_state_round_trips_in_equilibrium():
    """YADE -> SceneState -> a new YADE scene, fem cells (clumped apex nodes): the new scene is in the old one's
    equilibrium (the clumps' principal frames kept under the state's rotations)."""
    p = _params("yade", fem=True)
    specimen = build_specimen(p, 1)
    yade = engine("yade")
    a = yade.build_scene(specimen, p)
    pa = a.attach_platens("free")
    pa.set_axial_velocity(0.5 * pa.height)
    a.run(3000)
    pa.set_axial_velocity(0.0)
    a.run(3000)
    ref = float(np.abs(a.bond_forces()[0]).mean())
    b = yade.scene_from_state(specimen, p, a.export_state(pa))
    pb = b.attach_platens("free")
    pb.set_axial_velocity(0.0)
    b.run(10)
    assert pb.axial_stress() == pytest.approx(pa.axial_stress(), rel=1e-6)
    assert b.broken.sum() == a.broken.sum() and b.unbalanced(ref)[1] < 1e-3


@needs_yade
def test_a_creep_hold_hands_a_cascade_to_yade_and_takes_its_breaks_back(tmp_path):
    """Creep on 4 x 8 mm (seed 3, 160 MPa) with a cascade limit of 2 bonds: a stint under the held stress reaches
    equilibrium, the bonds YADE broke are broken in the static scene after it, the hold goes on to a physical
    failure (the static rule), and summary.json records the engine and the stint."""
    from grainfrac_yade.protocols.creep_output import run_creep_to_folder
    p = load_parameters(overrides=["specimen.width=4e-3", "specimen.height=8e-3", "numerics.engine=hybrid",
                                   "numerics.handover_cascade_bonds=2"])
    summary = run_creep_to_folder(p, 3, tmp_path / "run", 160e6, 160e6 / p.calibration.reference_ucs,
                                  p.calibration.reference_ucs)
    assert summary["engine"] == "hybrid" and summary["dynamic_stints"] >= 1
    stint = summary["dynamic_stint_log"][0]
    assert stint["held"] is True and stint["outcome"] == "equilibrium" and stint["dem_steps"] > 0
    assert stint["broken_after"] > stint["broken_before"] and stint["taken_back"] in ("state", "breaks")
    # the bonds YADE broke, per elastic wave crossing of the stint: one entry per crossing begun, summing to the total
    assert len(stint["broken_per_crossing"]) >= 1 and all(n >= 0 for n in stint["broken_per_crossing"])
    assert sum(stint["broken_per_crossing"]) == stint["broken_after"] - stint["broken_before"]
    assert stint["stress_after_pa"] == pytest.approx(160e6, rel=p.creep.stress_tolerance)
    # the budget the stint ran under, in YADE's DEM steps (a crossing at YADE's step, not the static scene's)
    assert stint["wave_crossing_steps"] > 0 and stint["servo_response_steps"] == steps_for(
        p.creep.servo_response_steps, p.creep.servo_response_crossings, stint["wave_crossing_steps"])
    assert stint["max_relaxation_steps"] == steps_for(p.creep.max_relaxation_steps, p.creep.max_relaxation_crossings,
                                                      stint["wave_crossing_steps"])
    assert summary["lifetime_s"] > 0 and summary["numerical_failure"] is False
    assert summary["broken_total"] >= stint["broken_after"]
    saved = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert saved["dynamic_stint_dem_steps"] == sum(s["dem_steps"] for s in saved["dynamic_stint_log"])


@needs_yade
def test_a_ucs_ends_where_a_stint_with_fixed_platens_loses_the_load(tmp_path):
    """UCS on 4 x 8 mm (seed 3) with a cascade limit of 3 bonds: a first stint ends in equilibrium near the stress
    it started from and the static path goes on with YADE's breaks; a later one loses the load at fixed platens
    (below ucs.stop_stress_ratio of its start): the specimen's failure, the test's post-peak end, a UCS."""
    from grainfrac_yade.protocols.ucs_output import run_ucs_to_folder
    p = load_parameters(overrides=["specimen.width=4e-3", "specimen.height=8e-3", "numerics.engine=hybrid",
                                   "numerics.handover_cascade_bonds=3"])
    summary = run_ucs_to_folder(p, 3, tmp_path / "run")
    log = summary["dynamic_stint_log"]
    assert len(log) >= 2 and all(s["held"] is False for s in log)
    first, last = log[0], log[-1]
    assert first["outcome"] == "equilibrium" and first["taken_back"] in ("state", "breaks")
    assert first["stress_after_pa"] >= p.ucs.stop_stress_ratio * first["stress_pa"]
    assert last["stress_after_pa"] < p.ucs.stop_stress_ratio * last["stress_pa"]
    assert summary["engine_failure_reason"].startswith("dynamic stint")
    assert summary["numerical_failure"] is False and summary["end_reason"].startswith("post-peak")
    assert summary["ucs_pa"] >= last["stress_pa"] > 0


@needs_yade
def test_a_stint_runs_its_minimum_wave_crossings_before_equilibrium_may_end_it(tmp_path):
    """numerics.stint_min_crossings: a stint that ends in equilibrium has run at least that many elastic wave
    crossings (its log names the DEM steps), where the default ends it at the first check that passes (4,550 DEM
    steps here, 33 crossings of 137 steps: 50 crossings lie beyond it)."""
    from grainfrac_yade.protocols.creep_output import run_creep_to_folder
    logs = {}
    for crossings in (0, 50):
        p = load_parameters(overrides=["specimen.width=4e-3", "specimen.height=8e-3", "numerics.engine=hybrid",
                                       "numerics.handover_cascade_bonds=2", f"numerics.stint_min_crossings={crossings}"])
        ucs = p.calibration.reference_ucs
        logs[crossings] = run_creep_to_folder(p, 3, tmp_path / str(crossings), 160e6, 160e6 / ucs, ucs)["dynamic_stint_log"]
    first0, first1 = logs[0][0], logs[50][0]
    assert first0["min_dem_steps"] == 0 and first1["min_dem_steps"] > 0
    assert first1["outcome"] == "equilibrium" and first1["dem_steps"] >= first1["min_dem_steps"]
    assert first0["dem_steps"] < first1["min_dem_steps"]


@needs_yade
def test_a_hybrid_creep_killed_after_a_stint_resumes_to_the_uninterrupted_run(tmp_path, monkeypatch):
    """Checkpoints at every safe point; the run killed at the first checkpoint after its first stint and resumed:
    history (but wall times), events, failure, break times and the stint log as the uninterrupted run's (rigid
    cells: YADE's stints repeat bit for bit)."""
    p = load_parameters(overrides=["specimen.width=4e-3", "specimen.height=8e-3", "numerics.engine=hybrid",
                                   "numerics.handover_cascade_bonds=2", "numerics.checkpoint_interval=1e-9"])
    whole, resumed = run_killed_and_resumed(tmp_path, monkeypatch, p, 3, 160e6,
                                            lambda run, written: bool(run.scene.strategy.stints))
    assert len(whole.scene.strategy.stints) >= 1
    assert_resumed_as_whole(resumed, whole)
    strip = [{k: v for k, v in s.items() if k != "cpu_s"} for s in whole.scene.strategy.stints]
    assert [{k: v for k, v in s.items() if k != "cpu_s"} for s in resumed.scene.strategy.stints] == strip


def test_the_hybrid_relaxes_by_its_stints_not_by_the_static_relaxation():
    """The static engine's default relaxation is the inertial one; the hybrid's static path stays the plain one
    (YADE's stints relax where it gives out), and a static relaxation given to it is warned about and recorded as
    not used."""
    from grainfrac_yade.engines.registry import engine
    from grainfrac_yade.geometry.specimen import build_specimen
    from grainfrac_yade.params import load_parameters
    from grainfrac_yade.engines.static.cascade import Path
    from grainfrac_yade.engines.static.inertial import InertialPath
    p = load_parameters(overrides=["specimen.width=3e-3", "specimen.height=6e-3"])
    assert p.numerics.static_relaxation == "inertial"
    specimen = build_specimen(p, 1)
    assert isinstance(engine("static").build_scene(specimen, p).path, InertialPath)
    hybrid = engine("hybrid").build_scene(specimen, p)
    assert type(hybrid.path) is Path
    assert hybrid.summary_keys()["settings_not_used"] == {"numerics.static_relaxation": "inertial",
                                                          "numerics.static_relaxation_steps": 1000}
    lines = engine("hybrid").warn_dynamic_only(["numerics.static_relaxation=overdamped", "numerics.damping=0.5"], p)
    assert lines == ["warning: --set numerics.static_relaxation: the hybrid engine relaxes by YADE's dynamics and "
                     "does not use it"]
