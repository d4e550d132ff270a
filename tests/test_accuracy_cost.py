"""The accuracy-cost study: its plan (params/accuracy_cost.toml and bad plans), the yade-batch rows it
writes, the error, slope and cost of each setting on hand-made runs with known answers, and one quick
run end to end through yade-batch (slow)."""
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from conftest import ROOT, needs_yade
from grainfrac_yade.analysis.accuracy_study import (DEFAULT_SETTING, creep_rows, load_study, setting_of_folder,
                                           ucs_rows)
from grainfrac_yade.analysis.accuracy import (creep_strain_before_tertiary, history_measures, label_runs,
                                              markdown_table, pareto_figure, setting_rows, slope_b)
from grainfrac_yade.errors import GrainfracError
from grainfrac_yade.params import default_files, flatten, read_toml

PLAN = ROOT / "params" / "accuracy_cost.toml"

SMALL_PLAN = """
[study]
folder = "{folder}"
width = 5e-3
height = 10e-3
seeds = [1, 2]
ratios = [0.7, 0.85]
ucs = 250e6
creep_time_limit = 1e13

[knob.relaxation]
reference = "tight"

[knob.clock]
reference = "default"

[[setting]]
name = "default"
ucs_test = true

[[setting]]
name = "tight"
knob = "relaxation"
set = {{ "creep.equilibrium_tolerance" = 1e-4 }}

[[setting]]
name = "paper"
knob = "clock"
set = {{ "stress_corrosion.clock" = "paper" }}

[[setting]]
name = "damped"
knob = "relaxation"
set = {{ "numerics.damping" = 0.4 }}
ucs_test = true
"""


@pytest.fixture
def small_plan(tmp_path):
    path = tmp_path / "plan.toml"
    path.write_text(SMALL_PLAN.format(folder=tmp_path / "study"))
    return path


# ------------------------------------------------------------------ the plan
def test_the_shipped_plan_loads_with_a_reference_for_every_knob():
    study = load_study(PLAN)
    names = [s.name for s in study.settings]
    assert names[0] == DEFAULT_SETTING
    for knob in study.knobs.values():
        assert knob.reference in names
        assert any(s.knob == knob.name for s in study.settings if s.name != DEFAULT_SETTING)
    assert study.ratios == (0.7, 0.85) and len(study.seeds) >= 3


def test_the_quick_plan_keeps_the_references_of_its_settings():
    quick = load_study(PLAN, quick=True)
    names = {s.name for s in quick.settings}
    assert DEFAULT_SETTING in names
    for s in quick.settings:
        if s.name != DEFAULT_SETTING:
            assert quick.knobs[s.knob].reference in names


@pytest.mark.parametrize("edit, words", [
    (lambda t: t.replace('"creep.equilibrium_tolerance"', '"creep.equilibrium_tolerence"'), "equilibrium_tolerence"),
    (lambda t: t.replace('reference = "tight"', 'reference = "tigth"'), "tigth"),
    (lambda t: t.replace("ratios = [0.7, 0.85]", "ratios = [0.7, 1.2]"), "ratios"),
    (lambda t: t.replace('knob = "clock"', 'knob = "clok"'), "clok"),
    (lambda t: t.replace("ucs_test = true\n\n[[setting]]\nname = \"tight\"", "ucs_tset = true\n\n[[setting]]\n"
                                                                           "name = \"tight\""), "ucs_tset"),
    (lambda t: t.replace('name = "damped"', 'name = "tight"'), "named twice"),
    (lambda t: t.replace("ucs = 250e6", "ucs = -250e6"), "study.ucs"),
])
def test_a_bad_plan_stops_with_one_line_naming_the_file_and_key(small_plan, edit, words):
    small_plan.write_text(edit(small_plan.read_text()))
    with pytest.raises(GrainfracError) as err:
        load_study(small_plan)
    message = str(err.value)
    assert words in message and "\n" not in message and "fix" in message


def test_a_missing_plan_is_one_line(tmp_path):
    with pytest.raises(GrainfracError, match="no such file"):
        load_study(tmp_path / "nope.toml")


