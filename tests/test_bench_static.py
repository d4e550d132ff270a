"""``bench --static``: the quick static bench on tiny specimens writes every key, every ratio finite and positive; the
size series alone without YADE; the timed hold is the protocol's hold; bad flags are one line.

No timing thresholds: the machine is shared, and the bench's ratios are only meaningful within a run.
"""
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from conftest import ROOT, needs_yade
from grainfrac_yade.commands.bench_static import StaticBenchSettings, run_static_bench, static_tables

FEM = ROOT / "params" / "presets" / "fem_coarse.toml"
#: Two tiny specimens (3 x 6 and 4 x 8 mm: 286 and 522 dofs with fem cells), 3 events each: about a second.
TINY = StaticBenchSettings(compare=None, compare_events=0, sizes=(("3x6", 3e-3, 6e-3), ("4x8", 4e-3, 8e-3)), events=3)
SIZE_KEYS = {"specimen", "width_m", "height_m", "dofs", "bonds", "build_cpu_s", "stress_pa", "ramp", "events",
             "events_asked", "failed", "numerical_failure", "end", "broken", "creep_time_s", "cpu_s", "events_cpu_s",
             "cpu_per_event_s", "equilibria_per_event", "iterations_per_event", "iterations_per_equilibrium",
             "bonds_per_event", "quiet_events", "cpu_per_quiet_event_s", "event_cpu_s", "event_equilibria",
             "event_iterations", "event_broken", "counters", "sequence_hash", "peak_rss_mb_after"}
ENGINE_KEYS = {"engine", "n_bodies", "n_bonds", "ramp_and_first_relaxation_cpu_s", "events", "event_cpu_s",
               "event_steps", "cpu_per_event_s", "steps_per_event", "failed", "numerical_failure", "end"}


def _positive(x):
    return isinstance(x, (int, float)) and math.isfinite(x) and x > 0


def _check_sizes(result, settings):
    assert [r["specimen"] for r in result["sizes"]] == [s[0] for s in settings.sizes]
    dofs = [r["dofs"] for r in result["sizes"]]
    assert dofs == sorted(dofs) and len(set(dofs)) == len(dofs)
    for r in result["sizes"]:
        assert SIZE_KEYS <= set(r), r["specimen"]
        assert r["events"] == settings.events and not r["numerical_failure"]
        assert len(r["event_cpu_s"]) == len(r["event_equilibria"]) == len(r["event_broken"]) == r["events"]
        for key in ("cpu_per_event_s", "equilibria_per_event", "iterations_per_event", "iterations_per_equilibrium",
                    "build_cpu_s", "peak_rss_mb_after"):
            assert _positive(r[key]), (r["specimen"], key)
        assert _positive(r["ramp"]["cpu_s"]) and r["ramp"]["equilibria"] >= 1
        assert r["cpu_per_quiet_event_s"] is None if r["quiet_events"] == 0 else _positive(r["cpu_per_quiet_event_s"])
        assert min(r["event_equilibria"]) >= 1 and min(r["event_broken"]) >= 1   # every event breaks and re-solves
    assert math.isfinite(result["dofs_scaling"]["cpu_per_event_exponent"])
    assert result["dofs_scaling"]["cpu_per_event_sizes"] == len(settings.sizes)
    assert _positive(result["peak_rss_mb"]) and _positive(result["bench"]["cpu_s"])


def test_size_series_without_yade(tmp_path):
    """The creep test on the static engine's plain path on two tiny sizes: every key, per-event lists as long as the events, positive costs,
    a finite exponent; the JSON is rewritten after each size and at the end holds what the function returns."""
    from grainfrac_yade.commands.bench import peak_rss_mb
    out = tmp_path / "static.json"
    written = []   # sizes in the JSON on disk as each size is reported: partial results survive an interruption
    result = run_static_bench(TINY, preset=FEM, peak_rss=peak_rss_mb, out=out,
                              progress=lambda msg: written.append((msg, len(json.loads(out.read_text())["sizes"]))
                                                                  if out.exists() else (msg, 0)))
    assert [n for msg, n in written if "CPU s per event" in msg] == [1, 2]
    assert any("event 0:" in msg for msg, _ in written) and any("ramp to 160 MPa" in msg for msg, _ in written)
    assert "engines_per_event" not in result
    _check_sizes(result, TINY)
    assert json.loads(out.read_text())["sizes"][0]["dofs"] == result["sizes"][0]["dofs"]
    result["machine"] = {}
    text = static_tables(result)
    assert "| 3x6 | 286 |" in text and "CPU per event ~ dofs^b" in text


