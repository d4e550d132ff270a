"""Hard cases on tiny specimens: an unstable DEM step, loads above the UCS and far below it, a stiffness
contrast of 100 between minerals, sliver cells, one-cell-wide columns, reruns of one seed, and the paper
clock with a creep step of up to 1e8 s.

Each run asserts that no output holds NaN or inf, that no bond strength is negative, that the run ends
with its reason (``end_reason`` in summary.json), and that a numerical failure is that outcome and
nothing else.  Run times (one thread, this 2-core machine) are in each test's docstring.
"""
import dataclasses
import itertools
import json
import math
import os
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from conftest import ROOT, needs_yade
from test_reliability import StandInBonds, StandInHolder, loop_params
from grainfrac_yade.law import degrade_step, failed_now, hillig_charles
from grainfrac_yade.clocks import EventClock, PaperClock
from grainfrac_yade.errors import GrainfracError
from grainfrac_yade.params import load_parameters

TINY = ["specimen.width=4e-3", "specimen.height=8e-3"]
FEM = [str(ROOT / "params" / "presets" / "fem_coarse.toml")]


# ------------------------------------------------------------------ checks shared by every run
def _refuse_nan_token(token):
    raise AssertionError(f"JSON holds {token}")


def clean_folder(out, nullable=()) -> dict:
    """Assert a run folder holds nothing NaN or infinite; return its summary.

    JSON files may not hold NaN/Infinity tokens; summary.json's numbers must be finite, and null only
    for the ``nullable`` keys (not measured, or no result); every number in every CSV must be finite,
    except cracks.csv's ``macro_time_s`` (empty: never a macrocrack) and ``creep_time_s`` on the rows of
    phase ``ramp`` (a crack of the ramp has no creep time).  ``end_reason`` must say why the
    run ended.
    """
    out = Path(out)
    for path in out.glob("*.json"):
        json.loads(path.read_text(), parse_constant=_refuse_nan_token)
    summary = json.loads((out / "summary.json").read_text())
    nulls = sorted(k for k, v in summary.items() if v is None)
    assert set(nulls) <= set(nullable), f"null in summary.json: {nulls}"
    numbers = {k: v for k, v in summary.items() if isinstance(v, (int, float)) and not isinstance(v, bool)}
    assert all(math.isfinite(v) for v in numbers.values()), numbers
    assert isinstance(summary["end_reason"], str) and summary["end_reason"]
    for path in out.glob("*.csv"):
        table = pd.read_csv(path)
        if path.name == "cracks.csv" and "phase" in table:
            assert table["creep_time_s"].isna().tolist() == (table["phase"] == "ramp").tolist()
            table = table[table["phase"] != "ramp"]
        table = table.select_dtypes("number")
        table = table.drop(columns=["macro_time_s"] if path.name == "cracks.csv" else [], errors="ignore")
        assert np.isfinite(table.to_numpy()).all(), f"{path.name}: NaN or inf"
    return summary


def no_negative_strength(scene, corr=None):
    """Every bond's YADE strengths (and the corrosion engine's, if any) are finite and >= 0."""
    for name in ("FnMax", "FsMax"):
        values = np.array([getattr(i.phys, name) for i in scene.interactions])
        assert np.isfinite(values).all() and (values >= 0).all(), name
    if corr is not None:
        for values in corr.state.arrays.values():
            assert np.isfinite(values).all() and (values >= 0).all()


@pytest.fixture
def captured(monkeypatch):
    """The scene (and corrosion engine) of the next UCS or creep run made through the run-folder functions."""
    from grainfrac_yade.protocols import ucs as ucs_test
    from grainfrac_yade.protocols import creep as creep_test
    got = {}

    def keep(module, name, pick):
        original = getattr(module, name)

        def wrapper(*args, **kwargs):
            result = original(*args, **kwargs)
            got["scene"], got["corr"] = pick(result)
            return result
        monkeypatch.setattr(module, name, wrapper)
    keep(creep_test, "run_creep", lambda run: (run.scene, run.corr))
    keep(ucs_test, "run_ucs", lambda result: (result[2], None))
    return got