def test_rows_give_every_column_and_the_shipped_value_where_a_setting_is_silent(small_plan):
    study = load_study(small_plan)
    shipped = {}
    for f in default_files():
        shipped.update(flatten(read_toml(f)))
    creep = creep_rows(study, ROOT)
    assert len(creep) == 4 * 2 * 2 and len({tuple(r) for r in creep}) == 1   # same columns in every row
    by_name = {r["description"]: r for r in creep}
    assert by_name["default_r0.7_seed1"]["creep.equilibrium_tolerance"] == shipped["creep.equilibrium_tolerance"]
    assert by_name["tight_r0.7_seed1"]["creep.equilibrium_tolerance"] == 1e-4
    assert by_name["paper_r0.85_seed2"]["stress_corrosion.clock"] == "paper"
    assert by_name["default_r0.85_seed2"]["stress_corrosion.clock"] == shipped["stress_corrosion.clock"]
    assert all(r["ucs"] == 250e6 and r["specimen.width"] == 5e-3 for r in creep)
    ucs = ucs_rows(study, ROOT)
    assert [r["description"] for r in ucs] == ["default_ucs_seed1", "default_ucs_seed2", "damped_ucs_seed1",
                                               "damped_ucs_seed2"]
    assert setting_of_folder(study, by_name["paper_r0.85_seed2"]["out"]) == ("paper", "creep", 0.85, 2)
    assert setting_of_folder(study, ucs[2]["out"]) == ("damped", "ucs", None, 1)
    assert setting_of_folder(study, "/elsewhere/run") is None


# ------------------------------------------------------------------ the analysis, on runs with known answers
def _runs(study, lifetimes, ucs=None, wall=10.0):
    """collect_runs-like frame: creep runs failed at the given lifetimes {(setting, ratio, seed): t or None}."""
    rows = []
    for (name, ratio, seed), t in lifetimes.items():
        folder = study.run_folder(study.setting(name), "creep", seed, ratio)
        row = {"folder": str(folder), "command": "creep", "status": "finished", "numerical_failure": False,
               "failed_on_loading": False, "dem_steps": 1000, "wall_s": wall, "cpu_s": wall, "broken_total": 10, "macrocracks": 4,
               "n_events": 3}
        if t is None:
            row.update(failed=False, lifetime_s=float("nan"), creep_time_end_s=1e13)
        else:
            row.update(failed=True, lifetime_s=t, creep_time_end_s=t)
        rows.append(row)
    for (name, seed), value in (ucs or {}).items():
        rows.append({"folder": str(study.run_folder(study.setting(name), "ucs", seed)), "command": "ucs",
                     "status": "finished", "ucs_pa": value, "young_pa": 70e9})
    return pd.DataFrame(rows)


