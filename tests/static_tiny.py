"""Tiny static networks with closed-form answers (helpers of tests/test_static_*.py; no YADE)."""
import numpy as np
import pytest

from grainfrac_yade.elastic import Network
from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.engines.static.network import from_network

#: Bond stiffnesses [N/m] and strengths [Pa] of the tiny networks: Table 2's orders of magnitude.
KN, KS = 5e9, 2e9
JT, JC = 10e6, 30e6
PHI, PHI_R = np.radians(40.0), np.radians(25.0)


def network(pos, springs, normals, *, top, bottom, left=(), right=(), area=1e-6, kn=KN, ks=KS, jt=JT, jc=JC,
            phi=PHI, phi_r=PHI_R, width=1e-3, height=1e-3, thickness=1e-3, face=None):
    """Translating nodes at ``pos`` joined by springs (pairs) with the given unit normals; every spring a bond of
    ``area`` [m^2]; per-spring arrays or scalars for stiffness and strengths; ``face``: each spring's face (default:
    a face of its own)."""
    pos = np.asarray(pos, float)
    springs = np.asarray(springs, np.int64)
    m, n = len(springs), len(pos)
    full = lambda v: np.broadcast_to(np.asarray(v, float), (m,)).copy()  # noqa: E731
    net = Network(node_pos=pos, node_rotates=np.zeros(n, bool), node_cell=np.arange(n), spring_nodes=springs,
                  spring_normal=np.asarray(normals, float), spring_arm=np.zeros((m, 2, 2)), spring_kn=full(kn),
                  spring_ks=full(ks), spring_area=full(area),
                  spring_face=np.arange(m) if face is None else np.asarray(face, np.int64),
                  tri_nodes=np.zeros((0, 3), np.int64), tri_stiffness=np.zeros((0, 3, 3)))
    mask = lambda idx: np.isin(np.arange(n), idx)  # noqa: E731
    return from_network(net, top=mask(top), bottom=mask(bottom), left=mask(left), right=mask(right), width=width,
                        height=height, thickness=thickness, tensile_strength=full(jt), cohesion=full(jc),
                        friction_angle=full(phi), residual_friction_angle=full(phi_r))


def shear_pair(**kw):
    """Two nodes side by side, the left one on the bottom platen, the right one on the top platen, one bond with
    a vertical face (normal +x): closing the platens shears it; a lateral traction on the sides presses it.
    width x thickness = area = height x thickness, so platen stress = tau and confinement = -sigma."""
    return network([[0.0, 0.0], [1e-3, 0.0]], [[0, 1]], [[1.0, 0.0]], top=[1], bottom=[0], left=[0], right=[1], **kw)


def chain(**kw):
    """Three nodes in a column: bottom platen, one free node, top platen; two bonds with horizontal faces."""
    return network([[0.0, 0.0], [0.0, 0.5e-3], [0.0, 1e-3]], [[0, 1], [1, 2]], [[0.0, 1.0], [0.0, 1.0]],
                   top=[2], bottom=[0], **kw)


def creep_giving_out(*extra):
    """The 4 x 8 mm rigid-cell creep at 180 MPa of seed 1 on the static engine (``extra``: overrides): the plain path's
    regain (``numerics.static_relaxation = "none"`` unless ``extra`` says otherwise) gives out (a status cycle) at its
    16th event, the same with every bond's properties changed at round-off and
    with another CPU's arithmetic (OpenBLAS's Haswell, SkylakeX or Zen kernels, numpy with or without AVX-512)."""
    from grainfrac_yade.params import load_parameters
    from grainfrac_yade.protocols.creep import run_creep
    p = load_parameters(overrides=["numerics.engine=static", "numerics.static_relaxation=none", "specimen.width=4e-3",
                                   "specimen.height=8e-3", *extra])
    return run_creep(build_specimen(p, 1), p, 180e6)


def fem_creep_4x8(*extra):
    """The 4 x 8 mm fem creep at 160 MPa of seed 4 on the static engine's plain path (``extra``: overrides): it reaches
    the time limit after 15 events, its plain regains all settling."""
    from grainfrac_yade.params import load_parameters
    from grainfrac_yade.protocols.creep import run_creep
    p = load_parameters(extra_files=["params/presets/fem_coarse.toml"],
                        overrides=["numerics.engine=static", "numerics.static_relaxation=none", "specimen.width=4e-3",
                                   "specimen.height=8e-3", *extra])
    return run_creep(build_specimen(p, 4), p, 160e6)


def tension_pair(**kw):
    """Two nodes one above the other, on the bottom and top platens, one bond with a horizontal face (normal +y):
    opening the platens pulls it (width x thickness = area, so platen stress = -sigma)."""
    return network([[0.0, 0.0], [0.0, 1e-3]], [[0, 1]], [[0.0, 1.0]], top=[1], bottom=[0], **kw)