def ucs_folder(params, out, captured, nullable=("crack_initiation_pa",)) -> dict:
    from grainfrac_yade.protocols.ucs_output import run_ucs_to_folder
    run_ucs_to_folder(params, 1, out)
    s = clean_folder(out, nullable)
    no_negative_strength(captured["scene"])
    return s


#: summary.json keys a creep run leaves null when it has no lifetime or no creep stages
#: What a creep history resolves: the stages and the minimum creep strain rate between them (null where it does not).
STAGES = ("primary_end_s", "tertiary_start_s", "min_creep_strain_rate_per_s")
NO_LIFETIME = ("lifetime_s", "lifetime_readable") + STAGES
#: A run that never held its load (failed on loading, or before it) has no hold budget.
NO_HOLD = ("wave_crossing_steps", "servo_response_steps_used", "max_relaxation_steps_used")


def creep_folder(params, out, stress, ucs, captured, nullable=NO_LIFETIME) -> dict:
    from grainfrac_yade.protocols.creep_output import run_creep_to_folder
    run_creep_to_folder(params, 1, out, stress, stress / ucs, ucs)
    s = clean_folder(out, nullable)
    no_negative_strength(captured["scene"], captured["corr"])
    return s


def outcome_in_analysis(folder) -> list:
    from grainfrac_yade.analysis import classify_runs, collect_runs
    return list(classify_runs(collect_runs(folder))["outcome"])


# ------------------------------------------------------------------ (a) a DEM step 10 x the critical one
@pytest.fixture
def step_ten_times_critical(monkeypatch):
    """Scenes built for UCS and creep runs step at 10 x their critical DEM step (timestep_safety <= 1
    cannot ask for it: the step is set after the scene is built)."""
    from grainfrac_yade.engines.yade import engine

    def stepping_up(build):
        def build_then_step_up(*args, **kwargs):
            scene = build(*args, **kwargs)
            scene.O.dt = 10 * scene.dt_critical
            return scene
        return build_then_step_up
    # the engine the registry gives every test protocol (its module's ENGINE, read at each lookup)
    monkeypatch.setattr(engine, "ENGINE", dataclasses.replace(engine.ENGINE,
                                                             build_scene=stepping_up(engine.ENGINE.build_scene)))


@needs_yade
@pytest.mark.yade
def test_a_dem_step_ten_times_the_critical_one_is_a_numerical_failure_of_creep(tmp_path, step_ten_times_critical,
                                                                              captured):
    """Before, the unstable DEM 'reached' 176 MPa in 5 DEM steps and the run ended as failed ('no
    equilibrium') at creep time 0: a lifetime.  Now: a numerical failure before the first step (1 s)."""
    s = creep_folder(load_parameters(overrides=TINY), tmp_path / "run", 176e6, 252e6, captured,
                     NO_LIFETIME + ("failed",) + NO_HOLD)
    assert (s["numerical_failure"], s["failed"], s["lifetime_s"], s["failed_on_loading"]) == (True, None, None, False)
    assert s["end_reason"] == s["failure_reason"]
    assert s["end_reason"].startswith("numerical failure: DEM step ") and "critical step" in s["end_reason"]
    assert s["steps"] == 0 and s["creep_time_end_s"] == 0.0
    assert outcome_in_analysis(tmp_path) == ["numerical failure"]


@needs_yade
@pytest.mark.yade
def test_a_dem_step_ten_times_the_critical_one_is_no_ucs(tmp_path, step_ten_times_critical, captured):
    """Before: 'UCS 0 MPa', E and Poisson NaN, every bond broken.  Now: no result, and analyze-ucs lists
    the run apart (1 s)."""
    from grainfrac_yade.commands.analyze_ucs import cmd_analyze_ucs
    from grainfrac_yade.protocols.ucs_output import MEASURES
    s = ucs_folder(load_parameters(overrides=TINY), tmp_path / "run", captured, MEASURES)
    assert s["numerical_failure"] is True and s["ucs_pa"] is None and s["steps"] == 0
    assert s["end_reason"].startswith("numerical failure: DEM step ")
    cmd_analyze_ucs(SimpleNamespace(folder=str(tmp_path), out=None))
    assert f"numerical failure (no result, not counted): run: {s['end_reason']}" in \
        (tmp_path / "report" / "ucs_stats.md").read_text()


