"""The lab fit's pure core (grainfrac_yade.analysis.lab_fit): mapping, design, surface and solve against closed forms."""
import numpy as np
import pytest

from grainfrac_yade.analysis import lab_fit


def test_variable_mapping_ends_and_log_midpoint():
    for v in lab_fit.FIT_VARIABLES:
        assert v.value(0.0) == pytest.approx(v.low) and v.value(1.0) == pytest.approx(v.high)
        mid = np.sqrt(v.low * v.high) if v.log else 0.5 * (v.low + v.high)
        assert v.value(0.5) == pytest.approx(mid)


def test_weibull_coordinate_is_inverse_modulus_and_zero_is_no_scatter():
    w = next(v for v in lab_fit.FIT_VARIABLES if v.name == "inverse_weibull_modulus")
    assert lab_fit.key_value(w, 0.0) == 0.0
    assert lab_fit.key_value(w, 1.0) == pytest.approx(1.0 / w.high)


def test_as_printed_point_gives_every_factor_one():
    values = dict(o.split("=") for o in lab_fit.overrides(lab_fit.AS_PRINTED))
    assert all(float(x) == 1.0 for k, x in values.items() if k != "calibration.strength_weibull_modulus")
    assert float(values["calibration.strength_weibull_modulus"]) == 0.0


def test_design_is_seeded_in_the_cube_and_starts_as_printed():
    a, b = lab_fit.design(8, 3), lab_fit.design(8, 3)
    assert np.array_equal(a, b) and a.shape == (9, 5)
    assert np.array_equal(a[0], lab_fit.AS_PRINTED)
    assert a.min() >= 0.0 and a.max() <= 1.0
    # Latin hypercube: each coordinate of the n points has one point in each of n equal strata
    for j in range(5):
        assert sorted(np.floor(a[1:, j] * 8).astype(int)) == list(range(8))
    with pytest.raises(ValueError):
        lab_fit.design(3, 1)


def test_surface_recovers_an_exact_linear_law_and_drops_nan_per_observable():
    rng = np.random.default_rng(0)
    u = rng.random((12, 5))
    slope = rng.normal(size=(5, 5))
    y = 0.3 + u @ slope.T
    y[2, 4] = np.nan
    s = lab_fit.fit_surrogate(u, y)
    assert np.allclose(s.slope, slope, atol=1e-10) and np.allclose(s.intercept, 0.3, atol=1e-10)
    assert np.allclose(s.r2, 1.0) and s.n_points.tolist() == [12, 12, 12, 12, 11]


def test_a_square_term_recovers_a_quadratic_law_exactly():
    """y = 0.3 + slope u + c u_4^2 (the Weibull axis curved): recovered to rounding; the linear surface on
    the same points is not exact, and a surface without square terms predicts as before."""
    rng = np.random.default_rng(2)
    u = rng.random((15, 5))
    slope = rng.normal(size=(5, 5))
    c = np.array([0.0, 0.1, -2.0, 0.5, 0.0])
    y = 0.3 + u @ slope.T + np.outer(u[:, 4] ** 2, c)
    s = lab_fit.fit_surrogate(u, y, squared=[4])
    assert np.allclose(s.slope, slope, atol=1e-9) and np.allclose(s.curvature[:, 0], c, atol=1e-9)
    assert np.allclose(s.predict(u[3]), y[3], atol=1e-9) and np.allclose(s.r2, 1.0)
    linear = lab_fit.fit_surrogate(u, y)
    assert linear.r2[2] < 0.999 and linear.squared == ()
    assert np.allclose(linear.predict(u[3]), linear.intercept + linear.slope @ u[3])


def test_solve_hits_targets_reachable_inside_the_cube():
    targets = lab_fit.lab_targets()
    rng = np.random.default_rng(1)
    slope = np.eye(5) + 0.1 * rng.normal(size=(5, 5))
    u_true = np.array([0.2, 0.7, 0.4, 0.9, 0.5])
    intercept = targets.scaled_value - slope @ u_true
    s = lab_fit.Surrogate(intercept, slope, np.ones(5), np.zeros(5), np.full(5, 12))
    u, r = lab_fit.solve(s, targets)
    assert np.allclose(u, u_true, atol=1e-6) and np.abs(r).max() < 1e-6


