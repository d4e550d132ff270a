"""Confined (biaxial) compression and creep: envelope fits against their closed forms, the deviatoric
driving-stress ratio, bad input, and in YADE: the side-wall forces, the isotropic stage, a peak that
rises with confinement on the same seed, and a confined creep run that resumes exactly."""
import json
import math

import numpy as np
import pytest

from conftest import needs_yade
from grainfrac_yade.analysis.envelope import fit_hoek_brown, fit_mohr_coulomb
from grainfrac_yade.errors import GrainfracError
from grainfrac_yade.params import load_parameters
from test_grain_model_runs import UCS_SUMMARY, write_run_folder

MPA = 1e6
#: 3 x 6 mm specimen (about 23 cells): a UCS test in about 2 s.
TINY = ["specimen.width=3e-3", "specimen.height=6e-3"]


# ------------------------------------------------------------------ envelope fits (no YADE)
def test_mohr_coulomb_fit_recovers_friction_angle_and_cohesion():
    phi, c = math.radians(35.0), 30 * MPA
    q = (1 + math.sin(phi)) / (1 - math.sin(phi))
    c0 = 2 * c * math.cos(phi) / (1 - math.sin(phi))
    s3 = np.repeat([0, 5, 10, 20, 40], 3) * MPA
    fit = fit_mohr_coulomb(s3, c0 + q * s3)
    assert fit.friction_angle_deg == pytest.approx(35.0, rel=1e-9)
    assert fit.cohesion == pytest.approx(c, rel=1e-9)
    assert fit.unconfined_strength == pytest.approx(c0, rel=1e-9)


def test_hoek_brown_fit_recovers_sigma_ci_and_m_i():
    sigma_ci, m_i = 200 * MPA, 28.0
    s3 = np.array([0, 0, 5, 10, 20, 40, 60]) * MPA
    s1 = s3 + sigma_ci * np.sqrt(m_i * s3 / sigma_ci + 1)
    fit = fit_hoek_brown(s3, s1)
    assert fit.sigma_ci == pytest.approx(sigma_ci, rel=1e-9)
    assert fit.m_i == pytest.approx(m_i, rel=1e-9)
    assert fit.r2 == pytest.approx(1.0, abs=1e-12)
    assert np.allclose(fit.peak(s3), s1, rtol=1e-12)


@pytest.mark.parametrize("s3, s1, words", [
    ([0, 0], [200, 210], "two confining stresses"),
    ([0, 10], [200, math.nan], "NaN"),
    ([0, 10], [200, 5], "peak sigma_1 above"),
    ([-5, 10], [200, 260], "sigma_3 >= 0"),
])
def test_envelope_bad_input_is_one_line(s3, s1, words):
    with pytest.raises(GrainfracError, match=words):
        fit_mohr_coulomb(np.array(s3) * MPA, np.array(s1) * MPA, "study")


def test_hoek_brown_refuses_peaks_without_a_positive_sigma_ci_squared():
    # deviators 10, 200, 300 MPa: the line through their squares crosses sigma_3 = 0 below zero
    with pytest.raises(GrainfracError, match="Hoek-Brown"):
        fit_hoek_brown(np.array([0, 10, 20]) * MPA, np.array([10, 210, 320]) * MPA)


def test_analyze_ucs_writes_the_envelope_of_a_confined_study(tmp_path):
    from grainfrac_yade.cli import main
    sigma_ci, m_i = 250 * MPA, 20.0
    for k, s3 in enumerate((0.0, 10 * MPA, 20 * MPA, 40 * MPA)):
        params = load_parameters(overrides=[("confinement.stress", s3)])
        peak = s3 + sigma_ci * math.sqrt(m_i * s3 / sigma_ci + 1)
        write_run_folder(tmp_path / f"run{k}", params, summary=dict(UCS_SUMMARY, ucs_pa=peak))
    assert main(["analyze-ucs", str(tmp_path)]) == 0
    env = json.loads(json.dumps(__import__("pandas").read_csv(tmp_path / "report" / "envelope.csv").iloc[0].to_dict()))
    assert env["n_tests"] == 4
    assert env["hb_sigma_ci_pa"] == pytest.approx(sigma_ci, rel=1e-9) and env["hb_m_i"] == pytest.approx(m_i, rel=1e-9)
    assert (tmp_path / "report" / "envelope_1.png").stat().st_size > 0
    table = (tmp_path / "report" / "ucs_stats.md").read_text()
    assert "| 40 | 1 |" in table and "Hoek-Brown sigma_ci 250.0 MPa, m_i 20.0" in table


