"""The static engine's discrete decisions do not flip on round-off (grainfrac_yade.engines.static.ties; no YADE).

Another x86-64 CPU computes the same specimen only to round-off: numpy's SIMD kernels with and without AVX-512 give
every bond's stiffness, area and friction coefficient another last bit, OpenBLAS's kernels per CPU sum in another
order (docs/studies/paper_static.md, "Across CPUs").  The tests model that two ways: every bond's stiffnesses, area,
friction coefficients and strengths changed at random by :data:`ROUNDOFF` relative (about 45 ulp, where another CPU
changes one or two), and, in a fresh interpreter, another CPU's arithmetic itself.  Either way the path breaks the
same bonds in the same order and ends the same way; its continuous results agree to the path's resolution.
"""
import ctypes
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from grainfrac_yade.params import load_parameters
from grainfrac_yade.engines.static import contacts as cl
from grainfrac_yade.engines.static import tangent as tg
from grainfrac_yade.engines.static import ties
from grainfrac_yade.engines.static.cascade import Path
from grainfrac_yade.engines.static.solver import Equilibrium

#: Relative change of every bond's properties that models another CPU's round-off [1] (module doc).
ROUNDOFF = 1e-14
#: Agreement of continuous results (peak stress, lifetimes) between a run and its perturbed twin [1]: the path finds a
#: crossing to a bond ratio within cascade.BRACKET_TOL = 1e-9 of 1, and the platen stress there moves with the ratio
#: by the path's stress-to-ratio slope; measured up to 1.8e-7 on the peak of 24 rigid 4 x 8 mm UCS paths (seed 21;
#: the others below 1.5e-12) and 1.3e-11 on the lifetimes of six rigid 4 x 8 mm creep holds.
CONTINUOUS = 1e-6
#: Bond properties another CPU's arithmetic reaches (stiffnesses, area, friction) and the strengths.
PROPERTIES = ("kn", "ks", "area", "tan_friction", "tan_residual", "tensile_strength", "cohesion")


def _perturb(monkeypatch, rel):
    """Every static network built from now on with its bonds' PROPERTIES times (1 + rel x U(-1, 1)), seeded."""
    import grainfrac_yade.engines.static.scene as scene_mod
    build = scene_mod.build_static_network

    def perturbed(*args, **kw):
        net = build(*args, **kw)
        rng = np.random.default_rng(2024)
        for name in PROPERTIES:
            v = getattr(net, name)
            setattr(net, name, v * (1.0 + rel * rng.uniform(-1.0, 1.0, len(v))))
        return net
    monkeypatch.setattr(scene_mod, "build_static_network", perturbed)


def _record_breaks(monkeypatch) -> list:
    """A list that receives (layout bond number, mode) of every bond the static path breaks, in order."""
    seq = []
    original = Path.break_bonds   # every break goes through it (a bond alone, or a face's bonds at once)

    def recording(self, state, bonds, mode):
        seq.extend((int(self.net.order[bond]), int(mode)) for bond in bonds)
        return original(self, state, bonds, mode)
    monkeypatch.setattr(Path, "break_bonds", recording)
    return seq


def _kind(reason: str) -> str:
    """What kind of end a reason names: its words before any figure in brackets."""
    return reason.split("(")[0].strip()


def _ucs(seed, *extra):
    from grainfrac_yade.geometry.specimen import build_specimen
    from grainfrac_yade.protocols.ucs import run_ucs
    p = load_parameters(overrides=["numerics.engine=static", "numerics.static_relaxation=none", "specimen.width=4e-3",
                                   "specimen.height=8e-3", *extra])
    cols, result, _, _ = run_ucs(build_specimen(p, seed), p)
    return _kind(result["end_reason"]), float(np.max(cols["axial_stress_pa"]))


def _creep(model, seed, stress):
    from grainfrac_yade.geometry.specimen import build_specimen
    from grainfrac_yade.protocols.creep import run_creep
    files = ["params/presets/fem_coarse.toml"] if model == "fem" else []
    p = load_parameters(extra_files=files, overrides=["numerics.engine=static", "numerics.static_relaxation=none",
                                                      "specimen.width=4e-3", "specimen.height=8e-3"])
    run = run_creep(build_specimen(p, seed), p, stress)
    return run


# ---------------------------------------------------------------------------------------------- the rules themselves
def test_near_ties_go_to_the_first_in_canonical_order():
    """Values within DECISION_REL_TOL of the largest are tied (the first canonical bond wins); beyond it the larger
    wins; the status changes of an active-set iteration are ranked the same way."""
    tol = ties.DECISION_REL_TOL
    r = np.array([0.5, 1.0, 0.9, 1.0 + 0.4 * tol, 1.0 - 0.4 * tol])
    assert ties.first_of_largest(r, np.array([4, 3, 1, 2])) == 1
    assert ties.first_of_largest(r, np.array([2, 4])) == 4
    r2 = np.array([1.0, 1.0 + 3 * tol])
    assert ties.first_of_largest(r2, np.array([0, 1])) == 1
    v = np.array([5.0, 2.0, 5.0 * (1 + 0.2 * tol), 7.0, 2.0])
    assert list(ties.ranked(v, np.arange(5))) == [3, 0, 2, 1, 4]