def test_solve_stays_in_bounds_when_targets_are_out_of_reach():
    targets = lab_fit.lab_targets()
    s = lab_fit.Surrogate(targets.scaled_value - 10 * targets.scaled_spread, np.eye(5) * targets.scaled_spread,
                          np.ones(5), np.zeros(5), np.full(5, 12))
    u, r = lab_fit.solve(s, targets)
    # y = y* - 10 s + s u: the best is u = 1 on every axis, 9 spreads short
    assert np.allclose(u, 1.0) and np.allclose(r, -9.0)


def test_targets_are_the_lab_csv_in_fit_scale():
    t = lab_fit.lab_targets()
    assert t.value.tolist() == [200e6, 69e9, 9.0e6, 0.45, 0.75]
    assert t.scaled_value[0] == pytest.approx(np.log(200e6))
    assert t.scaled_spread[2] == pytest.approx(np.log1p(0.3 / 9.0))
    assert lab_fit.lab_targets(ucs_value=234.5e6).value[0] == 234.5e6


def _synthetic_rows(points, law, seeds=(1, 2)):
    """Rows as the study's design CSV holds them, measured = law(u) (Pa and 1) on every seed."""
    rows = []
    for i, u in enumerate(points):
        ucs, young, sigma_t, ci, cd = law(u)
        coords = {f"u_{v.name}": str(x) for v, x in zip(lab_fit.FIT_VARIABLES, u)}
        for seed in seeds:
            rows.append({"point": str(i), **coords, "test": "ucs", "seed": str(seed), "ucs_pa": str(ucs),
                         "young_pa": str(young), "ci_over_ucs": str(ci), "cd_over_ucs": str(cd),
                         "crack_initiation_volumetric_pa": str(ci * ucs)})
            rows.append({"point": str(i), **coords, "test": "brazilian", "seed": str(seed), "broken_total": "100",
                         "tensile_strength_pa": str(sigma_t)})
    return rows


def test_study_fit_and_preset_on_a_known_linear_law(tmp_path):
    """The study's fit reads its CSV, finds the point where a log-linear law meets the lab's values, and
    writes a preset that loads with those keys and the measured UCS as its reference."""
    import csv
    from grainfrac_yade.params import load_parameters
    from studies import lab_calibration as study
    targets = lab_fit.lab_targets()
    rng = np.random.default_rng(2)
    slope = np.eye(5) * targets.scaled_spread * 20 + 0.01 * rng.normal(size=(5, 5)) * targets.scaled_spread
    u_true = np.array([0.3, 0.6, 0.5, 0.8, 0.2])
    intercept = targets.scaled_value - slope @ u_true

    def law(u):
        return lab_fit.unscaled(intercept + slope @ u)
    path = tmp_path / "design.csv"
    rows = _synthetic_rows(lab_fit.design(14, 1), law)
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(study.POINT_FIELDS))
        w.writeheader()
        w.writerows({k: r.get(k, "") for k in study.POINT_FIELDS} for r in rows)
    result = study.fit(path)
    u = np.array([result["candidate_u"][v.name] for v in lab_fit.FIT_VARIABLES])
    assert np.allclose(u, u_true, atol=1e-6)
    assert all(abs(r) < 1e-6 for r in result["predicted_weighted_residuals"].values())
    verify = _synthetic_rows([u_true], law, seeds=(1, 2, 3))
    preset = tmp_path / "ldb_lab.toml"
    preset.write_text(study.preset_text(result, verify))
    p = load_parameters(extra_files=[str(preset)])
    expected = dict(o.split("=") for o in lab_fit.overrides(u))
    assert p.calibration.strength_scale == pytest.approx(float(expected["calibration.strength_scale"]), rel=1e-5)
    assert p.calibration.shear_stiffness_ratio_scale == pytest.approx(
        float(expected["calibration.shear_stiffness_ratio_scale"]), rel=1e-5)
    assert p.calibration.reference_ucs == pytest.approx(200e6, rel=1e-5)
    assert p.resolution.grain_model == "fem"
    # the end criteria the verification ran with travel with the preset
    assert (p.ucs.stop_min_strain, p.brazilian.stop_min_strain) == (2e-4, 2e-4)