# ------------------------------------------------------------------ (b) a load above the UCS
@pytest.fixture(scope="module")
def rigid_ucs():
    """UCS of the 4 x 8 mm specimen, seed 1 (measured 251.8 MPa; 3 s)."""
    from grainfrac_yade.geometry.specimen import build_specimen
    from grainfrac_yade.analysis.ucs_analysis import ucs_summary
    from grainfrac_yade.protocols.ucs import run_ucs
    p = load_parameters(overrides=TINY)
    return ucs_summary(run_ucs(build_specimen(p, 1), p)[0])["ucs_pa"]


def _fails_on_loading(s):
    assert (s["failed"], s["failed_on_loading"], s["lifetime_s"], s["numerical_failure"]) == (True, True, 0.0, False)
    assert s["end_reason"] == s["failure_reason"] == "failed during the ramp: load above the specimen's strength"
    assert s["creep_time_end_s"] == 0.0 and s["n_events"] == 0 and s["broken_creep"] == 0


@needs_yade
@pytest.mark.yade
@pytest.mark.parametrize("factor", [1.001, 1.5])
def test_b_a_load_above_the_ucs_fails_on_loading_with_lifetime_0(tmp_path, rigid_ucs, captured, factor):
    """Just (0.1 %) and well above the specimen's own UCS, same seed and loading rate (2 s each).

    At exactly the recorded UCS the ramp reaches the load: the recorded peak is a state the specimen
    carried (sampled every 2e-5 strain; the ramp checks every 1e-5), and the run is a short lifetime.
    The CLI and batch rows refuse a load at or above the UCS they refer to."""
    s = creep_folder(load_parameters(overrides=TINY), tmp_path / "run", factor * rigid_ucs, rigid_ucs, captured,
                     STAGES + NO_HOLD)
    _fails_on_loading(s)
    assert outcome_in_analysis(tmp_path) == ["failed at load"]


@needs_yade
@pytest.mark.yade
@pytest.mark.slow
def test_b_fem_grains_above_their_ucs_fail_on_loading(tmp_path, captured):
    """Fem preset, 4 x 8 mm: UCS, then 1.01 x it.

    Not 1.001 x as for rigid cells: the recorded UCS is the highest of rows ``ucs.record_strain_increment``
    (2e-5) apart, and this specimen's stress rose by 2.2 MPa (0.7 %) between two rows just before its peak
    (324.1 MPa), so the state it carried between rows can lie that much above the record.  Measured: at 1.001 x
    the ramp (checks every 1e-5) reached the load and the specimen collapsed in its first relaxation
    (lifetime 0, not on loading); at 1.01 and 1.03 x it failed in the ramp."""
    p = load_parameters(overrides=TINY, extra_files=FEM)
    ucs = ucs_folder(p, tmp_path / "ucs", captured)["ucs_pa"]
    _fails_on_loading(creep_folder(p, tmp_path / "creep", 1.01 * ucs, ucs, captured, STAGES + NO_HOLD))


# ------------------------------------------------------------------ (c) a very low load
@needs_yade
@pytest.mark.yade
@pytest.mark.parametrize("clock", ["event", "paper"])
def test_c_a_very_low_load_reaches_the_creep_time_limit_not_failed(tmp_path, captured, clock):
    """0.1 x the UCS (25 MPa): the run stops at stress_corrosion.creep_time_limit (1e9 s) as not failed, a
    lower bound of the lifetime (1 s each; the paper clock with dt_max = 1e8 s: 53 creep steps)."""
    p = load_parameters(overrides=TINY + [f"stress_corrosion.clock={clock}", "stress_corrosion.dt_max=1e8"])
    s = creep_folder(p, tmp_path / "run", 25e6, 252e6, captured)
    assert (s["failed"], s["lifetime_s"], s["numerical_failure"], s["failure_reason"]) == (False, None, False, "")
    assert s["creep_time_end_s"] >= 1e9 and s["end_reason"] == (
        "creep time reached stress_corrosion.creep_time_limit = 1e+09 s: not failed, the lifetime is a lower bound")
    assert outcome_in_analysis(tmp_path) == ["not failed"]
    from grainfrac_yade.analysis.durations import readable_duration
    from grainfrac_yade.commands._outcome import outcome
    assert outcome(s) == (f"not failed by {s['creep_time_end_s']:.4g} s "   # the paper clock's last step may pass
                          f"({readable_duration(s['creep_time_end_s'])})")
    assert s["creep_time_end_s"] < 1e9 + p.stress_corrosion.dt_max    # the limit by less than dt_max: 1.076e9 s


