"""Creep clocks: paper Eq. 8 step rule, the event clock with creep_step (pure), checkpoint round trips,
validation."""
import json
import math

import numpy as np
import pytest

from grainfrac_yade.clocks import EventClock, PaperClock
from grainfrac_yade.law import MODE_SHEAR, MODE_TENSION, Stresses, area, creep_step, failed_now, hillig_charles
from grainfrac_yade.law._common import RATE_CAP
from grainfrac_yade.law.area import AreaLaw
from grainfrac_yade.law.hillig_charles import HilligCharles

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
    t_exact, mode = hillig_charles.time_to_failure(jt, jc, sigma, tau, TAN55, B1, B2)
    assert mode == MODE_SHEAR
    clock = PaperClock(dt_min=1e-5, dt_max=dt_max)
    rng = np.random.default_rng(3)
    while True:
        dt = clock.next_step(rng.choice([0.0, 2 * F_U], p=[0.9, 0.1]))
        jt, jc = hillig_charles.degrade(jt, jc, sigma, tau, dt, B1, B2)
        if any(failed_now(jt, jc, sigma, tau, TAN55)):
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


# ------------------------------------------------------------------ EventClock with creep_step
def _bonds(law, jt, jc, sigma, tau, tphi, area_fraction=None):
    """(state, stresses) of bonds given as lists (tan(phi) may be a scalar)."""
    jt, jc, sigma, tau = (np.atleast_1d(np.asarray(x, float)) for x in (jt, jc, sigma, tau))
    tphi = np.broadcast_to(np.asarray(tphi, float), jt.shape).copy()
    state = law.initial_state(jt, jc, tphi)
    if area_fraction is not None:
        state = state.replaced(np.arange(len(jt)), {"area_fraction": np.asarray(area_fraction, float)})
    return state, Stresses.of(np.arange(len(jt)), sigma, tau)


def _run_to_first_failure(clock, law, state, stresses):
    while True:
        step = creep_step(law, clock, state, stresses)
        clock.advance(step.dt, step.failing)
        state = step.state
        if len(step.failing):
            return step, state


def test_strength_law_jumps_in_one_interval_exactly_to_the_closed_form_failure():
    """Eq. 7 does not change stiffness: under frozen sigma the event clock needs no loss cap and lands on
    the closed-form time t = (J0 - s) / (beta1 exp(beta2 s)) in one interval, with J^T = s exactly."""
    j0, s = 20e6, 5e6
    law = HilligCharles(B1, B2)
    state, stresses = _bonds(law, [j0], [1e12], [s], [0.0], 0.0)
    clock = EventClock(max_strength_loss_fraction=0.1)
    step, state = _run_to_first_failure(clock, law, state, stresses)
    assert list(step.failing) == [0] and list(step.modes) == [MODE_TENSION]
    assert clock.n_intervals == 1 and clock.n_events == 1 and clock.n_failures == 1
    assert clock.creep_time == pytest.approx((j0 - s) / (B1 * math.exp(B2 * s)), rel=1e-12)
    assert state["tensile_strength"][0] == s
    assert failed_now(state["tensile_strength"], state["cohesion"], s, 0.0, 0.0)[0][0]


def test_event_clock_shear_failure_lands_exactly_on_the_criterion():
    law = HilligCharles(B1, B2)
    state, stresses = _bonds(law, [23e6], [52e6], [-100e6], [150e6], TAN55)
    t_exact, _ = hillig_charles.time_to_failure(23e6, 52e6, -100e6, 150e6, TAN55, B1, B2)
    clock = EventClock()
    step, state = _run_to_first_failure(clock, law, state, stresses)
    assert clock.creep_time == pytest.approx(float(t_exact), rel=1e-12) and list(step.modes) == [MODE_SHEAR]
    assert failed_now(state["tensile_strength"], state["cohesion"], -100e6, 150e6, TAN55)[1][0]
    assert state["cohesion"][0] == pytest.approx(150e6 - 100e6 * TAN55, rel=1e-12)


def test_event_clock_picks_the_earliest_bonds_among_those_given():
    sigma = np.array([12e6, 18e6, 15e6, 18e6, -5e6])  # bonds 1 and 3 identical and earliest
    law = HilligCharles(B1, B2)
    state, stresses = _bonds(law, np.full(5, 20e6), np.full(5, 1e12), sigma, np.zeros(5), 0.0)
    t, _ = hillig_charles.time_to_failure(np.full(5, 20e6), 1e12, sigma, 0.0, 0.0, B1, B2)
    step = creep_step(law, EventClock(), state, stresses)
    assert step.dt == np.min(t) and list(step.failing) == [1, 3]
    intact = stresses.take([0, 2, 4])            # only the intact bonds are given
    step = creep_step(law, EventClock(), state, intact)
    assert step.dt == t[2] and list(step.failing) == [2] and list(step.positions) == [1]
    assert step.state["tensile_strength"][1] == 20e6 and step.state["tensile_strength"][3] == 20e6   # not given: kept


def test_area_law_cap_gives_an_interval_without_failures():
    """The area law changes stiffness: the clock stops when a bond has lost the set fraction of its intact area."""
    law = AreaLaw(B1, B2)
    state, stresses = _bonds(law, [23e6], [52e6], [-50e6], [100e6], TAN55)
    step = creep_step(law, EventClock(max_strength_loss_fraction=0.1), state, stresses)
    assert step.failing.size == 0
    assert step.dt == pytest.approx(float(area.area_time(1.0, 0.9, -50e6, 100e6, 23e6, 52e6, B1, B2)), rel=1e-12)
    assert step.state["area_fraction"][0] == pytest.approx(0.9, rel=1e-12)


