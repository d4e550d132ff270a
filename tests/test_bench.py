"""The benchmark: the quick one (a YADE run) writes the JSON with every key, every number finite and
positive; the stored full one (docs/bench.json) has the runs to failure too and renders as tables.

No timing thresholds: the machine is shared, and the bench's ratios are only meaningful within a run.
"""
import json
import math
import subprocess
import sys

import pytest

from conftest import ROOT, needs_yade
from grainfrac_yade.commands.bench import markdown_tables

SCENE_KEYS = {"label", "grain_model", "spheres_per_cell", "stress_pa", "n_cells", "n_bodies", "n_bonds",
              "n_interactions", "dem_timestep_s", "ramp_steps", "ramp_wall_s", "steps_to_first_equilibrium",
              "equilibrium_at_hold", "held_after_events", "timing_window_steps", "timing_repeats", "steps_per_s",
              "steps_per_s_yade_only", "steps_per_s_python_stepping", "steps_per_s_drivers",
              "steps_per_s_relaxation_loop", "engine_overhead", "engine_overhead_range", "engine_overhead_cpu",
              "engine_overhead_quartiles", "python_stepping_overhead", "python_stepping_overhead_range",
              "python_stepping_overhead_cpu", "python_stepping_overhead_quartiles", "relaxation_loop_overhead",
              "relaxation_loop_overhead_range", "relaxation_loop_overhead_cpu", "relaxation_loop_overhead_quartiles",
              "drivers", "drivers_s_per_step", "engine_overhead_from_driver_cost",
              "n_intact_bonds", "read_all_bonds_s", "write_all_strengths_s", "time_to_failure_all_bonds_s",
              "read_per_bond_s", "write_per_bond_s", "events", "peak_rss_mb_after"}
EVENT_KEYS = {"n_events_timed", "relaxation_steps_median", "relaxation_steps_mean", "relaxation_steps_max",
              "relaxation_wall_s_median", "clock_work_s_median"}
MACHINE_KEYS = {"cpu_model", "cores", "cores_usable", "omp_num_threads", "python", "yade", "numpy", "platform",
                "load_average_1min"}


def numbers(tree, path="") -> list:
    """(path, value) of every leaf that is not text or a yes/no flag (None included: a NaN written as null)."""
    if isinstance(tree, dict):
        return [pair for key, value in tree.items() for pair in numbers(value, f"{path}.{key}")]
    if isinstance(tree, list):
        return [pair for n, value in enumerate(tree) for pair in numbers(value, f"{path}[{n}]")]
    return [] if isinstance(tree, (str, bool)) else [(path, tree)]


@pytest.fixture(scope="module")
def quick_bench(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench") / "bench.json"
    res = subprocess.run([sys.executable, "-m", "grainfrac_yade", "bench", "--quick", "--out", str(out)],
                         capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 0, res.stderr
    return json.loads(out.read_text()), res.stdout


@needs_yade
@pytest.mark.yade
def test_quick_bench_writes_every_key(quick_bench):
    data, _ = quick_bench
    assert set(data) == {"bench", "machine", "scenes", "peak_rss_mb"}   # no runs to failure in --quick
    assert data["bench"]["quick"] is True
    assert MACHINE_KEYS <= set(data["machine"])
    assert set(data["scenes"]) == {"rigid_1", "rigid_8", "fem"}
    for key, scene in data["scenes"].items():
        assert SCENE_KEYS <= set(scene), key
        assert EVENT_KEYS <= set(scene["events"]), key
        assert scene["equilibrium_at_hold"] is True and scene["held_after_events"] is True, key
    assert [s["spheres_per_cell"] for s in data["scenes"].values()][:2] == [1, 8]
    assert data["scenes"]["fem"]["grain_model"] == "fem"


@needs_yade
@pytest.mark.yade
def test_quick_bench_numbers_are_finite_and_positive(quick_bench):
    data, _ = quick_bench
    found = numbers(data)
    assert len(found) > 100
    bad = [(path, value) for path, value in found
           if not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0]
    assert not bad


@needs_yade
@pytest.mark.yade
def test_quick_bench_prints_its_table(quick_bench):
    data, stdout = quick_bench
    for scene in data["scenes"].values():
        assert f"| {scene['label']} |" in stdout
    assert "engine overhead" in stdout


def test_stored_full_bench_has_the_clocks_to_failure_and_renders():
    """docs/bench.json (the full bench, README's table): same keys as the quick one plus the runs to
    failure; its numbers finite and positive; the tables render."""
    data = json.loads((ROOT / "docs" / "bench.json").read_text())
    assert data["bench"]["quick"] is False
    for scene in data["scenes"].values():
        assert SCENE_KEYS <= set(scene) and EVENT_KEYS <= set(scene["events"])
    runs = data["clocks_to_failure"]
    for clock in ("event", "paper"):
        assert {"failed", "n_events", "dem_steps", "wall_s", "cpu_s", "creep_steps_per_s"} <= set(runs[clock])
    assert not [(path, value) for path, value in numbers(data)
                if not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0]
    text = markdown_tables(data)
    assert "Creep to failure" in text and "| paper |" in text and "| event |" in text


@needs_yade
@pytest.mark.yade
def test_fem_size_bench_on_tiny_specimens(monkeypatch, tmp_path):
    """``bench --fem-sizes`` on two tiny specimens and one seed: the scene's critical step equals the core's
    bound (the same formula, no YADE) to the last bits, the scene steps at or below it, every number is finite
    and positive, the JSON written as it goes equals the result, and the table renders."""
    from grainfrac_yade.commands import bench
    monkeypatch.setattr(bench, "FEM_SIZES", (("10x20", 3e-3, 6e-3), ("paper", 4e-3, 8e-3)))
    monkeypatch.setattr(bench, "FEM_SEEDS", (2,))
    monkeypatch.setattr(bench, "FEM_WARMUP_STEPS", 20)
    monkeypatch.setattr(bench, "FEM_TIMED_STEPS", 50)
    out = tmp_path / "fem_sizes.json"
    result = bench.run_fem_sizes(out=out)
    assert [(r["specimen"], r["seed"]) for r in result["scenes"]] == [("10x20", 2), ("paper", 2)]
    for r in result["scenes"]:
        assert r["critical_step_s"] == pytest.approx(r["critical_step_core_s"], rel=1e-12)
        assert 0 < r["dem_step_s"] <= r["critical_step_s"]
        assert r["steps"] == 50
    assert not [(path, value) for path, value in numbers(result)
                if not isinstance(value, (int, float)) or not math.isfinite(value) or value < 0]
    assert json.loads(out.read_text()) == json.loads(json.dumps(result))
    text = bench.fem_sizes_table(result)
    assert "| paper | 2 |" in text and "Cost per body, paper size over 10 x 20 mm" in text


def test_creep_stress_needs_the_fem_size_bench():
    """``--creep-stress`` alone gets one line naming the fix, not a traceback."""
    res = subprocess.run([sys.executable, "-m", "grainfrac_yade", "bench", "--creep-stress", "160"],
                         capture_output=True, text=True, cwd=ROOT)
    assert res.returncode != 0
    assert "--fem-sizes" in res.stderr and "Traceback" not in res.stderr
