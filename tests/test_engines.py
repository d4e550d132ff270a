"""The engine registry and the scene interface: a YADE state through the engine-neutral form and back."""
import numpy as np
import pytest

from conftest import needs_yade
from grainfrac_yade.engines import Scene, SceneState
from grainfrac_yade.engines.registry import ENGINE_NAMES, engine, engine_for
from grainfrac_yade.errors import ParameterError
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen

TINY = ["specimen.width=3e-3", "specimen.height=6e-3"]


def test_registry_names_the_schema_choices():
    """Every engine of the registry is a choice of numerics.engine and the other way round."""
    from grainfrac_yade.params.schema import NumericsParams
    import dataclasses
    spec = next(f for f in dataclasses.fields(NumericsParams) if f.name == "engine").metadata
    assert tuple(spec["choices"]) == ENGINE_NAMES
    assert load_parameters().numerics.engine == "yade"


def test_misspelt_engine_is_one_line():
    with pytest.raises(ParameterError) as err:
        load_parameters(overrides=["numerics.engine=yadee"])
    assert "numerics.engine" in str(err.value) and "'yade'" in str(err.value) and "\n" not in str(err.value)
    with pytest.raises(ParameterError) as err:
        engine("yadee")
    assert "numerics.engine" in str(err.value) and "\n" not in str(err.value)


def test_engine_module_loads_without_yade():
    """The registry's module is found without building a scene (YADE is imported only then)."""
    e = engine_for(load_parameters())
    assert e.name == "yade" and callable(e.build_scene) and callable(e.scene_from_state)


def test_the_dynamic_engines_are_the_registry_s_dynamic_ones():
    """The table an engine looks a dynamic engine up in names the registry's modules, and exactly those that
    integrate motion in time; a quasi-static name there is one line naming the choices."""
    from grainfrac_yade.engines.dynamic import DYNAMIC_ENGINE_MODULES, dynamic_engine
    from grainfrac_yade.engines.registry import ENGINE_MODULES
    assert DYNAMIC_ENGINE_MODULES.items() <= ENGINE_MODULES.items()
    assert {n for n in ENGINE_NAMES if engine(n).dynamic} == set(DYNAMIC_ENGINE_MODULES)
    assert dynamic_engine("yade") is engine("yade")
    with pytest.raises(ParameterError) as err:
        dynamic_engine("static")
    assert "numerics.engine" in str(err.value) and "'yade'" in str(err.value) and "\n" not in str(err.value)