# ------------------------------------------------------------------ (d) stiffness contrast of 100
CONTRASTS = {
    "biotite 100 x softer": ["grains.biotite.young=35e7", 'contacts."biotite/biotite".normal_stiffness=4.2e12'],
    "quartz 100 x stiffer": ["grains.quartz.young=91e11", 'contacts."quartz/quartz".normal_stiffness=1.01e17'],
}


@needs_yade
@pytest.mark.yade
@pytest.mark.parametrize("contrast", [
    "biotite 100 x softer", pytest.param("quartz 100 x stiffer", marks=pytest.mark.slow)])
def test_d_a_stiffness_contrast_of_100_runs_ucs_and_creep_without_nan(tmp_path, captured, contrast):
    """One mineral's E (Table 1) and pure-contact k_n (Table 2) times 1/100 or 100 (mixed contacts are the
    averages): a UCS, then creep at 0.7 x that UCS, both ending as measures.  Soft biotite: UCS 164 MPa,
    creep lifetime 5.3e8 s (7 s); stiff quartz: DEM step 8 x smaller, UCS 249 MPa, lifetime 4.5e7 s (21 s)."""
    p = load_parameters(overrides=TINY + CONTRASTS[contrast])
    u = ucs_folder(p, tmp_path / "ucs", captured)
    assert u["numerical_failure"] is False and u["peak_reached"] and 1e8 < u["ucs_pa"] < 1e9
    s = creep_folder(p, tmp_path / "creep", 0.7 * u["ucs_pa"], u["ucs_pa"], captured, STAGES)
    assert s["numerical_failure"] is False and s["failed"] and s["lifetime_s"] > 0 and not s["failed_on_loading"]


# ------------------------------------------------------------------ (e) sliver cells
def sliver_seeds(width, grain=1e-3, jitter_seed=3):
    """A jittered 4 x 8 grid of seeds at 1 mm (the 4 x 8 mm specimen) with one seed replaced by three
    in a row ``width`` apart: the middle cell is a sliver ``width`` wide and about a grain long."""
    rng = np.random.default_rng(jitter_seed)
    xs, ys = np.meshgrid((np.arange(4) + 0.5) * grain, (np.arange(8) + 0.5) * grain)
    seeds = np.column_stack([xs.ravel(), ys.ravel()]) + rng.uniform(-0.1, 0.1, (32, 2)) * grain
    centre = seeds[13].copy()
    return np.vstack([seeds, centre - [width, 0.0], centre + [width, 0.0]])


def sliver_specimen(params, width):
    from grainfrac_yade.geometry.specimen import specimen_from_tessellation
    from grainfrac_yade.geometry.tessellation import tessellate_seeds
    t = tessellate_seeds(sliver_seeds(width), [4e-3, 8e-3], 1e-3)
    assert t.cell_measure.sum() == pytest.approx(32e-6, rel=1e-12)   # no cell overlaps another
    minerals = np.random.default_rng(1).integers(0, len(params.minerals), t.n_cells)
    return specimen_from_tessellation(t, minerals, params.minerals, params.specimen.thickness)


