"""Overdamped implicit relaxation (grainfrac_yade.static.damped) against closed forms and the static solve (no YADE)."""
import numpy as np
import pytest

from grainfrac_yade.static.cascade import Path
from grainfrac_yade.static.damped import AnchoredEquilibrium, intact_diagonal, relax_held
from grainfrac_yade.static.failure import FailureRule
from grainfrac_yade.static.solver import Equilibrium

from static_tiny import KN, network


def chain(**kw):
    """Three nodes in a column: bottom platen, one free node, top platen; two bonds with horizontal faces."""
    return network([[0.0, 0.0], [0.0, 0.5e-3], [0.0, 1e-3]], [[0, 1], [1, 2]], [[0.0, 1.0], [0.0, 1.0]],
                   top=[2], bottom=[0], **kw)


@pytest.mark.parametrize("alpha", [0.3, 1.0, 10.0])
@pytest.mark.parametrize("reuse", [True, False])
def test_backward_euler_of_a_kelvin_voigt_element(alpha, reuse):
    """The free node of the chain (stiffness 2 k_n against the platens, anchor alpha 2 k_n) relaxes from an offset
    u_0 as u_k = (alpha / (1 + alpha))^k u_0 at a closure whose static answer is u = 0 (the platens move
    symmetrically): backward Euler of C du/dt + K u = 0, exactly."""
    net = chain(jt=1e12, jc=1e12)
    eq = AnchoredEquilibrium(net, alpha, reuse_factor=reuse)
    dof = net.dofs[1, 1]
    assert intact_diagonal(eq)[dof] == pytest.approx(2 * KN, rel=1e-12)
    state = Equilibrium(net).initial(1e-9)
    u0 = 2e-8
    state.u[dof] = u0
    r = alpha / (1 + alpha)
    for k in range(1, 6):
        eq.u_ref = state.u.copy()
        state = eq.solve(1e-9, state)
        assert state.u[dof] == pytest.approx(r ** k * u0, rel=1e-9, abs=1e-22)
        assert eq.unbalanced(state)[dof] == pytest.approx(2 * KN * alpha * (r ** (k - 1) - r ** k) * u0, rel=1e-9)


def test_fixed_point_is_the_static_equilibrium():
    """Anchored steps from the static equilibrium stay on it: it is their fixed point (forces to 1e-9)."""
    net = chain(jt=1e12, jc=1e12)
    plain = Equilibrium(net).initial(2e-9)
    eq = AnchoredEquilibrium(net, 1.0)
    eq.u_ref = plain.u.copy()
    again = eq.solve(2e-9, plain)
    assert np.allclose(again.fn, plain.fn, rtol=1e-9, atol=1e-9 * np.abs(plain.fn).max())
    assert np.abs(eq.unbalanced(again)).max() <= 1e-9 * np.abs(plain.fn).max()


def test_relax_held_ends_on_the_plain_static_hold():
    """Where the plain hold settles, a relaxation ends at its first attempt on the same state as the plain hold."""
    net = chain(jt=1e12, jc=1e12)
    eq = Equilibrium(net)
    path = Path(eq)
    target = 50e6
    plain, reason = path.hold(eq.initial(0.0), target, FailureRule(1e-3))
    assert reason is None
    start = eq.initial(0.0)
    out = relax_held(Path(eq), AnchoredEquilibrium(net, 1.0), start, target, FailureRule(1e-3))
    assert out.failure is None and out.steps == 1 and out.static_attempts == 1
    assert out.state.stress == pytest.approx(plain.stress, rel=1e-9)
    assert out.state.closure == pytest.approx(plain.closure, rel=1e-9)


def test_anchor_must_be_positive():
    with pytest.raises(ValueError):
        AnchoredEquilibrium(chain(), 0.0)


def test_relaxing_path_relaxes_where_the_plain_hold_gives_out(monkeypatch):
    """A plain regain that gives out (made to fail once here) is relaxed from the last converged state and ends on
    the plain static hold's state; a regain that does not give out is the plain one's, bit for bit."""
    from grainfrac_yade.errors import NumericalFailure
    from grainfrac_yade.static.damped import RelaxingPath

    net = chain(jt=1e12, jc=1e12)
    target = 50e6
    plain, _ = Path(Equilibrium(net)).hold(Equilibrium(net).initial(0.0), target, FailureRule(1e-3))
    eq = Equilibrium(net)
    rp = RelaxingPath(eq, AnchoredEquilibrium(net, 1.0))
    same, reason = rp.hold(eq.initial(0.0), target, FailureRule(1e-3))
    assert reason is None and np.array_equal(same.u, plain.u) and not rp.relaxations
    calls = {"n": 0}
    original = Path.hold

    def fails_once(self, *args, **kw):
        calls["n"] += 1
        if calls["n"] == 1:
            self.last_converged = args[0]
            raise NumericalFailure("static equilibrium: contact statuses did not settle (made to fail)")
        return original(self, *args, **kw)
    monkeypatch.setattr(Path, "hold", fails_once)
    eq = Equilibrium(net)
    rp = RelaxingPath(eq, AnchoredEquilibrium(net, 1.0))
    state, reason = rp.hold(eq.initial(0.0), target, FailureRule(1e-3))
    assert reason is None and len(rp.relaxations) == 1 and rp.relaxations[0].steps >= 1
    assert state.stress == pytest.approx(plain.stress, rel=1e-9)
    assert np.allclose(state.u, plain.u, rtol=1e-9, atol=1e-9 * np.abs(plain.u).max())
