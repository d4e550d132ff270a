"""The degradation-law package: each law against its closed form, the activation threshold, the
strength-normalised exponent, the interface built from the parameters (pure numpy, no YADE)."""
import math
import warnings

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

from grainfrac_yade.clocks import EventClock
from grainfrac_yade.errors import ParameterError
from grainfrac_yade.law import (LAW_NAMES, MODE_NEVER, MODE_SHEAR, MODE_TENSION, DegradationLaw, Stresses, build_law,
                                creep_step, failed_now, law_module)
from grainfrac_yade.law.hillig_charles import HilligCharles
from grainfrac_yade.law.normalised import Normalised, closed_form_time
from grainfrac_yade.params import load_parameters

B1, B2 = 1e-3, 1e-7           # paper section 4.1
B2N = 16.0                    # the shipped beta2_normalised
JT, JC = 23e6, 52e6           # K-feldspar/K-feldspar, Table 2
TAN55 = math.tan(math.radians(55.0))

pytestmark = pytest.mark.usefixtures("strict_floats")  # conftest: float warnings are errors


def one_bond(law, sigma, tau, jt=JT, jc=JC, tphi=TAN55):
    state = law.initial_state(np.array([jt]), np.array([jc]), np.array([tphi]))
    return state, Stresses.of([0], [sigma], [tau])


def run_to_failure(law, state, stresses, limit=math.inf):
    clock = EventClock(0.1, limit)
    while True:
        step = creep_step(law, clock, state, stresses)
        if step.stalled:
            return clock, state, step
        clock.advance(step.dt, step.failing)
        state = step.state
        if len(step.failing) or clock.finished:
            return clock, state, step


# ------------------------------------------------------------------ paper Eq. 7 (hillig_charles)
def test_hillig_charles_one_bond_fails_at_the_closed_form_time():
    """t = (J0 - s) / (beta1 exp(beta2 s)) for a bond in tension at constant stress s."""
    s = 15e6
    law = HilligCharles(B1, B2)
    clock, state, step = run_to_failure(law, *one_bond(law, s, 0.0))
    assert clock.creep_time == pytest.approx((JT - s) / (B1 * math.exp(B2 * s)), rel=1e-12)
    assert list(step.modes) == [MODE_TENSION] and state["tensile_strength"][0] == s


def test_threshold_below_it_a_bond_never_fails_above_it_the_closed_form_holds():
    """Activation threshold r: a channel corrodes only while s >= r x its strength.  Tension at 0.3 J^T with
    r = 0.4: never (the creep-time limit ends it, strengths untouched); at 0.5 J^T: Eq. 7's closed form."""
    law = HilligCharles(B1, B2, threshold_ratio=0.4)
    below = one_bond(law, 0.3 * JT, 0.0)
    t, mode = law.time_to_failure(*below)
    assert np.isinf(t[0]) and mode[0] == MODE_NEVER
    assert law.rate(*below)[0][0] == 0.0
    clock, state, step = run_to_failure(law, *below, limit=1e12)
    assert clock.creep_time == 1e12 and not len(step.failing) and state["tensile_strength"][0] == JT
    s = 0.5 * JT
    clock, state, step = run_to_failure(law, *one_bond(law, s, 0.0))
    assert clock.creep_time == pytest.approx((JT - s) / (B1 * math.exp(B2 * s)), rel=1e-12)


def test_threshold_on_shear_uses_the_mohr_coulomb_strength():
    """Shear with s_n = 20 MPa: strength J^C + s_n tan(phi) = 80.6 MPa; tau = 30 MPa is 0.37 of it."""
    strength = JC + 20e6 * TAN55
    tau = 30e6
    for r, never in ((0.3, False), (0.4, True)):
        law = HilligCharles(B1, B2, threshold_ratio=r)
        t, mode = law.time_to_failure(*one_bond(law, -20e6, tau))
        assert np.isinf(t[0]) == never
        if not never:
            assert mode[0] == MODE_SHEAR
            assert t[0] == pytest.approx((strength - tau) / (B1 * math.exp(B2 * tau)), rel=1e-12)


def test_absolute_threshold_stress():
    """threshold_stress sigma_A (Potyondy's activation stress): nothing below it corrodes."""
    law = HilligCharles(B1, B2, threshold_stress=10e6)
    t, _ = law.time_to_failure(*one_bond(law, 9e6, 0.0))
    assert np.isinf(t[0])
    t, _ = law.time_to_failure(*one_bond(law, 11e6, 0.0))
    assert t[0] == pytest.approx((JT - 11e6) / (B1 * math.exp(B2 * 11e6)), rel=1e-12)


