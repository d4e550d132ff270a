"""Creep tests on a small specimen: control run without corrosion, load ordering, CLI outputs."""
import json
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from conftest import ROOT, needs_yade
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen

pytestmark = [needs_yade, pytest.mark.yade]

SMALL = ["specimen.width=6e-3", "specimen.height=12e-3", "stress_corrosion.creep_time_limit=1e30"]


@pytest.fixture(scope="module")
def small_ucs():
    """UCS of the small specimen (seed 1), measured: creep loads are ratios of it."""
    from grainfrac_yade.analysis.ucs_analysis import ucs_summary
    from grainfrac_yade.protocols.ucs import run_ucs
    p = load_parameters(overrides=SMALL)
    hist, *_ = run_ucs(build_specimen(p, 1), p)
    return ucs_summary(hist)["ucs_pa"]


def _creep(ratio, ucs, extra=()):
    from grainfrac_yade.protocols.creep import run_creep
    p = load_parameters(overrides=SMALL + list(extra))
    return run_creep(build_specimen(p, 1), p, ratio * ucs)


@pytest.fixture(scope="module")
def creep_at_08(small_ucs):
    """The small specimen's creep run at 0.8 of its UCS, once for the tests that read it (load ordering, beta1)."""
    return _creep(0.8, small_ucs)


def test_without_stress_corrosion_a_load_below_ucs_is_held(small_ucs):
    run = _creep(0.85, small_ucs, ["stress_corrosion.enabled=false"])
    assert not run.failed, run.failure_reason
    assert "StressCorrosion" not in run.scene.engine_names()
    assert run.servo.stress == pytest.approx(0.85 * small_ucs, rel=0.01)


def test_higher_load_fails_sooner(small_ucs, creep_at_08):
    low, high = creep_at_08, _creep(0.9, small_ucs)
    assert low.failed and high.failed
    t_low, t_high = low.rows[-1]["creep_time_s"], high.rows[-1]["creep_time_s"]
    assert 0 < t_high < t_low
    assert "StressCorrosion" in high.scene.engine_names()


