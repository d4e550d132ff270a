"""Degradation laws: Hillig-Charles on strength (paper Eq. 5-7) and the area law, closed forms and limits
(the laws' module functions; the law objects, the threshold and the normalised exponent: tests/test_law.py)."""
import itertools
import math
import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from grainfrac_yade.law import _common, area, hillig_charles

# the laws' functions under one name, as the tests below call them
c = SimpleNamespace(**{k: getattr(m, k) for m in (_common, hillig_charles, area) for k in dir(m) if not k.startswith("_")})

B1, B2 = 1e-3, 1e-7  # paper section 4.1: beta1 [Pa/s], beta2 [1/Pa]
TAN55 = math.tan(math.radians(55.0))  # K-feldspar/K-feldspar friction angle, Table 2


pytestmark = pytest.mark.usefixtures("strict_floats")  # conftest: float warnings are errors


# ------------------------------------------------------------------ strength mode (paper)
def test_tension_closed_form():
    j0, s = 20e6, 15e6
    t, mode = c.time_to_failure(j0, 1e9, s, 0.0, 0.0, B1, B2)
    assert t == pytest.approx((j0 - s) / (B1 * math.exp(B2 * s)), rel=1e-12)
    assert mode == c.MODE_TENSION


def test_shear_closed_form_with_compression():
    jc, sigma, tau = 52e6, -100e6, 150e6  # s_n = 100 MPa compressive
    s_n = -sigma
    t, mode = c.time_to_failure(23e6, jc, sigma, tau, TAN55, B1, B2)
    assert t == pytest.approx((jc - (tau - s_n * TAN55)) / (B1 * math.exp(B2 * tau)), rel=1e-12)
    assert mode == c.MODE_SHEAR


def test_already_failed_bonds_take_no_time():
    t, mode = c.time_to_failure([20e6, 20e6, 20e6, 52e6], [52e6, 52e6, 52e6, 10e6],
                                [20e6, 25e6, 0.0, -10e6], [0.0, 0.0, 60e6, 30e6], TAN55, B1, B2)
    assert np.all(t == 0.0)
    assert list(mode) == [c.MODE_TENSION, c.MODE_TENSION, c.MODE_SHEAR, c.MODE_SHEAR]
    ten, sh = c.failed_now([20e6, 20e6, 20e6, 52e6], [52e6, 52e6, 52e6, 10e6],
                           [20e6, 25e6, 0.0, -10e6], [0.0, 0.0, 60e6, 30e6], TAN55)
    assert np.all(ten | sh)


def test_compression_only_bond_never_fails():
    """sigma < 0 cannot fail in tension (J^T >= 0); tau < s_n tan(phi) cannot fail in shear."""
    t, mode = c.time_to_failure(20e6, 50e6, -30e6, 10e6, TAN55, B1, B2)
    assert np.isinf(t) and mode == c.MODE_NEVER


def test_shear_strength_is_mohr_coulomb_and_drops_in_tension():
    assert c.shear_strength(50e6, -20e6, TAN55) == pytest.approx(50e6 + 20e6 * TAN55, rel=1e-15)
    assert c.shear_strength(50e6, 10e6, TAN55) < 50e6


@pytest.mark.parametrize("channel", ["tension", "shear"])
def test_degrade_over_closed_form_time_reaches_the_stress(channel):
    jt, jc = 20e6, 52e6
    sigma, tau = (15e6, 0.0) if channel == "tension" else (-100e6, 150e6)
    t, _ = c.time_to_failure(jt, jc, sigma, tau, TAN55, B1, B2)
    new_t, new_c = c.degrade(jt, jc, sigma, tau, t, B1, B2)
    if channel == "tension":
        assert new_t == pytest.approx(sigma, rel=1e-12)
    else:
        assert new_c == pytest.approx(tau - (-sigma) * TAN55, rel=1e-12)


def test_degrade_is_exact_for_frozen_stress_and_floors_at_zero():
    jt, jc, sigma, tau = 20e6, 52e6, 5e6, 40e6
    a = c.degrade(*c.degrade(jt, jc, sigma, tau, 3e5, B1, B2), sigma, tau, 7e5, B1, B2)
    b = c.degrade(jt, jc, sigma, tau, 1e6, B1, B2)
    np.testing.assert_allclose(a, b, rtol=1e-12)
    assert b[0] == pytest.approx(jt - B1 * math.exp(B2 * sigma) * 1e6, rel=1e-12)
    assert c.degrade(jt, jc, sigma, tau, 0.0, B1, B2) == (jt, jc)
    assert c.degrade(jt, jc, sigma, tau, 1e30, B1, B2) == (0.0, 0.0)