def test_best_picks_the_measured_point_nearest_the_lab_and_skips_incomplete_points(tmp_path):
    """best: of three measured points, the one at the lab's values (cost 0), not the one nearer in four
    observables whose disc did not split (no sigma_t: no cost); its rows become the verification's start."""
    import csv
    import json
    from studies import lab_calibration as study
    values = {0: [260e6, 75e9, 30e6, 0.60, 0.95], 1: [200e6, 69e9, 9e6, 0.45, 0.75], 2: [200e6, 69e9, 9e6, 0.45, 0.75]}
    pts = [lab_fit.AS_PRINTED, np.full(5, 0.25), np.full(5, 0.75)]
    rows = _synthetic_rows(pts, lambda u: values[[tuple(q) for q in pts].index(tuple(u))])
    for r in rows:
        if r["point"] == "2" and r["test"] == "brazilian":
            r["broken_total"] = "1"
        if r["point"] == "1" and r["test"] == "ucs":
            r["ucs_pa"] = str(1.1 * 200e6)      # +0.95 lab spreads in ln UCS
    design = tmp_path / "design.csv"
    with design.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(study.POINT_FIELDS))
        w.writeheader()
        w.writerows({k: r.get(k, "") for k in study.POINT_FIELDS} for r in rows)
    out, verify = tmp_path / "best.json", tmp_path / "verify.csv"
    assert study.main(["best", "--csv", str(design), "--json", str(out), "--verify-csv", str(verify)]) == 0
    best = json.loads(out.read_text())
    assert best["design_point"] == 1 and best["measured_cost_per_point"]["2"] is None
    assert best["predicted_weighted_residuals"]["ucs"] == pytest.approx(np.log(1.1) / np.log1p(22 / 200))
    assert [float(best["candidate_u"][v.name]) for v in lab_fit.FIT_VARIABLES] == [0.25] * 5
    copied = study._rows(verify)
    assert len(copied) == 4 and {r["point"] for r in copied} == {"-1"}
    assert "design point 1" in study.preset_text(best, copied)


def test_a_brazilian_peak_without_a_split_is_left_out():
    """Fewer bonds broken than grains on the diameter: a seating transient, not a tensile strength."""
    from studies import lab_calibration as study
    u = lab_fit.AS_PRINTED
    rows = _synthetic_rows([u], lambda u: [200e6, 69e9, 9e6, 0.45, 0.75], seeds=(1, 2))
    bz = [r for r in rows if r["test"] == "brazilian"]
    bz[0]["broken_total"], bz[0]["tensile_strength_pa"] = "1", "1.3e6"
    _, _, y = study.point_means(rows)
    assert y[0, 2] == 9e6
    bz[1]["broken_total"] = str(study.MIN_SPLIT_BREAKS - 1)
    _, _, y = study.point_means(rows)
    assert np.isnan(y[0, 2])


def test_crack_volumetric_strain_onset_of_a_known_history():
    """Elastic to sigma_ci = 90 MPa, then a crack dilation growing as (sigma - sigma_ci)^2: the lab's
    crack-initiation reading finds where the dilation reaches 2 % of its peak value, to the stress step."""
    from grainfrac_yade.analysis.ucs_analysis import crack_initiation_volumetric_stress, crack_volumetric_strain
    young, poisson, ci = 70e9, 0.25, 90e6
    stress = np.linspace(0.0, 200e6, 401)          # 0.5 MPa a row
    ea = stress / young
    crack = 1e-3 * np.clip((stress - ci) / 110e6, 0.0, None) ** 2
    el = -poisson * stress / young - crack        # cracks open laterally: area strain falls by `crack`
    assert np.allclose(crack_volumetric_strain(stress, ea, el, young, poisson), -crack, atol=1e-15)
    found = crack_initiation_volumetric_stress(stress, ea, el, young, poisson)
    # 2 % of the peak dilation is reached at ci + 110 MPa sqrt(0.02) = 105.6 MPa
    assert found == pytest.approx(ci + 110e6 * np.sqrt(0.02), abs=0.5e6)
    assert np.isnan(crack_initiation_volumetric_stress(stress, ea, -poisson * stress / young, young, poisson))


