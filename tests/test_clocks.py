"""Creep clocks: paper Eq. 8 step rule, event clock, checkpoint round trips, validation."""
import json
import math

import numpy as np
import pytest

from grainfrac_yade import corrosion as c
from grainfrac_yade.clocks import EventClock, PaperClock

B1, B2 = 1e-3, 1e-7  # paper section 4.1: beta1 [Pa/s], beta2 [1/Pa]
TAN55 = math.tan(math.radians(55.0))  # K-feldspar/K-feldspar friction angle, Table 2
F_U = 100.0  # paper's unbalanced-force threshold [N]


pytestmark = pytest.mark.usefixtures("strict_floats")  # conftest: float warnings are errors


# ------------------------------------------------------------------ PaperClock (Eq. 8)
def test_paper_clock_follows_eq8_on_a_hand_made_sequence():
    d = 1e-5
    clock = PaperClock(dt_min=d, dt_max=8 * d, unbalanced_force_threshold=F_U)
    forces = [1e3, 0.0, 50.0, 99.99, 0.0, 0.0, F_U, 0.0, 2 * F_U, 0.0, 0.0]
    expected = [d,  # the first step is dt_min whatever F_u
                2 * d, 4 * d, 8 * d,  # F_u < threshold: doubling ...
                8 * d, 8 * d,  # ... capped at dt_max
                d,  # F_u >= threshold (equality included): back to dt_min
                2 * d, d, 2 * d, 4 * d]
    steps = [clock.next_step(f) for f in forces]
    assert steps == expected
    assert clock.creep_time == sum(expected)
    assert clock.n_steps == len(forces)
    clock.reset_step()
    assert clock.next_step(0.0) == d


def test_paper_clock_stays_within_bounds():
    rng = np.random.default_rng(7)
    clock = PaperClock()
    doublings_to_cap = math.ceil(math.log2(clock.dt_max / clock.dt_min))
    forces = np.concatenate([rng.uniform(0.0, 2 * F_U, 300), np.zeros(doublings_to_cap + 5),
                             rng.uniform(0.0, 2 * F_U, 300)])
    steps = [clock.next_step(f) for f in forces]
    assert min(steps) == clock.dt_min and max(steps) == clock.dt_max
    assert all(clock.dt_min <= s <= clock.dt_max for s in steps)


def test_advance_many_returns_the_summed_step():
    forces = [0.0, 0.0, 500.0, 0.0, 0.0, 0.0]
    one, many = PaperClock(), PaperClock()
    total = sum(one.next_step(f) for f in forces)
    assert many.advance_many(forces) == total
    assert many.state_dict() == one.state_dict()


def test_paper_clock_state_round_trip_continues_identically():
    rng = np.random.default_rng(11)
    clock = PaperClock(dt_min=1e-5, dt_max=1e4)
    clock.advance_many(rng.uniform(0.0, 2 * F_U, 37))
    restored = PaperClock.from_state(json.loads(json.dumps(clock.state_dict())))
    assert restored.state_dict() == clock.state_dict()
    for f in rng.uniform(0.0, 2 * F_U, 50):
        assert restored.next_step(f) == clock.next_step(f)
    assert restored.creep_time == clock.creep_time
    fresh = PaperClock.from_state(PaperClock().state_dict())
    assert fresh.next_step(0.0) == fresh.dt_min  # first step after restoring a fresh clock


@pytest.mark.parametrize("dt_max", [1e4, 1e2])
def test_stepping_degrade_with_paper_clock_fails_at_the_closed_form_time(dt_max):
    """Frozen stresses: failure is detected at the end of the step containing the closed-form
    time, so the overshoot is in [0, last dt_b] and dt_b <= dt_max."""
    jt, jc, sigma, tau = 23e6, 52e6, -100e6, 150e6  # compressed bond sheared near its limit
    t_exact, mode = c.time_to_failure(jt, jc, sigma, tau, TAN55, B1, B2)
    assert mode == c.MODE_SHEAR
    clock = PaperClock(dt_min=1e-5, dt_max=dt_max)
    rng = np.random.default_rng(3)
    while True:
        dt = clock.next_step(rng.choice([0.0, 2 * F_U], p=[0.9, 0.1]))
        jt, jc = c.degrade(jt, jc, sigma, tau, dt, B1, B2)
        if any(c.failed_now(jt, jc, sigma, tau, TAN55)):
            break
        assert clock.creep_time < t_exact * (1 + 1e-12)
    overshoot = clock.creep_time - t_exact
    assert -1e-12 * t_exact <= overshoot <= dt * (1 + 1e-12)
    assert dt <= dt_max