@needs_yade
@pytest.mark.yade
@pytest.mark.parametrize("width", [1e-5, 1e-8])
def test_e_a_sliver_cell_builds_a_stable_scene_and_compresses_finitely(width):
    """A cell 1/100 and 1/100,000 of a grain wide (width/length 0.01 and 1e-5): the critical DEM step is
    finite and positive (1.9e-8 s and 5.9e-10 s, against 3.8e-7 s without the sliver; it falls as the
    square root of the width), and 20,000 DEM steps of compression stay finite (1 s each)."""
    from grainfrac_yade.engines.yade.platens import Platens
    from grainfrac_yade.engines.yade.scene import build_scene
    p = load_parameters(overrides=TINY)
    specimen = sliver_specimen(p, width)
    eq_width = specimen.tessellation.cell_measure / np.array([np.ptp(v[:, 1]) for v in
                                                              specimen.tessellation.cell_vertices])
    assert eq_width.min() == pytest.approx(width, rel=1e-3)
    sc = build_scene(specimen, p)
    assert 0 < sc.dt_critical < math.inf and sc.O.dt == p.numerics.timestep_safety * sc.dt_critical
    platens = Platens(sc, p.ucs.platen_lateral)
    sc.extras.append(platens)
    platens.set_axial_velocity(p.ucs.strain_rate * platens.height)
    sc.run(20000)
    positions = np.array([tuple(b.state.pos) for b in sc.O.bodies])
    assert np.isfinite(positions).all()
    stress, strain = platens.axial_stress(), platens.axial_strain()
    assert math.isfinite(stress) and stress > 0 and strain == pytest.approx(20000 * sc.O.dt * p.ucs.strain_rate,
                                                                            rel=1e-6)
    no_negative_strength(sc)


def test_e_seeds_too_close_to_tell_apart_are_one_clear_error_not_overlapping_cells():
    """1e-9 m apart (Qhull's precision in a 4 x 8 mm box): Qhull gave two seeds one region, so two cells
    overlapped (areas summing to 1.015 x the box) and one had no face: an unbonded body inside another."""
    from grainfrac_yade.geometry.tessellation import tessellate_seeds
    with pytest.raises(GrainfracError) as err:
        tessellate_seeds(sliver_seeds(1e-9), [4e-3, 8e-3], 1e-3)
    assert str(err.value) == ("tessellation: seeds 13 and 33 lie 1e-09 m apart, too close for the Voronoi "
                              "construction to tell apart (their cells would overlap); fix: merge them or move "
                              "them apart")
    assert tessellate_seeds(sliver_seeds(3e-9), [4e-3, 8e-3], 1e-3).n_cells == 34


# ------------------------------------------------------------------ (f) one-cell-wide columns
def test_f_a_grain_size_that_leaves_one_cell_is_one_line_not_a_traceback():
    """3.9 mm grains in a 4 x 4 mm specimen: below the width and height, but one cell (it ended in numpy's
    lexsort traceback while tessellating)."""
    from grainfrac_yade.errors import ParameterError
    with pytest.raises(ParameterError) as err:
        load_parameters(overrides=["specimen.width=4e-3", "specimen.height=4e-3", "specimen.grain_size=3.9e-3"])
    assert str(err.value) == ("--set: specimen.grain_size: 0.0039 m gives a specimen of one cell (a lone cell has "
                              "no face to bond); fix: make specimen.grain_size smaller or enlarge the specimen")


@needs_yade
@pytest.mark.yade
def test_f_grains_just_below_the_width_run_a_ucs_to_a_finite_peak(tmp_path, captured):
    """2 x 8 mm with 1.9 mm grains: 6 cells, 2 of them spanning the width: a post-peak UCS of 654 MPa (1 s)."""
    p = load_parameters(overrides=["specimen.width=2e-3", "specimen.height=8e-3", "specimen.grain_size=1.9e-3"])
    s = ucs_folder(p, tmp_path / "run", captured)
    assert s["n_cells"] == 6 and s["numerical_failure"] is False
    assert s["peak_reached"] and s["end_reason"] == "post-peak: the axial stress fell below 0.7 x its peak"
    assert 1e8 < s["ucs_pa"] < 2e9 and s["broken_total"] >= 1


def column_specimen(params, n=5, grain=1.9e-3):
    """n cells stacked in a 2 x 8 mm box, every one spanning the width (seeds jittered about the axis,
    so faces are inclined by 18 to 31 degrees)."""
    from grainfrac_yade.geometry.specimen import specimen_from_tessellation
    from grainfrac_yade.geometry.tessellation import tessellate_seeds
    rng = np.random.default_rng(1)
    seeds = np.column_stack([1e-3 + rng.uniform(-0.3, 0.3, n) * 2e-3, (np.arange(n) + 0.5) * 8e-3 / n])
    t = tessellate_seeds(seeds, [2e-3, 8e-3], grain)
    assert len(np.intersect1d(t.cells_on_side("left"), t.cells_on_side("right"))) == n
    return specimen_from_tessellation(t, rng.integers(0, 4, n), params.minerals, params.specimen.thickness)