def test_error_slope_and_notes_against_the_knobs_reference(small_plan, tmp_path):
    study = load_study(small_plan)
    # reference 'tight': ln t = 40 - 30 r exactly; 'default' twice as long at every point (error ln 2);
    # 'damped' e-fold longer at 0.7 only (error (1 + 0)/2, b changes by 1/0.15); 'paper' misses one run.
    ref = {(r, s): math.exp(40 - 30 * r) for r in (0.7, 0.85) for s in (1, 2)}
    life = {}
    for (r, s), t in ref.items():
        life[("tight", r, s)] = t
        life[("default", r, s)] = 2 * t
        life[("damped", r, s)] = t * (math.e if r == 0.7 else 1.0)
        life[("paper", r, s)] = None if (r, s) == (0.85, 2) else 4 * t
    runs = _runs(study, life, ucs={("default", 1): 240e6, ("default", 2): 260e6, ("damped", 1): 230e6,
                                   ("damped", 2): 230e6})
    table = setting_rows(study, label_runs(study, runs))
    row = {(r["knob"], r["setting"]): r for r in table.to_dict("records")}
    assert row[("relaxation", "tight")]["error_ln_mean"] == pytest.approx(0.0, abs=1e-12)
    assert row[("relaxation", "default")]["error_ln_mean"] == pytest.approx(math.log(2))
    assert row[("relaxation", "default")]["error_pct"] == pytest.approx(100.0)
    assert row[("relaxation", "damped")]["error_ln_mean"] == pytest.approx(0.5)
    assert row[("relaxation", "tight")]["slope_b"] == pytest.approx(30.0)
    assert row[("relaxation", "damped")]["slope_b_change"] == pytest.approx(1 / 0.15)
    assert row[("relaxation", "default")]["slope_b_change"] == pytest.approx(0.0, abs=1e-9)
    # the clock knob's reference is the default (2 t): paper (4 t) is x2 on the three pairs it has
    assert row[("clock", "paper")]["error_ln_mean"] == pytest.approx(math.log(2))
    assert row[("clock", "paper")]["pairs_compared"] == 3
    assert "1 of 4" in row[("clock", "paper")]["note"] and "1 not failed" in row[("clock", "paper")]["note"]
    # UCS: own tests where the knob changes them, else the default's
    assert row[("relaxation", "damped")]["ucs_mpa"] == pytest.approx(230.0)
    assert row[("clock", "paper")]["ucs_mpa"] == pytest.approx(250.0) and row[("clock", "paper")]["ucs_from"] == "default"
    assert row[("clock", "default")]["lifetime_geomean_r0.7_s"] == pytest.approx(2 * math.exp(40 - 21))
    text = markdown_table(table, study.ratios)
    assert text.count("\n| ") == len(table) and "tight (ref)" in text
    png = pareto_figure(table, tmp_path / "pareto.png")
    assert png.stat().st_size > 1000


def test_slope_needs_two_ratios():
    assert math.isnan(slope_b([(0.7, 1e5), (0.7, 2e5)]))
    assert slope_b([(0.6, math.exp(20)), (0.8, math.exp(14))]) == pytest.approx(30.0)


def test_creep_strain_before_tertiary_is_read_from_the_history():
    history = pd.DataFrame({"creep_time_s": [0.0, 10.0, 20.0, 30.0], "axial_strain": [2e-3, 2.1e-3, 2.3e-3, 3e-3]})
    assert creep_strain_before_tertiary(history, 15.0) == pytest.approx(0.2e-3)
    assert math.isnan(creep_strain_before_tertiary(history, float("nan")))
    assert math.isnan(creep_strain_before_tertiary(None, 5.0))


def test_steps_per_relaxation_count_the_relaxations_to_equilibrium_of_the_event_clock():
    history = pd.DataFrame({"creep_time_s": [0.0, 0.0, 5.0, 9.0], "axial_strain": [1e-3] * 4,
                            "step": [40000, 40600, 41500, 52000]})
    m = history_measures(history, None, "event")
    # rows: after the ramp, after each relaxation; the last relaxation (10,500 steps) is the collapse
    assert m["creep_dem_steps"] == 12000 and m["final_relaxation_steps"] == 10500
    assert m["steps_per_relaxation"] == 750
    assert math.isnan(history_measures(history, None, "paper")["steps_per_relaxation"])


# ------------------------------------------------------------------ one quick study through yade-batch
@needs_yade
@pytest.mark.slow
def test_quick_study_end_to_end(tmp_path):
    out = tmp_path / "quick"
    cmd = [sys.executable, "-m", "grainfrac_yade", "accuracy-cost", "--quick", "--jobs", "2", "--out", str(out)]
    done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]
    table = pd.read_csv(out / "accuracy_cost.csv")
    study = load_study(PLAN, quick=True)
    assert set(table["setting"]) == {s.name for s in study.settings}
    assert (table["creep_runs_finished"] == table["creep_runs_planned"]).all()
    refs = table[table["setting"] == table["reference"]]
    assert np.allclose(refs["error_ln_mean"], 0.0)
    assert np.isfinite(table["cpu_s_per_run"]).all() and (table["dem_steps_per_run"] > 0).all()
    assert (out / "accuracy_cost.png").stat().st_size > 1000
    # a second call keeps every finished row (nothing reruns) and gives the same table
    again = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    assert again.returncode == 0, again.stderr[-2000:]
    pd.testing.assert_frame_equal(pd.read_csv(out / "accuracy_cost.csv"), table)