def test_rate_is_the_paper_law_and_vectorised():
    s = np.array([[0.0, 20e6], [-50e6, 150e6]])
    np.testing.assert_allclose(c.degradation_rate(s, B1, B2), B1 * np.exp(B2 * s), rtol=1e-14)
    t, mode = c.time_to_failure(20e6, 52e6, np.array([5e6, 10e6, 15e6]), 0.0, TAN55, B1, B2)
    assert t.shape == mode.shape == (3,)


def test_rising_stress_gives_shorter_lifetimes():
    scale = np.linspace(0.6, 1.0, 9)
    t, _ = c.time_to_failure(52e6, 52e6, -100e6 * scale, 150e6 * scale, TAN55, B1, B2)
    assert np.all(np.diff(t) < 0)


@pytest.mark.parametrize("beta1, beta2, name", [(0.0, B2, "beta1"), (-1.0, B2, "beta1"),
                                                (B1, -1e-7, "beta2"), (B1, math.nan, "beta2")])
def test_bad_law_constants_raise(beta1, beta2, name):
    with pytest.raises(ValueError, match=name):
        c.degradation_rate(1e6, beta1, beta2)


def test_negative_shear_stress_is_refused():
    with pytest.raises(ValueError, match="shear_stress"):
        c.time_to_failure(20e6, 52e6, 0.0, -1.0, TAN55, B1, B2)


EXTREME_STRESSES = [0.0, 5e-324, 1e-300, 1.0, 1e6, -1e12, 1e12, -1e300, 1e300, -1.7e308, 1.7e308]


@pytest.mark.parametrize("beta2", [0.0, B2, 1.0, 1e10, 1e300])
@pytest.mark.parametrize("strength", [0.0, 5e-324, 1e-300, 20e6, 1e300])
def test_no_overflow_or_nan_in_strength_mode(beta2, strength):
    sig, tau = np.array(list(itertools.product(EXTREME_STRESSES, repeat=2))).T
    tau = np.abs(tau)
    for beta1 in (1e-300, B1, 1e300):
        assert np.all(np.isfinite(c.degradation_rate(sig, beta1, beta2)))
        assert np.all(np.isfinite(c.degrade(strength, strength, sig, tau, 1e6, beta1, beta2)))
        t, mode = c.time_to_failure(strength, strength, sig, tau, TAN55, beta1, beta2)
        assert not np.any(np.isnan(t)) and np.all(t >= 0)
        assert np.array_equal(np.isinf(t), mode == c.MODE_NEVER)  # inf only as 'never'
        never_t = sig < 0  # J^T cannot reach a compressive sigma
        never_s = c.shear_strength(0.0, sig, TAN55) > tau  # friction alone carries tau
        assert np.all(np.isinf(t) <= (never_t & never_s))


# ------------------------------------------------------------------ area mode
JT0, JC0 = 23e6, 52e6  # K-feldspar/K-feldspar intrinsic strengths [Pa], Table 2
HUGE = 1e300  # an intrinsic strength that makes its channel's rate beta1/HUGE negligible


def test_area_rate_at_full_area_is_the_paper_relative_rate():
    p, q = 8e6, 30e6
    expected = B1 * math.exp(B2 * p) / JT0 + B1 * math.exp(B2 * q) / JC0
    assert c.area_rate(1.0, p, q, JT0, JC0, B1, B2) == pytest.approx(expected, rel=1e-14)
    a = 0.5  # stresses on what remains rise as 1/a
    expected = B1 * math.exp(B2 * p / a) / JT0 + B1 * math.exp(B2 * q / a) / JC0
    assert c.area_rate(a, p, q, JT0, JC0, B1, B2) == pytest.approx(expected, rel=1e-14)