@needs_yade
@pytest.mark.yade
@pytest.mark.parametrize("spheres_per_cell, largest", [(1, 4e6), (8, 3e9)])
def test_f_a_strict_one_cell_column_ends_at_the_strain_cap_as_a_lower_bound(spheres_per_cell, largest):
    """A column of rigid cells has no failure mode in uniaxial compression between smooth platens: no
    cell beside another to push apart (no tension), and friction on its inclined faces (tan 55 deg) holds
    shear.  One sphere per cell: one bond per face, a hinge, so the column is a mechanism that folds
    sideways (largest stress 3.4 MPa, the ringing of the first steps); 8 spheres per cell: 2 bonds per face,
    elastic to the 2 % strain cap (1.8 GPa).  Neither breaks a bond.  Before, the first run 'failed'
    post-peak at 3.4 MPa after 376 DEM steps (the ringing read as softening).  1-2 s each."""
    from grainfrac_yade.analysis.ucs_analysis import ucs_summary
    from grainfrac_yade.protocols.ucs import run_ucs
    p = load_parameters(overrides=["specimen.width=2e-3", "specimen.height=8e-3", "specimen.grain_size=1.9e-3",
                                   f"resolution.spheres_per_cell={spheres_per_cell}"])
    history, result, scene, _ = run_ucs(column_specimen(p), p)
    assert np.isfinite(pd.DataFrame(history).to_numpy()).all()
    assert result["peak_reached"] is False and result["broken_total"] == 0 and result["end_reason"] == (
        "axial strain reached ucs.max_strain = 0.02 before the stress fell below 0.7 x its peak: the largest "
        "stress is a lower bound of the strength")
    assert 0 < ucs_summary(history)["ucs_pa"] < largest
    no_negative_strength(scene)


# ------------------------------------------------------------------ (g) the same seed twice
def _cli_run(*args):
    res = subprocess.run([sys.executable, "-m", "grainfrac_yade", *map(str, args)], capture_output=True, text=True,
                         cwd=ROOT, env=dict(os.environ, OMP_NUM_THREADS="1"))
    assert res.returncode == 0, res.stderr
    return res


def assert_same_runs(a, b):
    """summary.json equal but for wall time and code version; every CSV equal but for wall time."""
    sa, sb = (json.loads((d / "summary.json").read_text()) for d in (a, b))
    for s in (sa, sb):
        del s["wall_s"], s["cpu_s"], s["code_version"]   # the tree may change between runs (others commit)
    assert sa == sb
    names = sorted(p.name for p in a.glob("*.csv"))
    assert names == sorted(p.name for p in b.glob("*.csv")) and "history.csv" in names
    for name in names:
        ta, tb = (pd.read_csv(d / name).drop(columns=["wall_s"], errors="ignore") for d in (a, b))
        pd.testing.assert_frame_equal(ta, tb, check_exact=True)


@pytest.mark.slow   # a creep command in its own process repeating an in-process run of 4 x 8 mm bit for bit (events,
#                     lifetime, history, cracks): tests/test_resume.py's kill inside a relaxation, resumed
@needs_yade
@pytest.mark.yade
def test_g_the_same_seed_twice_gives_identical_creep_results(tmp_path):
    """Two CLI processes, one thread each: creep at 0.8 x 252 MPa, 4 x 8 mm, seed 1 (5 s each)."""
    for name in ("a", "b"):
        _cli_run("creep", "--width", 4e-3, "--height", 8e-3, "--seed", 1, "--ratio", 0.8, "--ucs", 252,
                 "--out", tmp_path / name)
    assert_same_runs(tmp_path / "a", tmp_path / "b")
    s = clean_folder(tmp_path / "a", STAGES)
    assert s["failed"] and s["n_events"] > 0


