"""Explicit dynamic relaxation of the static network (grainfrac_yade.engines.static.inertial) against closed forms, the
static solve and the protocol (no YADE)."""
import math

import numpy as np
import pytest

from grainfrac_yade.params import load_parameters
from grainfrac_yade.engines.static.cascade import Path
from grainfrac_yade.engines.static.failure import COLLAPSE, FailureRule
from grainfrac_yade.engines.static.inertial import (LOST_LOAD, InertialPath, InertialRelaxation, critical_step, damped_step,
                                            dof_masses)
from grainfrac_yade.engines.static.solver import Equilibrium

from static_tiny import KN, chain, creep_giving_out, plain_hold_fails_once, shear_pair

#: Steps per period of the oscillator in the closed-form test [1]: the damping's switch of sign falls inside one
#: step, an error of about 2 pi / STEPS of the swing (3e-4 here); the test's tolerance 2e-3 states that.
STEPS = 20_000


@pytest.mark.parametrize("damping", [0.0, 0.2, 0.7])
def test_damped_release_swings_past_equilibrium_by_the_closed_form(damping):
    """A unit mass on a unit spring released from rest at u_0 = 1 reaches -sqrt((1 - D) / (1 + D)) (Cundall's
    non-viscous damping D: (1 - D) of the spring's work gained on the way in, (1 + D) lost on the way out)."""
    u, v, inv_m = np.array([1.0]), np.array([0.0]), np.array([1.0])
    dt = 2 * math.pi / STEPS
    low = 1.0
    for _ in range(STEPS):
        damped_step(u, v, -u.copy(), inv_m, dt, damping)
        low = min(low, float(u[0]))
        if v[0] > 0:
            break
    assert low == pytest.approx(-math.sqrt((1 - damping) / (1 + damping)), abs=2e-3)


@pytest.mark.parametrize("model", ["rigid", "fem"])
def test_dof_masses_carry_the_cells_masses(model):
    """Every translation dof of the network carries its body's mass: summed over the x dofs they are the cells'
    masses, density x numerics.density_scale x area x thickness (to 1e-12); rotations carry an inertia."""
    from grainfrac_yade.geometry.specimen import build_specimen
    from grainfrac_yade.grains import layout_for
    from grainfrac_yade.engines.static.network import build_static_network
    p = load_parameters(overrides=["specimen.width=3e-3", "specimen.height=6e-3", f"resolution.grain_model={model}"])
    s = build_specimen(p, 1)
    lay = layout_for(s, p)
    net = build_static_network(s, p, lay)
    m = dof_masses(s, p, lay, net)
    rho = np.array([p.grains[k].density for k in s.mineral_names])[s.mineral] * p.numerics.density_scale
    total = float((rho * s.tessellation.cell_measure * s.thickness).sum())
    assert m[net.dofs[:, 0]].sum() == pytest.approx(total, rel=1e-12)
    assert np.all(m > 0) and (net.dofs[:, 2] >= 0).any() == (model == "rigid")


def test_critical_step_of_the_chain():
    """Gershgorin on the chain's free node (2 k_n on its diagonal, k_n to each platen): omega_max^2 <= 4 k_n / m."""
    net = chain(jt=1e12, jc=1e12)
    masses = np.full(net.ndof, 2e-6)
    assert critical_step(Equilibrium(net), masses) == pytest.approx(2 / math.sqrt(4 * KN / 2e-6), rel=1e-12)


def test_relaxation_comes_to_rest_on_the_static_hold(monkeypatch):
    """A plain regain made to give out once is relaxed with inertia from the last converged state; at rest the
    static regain from the relaxed state is the plain static hold's state (stress to 1e-9)."""
    net = chain(jt=1e12, jc=1e12)
    target = 50e6
    plain, _ = Path(Equilibrium(net)).hold(Equilibrium(net).initial(0.0), target, FailureRule(1e-3))
    plain_hold_fails_once(monkeypatch)
    eq = Equilibrium(net)
    path = InertialPath(eq, InertialRelaxation(eq, np.full(net.ndof, 2e-6), load_parameters()))
    start = eq.initial(0.0)
    start = eq.solve(0.5 * plain.closure, start)          # half way: the servo has the rest to close
    state, reason = path.hold(start, target, FailureRule(1e-3))
    assert reason is None and len(path.relaxations) == 1 and 0 < path.relaxations[0].steps
    assert state.stress == pytest.approx(plain.stress, rel=1e-9)
    assert np.allclose(state.u, plain.u, rtol=1e-9, atol=1e-9 * np.abs(plain.u).max())


