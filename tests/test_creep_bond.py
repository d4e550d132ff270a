"""One bond under constant stress in YADE: creep clocks against the closed form (paper Eq. 7)."""
import math

import numpy as np

import pytest

from conftest import needs_yade
from grainfrac_yade.params import load_parameters, unbalanced_threshold

pytestmark = [needs_yade, pytest.mark.yade]

BETA1, BETA2 = 1e-3, 1e-7   # paper section 4.1


def _params(clock, extra=()):
    return load_parameters(overrides=[f"stress_corrosion.clock={clock}", "stress_corrosion.creep_time_limit=1e30",
                                      *extra])


def _closed_form_tension(j0, s):
    return (j0 - s) / (BETA1 * math.exp(BETA2 * s))


def _closed_form_shear(c0, tau, s_n, tan_phi):
    return (c0 - (tau - s_n * tan_phi)) / (BETA1 * math.exp(BETA2 * tau))


def _run(clock, sigma, tau, extra=()):
    from grainfrac_yade.clocks import EventClock, PaperClock
    from grainfrac_yade.protocols.creep_loops import event_clock_loop, paper_clock_loop
    from single_bond import BondUnderForce
    p = _params(clock, extra)
    holder = BondUnderForce(p, sigma, tau)
    sc = p.stress_corrosion
    if clock == "event":
        c = EventClock(sc.max_strength_loss_fraction, sc.creep_time_limit)
        event_clock_loop(holder, holder.corr, c)
    else:
        c = PaperClock(sc.dt_min, sc.dt_max, unbalanced_threshold(sc))
        paper_clock_loop(holder, holder.corr, c, sc, p.creep)
    return holder, c, p


def test_event_clock_tension_matches_closed_form():
    p = load_parameters()
    j0 = p.contact("quartz", "quartz").tensile_strength * p.calibration.strength_scale
    s = 0.9 * j0
    holder, clock, _ = _run("event", s, 0.0)
    assert holder.failed and holder.scene.break_mode[0] == 1           # tensile break
    assert holder.sigma0 == pytest.approx(s, rel=1e-3)
    assert holder.lifetime == pytest.approx(_closed_form_tension(j0, holder.sigma0), rel=0.01)


def test_event_clock_shear_matches_closed_form():
    p = load_parameters()
    c = p.contact("quartz", "quartz")
    c0 = c.cohesion * p.calibration.strength_scale
    s_n = 0.2 * c0                       # compressive normal stress
    tau = 0.9 * (c0 + s_n * math.tan(c.friction_angle))
    holder, clock, _ = _run("event", -s_n, tau)
    assert holder.failed and holder.scene.break_mode[0] == 2           # shear break
    # the bond's own stresses: the centre-line normal of a one-sphere pair turns ~2 mrad as the cell
    # slides, so they differ ~1 % from the applied ones; the law is checked against what the bond carries
    assert holder.tau0 == pytest.approx(tau, rel=0.01) and -holder.sigma0 == pytest.approx(s_n, rel=0.03)
    expected = _closed_form_shear(c0, holder.tau0, -holder.sigma0, math.tan(c.friction_angle))
    assert holder.lifetime == pytest.approx(expected, rel=0.01)


def test_paper_clock_tension_within_one_creep_step():
    """Eq. 8 reaches the closed-form lifetime to within one creep step dt_max (here 1e4 s)."""
    p = load_parameters()
    j0 = p.contact("quartz", "quartz").tensile_strength * p.calibration.strength_scale
    s = 0.95 * j0
    holder, clock, p = _run("paper", s, 0.0)
    t_exact = _closed_form_tension(j0, holder.sigma0)
    assert holder.failed
    dt_max = p.stress_corrosion.dt_max
    assert t_exact - dt_max <= holder.lifetime <= t_exact + dt_max


def test_engine_state_round_trip():
    """The corrosion engine's whole state (the law's strengths, creep time) saves and restores."""
    import json
    from grainfrac_yade.clocks import EventClock
    from single_bond import BondUnderForce
    p = _params("event")
    a = BondUnderForce(p, 5e6, 0.0)
    a.corr.degrade(1e6, a.corr.stresses([0]))
    clock = EventClock(0.1)
    clock.advance(1e6)
    saved = json.loads(json.dumps({"engine": a.corr.state_dict(), "clock": clock.state_dict()}))
    b = BondUnderForce(p, 5e6, 0.0)
    b.corr.load_state(saved["engine"])
    restored = EventClock.from_state(saved["clock"])
    assert b.corr.creep_time == a.corr.creep_time == restored.creep_time == 1e6
    np.testing.assert_array_equal(b.corr.state["tensile_strength"], a.corr.state["tensile_strength"])
    assert b.scene.interactions[0].phys.FnMax == a.scene.interactions[0].phys.FnMax
    assert a.corr.state["tensile_strength"][0] < a.corr.tensile0[0]


def test_event_clock_normalised_law_tension_matches_its_closed_form():
    """The strength-normalised exponent in YADE: dJ/dt = -beta1 exp(beta2 sigma/J) reaches sigma at
    (F(J0) - F(sigma))/beta1, F(y) = y e^(-k/y) G(k/y) (grainfrac_yade.law.normalised)."""
    from grainfrac_yade.law.normalised import closed_form_time
    p = load_parameters()
    j0 = p.contact("quartz", "quartz").tensile_strength * p.calibration.strength_scale
    holder, clock, p = _run("event", 0.8 * j0, 0.0, ["stress_corrosion.law=normalised"])
    assert holder.failed and holder.scene.break_mode[0] == 1
    expected = float(closed_form_time(j0, holder.sigma0, holder.sigma0, BETA1, p.stress_corrosion.beta2_normalised))
    assert holder.lifetime == pytest.approx(expected, rel=0.01)


def test_below_the_activation_threshold_a_bond_never_fails():
    """Tension at 0.3 J^T with threshold_ratio 0.4: no corrosion; the run reaches its creep-time limit with
    the bond whole and its strength untouched."""
    p = load_parameters()
    j0 = p.contact("quartz", "quartz").tensile_strength * p.calibration.strength_scale
    holder, clock, p = _run("event", 0.3 * j0, 0.0, ["stress_corrosion.threshold_ratio=0.4",
                                                     "stress_corrosion.creep_time_limit=1e12"])
    assert not holder.failed and clock.creep_time == 1e12 and not holder.scene.broken[0]
    assert holder.corr.state["tensile_strength"][0] == holder.corr.tensile0[0]