def test_the_engines_load_apart():
    """The static and hybrid engines load without YADE's engine module (the hybrid fetches it by name at its
    first dynamic stint); YADE's engine module loads without YADE itself."""
    import subprocess
    import sys
    from pathlib import Path
    code = ("import sys; import grainfrac_yade.engines.hybrid.engine, grainfrac_yade.engines.static.engine; "
            "print('grainfrac_yade.engines.yade.engine' in sys.modules, 'yade' in sys.modules); "
            "import grainfrac_yade.engines.yade.engine; print('yade' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=Path(__file__).resolve().parent.parent).stdout
    assert out.split() == ["False", "False", "False"]


@needs_yade
@pytest.mark.yade
@pytest.mark.parametrize("model", ["rigid", "fem"])
def test_yade_state_round_trip(model):
    """Load a tiny specimen until bonds carry force (some broken by hand), export its state, build a new
    YADE scene from it, and export again: every field equal bit for bit, but the rotations, which pass
    through a quaternion (angle -> quaternion -> angle: 1e-15 rad of rounding).  One step of the rebuilt
    scene keeps the bonds' reference gaps (a fresh bond would have them reset by YADE's law).  Both grain
    models: one body per cell, and a body per sphere with bonds on their faces' planes."""
    p = load_parameters(overrides=[*TINY, f"resolution.grain_model={model}"])
    specimen = build_specimen(p, 1)
    yade = engine_for(p)
    scene = yade.build_scene(specimen, p)
    assert isinstance(scene, Scene)
    platens = scene.attach_platens("free")
    platens.set_axial_velocity(0.05 * platens.height)
    scene.run(300)
    scene.break_bonds([0, 3], 2)
    first = scene.export_state(platens)
    assert first.steps == 300 and np.any(first.bond_normal_force != 0) and first.bond_broken.sum() >= 2
    assert np.max(np.abs(first.node_displacement)) > 0
    rebuilt = yade.scene_from_state(specimen, p, first)
    second = rebuilt.export_state()
    second.platens = first.platens
    differ = first.differences(second)
    assert differ in ([], ["node_rotation"])
    np.testing.assert_allclose(second.node_rotation, first.node_rotation, rtol=0, atol=1e-15)
    assert rebuilt.steps == 300 and rebuilt.time == first.time
    # the neutral form passes through arrays (a checkpoint's npz) unchanged
    again = SceneState.from_arrays(first.arrays(), first.platens)
    assert first.differences(again) == []
    rebuilt.run(1)
    np.testing.assert_array_equal(rebuilt.export_state().bond_reference_gap, first.bond_reference_gap)
    assert rebuilt.steps == 301


def test_engine_is_recorded_read_from_batch_tables_and_migrated():
    """params.json records numerics.engine; a batch table may name it as a column; a params.json of a run made
    before the choice existed reads as YADE's (every such run was)."""
    from grainfrac_yade.params import migrate_tree, shipped_values
    from grainfrac_yade.runs.batchrun import RUN_COLUMNS, check_columns
    assert load_parameters().to_dict()["numerics"]["engine"] == "yade"
    check_columns(["numerics.engine", "seed"], {**shipped_values(), **RUN_COLUMNS}, "t.table:2")   # quiet
    assert load_parameters(overrides=[("numerics.engine", "yade")]).numerics.engine == "yade"
    old = {"numerics": {"damping": 0.2}}
    migrate_tree(old)
    assert old["numerics"]["engine"] == "yade"


def test_old_step_names_are_read_as_today():
    """Histories and summaries of runs written before the step columns were renamed read as today's."""
    import pandas as pd
    from grainfrac_yade.runs.columns import history_as_today, summary_as_today
    frame = history_as_today(pd.DataFrame({"dem_step": [1, 2], "dem_time_s": [0.1, 0.2], "axial_strain": [0, 1]}))
    assert list(frame.columns) == ["step", "time_s", "axial_strain"]
    assert history_as_today({"creep_time_s": 0.0, "dem_steps": 7}) == {"creep_time_s": 0.0, "step": 7}
    assert summary_as_today({"dem_steps": 5, "wall_s": 1.0}) == {"steps": 5, "wall_s": 1.0}


def test_the_paper_clock_needs_a_dynamic_engine(monkeypatch, tmp_path):
    """An engine without dynamics (a static solver) is refused for the paper clock in one line, before any
    folder is made; YADE's is dynamic."""
    import sys
    from types import SimpleNamespace
    from grainfrac_yade.protocols.creep_output import run_creep_to_folder
    from grainfrac_yade.engines import registry
    import dataclasses
    assert registry.require_dynamic(load_parameters(), "the paper clock").name == "yade"
    stand_in = dataclasses.replace(registry.engine("yade"), name="static", dynamic=False)
    monkeypatch.setitem(sys.modules, "static_stand_in", SimpleNamespace(ENGINE=stand_in))
    monkeypatch.setitem(registry.ENGINE_MODULES, "static", "static_stand_in")
    p = load_parameters(overrides=["stress_corrosion.clock=paper"])
    p = dataclasses.replace(p, numerics=dataclasses.replace(p.numerics, engine="static"))
    with pytest.raises(ParameterError) as err:
        run_creep_to_folder(p, 1, tmp_path / "run", 200e6, 0.7, 285e6)
    assert "numerics.engine" in str(err.value) and "paper clock" in str(err.value) and "\n" not in str(err.value)
    assert not (tmp_path / "run").exists()


def test_every_engine_declares_a_typed_engine_module(monkeypatch):
    """Each registered engine's module declares an EngineModule under its own name, with the hooks the protocols
    call and one checkpoint scene file per scene format (YADE's gzip'd archive; the static and hybrid scenes'
    npz); a module without one is refused by name."""
    import sys
    from types import SimpleNamespace
    from grainfrac_yade.engines import EngineModule
    from grainfrac_yade.engines import registry
    for name in ENGINE_NAMES:
        e = engine(name)
        assert isinstance(e, EngineModule) and e.name == name
        assert all(callable(getattr(e, hook)) for hook in ("build_scene", "scene_from_state", "consolidate",
                                                           "apply_levers", "stress_corrosion", "version"))
        assert e.scene_file and "/" not in e.scene_file
    assert {n: engine(n).scene_file for n in ENGINE_NAMES} == {"yade": "scene.yade.gz", "static": "scene.npz",
                                                                "hybrid": "scene.npz"}
    assert engine("yade").refusal("creep") == "" and engine("hybrid").refusal("brazilian").startswith("the hybrid")
    monkeypatch.setitem(sys.modules, "engine_without_declaration", SimpleNamespace(build_scene=None))
    monkeypatch.setitem(registry.ENGINE_MODULES, "bare", "engine_without_declaration")
    with pytest.raises(TypeError, match="engine_without_declaration.ENGINE is NoneType, not an EngineModule"):
        engine("bare")