def test_an_active_channel_stays_active_under_frozen_stress():
    """The threshold is decided at the start of an interval: an active channel's strength only falls, so
    s / strength only rises; degrading by half the time to failure keeps it active and the rest of the time
    is exactly the other half."""
    law = HilligCharles(B1, B2, threshold_ratio=0.4)
    state, stresses = one_bond(law, 0.45 * JT, 0.0)
    t, _ = law.time_to_failure(state, stresses)
    half = state.replaced([0], law.degrade(state, stresses, t[0] / 2))
    assert law.active(half, stresses)[0][0]
    assert law.time_to_failure(half, stresses)[0][0] == pytest.approx(t[0] / 2, rel=1e-10)


def test_without_threshold_the_default_law_is_eq7_unchanged():
    """threshold 0 (off): every bond corrodes at beta1 exp(beta2 s), also in compression (the paper's law)."""
    law = HilligCharles(B1, B2)
    state, stresses = one_bond(law, -30e6, 10e6)
    r_t, r_s = law.rate(state, stresses)
    assert r_t[0] == pytest.approx(B1 * math.exp(B2 * -30e6), rel=1e-15)
    assert r_s[0] == pytest.approx(B1 * math.exp(B2 * 10e6), rel=1e-15)


# ------------------------------------------------------------------ strength-normalised exponent (normalised)
def _normalised_quad(y0, y1, s):
    """int_{y1}^{y0} dY / (beta1 exp(beta2 s / Y)) by adaptive quadrature."""
    value, _ = quad(lambda y: math.exp(-B2N * s / y) / B1, y1, y0, epsabs=0, epsrel=1e-12, limit=200)
    return value


@pytest.mark.parametrize("ratio", [0.2, 0.5, 0.9, 0.99])
def test_normalised_tension_fails_at_its_closed_form_time(ratio):
    """dJ/dt = -beta1 exp(beta2 sigma/J): t = (F(J0) - F(sigma))/beta1, F(y) = y e^(-k/y) G(k/y),
    G(x) = 1 - x e^x E1(x), k = beta2 sigma; checked against quadrature and the event clock."""
    s = ratio * JT
    expected = _normalised_quad(JT, s, s)
    assert float(closed_form_time(JT, s, s, B1, B2N)) == pytest.approx(expected, rel=1e-9)
    law = Normalised(B1, B2N)
    t, mode = law.time_to_failure(*one_bond(law, s, 0.0))
    assert mode[0] == MODE_TENSION and t[0] == pytest.approx(expected, rel=1e-9)
    clock, state, step = run_to_failure(law, *one_bond(law, s, 0.0))
    assert clock.creep_time == pytest.approx(expected, rel=1e-9) and state["tensile_strength"][0] == s


def test_normalised_shear_uses_the_mohr_coulomb_strength():
    """Shear: Y = J^C + s_n tan(phi) falls at beta1 exp(beta2 tau/Y), failure at Y = tau."""
    tau, s_n = 70e6, 20e6
    y0 = JC + s_n * TAN55
    law = Normalised(B1, B2N)
    t, mode = law.time_to_failure(*one_bond(law, -s_n, tau))
    assert mode[0] == MODE_SHEAR and t[0] == pytest.approx(_normalised_quad(y0, tau, tau), rel=1e-9)


def test_normalised_degrade_solves_the_ode_and_composes():
    """Degrading for dt matches the ODE solution; two halves give the whole (frozen stress)."""
    s = 0.6 * JT
    law = Normalised(B1, B2N)
    state, stresses = one_bond(law, s, 0.0)
    t, _ = law.time_to_failure(state, stresses)
    dt = 0.7 * t[0]
    one = law.degrade(state, stresses, dt)["tensile_strength"][0]
    with np.errstate(all="ignore"), warnings.catch_warnings():   # the integrator's own arithmetic
        warnings.simplefilter("ignore")
        sol = solve_ivp(lambda _, y: [-B1 * math.exp(B2N * s / y[0])], (0.0, dt), [JT], method="DOP853",
                        rtol=1e-12, atol=1e-6)
    assert one == pytest.approx(sol.y[0, -1], rel=1e-9)
    half = state.replaced([0], law.degrade(state, stresses, dt / 2))
    assert law.degrade(half, stresses, dt / 2)["tensile_strength"][0] == pytest.approx(one, rel=1e-12)


def test_normalised_compressed_bond_does_not_corrode_in_tension():
    law = Normalised(B1, B2N)
    state, stresses = one_bond(law, -30e6, 0.0)
    assert law.rate(state, stresses)[0][0] == 0.0
    assert law.degrade(state, stresses, 1e12)["tensile_strength"][0] == JT
    t, mode = law.time_to_failure(state, stresses)
    assert np.isinf(t[0]) and mode[0] == MODE_NEVER