def test_timed_hold_is_the_protocols_hold():
    """Timing a hold changes nothing it computes: the same events at the same creep times and the same bonds as the
    creep protocol's run stopped after as many events, untimed."""
    from grainfrac_yade.commands.bench_static import SIZE_SERIES_OVERRIDES, size_params, static_hold
    from grainfrac_yade.geometry.specimen import build_specimen
    from grainfrac_yade.protocols.timed_creep import TimedCreepRun
    p = size_params(FEM, [], 4e-3, 8e-3, SIZE_SERIES_OVERRIDES, "static")
    timed = static_hold(p, 1, 160e6, 4)
    plain = TimedCreepRun(build_specimen(p, 1), p, 160e6, max_events=4).run()
    assert timed["events"] == len(timed["times"]) == 4 and timed["times"] == [r["creep_time_s"] for r in plain.rows[2:]]
    assert timed["broken"] == int(plain.scene.broken.sum())
    assert timed["ramp"]["broken"] + sum(timed["event_broken"]) == timed["broken"]


@needs_yade
@pytest.mark.yade
def test_quick_static_bench_writes_every_key(tmp_path):
    """bench --static --quick (YADE and static on 4 x 8 mm, three tiny sizes): the JSON's keys, the ratio YADE /
    static of CPU per event finite and positive, the printed tables."""
    out = tmp_path / "bench_static.json"
    res = subprocess.run([sys.executable, "-m", "grainfrac_yade", "bench", "--static", "--quick", "--out", str(out)],
                         capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 0, res.stderr
    data = json.loads(out.read_text())
    assert {"bench", "machine", "engines_per_event", "sizes", "dofs_scaling", "peak_rss_mb"} <= set(data)
    assert data["bench"]["quick"] is True and data["bench"]["stress_pa"] == 160e6
    from grainfrac_yade.commands.bench_static import STATIC_QUICK
    _check_sizes(data, STATIC_QUICK)
    c = data["engines_per_event"]
    for name in ("static", "yade"):
        assert ENGINE_KEYS <= set(c[name]) and c[name]["engine"] == name
        assert c[name]["events"] == STATIC_QUICK.compare_events and _positive(c[name]["cpu_per_event_s"])
        assert _positive(c[name]["steps_per_event"]) and c[name]["n_bonds"] == c["static"]["n_bonds"]
    assert _positive(c["yade_over_static_cpu_per_event"])
    assert c["yade_over_static_cpu_per_event"] == c["yade"]["cpu_per_event_s"] / c["static"]["cpu_per_event_s"]
    assert "YADE / static, CPU per event: x" in res.stdout and "| 6x12 |" in res.stdout
    k = data["collapse"]
    assert [r["label"] for r in k["runs"]] == ["static + inertial", "hybrid"]
    assert all(_positive(r["cpu_s"]) and r["end"] for r in k["runs"])
    assert k["hybrid_over_inertial_cpu"] == k["runs"][1]["cpu_s"] / k["runs"][0]["cpu_s"]
    assert "The collapse, 4x8 mm" in res.stdout


@pytest.mark.parametrize("argv, words", [
    (["--static-large"], "--static-large belongs"),
    (["--static", "--fem-sizes"], "one at a time"),
    (["--static", "--quick", "--creep-stress", "-5"], "creep stress must be positive"),
])
def test_bad_static_bench_flags_are_one_line(tmp_path, capsys, argv, words):
    from grainfrac_yade.cli import main
    rc = main(["bench", *argv, "--out", str(tmp_path / "x.json")])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and words in err and "fix:" in err
    assert not (tmp_path / "x.json").exists()
