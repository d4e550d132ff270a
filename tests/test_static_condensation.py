"""The fem cells' interiors condensed out of the static system (``numerics.static_condensation = "cell_interiors"``,
grainfrac_yade/engines/static/condensation.py; no YADE): the condensed equilibrium against the full one, the same UCS,
where the option is refused or does not reach, and a checkpointed run resumed as the run without a stop."""
import numpy as np
import pytest

from static_tiny import assert_resumed_as_whole, run_killed_and_resumed

from grainfrac_yade.engines.static import contacts as cl
from grainfrac_yade.engines.static.condensation import CellInteriors
from grainfrac_yade.engines.static.damped import AnchoredEquilibrium
from grainfrac_yade.engines.static.network import build_static_network
from grainfrac_yade.engines.static.solver import Equilibrium, State, solver_options
from grainfrac_yade.errors import ParameterError
from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.grains import layout_for
from grainfrac_yade.params import load_parameters

#: Relative agreement [1] of condensed and full equilibria (displacements, bond forces, platen stress, the tangent
#: response): both solve the same linear systems exactly, in another elimination order, so they differ by round-off
#: times the condition number (measured 5e-13 to 8e-13 on this specimen); 1e-9 is the level at which the static path
#: calls two contacts' decisions a tie (ties.DECISION_REL_TOL), below which the paths cannot part.  A wrong Schur
#: term, a load left on the interior or a stale recovery shows at order 1e-3 or more.
AGREEMENT = 1e-9
#: Relative agreement [1] of stresses along one breaking path solved both ways: each break's closure is bracketed to
#: 1e-9 (cascade.BRACKET_TOL), so the bracketed closures, and with them the stresses, may differ within that, not more
#: (as tests/test_static_update_columns.py).
PATH_AGREEMENT = 1e-8
CONVERGED = ["specimen.width=3e-3", "specimen.height=6e-3"]     # params/presets/fem.toml: K = 8, 4 rings graded 2
CONDENSED = "numerics.static_condensation=cell_interiors"


def _params(*overrides, fem=True):
    return load_parameters(extra_files=["params/presets/fem.toml"] if fem else [], overrides=[*CONVERGED, *overrides])


def _rel(a, b):
    return np.abs(a - b).max() / np.abs(a).max()


@pytest.fixture(scope="module")
def net():
    p = _params()
    s = build_specimen(p, 1)
    return build_static_network(s, p, layout_for(s, p))


@pytest.mark.parametrize("confinement, direction, statuses", [(30e6, 1.0, {cl.STICK, cl.SLIP}),
                                                                  (0.0, -1.0, {cl.OPEN, cl.STICK, cl.SLIP})],
                         ids=["confined compression", "pull"])
def test_condensed_equilibrium_is_the_full_one(net, confinement, direction, statuses):
    """Confined compression (a load on the side cells' interior nodes) and a pull, with a fifth of the bonds broken
    (the active set then has contacts sticking and slipping, and open in the pull): the same statuses, and
    displacements (interior ones recovered), bond forces, platen stress and tangent response within AGREEMENT; the
    condensed factor has under a third of the full one's dofs."""
    full, cond = (Equilibrium(net, confinement=confinement, direction=direction, condensation=c)
                  for c in ("none", "cell_interiors"))
    assert full._interiors is None and cond._interiors is not None
    m = net.n_bonds
    broken = np.random.default_rng(5).random(m) < 0.2
    z = np.zeros(m)
    base = State(0.0, np.zeros(net.ndof), broken, np.where(broken, cl.STICK, cl.INTACT), np.ones(m), z, z, z, 0.0,
                 np.where(broken, cl.SHEAR, 0))
    a, b = full.solve(4e-6, base), cond.solve(4e-6, base)
    assert statuses <= set(a.status[broken].tolist())
    assert np.array_equal(a.status, b.status) and np.array_equal(a.sign, b.sign)
    interior = cond._interiors.interior
    assert np.abs(a.u[interior]).max() > 0.1 * np.abs(a.u).max()
    for x, y in ((a.u, b.u), (a.fn, b.fn), (a.fs, b.fs), (np.array([a.stress]), np.array([b.stress]))):
        assert _rel(x, y) <= AGREEMENT
    va, vb = full.response(a), cond.response(b)
    assert _rel(va[0], vb[0]) <= AGREEMENT and abs(va[3] - vb[3]) <= AGREEMENT * abs(va[3])
    assert 3 * cond._kff.shape[0] < full._kff.shape[0]


def test_a_fixed_set_holding_part_of_a_cell_interior_is_refused(net):
    """A cell held whole (cut loose) is fixed with its interior; a fixed set that holds part of an interior cannot be
    condensed (the interior is eliminated whole): ValueError."""
    cells = CellInteriors(net)
    some = cells.interior_cell[0]
    whole = np.zeros(net.ndof, bool)
    whole[net.dofs[net.node_cell == some, :2].ravel()] = True
    fixed, recover = cells.split(whole)
    assert fixed[cells.interior].all() and not recover[cells.interior_cell == some].any()
    assert recover[cells.interior_cell != some].all()
    part = np.zeros(net.ndof, bool)
    part[cells.interior_dofs[0]] = True
    with pytest.raises(ValueError, match="part of a cell's interior"):
        cells.split(part)


