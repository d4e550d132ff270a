"""Static engine: breaking one bond at a time, the tie rule, numbering and solver settings (no YADE)."""
import numpy as np
import pytest

from grainfrac_yade.errors import NumericalFailure
from grainfrac_yade.grains import layout_for
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.engines.static import contacts as cl
from grainfrac_yade.engines.static.cascade import Path
from grainfrac_yade.engines.static.failure import FailureRule
from grainfrac_yade.engines.static.network import build_static_network
from grainfrac_yade.engines.static.solver import Equilibrium
from static_tiny import KN, network

#: Tiny specimens per grain model: fem 3 x 6 mm; rigid 4 x 8 mm (on 3 x 6 mm seed 1 a rigid cell's mechanism
#: ends the path within a dozen breaks, reported as NumericalFailure).
TINY = {"fem": ["specimen.width=3e-3", "specimen.height=6e-3"],
        "rigid": ["specimen.width=4e-3", "specimen.height=8e-3"]}
#: Breaks followed on the tiny specimens: enough to pass cascades and friction, few enough for ~1 s.
BREAKS = 12


def _tiny(model):
    extra = ["params/presets/fem_coarse.toml"] if model == "fem" else []
    p = load_parameters(extra_files=extra, overrides=TINY[model])
    s = build_specimen(p, 1)
    return s, p, layout_for(s, p)


def _path(net, **settings):
    bracket = settings.pop("bracket_tol", None)
    eq = Equilibrium(net, **settings)
    path = Path(eq) if bracket is None else Path(eq, bracket_tol=bracket)
    state = path.run_closure(eq.initial(0.0), 0.02 * net.height, stop=lambda st, rec: len(rec) >= BREAKS)
    return path, state


def test_tie_rule_takes_the_first_in_canonical_order():
    """Ratios equal within round-off: the lowest canonical number wins, whatever order the candidates come in."""
    r = np.array([0.5, 1.0 + 1e-15, 0.9, 1.0, 1.0 - 1e-15])
    assert Path.pick(r, np.array([4, 3, 1, 2])) == 1
    assert Path.pick(r, np.array([2, 4])) == 4
    assert Path.pick(np.array([np.inf, 2.0, np.inf]), np.array([2, 1, 0])) == 0


@pytest.mark.parametrize("model", ["rigid", "fem"])
def test_results_do_not_depend_on_the_bond_numbering(model):
    """The same specimen with its bonds numbered at random breaks the same bonds (by place) in the same order at
    the same stresses: bonds are kept in a canonical order, so the two runs are bit for bit the same."""
    s, p, lay = _tiny(model)
    perm = np.random.default_rng(3).permutation(lay.n_bonds)
    a_net, b_net = build_static_network(s, p, lay), build_static_network(s, p, lay, bond_permutation=perm)
    (pa, sa), (pb, sb) = _path(a_net), _path(b_net)
    assert len(pa.records) >= BREAKS // 2
    seq_a = [a_net.order[k] for r in pa.records for k in r.bonds]
    seq_b = [perm[b_net.order[k]] for r in pb.records for k in r.bonds]
    assert seq_a == seq_b
    assert [r.stress_before for r in pa.records] == [r.stress_before for r in pb.records]
    assert sa.closure == sb.closure


@pytest.mark.parametrize("model", ["rigid", "fem"])
def test_path_does_not_depend_on_solver_settings(model):
    """Bracketing tolerance 1e-9 vs 1e-11, status changes per iteration unlimited vs 2, iteration limit 200 vs
    400: the same bonds break in the same order, at stresses equal within 1e-7 (the bracketing tolerance times
    the few-ulps slope of the path; an engine whose answer came from a solver tolerance would move by 1e-3)."""
    s, p, lay = _tiny(model)
    net = build_static_network(s, p, lay)
    pa, sa = _path(net)
    pb, sb = _path(net, bracket_tol=1e-11, changes_per_iteration=2, max_iterations=400)
    assert [k for r in pa.records for k in r.bonds] == [k for r in pb.records for k in r.bonds]
    assert np.allclose([r.stress_before for r in pa.records], [r.stress_before for r in pb.records], rtol=1e-7)


def test_ucs_of_a_tiny_rigid_specimen_on_the_plain_path_has_a_peak():
    """Rigid cells, 4 x 8 mm, the UCS protocol on the static engine's plain path: the stress rises, bonds break, the
    test passes a peak and ends post-peak (the last row below ucs.stop_stress_ratio of it).  (On 3 x 6 mm the path
    ends on a rigid cell's mechanism instead: reported.)"""
    from grainfrac_yade.protocols.ucs import run_ucs
    s, p, _ = _tiny("rigid")
    p = load_parameters(overrides=[*TINY["rigid"], "numerics.engine=static", "numerics.static_relaxation=none"])
    cols, result, _, _ = run_ucs(s, p)
    peak = max(cols["axial_stress_pa"])
    assert peak > 0 and result["peak_reached"] and not result["numerical_failure"]
    assert result["end_reason"].startswith("post-peak")
    assert cols["broken_total"][cols["axial_stress_pa"].index(peak)] > 0
    assert cols["axial_stress_pa"][-1] < p.ucs.stop_stress_ratio * peak