# ------------------------------------------------------------------ load and parameters (no YADE)
def test_a_confined_ratio_is_deviatoric_and_needs_the_confined_peak():
    from grainfrac_yade.commands._loads import resolve_stress
    p = load_parameters(overrides=[("confinement.stress", 20 * MPA)])
    stress, ratio, ref = resolve_stress(p, ratio=0.8, ucs=320 * MPA)
    assert stress == pytest.approx(20 * MPA + 0.8 * 300 * MPA) and ratio == pytest.approx(0.8) and ref == 320 * MPA
    stress, ratio, _ = resolve_stress(p, stress=170 * MPA, ucs=320 * MPA)
    assert ratio == pytest.approx(0.5)
    with pytest.raises(GrainfracError, match="give --ucs"):
        resolve_stress(p, ratio=0.8)
    with pytest.raises(GrainfracError, match="not above the confining stress"):
        resolve_stress(p, ratio=0.8, ucs=15 * MPA)
    with pytest.raises(GrainfracError, match="above the confining stress"):
        resolve_stress(p, stress=10 * MPA, ucs=320 * MPA)
    unconfined = load_parameters()
    assert resolve_stress(unconfined, ratio=0.5, ucs=300 * MPA)[0] == 150 * MPA   # sigma_1 / UCS as before


def test_a_negative_confinement_is_one_line(capsys):
    from grainfrac_yade.cli import main
    assert main(["ucs", "--confinement", "-5", "--out", "/nonexistent/never"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "confinement.stress" in err[0]


# ------------------------------------------------------------------ YADE
@needs_yade
@pytest.mark.yade
def test_confinement_forces_consolidation_and_a_higher_peak(tmp_path):
    from grainfrac_yade.protocols.ucs_output import run_ucs_to_folder
    from grainfrac_yade.geometry.specimen import build_specimen
    from grainfrac_yade.engines.yade.confinement import Confinement
    from grainfrac_yade.engines.yade.scene import build_scene
    p20 = load_parameters(overrides=TINY + [("confinement.stress", 20 * MPA)])
    specimen = build_specimen(p20, 1)
    scene = build_scene(specimen, p20)
    conf = Confinement(scene, 20 * MPA)
    # both walls, the whole height: 2 sigma_3 H t, inward (left +x, right -x)
    assert conf.total_force() == pytest.approx(2 * 20 * MPA * 6e-3 * specimen.thickness, rel=1e-12)
    assert sum(conf.body_force.values()) == pytest.approx(0.0, abs=1e-9 * conf.total_force())
    peaks = {}
    for s3 in (0.0, 20 * MPA):
        p = load_parameters(overrides=TINY + [("confinement.stress", s3)])
        s = run_ucs_to_folder(p, 1, tmp_path / f"s3_{s3 / MPA:g}")
        assert s["peak_reached"] and not s["numerical_failure"] and s["confining_stress_pa"] == s3
        peaks[s3] = s["ucs_pa"]
    s = json.loads((tmp_path / "s3_20" / "summary.json").read_text())
    assert s["consolidated"] and abs(s["consolidation_axial_stress_pa"] - 20 * MPA) < \
        p20.creep.stress_tolerance * 20 * MPA
    assert "deviator" in s["end_reason"]
    assert peaks[20 * MPA] > peaks[0.0] + 20 * MPA   # more than the confinement itself: friction mobilised


@pytest.mark.slow   # about 17 s: the default suite stays under about 10 min
@needs_yade
@pytest.mark.yade
def test_a_confined_creep_run_killed_mid_creep_resumes_to_the_uninterrupted_result(tmp_path):
    """The side-wall forces are YADE permanent forces, which O.save does not keep: the resume must set them
    again, or the resumed run would go on unconfined."""
    from test_resume import TINY as CREEP_TINY, _assert_same_run, _cli, _creep_args, _start_and_kill, mid_creep
    spec = dict(CREEP_TINY, ucs=320e6)
    confined = ["--confinement", "20"]
    ref = tmp_path / "uninterrupted"
    res = _cli(*_creep_args(spec, ref, *confined))
    assert res.returncode == 0, res.stderr
    s = json.loads((ref / "summary.json").read_text())
    assert s["confining_stress_pa"] == 20 * MPA and s["consolidated"] and s["failed"]
    killed = tmp_path / "killed"
    state = _start_and_kill(spec, killed, mid_creep, extra=confined)
    assert mid_creep(state)
    res = _cli("--resume", killed)
    assert res.returncode == 0, res.stderr
    _assert_same_run(ref, killed)


def test_confinement_lifetimes_group_by_law_ratio_and_sigma3():
    import pandas as pd

    from grainfrac_yade.analysis.lifetimes import confinement_lifetimes, with_confinement_columns
    runs = pd.DataFrame({
        "outcome": ["failed", "failed", "not failed", "failed", "failed", "unfinished"],
        "ratio": [0.8] * 6,
        "confinement.stress": [0.0, 0.0, 0.0, 20e6, 20e6, 20e6],
        "stress_corrosion.law": ["hillig_charles"] * 6,
        "lifetime_s": [1e6, 1e4, None, 10.0, 1000.0, None],
    })
    t = confinement_lifetimes(with_confinement_columns(runs)).set_index("confining_stress_mpa")
    assert t.loc[0.0, "n"] == 3 and t.loc[0.0, "n_failed"] == 2
    assert t.loc[0.0, "lifetime_geomean_s"] == pytest.approx(1e5)
    assert t.loc[20.0, "n"] == 2 and t.loc[20.0, "lifetime_geomean_s"] == pytest.approx(100.0)
    assert (t.loc[20.0, "lifetime_min_s"], t.loc[20.0, "lifetime_max_s"]) == (10.0, 1000.0)
