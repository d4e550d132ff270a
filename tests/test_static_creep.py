"""Static engine: creep events with the law package and the event clock on hand-made networks and a tiny specimen's
network, the failure rule, and the paper clock refused (no YADE)."""
import math

import numpy as np
import pytest

from grainfrac_yade.clocks import EventClock
from grainfrac_yade.errors import ParameterError
from grainfrac_yade.grains import layout_for
from grainfrac_yade.law.hillig_charles import HilligCharles
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.engines.static.cascade import Path
from grainfrac_yade.engines.static.failure import COLLAPSE, NO_EQUILIBRIUM, FailureRule
from grainfrac_yade.engines.static.network import build_static_network
from grainfrac_yade.engines.static.solver import Equilibrium
from static_tiny import JC, PHI, PHI_R, HeldEvents, network, shear_pair

#: Paper section 4.1: beta1 [Pa/s], beta2 [1/Pa].
BETA1, BETA2 = 1e-3, 1e-7
#: The closed form and the engine compute the same few operations in another order: 1e-12 relative.
EXACT = 1e-12


def test_two_cell_creep_lifetime_is_eq7_integrated_by_hand():
    """One bond pressed by sigma and sheared by tau at a held platen stress: Eq. 7 lowers J^C at the constant rate
    beta1 exp(beta2 tau) until tau = J^C + sigma tan(phi), so t_f = (J^C + sigma tan(phi) - tau) / (beta1
    exp(beta2 tau)); then the face slides at sigma tan(phi_r) < tau, the stress cannot be regained, and the
    specimen fails (no equilibrium ahead)."""
    sigma, tau = 20e6, 35e6
    eq = Equilibrium(shear_pair(), confinement=sigma)
    res = HeldEvents(eq, HilligCharles(BETA1, BETA2), EventClock(), tau, FailureRule(1e-3)).run()
    expected = (JC + sigma * np.tan(PHI) - tau) / (BETA1 * math.exp(BETA2 * tau))
    assert res.failed and res.reason == NO_EQUILIBRIUM
    assert res.events == 1
    assert res.times[-1] == pytest.approx(expected, rel=EXACT)


def test_the_paper_clock_is_refused_in_one_line():
    """The creep protocol on the static engine with the paper clock (Eq. 8 needs an unbalanced force): one line
    naming the key and the fix, before any creep."""
    from grainfrac_yade.protocols.creep import run_creep
    p = load_parameters(overrides=["numerics.engine=static", "stress_corrosion.clock=paper", "specimen.width=3e-3",
                                   "specimen.height=6e-3"])
    with pytest.raises(ParameterError) as err:
        run_creep(build_specimen(p, 1), p, 100e6)
    assert "Eq. 8" in str(err.value) and "fix:" in str(err.value) and "\n" not in str(err.value)


def _soft_backed_pair(collapse):
    """The shear pair with a second, soft and strong bond beside it (same nodes): after the first bond breaks the
    soft one must be sheared far to carry the held stress."""
    net = network([[0.0, 0.0], [1e-3, 0.0]], [[0, 1], [0, 1]], [[1.0, 0.0], [1.0, 0.0]], top=[1], bottom=[0],
                  left=[0], right=[1], ks=[2e9, 2e6], jc=[JC, 1e12], jt=[10e6, 1e12])
    return HeldEvents(Equilibrium(net, confinement=20e6), HilligCharles(BETA1, BETA2), EventClock(), 35e6,
                      FailureRule(collapse)).run()


def test_failure_rule_collapse_and_its_switch():
    """Regaining the held stress tau after the first break: the broken face (half the confinement on it: the two
    bonds share it by equal k_n) slides at sigma/2 tan(phi_r) and the soft bond must carry the rest, a strain of
    (tau - sigma/2 tan(phi_r)) A / k_s / H = 0.0152 (beyond 1e-3): collapse.
    With the collapse criterion off (0) the path finds that equilibrium and the hold goes on until the soft bond
    itself corrodes through (then no equilibrium is ahead)."""
    res = _soft_backed_pair(1e-3)
    assert res.failed and res.reason == COLLAPSE and res.events == 1
    res = _soft_backed_pair(0.0)
    expected = (35e6 - 10e6 * np.tan(PHI_R)) * 1e-6 / 2e6 / 1e-3
    assert res.strains[0] == pytest.approx(expected, rel=1e-9)   # a bracketed target: BRACKET_TOL 1e-9
    assert res.events == 2 and res.failed and res.reason == NO_EQUILIBRIUM


def _tiny_creep(**settings):
    p = load_parameters(extra_files=["params/presets/fem_coarse.toml"], overrides=["specimen.width=3e-3",
                                                                            "specimen.height=6e-3"])
    s = build_specimen(p, 1)
    net = build_static_network(s, p, layout_for(s, p))
    bracket = settings.pop("bracket_tol")
    eq = Equilibrium(net, **settings)
    return HeldEvents(eq, HilligCharles(BETA1, BETA2), EventClock(), 200e6, FailureRule(1e-3),
                      path=Path(eq, bracket_tol=bracket)).run(max_events=8)


def test_creep_does_not_depend_on_solver_settings():
    """fem cells, 3 x 6 mm, 200 MPa, 8 events: bracketing tolerance 1e-9 vs 1e-11, status changes per iteration
    unlimited vs 2, iteration limit 200 vs 400 give the same event times within 1e-7 relative and the same
    broken bonds (event times follow the stresses through exp(beta2 tau): 1e-7 in time is 1e-7/(beta2 tau) =
    5e-8 relative in a stress of 200 MPa, the bracketing tolerance's reach; a lifetime that came from a solver
    setting would move by orders of magnitude)."""
    a = _tiny_creep(bracket_tol=1e-9)
    b = _tiny_creep(bracket_tol=1e-11, changes_per_iteration=2, max_iterations=400)
    assert a.events == b.events >= 4
    assert np.allclose(a.times, b.times, rtol=1e-7)
    assert np.array_equal(a.state.broken, b.state.broken)


def test_creep_fast_path_equals_the_direct_path():
    """fem cells, 3 x 6 mm, 200 MPa, 8 events: the fast path (cached assembly, low-rank updates of a kept factor)
    and the plain direct path give the same event times within 1e-9 relative (their solves agree to a relative residual of 1e-14; the
    bracketing tolerance is 1e-9) and the same broken bonds."""
    a = _tiny_creep(bracket_tol=1e-9)
    b = _tiny_creep(bracket_tol=1e-9, reuse_factor=False)
    assert a.events == b.events >= 4
    assert np.allclose(a.times, b.times, rtol=1e-9)
    assert np.array_equal(a.state.broken, b.state.broken)