def test_cell_cut_loose_is_held_and_reported():
    """A node whose two bonds (to the two platens' nodes) are broken and pulled open: it is held in place,
    its two dofs counted, and nothing is NaN (the intact bond between the platens carries the pull)."""
    h = 1e-3
    net = network([[0, 0], [0, h], [h, h / 2]], [[0, 1], [0, 2], [1, 2]],
                  [[0, 1], [2 / 5 ** 0.5, 1 / 5 ** 0.5], [2 / 5 ** 0.5, -1 / 5 ** 0.5]], top=[1], bottom=[0])
    eq = Equilibrium(net, direction=-1.0)
    base = eq.initial(0.0)
    base.broken[1:], base.status[1:] = True, cl.OPEN
    state = eq.solve(1e-7, base)
    assert list(state.status) == [cl.INTACT, cl.OPEN, cl.OPEN]
    assert state.held == 2
    assert np.isfinite(state.u).all() and np.isfinite(state.fn).all()
    assert state.fn[0] == pytest.approx(net.kn[0] * 1e-7, rel=1e-12) and state.fn[1] == state.fn[2] == 0


def _hinged(**kw):
    """Node 2 bonded to node 0 by one bond whose tangent is x and whose shear stiffness is 0: free along x."""
    return network([[0, 0], [0, 1e-3], [1e-3, 0]], [[0, 1], [0, 2]], [[0, 1], [0, 1]], top=[1], bottom=[0],
                   right=[2], ks=[2e9, 0.0], **kw)


def test_unloaded_mechanism_is_held_by_the_ground_springs():
    """The free direction carries no load: the factor is made again with the ground springs, counted, and the
    forces are those of the rest of the network (bond 0 compressed by k_n x closure)."""
    eq = Equilibrium(_hinged())
    st = eq.initial(1e-7)
    assert eq.counters.grounded >= 1
    assert st.fn[0] == pytest.approx(-KN * 1e-7, rel=1e-9)   # the ground springs' 1e-12 moves it by less
    assert np.isfinite(st.u).all()


def test_loaded_mechanism_is_one_line_numerical_failure():
    """A confining traction pushes node 2 along its free direction: no equilibrium exists; one line says so."""
    with pytest.raises(NumericalFailure) as err:
        Equilibrium(_hinged(), confinement=1e6).initial(1e-7)
    assert "\n" not in str(err.value) and "mechanism" in str(err.value)


def test_confinement_is_a_constant_lateral_traction():
    """The confining stress is a dead load on the side nodes summing to sigma_3 x height x thickness on each side,
    and the confined UCS path starts from the hydrostatic state (axial stress = sigma_3 before the deviator)."""
    s, p, lay = _tiny("fem")
    net = build_static_network(s, p, lay)
    f = net.confinement_force(20e6)
    assert f[net.dofs[net.left, 0]].sum() == pytest.approx(20e6 * net.height * net.thickness, rel=1e-12)
    assert f[net.dofs[net.right, 0]].sum() == pytest.approx(-20e6 * net.height * net.thickness, rel=1e-12)
    eq = Equilibrium(net, confinement=20e6)
    state, reason = Path(eq).hold(eq.initial(0.0), 20e6, FailureRule(0.0))
    assert reason is None and state.stress == pytest.approx(20e6, rel=1e-9)   # the bracketing tolerance


#: Changed contacts allowed from a kept factor in the small-rank run of the fast-path test [1]: small enough that
#: the tiny paths pass the switch from low-rank updates to a new factor many times.
SMALL_RANK = 3


@pytest.mark.parametrize("model", ["rigid", "fem"])
def test_fast_path_breaks_the_same_bonds_as_the_direct_path(model):
    """The cached assembly with low-rank updates of a kept factor (default, and with at most SMALL_RANK changed
    contacts so that it refactorises often) against the plain direct path (every tangent assembled by sparse
    products and factorised): the same bonds break in the same order, at stresses equal within 1e-9 relative
    (the bracketing tolerance; the solves agree to a relative residual of 1e-14, tangent.FAST_RESIDUAL), and the fast path really
    updated (low-rank solves counted, fewer factorisations than tangents)."""
    s, p, lay = _tiny(model)
    net = build_static_network(s, p, lay)
    pd, sd = _path(net, reuse_factor=False)
    for rank in (None, SMALL_RANK):
        pf, sf = _path(net, **({} if rank is None else {"max_low_rank_contacts": rank}))
        assert len(pd.records) >= BREAKS // 2
        assert [k for r in pf.records for k in r.bonds] == [k for r in pd.records for k in r.bonds]
        assert np.allclose([r.stress_before for r in pf.records], [r.stress_before for r in pd.records], rtol=1e-9)
        assert np.allclose([r.stress_after for r in pf.records], [r.stress_after for r in pd.records], rtol=1e-9)
        c = pf.eq.counters
        assert c.low_rank > 0 and c.factorisations < c.tangents
    assert pd.eq.counters.low_rank == 0 and pd.eq.counters.factorisations >= pd.eq.counters.iterations // 2


def test_forget_factor_goes_on_as_a_fresh_equilibrium():
    """The fast path's answers depend on the kept factor at round-off; after forget_factor() a path goes on bit for
    bit as a new Equilibrium started from the same state does (what a saved and restored run needs)."""
    s, p, lay = _tiny("fem")
    net = build_static_network(s, p, lay)
    eq = Equilibrium(net)
    path = Path(eq)
    state = path.run_closure(eq.initial(0.0), 0.02 * net.height, stop=lambda st, rec: len(rec) >= BREAKS // 2)
    eq.forget_factor()
    a = path.run_closure(state, 0.02 * net.height, stop=lambda st, rec: len(rec) >= BREAKS)
    fresh = Path(Equilibrium(net))
    b = fresh.run_closure(state, 0.02 * net.height, stop=lambda st, rec: len(rec) >= BREAKS // 2)
    assert [k for r in path.records[BREAKS // 2:] for k in r.bonds] == [k for r in fresh.records for k in r.bonds]
    assert [r.stress_before for r in path.records[BREAKS // 2:]] == [r.stress_before for r in fresh.records]
    assert np.array_equal(a.u, b.u) and a.closure == b.closure