def plain_hold_fails_once(monkeypatch, at: int = 1):
    """Make the plain static regain (``Path.hold``) give out once, at its ``at``-th call, from its start state, as a
    status cycle does (helper of the relaxation tests: the next regain is the plain one)."""
    from grainfrac_yade.errors import NumericalFailure
    from grainfrac_yade.engines.static.cascade import Path
    calls = {"n": 0}
    original = Path.hold

    def fails_once(self, *args, **kw):
        calls["n"] += 1
        if calls["n"] == at:
            self.last_converged = args[0]
            raise NumericalFailure("static equilibrium: contact statuses did not settle (made to fail)")
        return original(self, *args, **kw)
    monkeypatch.setattr(Path, "hold", fails_once)


def assert_resumed_as_whole(resumed, whole):
    """A creep run resumed from a checkpoint against the uninterrupted one: the history (but wall times), events,
    failure and break times equal (helper of the kill-and-resume tests of the static and hybrid engines)."""
    def rows(run):
        return [{k: v for k, v in r.items() if k != "wall_s"} for r in run.rows]
    assert resumed.resumes
    assert rows(resumed) == rows(whole)
    assert (resumed.n_events, resumed.failed, resumed.failure_reason) == (whole.n_events, whole.failed,
                                                                          whole.failure_reason)
    assert np.array_equal(resumed.break_time, whole.break_time, equal_nan=True)


def run_killed_and_resumed(tmp_path, monkeypatch, params, seed, stress, killed_when, before_resume=None):
    """The creep run of ``params`` (``seed``, held ``stress`` [Pa]) uninterrupted, and the same run killed (a
    KeyboardInterrupt) at the first checkpoint after which ``killed_when(run, checkpoints written)`` holds, then
    resumed from it: (whole, resumed) (helper of the kill-and-resume tests of the static and hybrid engines).
    ``before_resume(run folder)``: called on the killed run's folder before the resume."""
    import grainfrac_yade.protocols.checkpoints as checkpoints
    from grainfrac_yade.protocols.creep import resume_creep, run_creep
    whole = run_creep(build_specimen(params, seed), params, stress, checkpoint_folder=tmp_path / "whole",
                      run_values={"seed": seed})
    write, written = checkpoints.Checkpointer.write, []

    def killed(self, run, *args, **kwargs):
        write(self, run, *args, **kwargs)
        written.append(1)
        if killed_when(run, len(written)):
            raise KeyboardInterrupt
    monkeypatch.setattr(checkpoints.Checkpointer, "write", killed)
    with pytest.raises(KeyboardInterrupt):
        run_creep(build_specimen(params, seed), params, stress, checkpoint_folder=tmp_path / "cut",
                  run_values={"seed": seed})
    monkeypatch.setattr(checkpoints.Checkpointer, "write", write)
    if before_resume is not None:
        before_resume(tmp_path / "cut")
    return whole, resume_creep(build_specimen(params, seed), params, stress, tmp_path / "cut")


class HeldEvents:
    """Creep events on a hand-made static network held at a platen stress (a test's helper: such a network is no
    specimen, so the creep protocol cannot run it): the path to ``stress`` [Pa] (failing only by "no equilibrium
    ahead"), then per event the law's interval to the next failure under frozen stresses (paper Eq. 7 for the
    Hillig-Charles law, :func:`grainfrac_yade.law.creep_step`), its strengths written to the path, the cascade and
    the regain of ``stress`` under ``rule``; what the static scene does under the creep protocol, without it.
    After :meth:`run`: ``times``, ``strains`` (axial, after each event), ``events``, ``failed``, ``reason``,
    ``state``."""

    def __init__(self, eq, law, clock, stress, rule, path=None):
        from grainfrac_yade.engines.static.cascade import Path
        self.eq, self.law, self.clock, self.stress, self.rule = eq, law, clock, stress, rule
        self.path = path or Path(eq)
        self.times, self.strains, self.events, self.failed, self.reason, self.state = [], [], 0, False, "", None

    def run(self, max_events=10**6):
        from grainfrac_yade.engines.static.failure import FailureRule
        from grainfrac_yade.law import Stresses, creep_step
        net, path = self.eq.net, self.path
        state, reason = path.hold(self.eq.initial(0.0), self.stress, FailureRule(0.0))
        self.state = state
        if reason:
            self.failed, self.reason = True, "at load: " + reason
            return self
        bonds = self.law.initial_state(net.tensile_strength, net.cohesion, net.tan_friction)
        while self.events < max_events:
            intact = np.flatnonzero(~state.broken)
            stresses = Stresses.of(intact, state.fn[intact] / net.area[intact],
                                   np.abs(state.fs[intact]) / net.area[intact])
            step = creep_step(self.law, self.clock, bonds, stresses)
            if step.stalled or not len(step.failing):
                self.reason = "nothing fails"
                break
            self.clock.advance(step.dt, step.failing)
            bonds = step.state
            jt, jc, _ = self.law.strengths(bonds)
            path.jt, path.jc = np.asarray(jt, float).copy(), np.asarray(jc, float).copy()
            state, reason = path.hold(path.cascade(state), self.stress, self.rule)
            self.events, self.state = self.events + 1, state
            self.times.append(self.clock.creep_time)
            self.strains.append(state.closure / net.height)
            if reason:
                self.failed, self.reason = True, reason
                break
        return self