def test_where_the_option_is_refused_or_does_not_reach(net):
    """Rigid cells (no interior node) are refused in one line naming the key; an unknown mode too; the direct path
    (the reference) and the overdamped relaxation's anchored steps (their anchor stiffens the interior) solve the
    full system; the parameter reaches the scene's solver."""
    with pytest.raises(ParameterError, match="numerics.static_condensation.*rigid cell has none"):
        _params(CONDENSED, fem=False)
    with pytest.raises(ParameterError, match="numerics.static_condensation"):
        _params("numerics.static_condensation=boundary")
    with pytest.raises(ValueError, match="static condensation"):
        Equilibrium(net, condensation="boundary")
    assert Equilibrium(net, reuse_factor=False, condensation="cell_interiors")._interiors is None
    assert AnchoredEquilibrium(net, condensation="cell_interiors")._interiors is None
    assert solver_options(_params(CONDENSED))["condensation"] == "cell_interiors"
    assert solver_options(_params())["condensation"] == "none"


def test_condensed_ucs_is_the_full_one():
    """The 3 x 6 mm fem UCS (K = 8, 4 graded rings; the inertial relaxation where the path gives out) both ways: the
    same bonds break in the same mode (213 of 400), the same equilibria and end (this small specimen reaches the 2 %
    strain limit before its stress falls off: the largest stress is the UCS), the UCS within PATH_AGREEMENT."""
    from grainfrac_yade.protocols.ucs import run_ucs
    out = {}
    for mode in ("none", "cell_interiors"):
        p = _params("numerics.engine=static", "numerics.static_relaxation=inertial",
                    f"numerics.static_condensation={mode}")
        history, result, scene, _ = run_ucs(build_specimen(p, 1), p)
        out[mode] = {**result, "ucs_pa": max(history["axial_stress_pa"])}, scene
    (ra, sa), (rb, sb) = out["none"], out["cell_interiors"]
    assert sb.eq._interiors is not None and sa.eq._interiors is None
    assert ra["broken_total"] > 100
    for k in ("broken_total", "broken_tensile", "broken_shear", "steps", "static_relaxations", "end_reason"):
        assert ra[k] == rb[k], k
    assert np.array_equal(sa.broken, sb.broken) and np.array_equal(sa.state.break_mode, sb.state.break_mode)
    assert abs(ra["ucs_pa"] - rb["ucs_pa"]) <= PATH_AGREEMENT * ra["ucs_pa"]


def test_condensed_creep_killed_and_resumed_is_the_run_without_a_stop(tmp_path, monkeypatch):
    """A fem creep (4 x 8 mm, K = 4, 2 graded rings, 160 MPa, the inertial relaxation) with the interiors condensed
    out, killed at its fifth checkpoint and resumed: the same history (wall times aside), events, break times and
    broken set, bit for bit, as the run without a stop, with checkpoints at every safe point and with none (the kept
    factor is rebuilt on the condensed system)."""
    from grainfrac_yade.protocols.creep import run_creep

    def params(interval):
        return load_parameters(extra_files=["params/presets/fem.toml"],
                               overrides=["numerics.engine=static", "numerics.static_relaxation=inertial", CONDENSED,
                                          "specimen.width=4e-3", "specimen.height=8e-3", "resolution.nodes_per_face=4",
                                          "resolution.cell_rings=2", f"numerics.checkpoint_interval={interval}"])
    p0 = params(0)
    plain = run_creep(build_specimen(p0, 1), p0, 160e6, checkpoint_folder=tmp_path / "plain", run_values={"seed": 1})
    whole, resumed = run_killed_and_resumed(tmp_path, monkeypatch, params(1e-9), 1, 160e6,
                                            lambda run, written: written == 5)
    assert whole.n_events > 1 and len(whole.checkpointer.write_s) > 5
    assert resumed.scene.eq._interiors is not None
    assert_resumed_as_whole(resumed, whole)
    assert_resumed_as_whole(resumed, plain)
    assert np.array_equal(resumed.scene.broken, whole.scene.broken)
    assert np.array_equal(resumed.scene.broken, plain.scene.broken)


def test_factor_state_rebuilds_the_condensed_factor_bit_for_bit():
    """A fem UCS path past its first breaks with the interiors condensed out (low-rank updates of a kept condensed
    factor in use): a second equilibrium given the first's factor_state answers the next steps as the first does, to
    the last bit (interior displacements too)."""
    from grainfrac_yade.engines.registry import engine
    p = _params("numerics.engine=static", CONDENSED)
    scene = engine("static").build_scene(build_specimen(p, 1), p)
    pl = scene.attach_platens("free")
    pl.set_axial_velocity(p.ucs.strain_rate * pl.height)
    scene.run(400)
    assert scene.broken.any() and scene.eq._lr is not None and scene.eq._interiors is not None
    saved = {k: v.copy() if isinstance(v, np.ndarray) else v for k, v in scene.eq.factor_state().items()}
    assert len(saved["reference_columns"])
    twin = Equilibrium(scene.net, **solver_options(p))
    twin.restore_factor_state(saved)
    state = scene.state
    for closure in (state.closure * 1.0001, state.closure * 1.0003):
        a, b = scene.eq.solve(closure, state), twin.solve(closure, state)
        assert np.array_equal(a.u, b.u) and np.array_equal(a.status, b.status)