def test_a_sliding_face_under_a_larger_held_shear_is_a_failure_not_a_numerical_one():
    """A broken face sliding at sigma tan(phi_r) under a held shear above it: the servo closes as fast as it may and
    no equilibrium comes: the relaxation ends in a failure of the specimen (collapse, or the load lost within the
    budget), never in a NumericalFailure."""
    sigma, tau = 20e6, 35e6
    net = shear_pair()
    eq = Equilibrium(net, confinement=sigma)
    path = InertialPath(eq, InertialRelaxation(eq, np.full(net.ndof, 1e-6), load_parameters()))
    state = Path.cascade(path, eq.initial(0.0), first=0)
    assert state.broken.all()
    out = path._relax(state, tau, FailureRule(1e-3), state.closure)
    assert out.failure in (COLLAPSE, LOST_LOAD) and out.steps > 0
    assert np.all(np.isfinite(out.state.u)) and math.isfinite(out.state.stress)


def test_creep_hold_goes_on_with_inertia_past_a_status_cycle_and_repeats():
    """Through the protocol: where the plain static engine ends this hold as a numerical failure, the inertial
    relaxation takes it on (no numerical failure, at least one relaxation, its DEM steps in the summary), and the
    same row run twice gives the same history and break times bit for bit (numpy in a fixed order, no YADE)."""
    a, b = (creep_giving_out("numerics.static_relaxation=inertial") for _ in range(2))
    assert not a.numerical_failure and a.scene.path.tally[0] >= 1 and a.scene.path.tally[1] > 0
    assert a.scene.summary_keys()["static_relaxation_steps"] == a.scene.path.tally[1]
    assert (a.n_events, a.failed, a.failure_reason) == (b.n_events, b.failed, b.failure_reason)
    assert np.array_equal(a.break_time, b.break_time, equal_nan=True)
    drop = {"wall_s", "cpu_s"}
    assert [{k: v for k, v in r.items() if k not in drop} for r in a.rows] == \
        [{k: v for k, v in r.items() if k not in drop} for r in b.rows]


def _rigid_ucs(*extra):
    """The 4 x 8 mm rigid-cell UCS of seed 14 on the static engine (shipped calibration): its plain path ends on a
    loaded mechanism, the same with every bond's properties changed at round-off and with another CPU's arithmetic
    (OpenBLAS's Haswell, SkylakeX or Zen kernels, numpy with or without AVX-512; tests/test_static_roundoff.py)."""
    from grainfrac_yade.geometry.specimen import build_specimen
    from grainfrac_yade.protocols.ucs import run_ucs
    p = load_parameters(overrides=["numerics.engine=static", "specimen.width=4e-3", "specimen.height=8e-3", *extra])
    return run_ucs(build_specimen(p, 14), p)


def test_ucs_past_a_loaded_mechanism_by_inertia_to_a_post_peak_end():
    """Through the protocol: the plain static UCS path of this specimen ends as a numerical failure (a loaded
    mechanism); with ``numerics.static_relaxation = "inertial"`` the specimen relaxes there with the platens held,
    loses its load, and the test ends post-peak with a strength, bit for bit the same in a second run."""
    _, plain, _, _ = _rigid_ucs("numerics.static_relaxation=none")
    assert plain["numerical_failure"] and "loaded mechanism" in plain["end_reason"] and not plain["peak_reached"]
    runs = [_rigid_ucs("numerics.static_relaxation=inertial") for _ in range(2)]
    (cols, result, scene, _), (cols2, result2, _, _) = runs
    assert not result["numerical_failure"] and result["end_reason"].startswith("post-peak")
    assert result["peak_reached"] and scene.path.tally[0] >= 1 and result["static_relaxations"] >= 1
    assert np.all(np.isfinite(cols["axial_stress_pa"]))
    drop = {"wall_s", "cpu_s", "static_relaxation_cpu_s"}
    assert {k: v for k, v in result.items() if k not in drop} == {k: v for k, v in result2.items() if k not in drop}
    assert all(np.array_equal(cols[k], cols2[k]) for k in cols if k not in drop)