BAD_CLOCKS = [
    (PaperClock, {"dt_min": 0.0}, "dt_min"),
    (PaperClock, {"dt_min": -1e-5}, "dt_min"),
    (PaperClock, {"dt_min": 1.0, "dt_max": 0.5}, "dt_min"),
    (PaperClock, {"dt_min": "fast"}, "dt_min"),
    (PaperClock, {"dt_max": math.inf}, "dt_max"),
    (PaperClock, {"dt_max": math.nan}, "dt_max"),
    (PaperClock, {"unbalanced_force_threshold": 0.0}, "unbalanced_force_threshold"),
    (PaperClock, {"unbalanced_force_threshold": math.nan}, "unbalanced_force_threshold"),
    (EventClock, {"max_strength_loss_fraction": 0.0}, "max_strength_loss_fraction"),
    (EventClock, {"max_strength_loss_fraction": 1.0}, "max_strength_loss_fraction"),
    (EventClock, {"time_limit": 0.0}, "time_limit"),
    (EventClock, {"time_limit": math.nan}, "time_limit"),
]


@pytest.mark.parametrize("cls, kwargs, name", BAD_CLOCKS)
def test_bad_parameters_name_themselves(cls, kwargs, name):
    with pytest.raises(ValueError, match=name):
        cls(**kwargs)


def test_bad_unbalanced_force_is_refused():
    with pytest.raises(ValueError, match="^unbalanced_force must be >= 0 "):
        PaperClock().next_step(-1.0)


@pytest.mark.parametrize("force", [math.nan, math.inf])
def test_non_finite_unbalanced_force_is_a_numerical_failure_even_on_the_first_step(force):
    from grainfrac_yade.errors import NumericalFailure
    clock = PaperClock()
    with pytest.raises(NumericalFailure) as err:
        clock.next_step(force)
    assert str(err.value) == f"unbalanced force is {force} (the DEM blew up)"
    assert clock.n_steps == 0 and clock.creep_time == 0.0


@pytest.mark.parametrize("threshold", [F_U, 1e-2])
def test_one_notion_of_balanced_decides_the_step(threshold):
    """balanced(F_u) is F_u < threshold, and the step doubles exactly when it holds (the creep
    loop's no-equilibrium counter uses the same method: tests/test_reliability.py)."""
    d = 1e-5
    below, at = threshold * (1 - 1e-12), threshold
    for f, expected in ((0.0, True), (below, True), (at, False), (2 * threshold, False)):
        clock = PaperClock(dt_min=d, dt_max=1e4, unbalanced_force_threshold=threshold)
        clock.next_step(0.0)                       # first step: dt_min whatever F_u
        assert clock.balanced(f) is expected
        assert clock.next_step(f) == (2 * d if expected else d)


def test_state_of_another_kind_or_version_is_refused():
    with pytest.raises(ValueError, match="kind"):
        PaperClock.from_state(EventClock().state_dict())
    with pytest.raises(ValueError, match="version"):
        EventClock.from_state({**EventClock().state_dict(), "version": -1})


# ------------------------------------------------------------------ EventClock
def _run_to_first_failure(clock, jt, jc, sigma, tau, tphi, beta2=B2, **kw):
    while True:
        dt, failing = clock.next_interval(jt, jc, sigma, tau, tphi, B1, beta2, **kw)
        state = clock.apply(dt, failing, jt, jc, sigma, tau, tphi, B1, beta2, **kw)
        clock.advance(dt, failing)
        if kw.get("mode") == "area":
            kw["area_fraction"] = state
        else:
            jt, jc = state
        if len(failing):
            return failing, state