@pytest.mark.parametrize("law_name", ["hillig_charles", "normalised"])
def test_strength_laws_scale_exactly_with_beta1(law_name):
    """Every time of a strength law is proportional to 1/beta1 (what calibrate-beta1 relies on)."""
    rng = np.random.default_rng(2)
    sigma, tau = rng.uniform(-50e6, 20e6, 50), rng.uniform(0, 90e6, 50)
    laws = [HilligCharles(b, B2) if law_name == "hillig_charles" else Normalised(b, B2N) for b in (B1, 7 * B1)]
    times = []
    for law in laws:
        state = law.initial_state(np.full(50, JT), np.full(50, JC), np.full(50, TAN55))
        times.append(law.time_to_failure(state, Stresses.of(np.arange(50), sigma, tau))[0])
    finite = np.isfinite(times[0])
    assert finite.sum() > 10 and np.array_equal(finite, np.isfinite(times[1]))
    np.testing.assert_allclose(times[1][finite], times[0][finite] / 7, rtol=1e-12)


# ------------------------------------------------------------------ the interface and the parameters
@pytest.mark.parametrize("name", LAW_NAMES)
def test_every_law_is_built_from_the_parameters_and_has_the_interface(name):
    params = load_parameters(overrides=[f"stress_corrosion.law={name}"])
    law = build_law(params.stress_corrosion)
    assert isinstance(law, DegradationLaw) and law.name == name == law_module(name).NAME
    state = law.initial_state(np.array([JT, JT]), np.array([JC, JC]), np.array([TAN55, TAN55]))
    stresses = Stresses.of([0, 1], [15e6, -40e6], [0.0, 60e6])
    assert set(law.state_names) == set(state.arrays)
    r_t, r_s = law.rate(state, stresses)
    assert np.all(r_t >= 0) and np.all(r_s >= 0)
    t, mode = law.time_to_failure(state, stresses)
    new = law.degrade(state, stresses, float(np.min(t)) / 2)
    assert set(new) == set(law.state_names)
    jt, jc, stiffness = law.strengths(state)
    assert np.all(jt == JT) and np.all(jc == JC) and (stiffness is None) == law.exact_jump
    assert law.describe().startswith(("Hillig-Charles", "area"))


def test_choices_of_the_law_parameter_are_the_law_modules():
    from grainfrac_yade.params import field_spec
    assert tuple(field_spec("stress_corrosion.law")["choices"]) == LAW_NAMES


def test_old_mode_key_is_refused_in_one_line_naming_the_new_key():
    with pytest.raises(ParameterError) as err:
        load_parameters(overrides=["stress_corrosion.mode=strength"])
    msg = str(err.value)
    assert "\n" not in msg and "stress_corrosion.law" in msg and "'strength' -> 'hillig_charles'" in msg


def test_old_params_json_with_mode_is_read_as_law(tmp_path):
    import json
    from grainfrac_yade.analysis.runparams import load_run_parameters
    tree = load_parameters().to_dict()
    sc = tree["stress_corrosion"]
    for key in ("law", "threshold_ratio", "threshold_stress", "beta2_normalised"):
        sc.pop(key)
    sc["mode"] = "area"
    (tmp_path / "params.json").write_text(json.dumps(tree))
    rp = load_run_parameters(tmp_path, fill_missing=True)
    assert rp.params.stress_corrosion.law == "area" and rp.params.stress_corrosion.threshold_ratio == 0.0


def test_a_threshold_with_the_area_law_is_one_line():
    with pytest.raises(ParameterError, match="area law has no activation threshold"):
        load_parameters(overrides=["stress_corrosion.law=area", "stress_corrosion.threshold_stress=1e6"])


@pytest.mark.parametrize("bad", ["stress_corrosion.threshold_ratio=1.0", "stress_corrosion.threshold_ratio=-0.1",
                                 "stress_corrosion.threshold_stress=-1"])
def test_bad_thresholds_are_one_line(bad):
    with pytest.raises(ParameterError) as err:
        load_parameters(overrides=[bad])
    assert "\n" not in str(err.value) and "fix:" in str(err.value)


def test_failed_now_at_the_failure_point():
    law = HilligCharles(B1, B2)
    state, stresses = one_bond(law, -100e6, 150e6)
    clock, state, step = run_to_failure(law, state, stresses)
    assert failed_now(state["tensile_strength"], state["cohesion"], -100e6, 150e6, TAN55)[1][0]


def test_the_laws_own_flag_decides_time_scaling():
    """Which laws rescale exactly with beta1 (the analysis, calibrate-beta1, calibrate-lifetimes) is read
    from each built law's ``time_scales_with_beta1``, not from a list of names."""
    import dataclasses
    from grainfrac_yade.law import build_law, scales_with_beta1, time_scaling_laws
    from grainfrac_yade.params import load_parameters
    sc = load_parameters().stress_corrosion
    for name in LAW_NAMES:
        assert scales_with_beta1(name) == build_law(dataclasses.replace(sc, law=name)).time_scales_with_beta1
    assert time_scaling_laws() == ("hillig_charles", "normalised") and not scales_with_beta1("no_such_law")