def test_canonical_order_is_blind_to_coordinates_a_round_off_apart():
    """Contact points a few ulp apart in x sort as equal ones do (by y), whichever of them is the larger."""
    pts = np.array([[1e-3, 2e-3], [1e-3, 1e-3], [0.5e-3, 3e-3]])
    nodes = np.zeros((3, 2))
    base = ties.canonical_order(pts, nodes, nodes)
    for shift in (4, -4):
        moved = pts.copy()
        moved[0, 0] = pts[0, 0] + shift * np.spacing(pts[0, 0])
        assert list(ties.canonical_order(moved, nodes, nodes)) == list(base) == [2, 1, 0]


def test_a_contact_within_round_off_of_its_open_close_point_keeps_its_status():
    """Closed (stick or slip) or open, a broken contact keeps its status while its normal force k_n du_n is within
    STATUS_HYSTERESIS of the largest normal force of the state, on either side; beyond, it changes."""
    kn, ks, tr = np.full(3, 1e9), np.full(3, 1e9), np.full(3, 0.5)
    big = -1e-6                                  # contact 0 pressed: the state's largest normal force, 1000 N
    band = cl.STATUS_HYSTERESIS * 1e9 * 1e-6 / 1e9      # the band as a normal displacement [m]
    s_p, du_s, broken = np.zeros(3), np.zeros(3), np.ones(3, bool)
    for du_n1, du_n2, keep in ((0.5 * band, -0.5 * band, True), (2 * band, -2 * band, False)):
        du_n = np.array([big, du_n1, du_n2])
        status, sign = np.array([cl.STICK, cl.STICK, cl.OPEN]), np.ones(3)
        new, _, _ = cl.trial_status(du_n, du_s, broken, s_p, kn, ks, tr, status, sign)
        assert (list(new[1:]) == [cl.STICK, cl.OPEN]) == keep
        assert (list(new[1:]) == [cl.OPEN, cl.STICK]) == (not keep)


def test_a_singular_update_is_refused_and_the_factor_decides(monkeypatch):
    """A status set that leaves one cell held by a single slipping contact (a mechanism, the same free dofs) makes
    a singular tangent whose low-rank capacitance has a smallest pivot a round-off above zero, below
    CAPACITANCE_PIVOT_RATIO: the update is refused, and the equilibrium is solved on the tangent's own factor, made
    with the ground springs (the mechanism carries no load here)."""
    from grainfrac_yade.geometry.specimen import build_specimen
    from grainfrac_yade.grains import layout_for
    from grainfrac_yade.engines.static.network import build_static_network
    p = load_parameters(overrides=["specimen.width=3e-3", "specimen.height=6e-3"])
    s = build_specimen(p, 1)
    net = build_static_network(s, p, layout_for(s, p))
    eq = Equilibrium(net)
    state = eq.initial(1e-6)
    cell = np.unique(net.node_cell[~(net.top | net.bottom)])[0]
    mine = np.flatnonzero((net.node_cell[net.bond_nodes] == cell).any(axis=1))
    status = state.status.copy()
    status[mine], status[mine[0]] = cl.OPEN, cl.SLIP
    assert np.array_equal(eq.fixed_dofs(status)[0], eq._lr_fixed)     # the kept factor's free dofs
    a_nn, _, a_sn, a_ss, _, _ = cl.affine_law(status, state.sign, state.s_p, net.kn, net.ks, net.tan_residual)
    coef = (a_nn, a_sn, a_ss, status != cl.INTACT)
    with monkeypatch.context() as m:
        m.setattr(tg, "CAPACITANCE_PIVOT_RATIO", 0.0)
        pivots = np.abs(np.diag(eq._lr.prepare(coef).lu_cap[0]))
    assert 0 < pivots.min() < tg.CAPACITANCE_PIVOT_RATIO * pivots.max()
    assert eq._lr.prepare(coef) is None
    grounded, low_rank = eq.counters.grounded, eq.counters.low_rank
    u = eq.displacements(state.closure, status, state.sign, state.s_p, state.u)
    assert eq.counters.grounded == grounded + 1 and eq.counters.low_rank == low_rank and np.all(np.isfinite(u))


# ---------------------------------------------------------------------------------------------- whole paths
@pytest.mark.parametrize("seed", [4, 14])
def test_ucs_path_breaks_the_same_bonds_and_ends_the_same_at_round_off(monkeypatch, seed):
    """The 4 x 8 mm rigid-cell UCS (seed 4: the specimen whose plain path ended one way on one CPU and the other way
    on another; seed 14: a path that ends on a loaded mechanism) and its twins with every bond's properties changed
    at round-off (+- ROUNDOFF): the same bonds break in the same order with the same modes, the path ends the same
    way, and the peak agrees within CONTINUOUS."""
    runs = []
    for rel in (0.0, ROUNDOFF, -ROUNDOFF):
        with monkeypatch.context() as m:
            if rel:
                _perturb(m, rel)
            seq = _record_breaks(m)
            kind, peak = _ucs(seed)
            runs.append((seq, kind, peak))
    (seq, kind, peak), others = runs[0], runs[1:]
    assert len(seq) >= 10
    for seq2, kind2, peak2 in others:
        assert seq2 == seq and kind2 == kind
        assert peak2 == pytest.approx(peak, rel=CONTINUOUS)


