"""Static engine: the bond and contact law against closed forms, one bond at a time (no YADE)."""
import numpy as np
import pytest

from grainfrac_yade.engines.static import contacts as cl
from grainfrac_yade.engines.static.cascade import Path
from grainfrac_yade.engines.static.solver import Equilibrium
from static_tiny import JC, JT, PHI, PHI_R, shear_pair, tension_pair

#: Closed forms hold to round-off: a handful of float operations on numbers of order 1e7 Pa (1e-12 relative).
EXACT = 1e-12


def _first_break(eq, max_closure=1e-3):
    path = Path(eq)
    state = eq.initial(0.0)
    state = path.run_closure(state, max_closure, stop=lambda st, rec: bool(rec))
    return path, state


def test_one_bond_breaks_in_tension_at_its_tensile_strength():
    """Pulling one bond: it breaks when sigma = J^T (paper Eq. 4), in tension, and then carries nothing."""
    eq = Equilibrium(tension_pair(), direction=-1.0)
    path, state = _first_break(eq)
    rec = path.records[0]
    assert -rec.stress_before == pytest.approx(JT, rel=EXACT)
    assert rec.modes == [cl.TENSION]
    assert state.broken[0] and state.status[0] == cl.OPEN
    assert state.fn[0] == 0.0 and state.fs[0] == 0.0 and rec.stress_after == 0.0


@pytest.mark.parametrize("sigma", [0.0, 20e6, 60e6])
def test_one_bond_breaks_in_shear_at_cohesion_plus_friction(sigma):
    """Shearing one bond pressed by sigma: it breaks when tau = J^C + sigma tan(phi) (paper Eq. 5)."""
    eq = Equilibrium(shear_pair(), confinement=sigma)
    path, state = _first_break(eq)
    rec = path.records[0]
    assert rec.stress_before == pytest.approx(JC + sigma * np.tan(PHI), rel=EXACT)
    assert rec.modes == [cl.SHEAR]


def test_broken_face_slides_at_residual_friction():
    """After the shear break the face slides: tau = sigma tan(phi_r) at once and for any further closure,
    and its normal force stays sigma A (compression only, closed)."""
    sigma = 40e6
    eq = Equilibrium(shear_pair(), confinement=sigma)
    path, state = _first_break(eq)
    assert path.records[0].stress_after == pytest.approx(sigma * np.tan(PHI_R), rel=EXACT)
    assert state.status[0] == cl.SLIP
    later = path.run_closure(state, 10 * state.closure)
    assert later.closure == pytest.approx(10 * state.closure, rel=EXACT)
    assert later.stress == pytest.approx(sigma * np.tan(PHI_R), rel=EXACT)
    assert -later.fn[0] / 1e-6 == pytest.approx(sigma, rel=EXACT)


def test_unconfined_broken_face_carries_no_shear():
    """Without a normal force a broken face has no friction to offer: the platen stress falls to 0."""
    eq = Equilibrium(shear_pair())
    path, state = _first_break(eq)
    assert path.records[0].stress_after == pytest.approx(0.0, abs=EXACT * JC)


def test_overstress_ratio_and_crossing_increment_agree():
    """Along F = F0 + x F1 the ratio reaches 1 exactly at the crossing increment (tension and both shear signs)."""
    rng = np.random.default_rng(0)
    m = 200
    area = np.full(m, 1e-6)
    jt, jc, tphi = np.full(m, JT), np.full(m, JC), np.full(m, np.tan(PHI))
    fn0, fs0 = rng.uniform(-20, 2, m), rng.uniform(-5, 5, m)
    fn1, fs1 = rng.normal(0, 10, m), rng.normal(0, 10, m)
    x = cl.crossing_increment(fn0, fs0, fn1, fs1, area, jt, jc, tphi)
    ok = np.isfinite(x)
    assert ok.sum() > 50
    r, _ = cl.overstress(fn0[ok] + x[ok] * fn1[ok], fs0[ok] + x[ok] * fs1[ok], area[ok], jt[ok], jc[ok], tphi[ok])
    assert r == pytest.approx(np.ones(ok.sum()), rel=1e-9)   # ratio of a sum of O(1) terms: 1e-9 is generous
    assert (cl.overstress(fn0, fs0, area, jt, jc, tphi)[0] < 1).all()


def test_return_mapping_from_the_last_converged_state():
    """A sticking contact pushed beyond the friction limit slips with the limit force; a slipping one whose trial
    force turns back sticks first; an opening one forgets its shear."""
    kn, ks, tr = np.full(3, 1e9), np.full(3, 1e9), np.full(3, 0.5)
    du_n, du_s, s_p = np.array([-1e-6, -1e-6, 1e-7]), np.array([2e-6, -2e-6, 5e-6]), np.zeros(3)
    broken = np.ones(3, bool)
    st, sign, _ = cl.trial_status(du_n, du_s, broken, s_p, kn, ks, tr)
    assert list(st) == [cl.SLIP, cl.SLIP, cl.OPEN]
    fn, fs = cl.forces(du_n, du_s, st, sign, s_p, kn, ks, tr)
    assert fs[:2] == pytest.approx([500.0, -500.0]) and fn[:2] == pytest.approx([-1000.0, -1000.0])
    assert fn[2] == 0 and fs[2] == 0
    st2, _, _ = cl.trial_status(du_n, du_s, broken, s_p, kn, ks, tr, st, -sign)
    assert list(st2[:2]) == [cl.STICK, cl.STICK]
    assert cl.converged_slip(du_s, st, fs, ks)[2] == du_s[2]