def test_area_failure_point_closed_form():
    p, q = np.array([10e6, -50e6, 8e6, -50e6]), np.array([0.0, 100e6, 30e6, 10e6])
    a_fail, mode = c.area_failure_point(p, q, JT0, JC0, TAN55)
    s_n0 = -p
    a_t, a_s = p / JT0, (q - s_n0 * TAN55) / JC0
    assert a_fail[0] == pytest.approx(max(a_t[0], a_s[0]), rel=1e-15) and mode[0] == c.MODE_TENSION
    assert a_fail[1] == pytest.approx(a_s[1], rel=1e-15) and mode[1] == c.MODE_SHEAR
    assert a_fail[2] == pytest.approx(a_s[2], rel=1e-15) and mode[2] == c.MODE_SHEAR
    assert a_fail[3] == 0.0 and mode[3] == c.MODE_CORRODED  # friction carries q: corrodes away
    ten, sh = c.failed_now_area(a_fail[:3], p[:3], q[:3], JT0, JC0, TAN55)
    assert np.all(ten | sh)
    ten, sh = c.failed_now_area(a_fail[:3] * (1 + 1e-9), p[:3], q[:3], JT0, JC0, TAN55)
    assert not np.any(ten | sh)


@pytest.mark.parametrize("a_from, a_to", [(1.0, 0.8), (1.0, 0.3), (0.9, 0.0), (0.6, 0.59)])
@pytest.mark.parametrize("channel", ["tension", "shear"])
def test_area_quadrature_matches_single_channel_closed_form(a_from, a_to, channel):
    force = 2e7 if channel == "tension" else 1.5e8
    j0 = JT0 if channel == "tension" else JC0
    args = (force, 0.0, j0, HUGE) if channel == "tension" else (0.0, force, HUGE, j0)
    t = c.area_time(a_from, a_to, *args, B1, B2)
    ref = c.area_time_single_channel(a_from, a_to, force, j0, B1, B2)
    assert t == pytest.approx(ref, rel=1e-10)


def test_single_channel_closed_form_at_zero_force_is_linear():
    t = c.area_time_single_channel(1.0, 0.25, 0.0, JT0, B1, B2)
    assert t == pytest.approx((1.0 - 0.25) * JT0 / B1, rel=1e-15)


BONDS = [  # (a0, p, q, tan_phi): both channels active, compressed shear, tension-led, a0 < 1
    (1.0, 8e6, 30e6, TAN55), (1.0, -50e6, 100e6, TAN55), (1.0, 18e6, 5e6, TAN55),
    (0.9, 5e6, 35e6, 1.0),
]


def _ivp_failure_time(a0, p, q, tphi):
    a_fail, _ = c.area_failure_point(p, q, JT0, JC0, tphi)
    rhs = lambda t, a: [-c.area_rate(min(max(a[0], 1e-6), 1.0), p, q, JT0, JC0, B1, B2)]
    hit = lambda t, a: a[0] - a_fail
    hit.terminal = True
    t_guess = a0 / c.area_rate(a0, p, q, JT0, JC0, B1, B2)
    with np.errstate(all="ignore"), warnings.catch_warnings():  # the integrator's own arithmetic
        warnings.simplefilter("ignore")
        sol = solve_ivp(rhs, (0.0, 10 * t_guess), [a0], method="DOP853", events=hit,
                        rtol=1e-11, atol=1e-14)
    return sol.t_events[0][0]


@pytest.mark.parametrize("bond", BONDS)
def test_area_time_to_failure_matches_solve_ivp(bond):
    a0, p, q, tphi = bond
    t, mode = c.time_to_failure_area(a0, p, q, JT0, JC0, tphi, B1, B2)
    assert mode in (c.MODE_TENSION, c.MODE_SHEAR)
    assert t == pytest.approx(_ivp_failure_time(*bond), rel=1e-6)


@pytest.mark.parametrize("bond", BONDS)
def test_degrade_area_over_failure_time_reaches_failure_point(bond):
    a0, p, q, tphi = bond
    t, _ = c.time_to_failure_area(a0, p, q, JT0, JC0, tphi, B1, B2)
    a_fail, _ = c.area_failure_point(p, q, JT0, JC0, tphi)
    assert c.degrade_area(a0, p, q, JT0, JC0, t, B1, B2) == pytest.approx(a_fail, rel=1e-9)
    half = c.degrade_area(a0, p, q, JT0, JC0, t / 2, B1, B2)  # frozen forces: steps compose
    assert c.degrade_area(half, p, q, JT0, JC0, t / 2, B1, B2) == pytest.approx(a_fail, rel=1e-9)
    assert c.area_time(a0, half, p, q, JT0, JC0, B1, B2) == pytest.approx(t / 2, rel=1e-9)