@pytest.mark.parametrize("model, seed, stress", [("rigid", 1, 160e6), ("fem", 4, 160e6)])
def test_creep_hold_breaks_the_same_bonds_and_ends_the_same_at_round_off(monkeypatch, model, seed, stress):
    """A 4 x 8 mm creep hold on the static engine (rigid seed 1: it fails; fem seed 4: it reaches the time limit)
    and its twin with every bond's properties changed at round-off: the same bonds break in the same order, the same
    events at the same creep times (within CONTINUOUS), and the same end."""
    runs = []
    for rel in (0.0, ROUNDOFF):
        with monkeypatch.context() as m:
            if rel:
                _perturb(m, rel)
            seq = _record_breaks(m)
            runs.append((seq, _creep(model, seed, stress)))
    (seq_a, a), (seq_b, b) = runs
    assert len(seq_a) >= 10 and a.n_events >= 5 and not a.numerical_failure
    assert seq_a == seq_b
    assert (a.n_events, a.failed, _kind(a.failure_reason)) == (b.n_events, b.failed, _kind(b.failure_reason))
    assert np.array_equal(np.isnan(a.break_time), np.isnan(b.break_time))
    done = ~np.isnan(a.break_time)
    assert np.allclose(b.break_time[done], a.break_time[done], rtol=CONTINUOUS, atol=0)
    assert b.rows[-1]["creep_time_s"] == pytest.approx(a.rows[-1]["creep_time_s"], rel=CONTINUOUS)


# ---------------------------------------------------------------------------------------------- another CPU
#: numpy's run-time dispatched features switched off to take another CPU's kernels (an x86-64 CPU without AVX-512).
NO_AVX512 = "AVX512F AVX512CD AVX512_SKX AVX512_CLX AVX512_CNL AVX512_ICL"


def _openblas_core():
    """OpenBLAS's kernel family on this machine (None where numpy is not on OpenBLAS)."""
    for name in ("libopenblas.so.0", "libopenblasp-r0.3.21.so"):
        try:
            lib = ctypes.CDLL(name)
        except OSError:
            continue
        lib.openblas_get_corename.restype = ctypes.c_char_p
        return lib.openblas_get_corename().decode()
    return None


def _other_arithmetic() -> dict:
    """Environment that gives this interpreter's child another x86-64 CPU's arithmetic: numpy without its AVX-512
    kernels and OpenBLAS on other kernels (Haswell's, or Sandybridge's where Haswell's are this machine's own)."""
    env = {"NPY_DISABLE_CPU_FEATURES": NO_AVX512}
    core = _openblas_core()
    flags = open("/proc/cpuinfo").read() if os.path.exists("/proc/cpuinfo") else ""
    if core is not None and " avx2" in flags and " fma" in flags:
        env["OPENBLAS_CORETYPE"] = "Sandybridge" if core.lower() in ("haswell", "zen") else "Haswell"
    return env


_CHILD = """
import json, sys
sys.path.insert(0, {tests!r})
import numpy as np
from test_static_roundoff import _kind, _ucs
import grainfrac_yade.engines.static.cascade as cascade
seq = []
original = cascade.Path.break_bonds
def recording(self, state, bonds, mode):
    seq.extend([int(self.net.order[bond]), int(mode)] for bond in bonds)
    return original(self, state, bonds, mode)
cascade.Path.break_bonds = recording
kind, peak = _ucs({seed})
print(json.dumps({{"seq": seq, "kind": kind, "peak": peak}}))
"""


def test_ucs_ends_the_same_with_another_cpus_arithmetic(monkeypatch):
    """The 4 x 8 mm rigid UCS of seed 4 here and in a fresh interpreter with another CPU's arithmetic (numpy without
    AVX-512 kernels, OpenBLAS on other kernels: what an AMD EPYC without AVX-512 picks by itself): the same bonds
    break in the same order and the path ends the same way."""
    env = _other_arithmetic()
    if "OPENBLAS_CORETYPE" not in env:
        pytest.skip("numpy is not on OpenBLAS with AVX2 kernels here: no other kernels to pick")
    tests = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(tests)
    out = subprocess.run([sys.executable, "-c", _CHILD.format(tests=tests, seed=4)], cwd=root, capture_output=True,
                         text=True, env={**os.environ, "OMP_NUM_THREADS": "1", **env}, check=True)
    child = json.loads(out.stdout.strip().splitlines()[-1])
    seq = _record_breaks(monkeypatch)
    kind, peak = _ucs(4)
    assert len(seq) >= 10 and [tuple(x) for x in child["seq"]] == seq and child["kind"] == kind
    assert child["peak"] == pytest.approx(peak, rel=CONTINUOUS)
