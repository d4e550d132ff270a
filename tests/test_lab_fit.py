"""The lab fit's pure core (grainfrac_yade.lab_fit): mapping, design, surface and solve against closed forms."""
import numpy as np
import pytest

from grainfrac_yade import lab_fit


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