@needs_yade
@pytest.mark.yade
@pytest.mark.slow
def test_g_the_same_seed_twice_gives_identical_fem_ucs_results(tmp_path):
    """Fem preset, 4 x 8 mm, seed 1, two CLI processes."""
    for name in ("a", "b"):
        _cli_run("ucs", "--params", FEM[0], "--width", 4e-3, "--height", 8e-3, "--seed", 1,
                 "--out", tmp_path / name)
    assert_same_runs(tmp_path / "a", tmp_path / "b")


# ------------------------------------------------------------------ (h) the paper clock with dt_max = 1e8 s
B1, B2 = 1e-3, 1e-7   # paper section 4.1
TAN_PHI = math.tan(math.radians(55))   # the stand-in bonds' friction


class FrozenBonds(StandInBonds):
    """Bonds under frozen stresses that corrode (Eq. 7) on a stand-in scene whose DEM steps break every
    intact bond past its failure point, as JCFpm does on the next step."""

    def __init__(self, sigma, tau, jt, jc):
        super().__init__(sigma, tau, jt, jc, breaks=True)
        self.scene.run = self._dem_steps

    def _dem_steps(self, n):
        idx = self.intact()
        tension, shear = failed_now(self.tensile[idx], self.cohesion[idx], self.sigma[idx], self.tau[idx],
                                    self.tan_phi[idx])
        self.scene.broken[idx[tension | shear]] = True

    def degrade(self, dt, stresses):
        self.state = degrade_step(self.law, self.state, stresses, dt)
        super().degrade(dt, stresses)


class BreakRecorder(StandInHolder):
    """The creep run's interface, always balanced (F_u = 0); records each bond's break time and the length
    of the creep step that ended there (the clock's last step)."""

    def __init__(self, bonds, clock):
        super().__init__(itertools.repeat(0.0))
        self.bonds, self.clock = bonds, clock
        self.break_time, self.break_step = np.full(len(bonds.sigma), np.nan), np.full(len(bonds.sigma), np.nan)

    def relax(self, creep_time, safe_point=None, resume=None):
        self.mark_breaks(creep_time)
        return super().relax(creep_time, safe_point, resume)

    def mark_breaks(self, creep_time):
        new = self.bonds.scene.broken & np.isnan(self.break_time)
        self.break_time[new] = creep_time
        self.break_step[new] = getattr(self.clock, "dt", None) or 0.0


def frozen_bonds():
    """60 K-feldspar bonds (J^T 23 MPa, J^C 52 MPa): 40 in tension at 0.05-0.95 J^T, 20 compressed at 5 MPa
    and sheared at 0.5-0.95 of their Mohr-Coulomb strength: closed-form lifetimes 2.1e7 to 1.9e10 s."""
    rng = np.random.default_rng(7)
    jt, jc = 23e6, 52e6
    sigma = np.concatenate([rng.uniform(0.05, 0.95, 40) * jt, np.full(20, -5e6)])
    tau = np.concatenate([rng.uniform(0.0, 0.3, 40) * jc, rng.uniform(0.5, 0.95, 20) * (jc + 5e6 * TAN_PHI)])
    return sigma, tau, jt, jc


def bonds_left_whole(holder):
    """Strengths of the stand-in bonds after a loop: finite and >= 0."""
    b = holder.bonds
    return np.isfinite(b.tensile) & np.isfinite(b.cohesion) & (b.tensile >= 0) & (b.cohesion >= 0)


def _clocked_breaks(clock_name, dt_max=1e8, limit=1e12):
    from grainfrac_yade.protocols.creep_loops import event_clock_loop, paper_clock_loop
    bonds = FrozenBonds(*frozen_bonds())
    if clock_name == "paper":
        clock = PaperClock(1e-5, dt_max, 1e-2)
        holder = BreakRecorder(bonds, clock)
        paper_clock_loop(holder, bonds, clock, *loop_params(
            {"creep_time_limit": limit, "engine_period": 1, "unbalanced_engine_period": 1,
             "unbalanced_force_reference": "relative"}, {"record_period": 10**9, "max_relaxation_steps": 20}))
    else:
        clock = EventClock(0.1, limit)
        holder = BreakRecorder(bonds, clock)
        event_clock_loop(holder, bonds, clock)
    return holder, clock


