"""The fast path's low-rank (Woodbury) solves against direct SuperLU solves of the changed tangent (no YADE)."""
import numpy as np
import scipy.sparse.linalg as spla

from grainfrac_yade.grains import layout_for
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.engines.static import contacts as cl
from grainfrac_yade.engines.static.network import build_static_network
from grainfrac_yade.engines.static.solver import Equilibrium

#: Relative agreement [1] of a Woodbury solve (unrefined) with a direct SuperLU solve of the assembled changed
#: tangent: both are exact algebra carried out in float64, each leaves a relative residual of ~1e-15
#: (tangent.RESIDUAL_MARGIN's measurements); the difference of the solutions is that residual times the
#: tangent's condition number (pivot ratios ~1e-6 on these specimens); measured 2.5e-14 and 4.8e-14 here, so
#: 1e-10 has a margin of ~2000 and still catches any algebraic slip (a wrong column, a wrong V row, a stale or
#: misplaced cached block), which shows at order 1.
AGREEMENT = 1e-10


def _equilibrium():
    p = load_parameters(extra_files=["params/presets/fem_coarse.toml"],
                        overrides=["specimen.width=3e-3", "specimen.height=6e-3"])
    s = build_specimen(p, 1)
    net = build_static_network(s, p, layout_for(s, p))
    eq = Equilibrium(net)
    state = eq.initial(1e-6)         # compressed: the kept factor is the intact tangent with every contact closed
    return net, eq, state


def _coef(net, status, sign, s_p):
    a_nn, _, a_sn, a_ss, _, _ = cl.affine_law(status, sign, s_p, net.kn, net.ks, net.tan_residual)
    return a_nn, a_sn, a_ss, status != cl.INTACT


def test_low_rank_solve_equals_a_direct_solve_of_the_changed_tangent():
    """Several contacts changed at once from the kept (intact) factor, first all new (their K^-1 U columns in one
    block back-substitution), then a superset of them whose first part is cached and whose rest is new, with
    stick and (non-symmetric) slip laws: the Woodbury solve equals SuperLU on the assembled changed tangent (by the
    plain sparse products, not the cached pattern) within AGREEMENT, and the counter counts one back-substitution
    per U column."""
    net, eq, state = _equilibrium()
    lr = eq._lr
    fixed = eq._lr_fixed
    rng = np.random.default_rng(3)
    interior = np.flatnonzero(~(net.top | net.bottom)[net.bond_nodes].any(axis=1))
    pick = rng.choice(interior, 12, replace=False)
    status, sign, s_p = state.status.copy(), state.sign.copy(), state.s_p.copy()
    v = np.zeros(net.ndof)          # the platens' unit closure: the right-hand side of the tangent response
    v[eq.platen_fixed] = eq.e[eq.platen_fixed]
    rhs = -(eq._kfc @ v[fixed])
    steps = [(pick[:5], cl.STICK), (pick[5:12], cl.SLIP)]   # the second keeps the first five as they were
    for contacts, law in steps:
        status[contacts] = law
        sign[contacts] = rng.choice([-1.0, 1.0], len(contacts))
        f2, _, _ = eq.fixed_dofs(status)
        assert np.array_equal(f2, fixed)        # closed contacts only: the same free set, a low-rank update
        before = lr.back_substitutions
        op = lr.prepare(_coef(net, status, sign, s_p))
        assert op is not None and op.z is not None
        assert lr.back_substitutions - before == 2 * len(contacts)     # only the new ones, two columns each
        assert len(op.z) == np.count_nonzero(status != state.status)
        k = eq.tangent(status, sign, s_p)
        kff = k[~fixed][:, ~fixed].tocsc()
        x_direct = spla.splu(kff, permc_spec="COLAMD").solve(rhs)
        x = op.apply(rhs)
        assert np.abs(x - x_direct).max() <= AGREEMENT * np.abs(x_direct).max()
        xr = op.solve(kff, rhs)                   # refined against the changed tangent: accepted, as close
        assert xr is not None
        assert np.abs(xr - x_direct).max() <= AGREEMENT * np.abs(x_direct).max()
    assert np.any(status == cl.SLIP) and np.any(status == cl.STICK)


def test_incremental_assembly_equals_a_full_one_bit_for_bit():
    """The tangent's values re-summed only where the contacts changed since the last assembly touch the pattern
    equal a full assembly of the same statuses bit for bit, over a sequence of random status changes of a few
    contacts (open, stick, slip of either sign, intact) and then of every contact."""
    net, eq, state = _equilibrium()
    pattern = eq._pattern
    rng = np.random.default_rng(5)
    status, sign, s_p = state.status.copy(), state.sign.copy(), state.s_p.copy()
    for size in (1, 3, 7, 2, len(status)):
        pick = rng.choice(len(status), size, replace=False)
        status[pick] = rng.integers(cl.INTACT, cl.SLIP + 1, size)
        sign[pick] = rng.choice([-1.0, 1.0], size)
        coef = _coef(net, status, sign, s_p)
        kept = pattern.data(*coef)
        assert np.array_equal(kept.view(np.int64), pattern._sum(None, *coef).view(np.int64))


def test_groups_of_fixed_dofs_are_the_connected_node_groups():
    """The groups that fixed_dofs holds or pins, solved on the graph of cells, are the connected components of the
    nodes joined by the grain stiffness and by the closed contacts (the same partition), with some contacts open."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from grainfrac_yade.engines.static.solver import net_tri_edges
    net, eq, state = _equilibrium()
    rng = np.random.default_rng(7)
    closed = rng.random(net.n_bonds) > 0.4
    ea, eb = net_tri_edges(net)
    a, b = np.concatenate([net.bond_nodes[closed, 0], ea]), np.concatenate([net.bond_nodes[closed, 1], eb])
    nn = len(net.node_pos)
    _, label = connected_components(coo_matrix((np.ones(len(a)), (a, b)), shape=(nn, nn)), directed=False)
    groups = eq._groups(closed)
    pairs = np.unique(np.stack([label, groups]), axis=1)      # one group for every component and back
    assert len(np.unique(pairs[0])) == len(np.unique(pairs[1])) == pairs.shape[1]