def test_event_clock_single_bond_interval_count_and_failure_time():
    """Under frozen sigma the loss rate R is constant, so a capped interval removes exactly
    f J_n: J_n = (1-f)^n J0. Interval n is capped while f J_n < J_n - s, i.e. (1-f)^(n+1) J0 > s;
    the failure interval is the first with (1-f)^(n+1) J0 <= s. Intervals = ceil(ln(s/J0)/ln(1-f)).
    J^C is chosen so that its own cap f J^C / beta1 exceeds the whole lifetime."""
    f, j0, s = 0.1, 20e6, 5e6
    t_exact = (j0 - s) / (B1 * math.exp(B2 * s))
    jc = 10 * t_exact * B1 / f
    clock = EventClock(max_strength_loss_fraction=f)
    failing, (jt, _) = _run_to_first_failure(clock, [j0], [jc], [s], [0.0], [0.0])
    assert list(failing) == [0]
    assert clock.n_intervals == math.ceil(math.log(s / j0) / math.log(1 - f))
    assert clock.n_events == 1 and clock.n_failures == 1
    assert clock.creep_time == pytest.approx(t_exact, rel=1e-12)
    assert jt[0] == s and c.failed_now(jt, jc, s, 0.0, 0.0)[0][0]


def test_event_clock_shear_failure_lands_exactly_on_the_criterion():
    jt, jc, sigma, tau = [23e6], [52e6], [-100e6], [150e6]
    t_exact, _ = c.time_to_failure(jt, jc, sigma, tau, TAN55, B1, B2)
    clock = EventClock()
    failing, (new_t, new_c) = _run_to_first_failure(clock, jt, jc, sigma, tau, [TAN55])
    assert clock.creep_time == pytest.approx(t_exact[0], rel=1e-12)
    assert c.failed_now(new_t, new_c, sigma, tau, TAN55)[1][0]
    assert new_c[0] == pytest.approx(tau[0] - (-sigma[0]) * TAN55, rel=1e-12)


def test_event_clock_picks_the_earliest_bonds():
    sigma = np.array([12e6, 18e6, 15e6, 18e6, -5e6])  # bonds 1 and 3 identical and earliest
    jt, jc, tau = np.full(5, 20e6), np.full(5, 1e12), np.zeros(5)
    clock = EventClock(max_strength_loss_fraction=0.99)
    dt, failing = clock.next_interval(jt, jc, sigma, tau, 0.0, B1, B2)
    t, _ = c.time_to_failure(jt, jc, sigma, tau, 0.0, B1, B2)
    assert dt == np.min(t) and list(failing) == [1, 3]
    dt, failing = clock.next_interval(jt, jc, sigma, tau, 0.0, B1, B2,
                                      intact=[True, False, True, False, True])
    assert dt == t[2] and list(failing) == [2]


def test_event_clock_cap_gives_empty_failing_index():
    clock = EventClock(max_strength_loss_fraction=0.1)
    dt, failing = clock.next_interval(20e6, 1e12, 5e6, 0.0, 0.0, B1, B2)
    assert dt == pytest.approx(0.1 * 20e6 / (B1 * math.exp(B2 * 5e6)), rel=1e-14)
    assert failing.size == 0


def test_event_clock_nothing_can_fail():
    clock = EventClock()
    dt, failing = clock.next_interval(20e6, 50e6, -30e6, 10e6, TAN55, B1, B2)
    assert dt == math.inf and failing.size == 0
    dt, failing = clock.next_interval(20e6, 50e6, 5e6, 0.0, TAN55, B1, B2, intact=[False])
    assert dt == math.inf and failing.size == 0
    limited = EventClock(time_limit=1e4)
    limited.advance(3e3)
    dt, failing = limited.next_interval(20e6, 50e6, -30e6, 10e6, TAN55, B1, B2)
    assert dt == 1e4 - 3e3 and failing.size == 0
    limited.advance(dt)
    assert limited.finished


def test_event_clock_area_mode_reaches_failure_in_the_expected_intervals():
    """Same argument as the strength mode with a in place of J: each capped interval removes
    f a_n, so intervals = ceil(ln(a_fail/a0)/ln(1-f)) (a_fail/a0 is not a power of 1-f)."""
    f, a0, p, q, jt0, jc0 = 0.1, 1.0, -50e6, 100e6, 23e6, 52e6
    a_fail, mode = c.area_failure_point(p, q, jt0, jc0, TAN55)
    t_exact, _ = c.time_to_failure_area(a0, p, q, jt0, jc0, TAN55, B1, B2)
    clock = EventClock(max_strength_loss_fraction=f)
    failing, a = _run_to_first_failure(clock, [jt0], [jc0], [p], [q], [TAN55], mode="area",
                                       area_fraction=[a0])
    assert list(failing) == [0] and a[0] == a_fail
    assert clock.n_intervals == math.ceil(math.log(a_fail / a0) / math.log(1 - f))
    assert clock.creep_time == pytest.approx(t_exact, rel=1e-9)
    assert any(x[0] for x in c.failed_now_area(a, p, q, jt0, jc0, TAN55))