def test_a_ucs_test_without_a_modulus_is_left_out():
    """A UCS run that stopped in its seating has no fitted E: none of its measures enter the fit."""
    from studies import lab_calibration as study
    rows = _synthetic_rows([lab_fit.AS_PRINTED], lambda u: [200e6, 69e9, 9e6, 0.45, 0.75], seeds=(1, 2))
    bad = next(r for r in rows if r["test"] == "ucs" and r["seed"] == "2")
    bad["ucs_pa"], bad["young_pa"] = "11.5e6", ""
    _, _, y = study.point_means(rows)
    assert y[0, 0] == 200e6 and y[0, 1] == 69e9


def test_reseat_runs_the_seating_stops_again_and_keeps_their_old_rows(tmp_path, monkeypatch):
    """A UCS test without a modulus or a disc with fewer than MIN_SPLIT_BREAKS breaks is a seating stop:
    its (point, seed) runs again with the end criteria's minimum strain; the old rows move to the side
    file, every other row stays as it was."""
    from studies import lab_calibration as study
    csv_path = tmp_path / "design.csv"
    u = lab_fit.design(6, 1)
    good = [{"point": p, "test": t, "seed": 1, "young_pa": 7e10 if t == "ucs" else "", "ucs_pa": 2e8,
             "broken_total": "" if t == "ucs" else 300, "tensile_strength_pa": 2e7} for p in (0, 1) for t in ("ucs", "brazilian")]
    stopped = [{"point": 2, "test": "ucs", "seed": 1, "young_pa": "", "ucs_pa": 1.1e7, "broken_total": ""},
               {"point": 2, "test": "brazilian", "seed": 1, "broken_total": 1, "tensile_strength_pa": 1.3e6}]
    study._write(csv_path, good + stopped)
    assert study.seating_stops(study._rows(csv_path)) == {(2, 1)}
    calls = []

    def fake_measure(files, overrides, seed, prefix, **kw):
        calls.append((list(overrides), seed, prefix.name))
        return [{"test": "ucs", "seed": seed, "young_pa": 7.1e10, "ucs_pa": 2.1e8, "cpu_s": 1.0},
                {"test": "brazilian", "seed": seed, "broken_total": 250, "tensile_strength_pa": 1.8e7, "cpu_s": 1.0}]
    monkeypatch.setattr(study, "measure", fake_measure)
    assert study.reseat(csv_path, tmp_path, 6, 1) == [(2, 1)]
    assert [c[1:] for c in calls] == [(1, "point2_seed1")]
    assert set(study.STOP_KEYS) <= set(calls[0][0]) and set(lab_fit.overrides(u[2])) <= set(calls[0][0])
    rows = study._rows(csv_path)
    assert len(rows) == 6 and not study.seating_stops(rows)
    assert [r["broken_total"] for r in study._rows(csv_path.with_name("design.csv.seating.csv"))] == ["", "1"]
    assert study.reseat(csv_path, tmp_path, 6, 1) == []   # nothing left to run


@pytest.mark.parametrize("table, n_rows", [("ldb_lab_creep.table", 18), ("ldb_lab_rate_ucs.table", 3)])
def test_the_preset_tables_run_the_preset(table, n_rows):
    """Every row of the preset's creep and rate tables gives the model of params/presets/ldb_lab.toml: the
    same [resolution], [numerics] and [calibration] values, so its lifetimes and strengths are the preset's."""
    import dataclasses
    import tomllib

    from conftest import ROOT
    from grainfrac_yade.params import load_parameters
    from grainfrac_yade.runs.batchrun import read_table_rows
    preset_file = ROOT / "params" / "presets" / "ldb_lab.toml"
    preset = load_parameters(extra_files=[str(preset_file)])
    sections = [name for name in tomllib.loads(preset_file.read_text()) if name in ("resolution", "numerics",
                                                                                    "calibration")]
    columns, rows, problems = read_table_rows(ROOT / "params" / table)
    assert not problems and len(rows) == n_rows
    for cells in rows.values():
        keys = [c for c in columns if c.split(".")[0] in sections]
        row = load_parameters(overrides=[f"{k}={cells[k].strip(chr(39))}" for k in keys])
        for name in sections:
            assert dataclasses.asdict(getattr(row, name)) == dataclasses.asdict(getattr(preset, name)), name