def test_event_clock_nothing_can_fail():
    law = HilligCharles(B1, B2)
    state, stresses = _bonds(law, [20e6], [50e6], [-30e6], [10e6], TAN55)
    step = creep_step(law, EventClock(), state, stresses)
    assert step.dt == math.inf and step.failing.size == 0 and step.stalled and step.state is state
    step = creep_step(law, EventClock(), state, stresses.take([]))    # no intact bond
    assert step.dt == math.inf and step.failing.size == 0
    limited = EventClock(time_limit=1e4)
    limited.advance(3e3)
    step = creep_step(law, limited, state, stresses)
    assert step.dt == 1e4 - 3e3 and step.failing.size == 0 and not step.stalled
    limited.advance(step.dt)
    assert limited.finished


def test_area_law_reaches_failure_in_the_expected_intervals():
    """Each capped interval removes f of the INTACT area (no geometric shrinking towards a = 0), so
    intervals = ceil((a0 - a_fail) / f); the creep time is the whole time to failure."""
    f, a0, p, q, jt0, jc0 = 0.1, 1.0, -50e6, 100e6, 23e6, 52e6
    a_fail, mode = area.area_failure_point(p, q, jt0, jc0, TAN55)
    t_exact, _ = area.time_to_failure_area(a0, p, q, jt0, jc0, TAN55, B1, B2)
    law = AreaLaw(B1, B2)
    state, stresses = _bonds(law, [jt0], [jc0], [p], [q], TAN55)
    clock = EventClock(max_strength_loss_fraction=f)
    step, state = _run_to_first_failure(clock, law, state, stresses)
    assert list(step.failing) == [0] and state["area_fraction"][0] == a_fail and list(step.modes) == [mode]
    assert clock.n_intervals == math.ceil((a0 - a_fail) / f)
    assert clock.creep_time == pytest.approx(float(t_exact), rel=1e-9)
    assert any(x[0] for x in area.failed_now_area(state["area_fraction"], p, q, jt0, jc0, TAN55))


def test_a_bond_corroding_away_takes_at_most_one_interval_per_capped_loss():
    """Friction carries the shear: no criterion is met, the bond corrodes to a = 0 (MODE_CORRODED).  With the
    cap on the current area this took endless geometrically shorter intervals; now 1/f of them."""
    law = AreaLaw(B1, B2)
    state, stresses = _bonds(law, [23e6], [52e6], [-50e6], [10e6], TAN55)
    clock = EventClock(max_strength_loss_fraction=0.1)
    step, state = _run_to_first_failure(clock, law, state, stresses)
    assert list(step.modes) == [area.MODE_CORRODED] and clock.n_intervals == 10
    t_away, _ = area.time_to_failure_area(1.0, -50e6, 10e6, 23e6, 52e6, TAN55, B1, B2)
    assert clock.creep_time == pytest.approx(float(t_away), rel=1e-9)


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
    with pytest.raises(ValueError, match="dt"):
        clock.advance(math.inf)


@pytest.mark.parametrize("bad", [math.nan, math.inf])
@pytest.mark.parametrize("law", [HilligCharles(B1, B2), AreaLaw(B1, B2)], ids=["hillig_charles", "area"])
def test_creep_step_refuses_non_finite_stresses(bad, law):
    """A NaN stress used to give a finite time to failure (the quotient helper replaced the NaN gap by 1)."""
    from grainfrac_yade.errors import NumericalFailure
    state, stresses = _bonds(law, [20e6, 20e6], [52e6, 52e6], [1e6, bad], [0.0, 0.0], TAN55)
    clock = EventClock(0.1)
    with pytest.raises(NumericalFailure, match="NaN or infinite at 1 of 2 bond"):
        creep_step(law, clock, state, stresses)
    with pytest.raises(NumericalFailure, match="NaN or infinite at 1 of 2 bond"):
        law.degrade(state, stresses, 1.0)
    assert clock.creep_time == 0.0 and clock.n_intervals == 0


@pytest.mark.parametrize("law", [HilligCharles(B1, 1e-3), AreaLaw(B1, 1e-3)], ids=["hillig_charles", "area"])
def test_event_clock_at_beta2_times_stress_of_1e4_has_no_overflow(law):
    """beta2 sigma = 1e4 (float warnings are errors here): finite intervals; with Eq. 7 the capped rate
    RATE_CAP gives the failure at (J^T - sigma) / RATE_CAP of creep time in one interval."""
    state, stresses = _bonds(law, [2e7, 2e7], [52e6, 52e6], [1e7, 1e3], [0.0, 1e7], TAN55)
    step = creep_step(law, EventClock(0.1), state, stresses)
    assert math.isfinite(step.dt) and step.dt >= 0
    later = EventClock(0.1)
    step, state = _run_to_first_failure(later, law, state, stresses)
    assert all(np.all(np.isfinite(v)) for v in state.arrays.values())
    if law.name == "hillig_charles":
        assert list(step.failing) == [0]
        assert failed_now(state["tensile_strength"][0], state["cohesion"][0], 1e7, 0.0, TAN55)[0]
        assert later.creep_time == pytest.approx((2e7 - 1e7) / RATE_CAP, rel=1e-9)