def test_event_clock_state_round_trip_and_validation():
    clock = EventClock(0.2, time_limit=1e6)
    clock.advance(12.5, [3])
    clock.advance(0.25)
    restored = EventClock.from_state(json.loads(json.dumps(clock.state_dict())))
    assert restored.state_dict() == clock.state_dict()
    assert (restored.n_intervals, restored.n_events, restored.n_failures) == (2, 1, 1)
    assert restored.advance(1.0) == clock.advance(1.0)
    inf_limit = EventClock.from_state(json.loads(json.dumps(EventClock().state_dict())))
    assert inf_limit.time_limit == math.inf
    with pytest.raises(ValueError, match="mode"):
        clock.next_interval(1.0, 1.0, 0.0, 0.0, 0.0, B1, B2, mode="bogus")
    with pytest.raises(ValueError, match="area_fraction"):
        clock.next_interval(1.0, 1.0, 0.0, 0.0, 0.0, B1, B2, mode="area")
    with pytest.raises(ValueError, match="dt"):
        clock.advance(math.inf)


@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_event_clock_refuses_non_finite_stresses(bad):
    """A NaN stress used to give a finite time to failure (the quotient helper replaced the NaN gap by 1)."""
    from grainfrac_yade.errors import NumericalFailure
    clock = EventClock(0.1)
    for mode, extra in (("strength", {}), ("area", {"area_fraction": [1.0, 1.0]})):
        with pytest.raises(NumericalFailure, match="NaN or infinite at 1 of 2 bond"):
            clock.next_interval([20e6, 20e6], [52e6, 52e6], [1e6, bad], [0.0, 0.0], TAN55, B1, B2, mode=mode,
                                **extra)
        with pytest.raises(NumericalFailure, match="NaN or infinite at 1 of 2 bond"):
            clock.apply(1.0, [1], [20e6, 20e6], [52e6, 52e6], [1e6, bad], [0.0, 0.0], TAN55, B1, B2, mode=mode,
                        **extra)
    assert clock.creep_time == 0.0 and clock.n_intervals == 0


@pytest.mark.parametrize("mode", ["strength", "area"])
def test_event_clock_at_beta2_times_stress_of_1e4_has_no_overflow(mode):
    """beta2 sigma = 1e4 (float warnings are errors here): finite intervals; in strength mode the
    capped rate RATE_CAP gives the first interval 0.1 J^T / RATE_CAP (loss cap) and the failure at
    (J^T - sigma) / RATE_CAP of creep time."""
    beta2 = 1e-3
    jt, jc, sigma, tau = [2e7, 2e7], [52e6, 52e6], [1e7, 1e3], [0.0, 1e7]   # beta2 sigma = 1e4, beta2 tau = 1e4
    extra = {"area_fraction": [1.0, 1.0]} if mode == "area" else {}
    clock = EventClock(0.1)
    dt, failing = clock.next_interval(jt, jc, sigma, tau, TAN55, B1, beta2, mode=mode, **extra)
    assert math.isfinite(dt) and dt > 0
    later = EventClock(0.1)
    failing, state = _run_to_first_failure(later, jt, jc, sigma, tau, TAN55, mode=mode, beta2=beta2, **extra)
    assert all(np.all(np.isfinite(x)) for x in np.atleast_2d(state))
    if mode == "strength":
        assert dt == pytest.approx(0.1 * 2e7 / c.RATE_CAP, rel=1e-12)
        assert list(failing) == [0] and c.failed_now(state[0][0], state[1][0], sigma[0], tau[0], TAN55)[0]
        assert later.creep_time == pytest.approx((2e7 - 1e7) / c.RATE_CAP, rel=1e-9)