def test_h_the_paper_clock_with_a_1e8_s_step_breaks_each_bond_in_the_step_that_passes_its_failure_point():
    """Pure clock and law objects (the stand-in scene breaks what the law says has failed, at the next DEM
    step, as JCFpm does).  Each bond breaks at the end of the creep step in which its closed-form lifetime
    falls: t_b - dt_b < t_fail <= t_b (to 1e-9, the rounding of the summed steps).  Before, a break was
    marked one creep step late while other bonds stayed intact (the clock advanced before the breaks were
    read): 1e8 s late at dt_max."""
    sigma, tau, jt, jc = frozen_bonds()
    t_fail, _ = hillig_charles.time_to_failure(np.full(60, jt), np.full(60, jc), sigma, tau, np.full(60, TAN_PHI), B1, B2)
    assert 1e7 < t_fail.min() and t_fail.max() < 1e11
    holder, clock = _clocked_breaks("paper")
    assert holder.failed and holder.failure_reason == "every bond broken"
    t_b, dt_b = holder.break_time, holder.break_step
    assert np.all(t_fail <= t_b * (1 + 1e-9)) and np.all(t_b - dt_b < t_fail * (1 + 1e-9))
    assert clock.dt == 1e8 and dt_b.max() == 1e8   # the late failures fall in steps at dt_max
    assert np.all(bonds_left_whole(holder))


def test_h_paper_clock_lifetimes_lie_within_one_doubling_of_the_event_clock():
    """The event clock jumps to each failure (t_event = closed form, 1e-9).  The paper clock's step doubles
    from dt_min while balanced, so a bond failing at t breaks at the end of a step no longer than t + dt_min
    (or dt_max once capped): t_event <= t_paper < min(2 t_event + dt_min, t_event + dt_max).  That is the
    tolerance: Eq. 8's resolution, up to a factor 2 with dt_max = 1e8 s (measured here: t_paper / t_event
    1.0004 to 1.55; beyond 1.8e8 s the step is capped at 1e8 s)."""
    sigma, tau, jt, jc = frozen_bonds()
    t_fail, _ = hillig_charles.time_to_failure(np.full(60, jt), np.full(60, jc), sigma, tau, np.full(60, TAN_PHI), B1, B2)
    event, _ = _clocked_breaks("event")
    paper, _ = _clocked_breaks("paper")
    t_event, t_paper = event.break_time, paper.break_time
    np.testing.assert_allclose(t_event, t_fail, rtol=1e-9)
    assert np.all(t_event <= t_paper * (1 + 1e-9))
    assert np.all(t_paper < np.minimum(2 * t_event + 1e-5, t_event + 1e8) * (1 + 1e-9))
    assert np.all(bonds_left_whole(event)) and np.all(bonds_left_whole(paper))
    ratio = t_paper / t_event
    assert 1.0 <= ratio.min() * (1 + 1e-9) and ratio.max() < 2.0


@needs_yade
@pytest.mark.yade
def test_h_one_bond_in_yade_with_the_paper_clock_at_dt_max_1e8():
    """One bond in tension at 0.9 x J^T in YADE (1 s): the paper clock with dt_max = 1e8 s breaks it at
    the end of the creep step that passes its closed-form lifetime, and within one doubling of the event
    clock's lifetime."""
    from test_creep_bond import _closed_form_tension, _run
    p0 = load_parameters()
    j0 = p0.contact("quartz", "quartz").tensile_strength * p0.calibration.strength_scale
    lifetimes = {}
    for name in ("event", "paper"):
        holder, clock, p = _run(name, 0.9 * j0, 0.0, ["stress_corrosion.dt_max=1e8"])
        assert holder.failed and holder.scene.break_mode[0] == 1
        no_negative_strength(holder.scene, holder.corr)
        t_exact = _closed_form_tension(j0, holder.sigma0)
        lifetimes[name] = holder.lifetime
    assert lifetimes["event"] == pytest.approx(t_exact, rel=1e-6)
    assert t_exact <= lifetimes["paper"] and lifetimes["paper"] - clock.dt < t_exact
    assert lifetimes["paper"] < 2 * lifetimes["event"] + p.stress_corrosion.dt_min