def test_degrade_area_limits():
    assert c.degrade_area(0.7, 8e6, 30e6, JT0, JC0, 0.0, B1, B2) == 0.7
    assert c.degrade_area(0.7, 8e6, 30e6, JT0, JC0, 1e30, B1, B2) == 0.0  # corroded away


def test_corroding_bond_reaches_zero_area():
    p, q = -50e6, 10e6  # friction carries the shear: no criterion is ever met
    t, mode = c.time_to_failure_area(1.0, p, q, JT0, JC0, TAN55, B1, B2)
    assert mode == c.MODE_CORRODED and np.isfinite(t)
    assert c.degrade_area(1.0, p, q, JT0, JC0, t * (1 - 1e-6), B1, B2) > 0
    assert c.degrade_area(1.0, p, q, JT0, JC0, t * (1 + 1e-6), B1, B2) == 0.0


def test_area_rising_load_gives_shorter_lifetimes():
    scale = np.linspace(0.5, 1.0, 11)
    t, _ = c.time_to_failure_area(1.0, -50e6 * scale, 100e6 * scale, JT0, JC0, TAN55, B1, B2)
    assert np.all(np.diff(t) < 0)


def test_area_arguments_are_validated():
    with pytest.raises(ValueError, match="area_fraction"):
        c.area_rate(1.5, 0.0, 0.0, JT0, JC0, B1, B2)
    with pytest.raises(ValueError, match="cohesion0"):
        c.area_time(1.0, 0.5, 0.0, 0.0, JT0, 0.0, B1, B2)
    with pytest.raises(ValueError, match="dt"):
        c.degrade_area(1.0, 0.0, 0.0, JT0, JC0, -1.0, B1, B2)


@pytest.mark.parametrize("beta2", [0.0, B2, 1.0, 1e300])
@pytest.mark.parametrize("strength0", [5e-324, 1e-300, 20e6, 1.7e308])
def test_no_overflow_or_nan_in_area_mode(beta2, strength0):
    vals = [0.0, 1e-300, 1e6, -1e12, 1e12, -1e300, 1e300]
    p, q = np.array(list(itertools.product(vals, repeat=2))).T
    q = np.abs(q)
    for a in (1.0, 1e-10, 5e-324):
        for beta1 in (1e-300, B1, 1e300):
            assert np.all(np.isfinite(c.area_rate(a, p, q, strength0, strength0, beta1, beta2)))
            t, _ = c.time_to_failure_area(a, p, q, strength0, strength0, TAN55, beta1, beta2)
            assert np.all(np.isfinite(t)) and np.all(t >= 0)
            new = c.degrade_area(a, p, q, strength0, strength0, 1e3, beta1, beta2)
            assert np.all((new >= 0) & (new <= a))


# ------------------------------------------------------------------ non-finite input and overflow
NON_FINITE = [math.nan, math.inf, -math.inf]
# one call per public function; ``bad`` is put in the middle of three bonds
LAW_CALLS = {
    "degradation_rate": lambda bad: c.degradation_rate([1e6, bad, 2e6], B1, B2),
    "failed_now": lambda bad: c.failed_now(20e6, 52e6, [0.0, bad, 1e6], 1e6, TAN55),
    "degrade": lambda bad: c.degrade(20e6, 52e6, [0.0, bad, 1e6], 1e6, 1e3, B1, B2),
    "time_to_failure": lambda bad: c.time_to_failure(20e6, 52e6, [0.0, bad, 1e6], 1e6, TAN55, B1, B2),
    "area_rate": lambda bad: c.area_rate(1.0, [0.0, bad, 1e6], 1e6, JT0, JC0, B1, B2),
    "area_time": lambda bad: c.area_time(1.0, 0.5, [0.0, bad, 1e6], 1e6, JT0, JC0, B1, B2),
    "time_to_failure_area": lambda bad: c.time_to_failure_area(1.0, [0.0, bad, 1e6], 1e6, JT0, JC0, TAN55, B1, B2),
    "degrade_area": lambda bad: c.degrade_area(1.0, [0.0, bad, 1e6], 1e6, JT0, JC0, 1e3, B1, B2),
    "area_failure_point": lambda bad: c.area_failure_point([0.0, bad, 1e6], 1e6, JT0, JC0, TAN55),
    "failed_now_area": lambda bad: c.failed_now_area(1.0, [0.0, bad, 1e6], 1e6, JT0, JC0, TAN55),
}
ARG_NAME = {"degradation_rate": "stress", "failed_now": "normal_stress", "degrade": "normal_stress",
            "time_to_failure": "normal_stress"}