def test_creep_cli_writes_the_run_folder(tmp_path, small_ucs):
    out = tmp_path / "creep"
    res = subprocess.run([sys.executable, "-m", "grainfrac_yade", "creep", "--width", "6e-3", "--height", "12e-3",
                          "--seed", "1", "--ratio", "0.9", "--ucs", str(small_ucs / 1e6), "--clock", "event",
                          "--set", "stress_corrosion.creep_time_limit=1e30", "--vtk-times", "0", "--out", str(out)],
                         capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 0, res.stderr
    s = json.loads((out / "summary.json").read_text())
    for key in ("lifetime_s", "failed", "stress_pa", "driving_stress_ratio", "ucs_pa", "clock", "n_events",
                "steps", "wall_s", "primary_end_s", "tertiary_start_s", "params", "seed", "code_version"):
        assert key in s
    assert s["failed"] and s["lifetime_s"] > 0 and s["driving_stress_ratio"] == pytest.approx(0.9)
    h = pd.read_csv(out / "history.csv")
    assert h["damage_index"].iloc[0] == 0 and h["damage_index"].iloc[-1] == 1
    assert np.all(np.diff(h["creep_time_s"]) >= 0)
    c = pd.read_csv(out / "cracks.csv")
    assert set(c["mode"]) <= {"tensile", "shear"} and len(c) == s["broken_total"]
    assert sorted(p.name for p in (out / "vtk").iterdir()) == ["bonds.pvd", "bonds_0000.vtp", "bonds_0001.vtp",
                                                               "cells.pvd", "cells_0000.vtp", "cells_0001.vtp"]
    # creep time 0 and the end
    assert s["vtk_creep_times_s"] == [0.0, s["lifetime_s"]]
    for png in ("strain_time.png", "crack_map_t1.00.png"):
        assert (out / png).stat().st_size > 10_000


def test_load_above_ucs_is_one_clear_line(tmp_path):
    res = subprocess.run([sys.executable, "-m", "grainfrac_yade", "creep", "--stress", "300", "--ucs", "200",
                          "--out", str(tmp_path / "x")], capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1
    assert "above the UCS" in res.stderr and "fix:" in res.stderr


def test_event_clock_lifetime_scales_exactly_with_beta1(small_ucs, creep_at_08):
    """Strength mode, event clock: Eq. 7 makes every time to failure proportional to 1/beta1 while
    the sequence of failures is unchanged, so beta1 x 10 must give lifetime / 10 and the same cracks
    (this is what makes a single calibration factor on beta1 meaningful)."""
    base = creep_at_08
    p = load_parameters()
    fast = _creep(0.8, small_ucs, [("stress_corrosion.beta1", 10 * p.stress_corrosion.beta1)])
    assert base.failed and fast.failed
    assert fast.n_events == base.n_events and int(fast.scene.broken.sum()) == int(base.scene.broken.sum())
    assert fast.rows[-1]["creep_time_s"] == pytest.approx(base.rows[-1]["creep_time_s"] / 10, rel=1e-9)


def test_small_specimen_creep_curve_has_three_stages():
    """10 x 20 mm, seed 1, 0.6 of 258 MPa (the 10 x 20 mm mean UCS): a decelerating start, a
    near-constant middle and an accelerating end before collapse (measured: primary ends at 0.40
    t_f, tertiary starts at 0.46 t_f; strain rate 4e-12 -> 8e-16 -> 5e-11 1/s). Small specimens
    creep in steps (16 events here), so this checks the stage detector on a real staircase; the
    paper-size specimen gives smooth three-stage curves (README)."""
    from grainfrac_yade.analysis.creep_analysis import STAGE_RATE_FACTOR, STAGE_WINDOW, creep_stages, local_rates
    from grainfrac_yade.protocols.creep import run_creep
    p = load_parameters(overrides=["specimen.width=10e-3", "specimen.height=20e-3",
                                   "stress_corrosion.creep_time_limit=1e30"])
    run = run_creep(build_specimen(p, 1), p, 0.6 * 258e6)
    assert run.failed and not run.failed_on_loading
    t = np.array([r["creep_time_s"] for r in run.rows])
    strain = np.array([r["axial_strain"] for r in run.rows])
    primary_end, tertiary_start = creep_stages(t[:-1], strain[:-1], t[-1])
    assert STAGE_WINDOW / 2 < primary_end / t[-1] <= tertiary_start / t[-1] < 1 - STAGE_WINDOW / 2
    tau, rate = local_rates(t[:-1], strain[:-1], t[-1])
    inner = rate[(tau >= STAGE_WINDOW / 2) & (tau <= 1 - STAGE_WINDOW / 2)]
    assert inner[0] > STAGE_RATE_FACTOR * inner.min() and inner[-1] > STAGE_RATE_FACTOR * inner.min()


@pytest.mark.slow   # about 14 s: the default suite stays under about 10 min
def test_hold_budget_in_wave_crossings(small_ucs):
    """The hold's budget: by default the fixed step counts exactly; with crossings, ceil(crossings x H / (c dt)),
    c = sqrt(E / rho) from the servo's modulus estimate and the scene's density (closed form, to the last bit).
    A control run (no corrosion) with a relaxation budget of 400 crossings holds the load as with 30,000 steps."""
    import math
    from grainfrac_yade.wave import scene_density
    plain = _creep(0.85, small_ucs, ["stress_corrosion.enabled=false"])
    assert (plain.hold_budget.servo_response_steps, plain.hold_budget.max_relaxation_steps) == (200, 30000)
    run = _creep(0.85, small_ucs, ["stress_corrosion.enabled=false", "creep.max_relaxation_crossings=400",
                                   "creep.servo_response_crossings=0.5"])
    young = run.target / run.rows[0]["axial_strain"]
    c = math.sqrt(young / scene_density(run.params))
    n = run.platens.height / (c * run.scene.O.dt)
    assert run.hold_budget.crossing_steps == pytest.approx(n, rel=1e-6)   # E from the strain at the ramp's end
    assert run.hold_budget.max_relaxation_steps == math.ceil(400 * run.hold_budget.crossing_steps) > 30000
    assert run.hold_budget.servo_response_steps == max(200, math.ceil(0.5 * run.hold_budget.crossing_steps))
    assert not run.failed, run.failure_reason


def test_with_a_bond_per_face_the_face_reading_is_the_node_reading_on_yade(creep_at_08, small_ucs):
    """Rigid cells have one bond per face: the face's F / L is the bond's own stress to the bit (one run against
    another on this machine, same arithmetic), so the face reading repeats every event of the default."""
    face = _creep(0.8, small_ucs, ["stress_corrosion.reading=face"])
    assert face.failed and face.n_events == creep_at_08.n_events
    assert face.clock.creep_time == creep_at_08.clock.creep_time
    assert np.array_equal(face.break_time, creep_at_08.break_time, equal_nan=True)
