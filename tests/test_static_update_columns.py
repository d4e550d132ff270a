"""The low-rank updates' named numerics (no YADE): ``numerics.static_update_columns = "rows"`` (each changed contact's
rows back-substituted once per kept factor, combined with the change of its coefficients) against direct SuperLU
solves of the changed tangent, the columns it back-substitutes, the same breaking path as ``"changes"`` to round-off,
and both parameters reaching the scene's solver."""
import numpy as np
import pytest
import scipy.sparse.linalg as spla

from grainfrac_yade.engines.registry import engine_for
from grainfrac_yade.engines.static import contacts as cl
from grainfrac_yade.engines.static.network import build_static_network
from grainfrac_yade.engines.static.solver import Equilibrium
from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.grains import layout_for
from grainfrac_yade.params import load_parameters

#: Relative agreement [1] of a low-rank solve with a direct SuperLU solve of the assembled changed tangent: the
#: reasoning and measurements of tests/test_static_lowrank.py (both exact algebra in float64; their difference is
#: ~1e-15 residuals times the condition number, measured ~5e-14); an algebraic slip (a wrong row kind, a
#: coefficient of the wrong sign, a stale column) shows at order 1.
AGREEMENT = 1e-10
#: Relative agreement [1] of the platen stresses along one breaking path solved with either kind of columns: the
#: solutions differ at round-off (~1e-14); the path brackets each crossing to 1e-9 (cascade.BRACKET_TOL), so the
#: bracketed closures, and with them the stresses, may differ within that tolerance, not more.
PATH_AGREEMENT = 1e-8


def _params(fem, *overrides):
    return load_parameters(extra_files=["params/presets/fem_coarse.toml"] if fem else [],
                           overrides=["specimen.width=3e-3", "specimen.height=6e-3", *overrides])


def _coef(net, status, sign, s_p):
    a_nn, _, a_sn, a_ss, _, _ = cl.affine_law(status, sign, s_p, net.kn, net.ks, net.tan_residual)
    return a_nn, a_sn, a_ss, status != cl.INTACT


@pytest.mark.parametrize("fem", [True, False], ids=["fem", "rigid"])
def test_rows_columns_solve_the_changed_tangent(fem):
    """From the kept intact factor: contacts broken sticking, then slipping (the same ones again, and new ones), then
    two opened: each low-rank solve equals SuperLU on the assembled changed tangent within AGREEMENT.  Fem cells
    (force rows = kinematic rows): breaking into stick changes nothing (no column), into slip only the shear row
    (one column, reused when the same contact changes again), opening both rows (two); rigid cells (torque arms in
    the intact rows) up to four rows a contact."""
    p = _params(fem)
    s = build_specimen(p, 1)
    net = build_static_network(s, p, layout_for(s, p))
    eq = Equilibrium(net, update_columns="rows")
    state = eq.initial(1e-6)
    assert eq._rows_kinematic is fem
    lr, fixed = eq._lr, eq._lr_fixed
    rng = np.random.default_rng(3)
    interior = np.flatnonzero(~(net.top | net.bottom)[net.bond_nodes].any(axis=1))
    pick = rng.choice(interior, 11, replace=False)
    status, sign, s_p = state.status.copy(), state.sign.copy(), state.s_p.copy()
    v = np.zeros(net.ndof)
    v[eq.platen_fixed] = eq.e[eq.platen_fixed]
    rhs = -(eq._kfc @ v[fixed])
    steps = [(pick[:5], cl.STICK, 0), (pick[:9], cl.SLIP, 9), (pick[9:], cl.OPEN, 4)]   # fem: new columns
    for contacts, law, fem_columns in steps:
        status[contacts] = law
        sign[contacts] = rng.choice([-1.0, 1.0], len(contacts))
        assert np.array_equal(eq.fixed_dofs(status)[0], fixed)     # the same free set: a low-rank update
        before = lr.back_substitutions
        op = lr.prepare(_coef(net, status, sign, s_p))
        assert op is not None and op.z is not None
        new_columns = lr.back_substitutions - before
        if fem:
            assert new_columns == fem_columns
        else:
            assert 0 < new_columns <= 4 * len(contacts)
        kff = eq.tangent(status, sign, s_p)[~fixed][:, ~fixed].tocsc()
        x_direct = spla.splu(kff, permc_spec="COLAMD").solve(rhs)
        for x in (op.apply(rhs), op.solve(kff, rhs)):
            assert x is not None
            assert np.abs(x - x_direct).max() <= AGREEMENT * np.abs(x_direct).max()


def _path(*overrides):
    p = _params(True, "numerics.engine=static", "numerics.static_relaxation=none", "resolution.nodes_per_face=4",
                *overrides)
    scene = engine_for(p).build_scene(build_specimen(p, 1), p)
    end = scene.path.run_closure(scene.state, 4e-3 * p.specimen.height)
    return scene, end


def test_rows_columns_give_the_same_breaking_path():
    """A fem UCS path to 0.4 % strain (3 x 6 mm, 4 bonds a face: 66 breaks) solved with each kind of columns and with
    another low-rank contact limit: the same bonds break in the same order, the stresses within PATH_AGREEMENT; the
    rows need fewer back-substitutions; and the parameters are what the scene's solver uses."""
    base, base_end = _path()
    rows, rows_end = _path("numerics.static_update_columns=rows", "numerics.static_low_rank_contacts=16")
    assert (rows.eq.update_columns, rows.eq.max_low_rank_contacts) == ("rows", 16)
    assert rows.eq._lr is None or (rows.eq._lr.columns, rows.eq._lr.max_contacts) == ("rows", 16)
    assert (base.eq.update_columns, base.eq.max_low_rank_contacts) == ("changes", 128)
    seq = [b for r in base.path.records for b in r.bonds]
    assert len(seq) > 50
    assert seq == [b for r in rows.path.records for b in r.bonds]
    a = np.array([r.stress_before for r in base.path.records] + [base_end.stress])
    b = np.array([r.stress_before for r in rows.path.records] + [rows_end.stress])
    assert np.abs(a - b).max() <= PATH_AGREEMENT * np.abs(a).max()
    assert rows.eq.counters.back_substitutions < base.eq.counters.back_substitutions
    assert rows.eq.counters.factorisations > base.eq.counters.factorisations     # the lower contact limit