@pytest.mark.parametrize("bad", NON_FINITE)
@pytest.mark.parametrize("name", LAW_CALLS)
def test_a_non_finite_stress_is_a_numerical_failure_never_a_time_or_verdict(name, bad):
    """A NaN or infinite stress (a DEM that blew up) gives no time, no strength, no failure verdict."""
    from grainfrac_yade.errors import NumericalFailure
    arg = ARG_NAME.get(name, "normal_force_per_area0")
    with pytest.raises(NumericalFailure) as err:
        LAW_CALLS[name](bad)
    assert str(err.value) == f"{arg} is NaN or infinite at 1 of 3 bond(s) (first: bond 1, {bad})"


@pytest.mark.parametrize("bad", NON_FINITE)
def test_a_non_finite_shear_stress_or_strength_is_refused_too(bad):
    from grainfrac_yade.errors import NumericalFailure
    with pytest.raises(NumericalFailure, match="^shear_stress is NaN or infinite"):
        c.time_to_failure(20e6, 52e6, 0.0, [1e6, abs(bad)], TAN55, B1, B2)
    with pytest.raises(NumericalFailure, match="^tensile_strength is NaN or infinite"):
        c.degrade([bad, 20e6], 52e6, 0.0, 1e6, 1e3, B1, B2)


def test_beta2_times_stress_of_1e4_gives_capped_finite_rates_and_times():
    """beta2 sigma = 1e4: exp() would overflow; the exponent is clipped at LOG_LIMIT (no warning:
    this module runs with float warnings as errors), so rate = RATE_CAP and t = gap / RATE_CAP."""
    beta2, sigma, jt = 1e-3, 1e7, 2e7          # beta2 * sigma = 1e4; ln(beta1) + 1e4 > LOG_LIMIT
    assert c.degradation_rate(sigma, B1, beta2) == c.RATE_CAP == math.exp(c.LOG_LIMIT)
    t, mode = c.time_to_failure(jt, 52e6, sigma, 0.0, TAN55, B1, beta2)
    assert mode == c.MODE_TENSION and t == pytest.approx((jt - sigma) / c.RATE_CAP, rel=1e-12) and t > 0
    new_t, new_c = c.degrade(jt, 52e6, sigma, 0.0, 1e-300, B1, beta2)   # loss RATE_CAP * 1e-300 ~ 1e4 Pa
    assert new_t == pytest.approx(jt - c.RATE_CAP * 1e-300, rel=1e-12)
    assert new_c == pytest.approx(52e6 - B1 * 1e-300, rel=1e-12)        # tau = 0: the plain law
    t_shear, mode = c.time_to_failure(jt, 52e6, -1e12, sigma, TAN55, B1, beta2)
    assert np.isinf(t_shear) and mode == c.MODE_NEVER                      # friction carries tau: never
    # area mode: p = 1e7 Pa at beta2 = 1e-3 1/Pa, both channels near or at the cap
    t_area, mode = c.time_to_failure_area(1.0, sigma, sigma, jt, 52e6, TAN55, B1, beta2)
    a_fail, _ = c.area_failure_point(sigma, sigma, jt, 52e6, TAN55)
    assert np.isfinite(t_area) and 0 < t_area <= (1.0 - a_fail) / (c.RATE_CAP * B1 / 52e6) * (1 + 1e-9)
    assert np.isfinite(c.area_time_single_channel(1.0, 0.5, sigma, jt, B1, beta2))
    assert 0 <= c.degrade_area(1.0, sigma, sigma, jt, 52e6, 1e-300, B1, beta2) <= 1.0
