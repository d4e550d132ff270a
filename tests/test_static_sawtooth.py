"""Saw-tooth softening on the static engine (grainfrac_yade/engines/static/teeth.py): one bond through its teeth against
the closed form (the static path and the inertial relaxation), checkpoints, the brittle settings as the default law, and the refusal on the other engines."""
import json

import numpy as np
import pytest

from grainfrac_yade.engines.registry import engine_for
from grainfrac_yade.engines.static.cascade import Path
from grainfrac_yade.engines.static.face_failure import BondFailure
from grainfrac_yade.engines.static.solver import Equilibrium
from grainfrac_yade.engines.static.teeth import EVENTS_KEY, BondTeeth
from grainfrac_yade.errors import GrainfracError
from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.params import load_parameters
from grainfrac_yade.softening import sawtooth_teeth

from static_tiny import JT, KN, KS, assert_resumed_as_whole, run_killed_and_resumed, tension_pair

#: Closed forms hold to round-off, and the bracketing finds a crossing to 1e-9 of its ratio (cascade.BRACKET_TOL).
BRACKET = 1e-9
SAW = ["numerics.static_softening=sawtooth", "numerics.static_softening_teeth=4",
       "numerics.static_softening_ductility=3"]
TINY = ["specimen.width=3e-3", "specimen.height=6e-3", "numerics.engine=static", "numerics.checkpoint_interval=0"]


@pytest.mark.parametrize("n,mu", [(4, 3.0), (3, 1.5), (1, 4.0)])
def test_one_bond_pulled_through_its_teeth_follows_the_closed_form(n, mu):
    """A single bond pulled open (platen stress = -sigma): tooth i reached at the separation delta_i = delta_0 (1 +
    (mu - 1) i / N) and the stress f_i = J^T (1 - i / N); there the force drops to k_{i+1} delta_i at the same
    separation, the bond intact; at the last tooth it breaks (the one crack); k_n and k_s end at k_{N-1} / k_0 of
    their intact values."""
    net = tension_pair()
    eq = Equilibrium(net, direction=-1.0)
    path = Path(eq)
    path.teeth = BondTeeth(net, sawtooth_teeth(n, mu))
    path.teeth.equilibria.append(eq)
    d0 = JT * net.area[0] / KN
    state = path.run_closure(eq.initial(0.0), 1.1 * mu * d0)
    k, f = sawtooth_teeth(n, mu)
    recs = path.records
    assert len(recs) == n
    for i, rec in enumerate(recs):
        assert rec.closure == pytest.approx(d0 * (1 + (mu - 1) * i / n), rel=BRACKET)
        assert -rec.stress_before == pytest.approx(JT * f[i], rel=BRACKET)
        if i < n - 1:
            assert rec.bonds == [] and -rec.stress_after == pytest.approx(KN * k[i + 1] * rec.closure / net.area[0],
                                                                          rel=BRACKET)
        else:
            assert rec.bonds == [0] and rec.stress_after == 0.0
    assert state.broken[0] and path.teeth.events == n - 1 and path.teeth.tooth[0] == n - 1
    assert net.kn[0] == pytest.approx(KN * k[-1], rel=1e-14) and net.ks[0] == pytest.approx(KS * k[-1], rel=1e-14)
    assert path.jt[0] == pytest.approx(JT * f[-1], rel=1e-14)


def _scene(p, seed=1):
    scene = engine_for(p).build_scene(build_specimen(p, seed), p)
    pl = scene.attach_platens("free")
    pl.set_axial_velocity(p.ucs.strain_rate * pl.height)
    return scene, pl


def test_ucs_with_teeth_saved_and_restored_goes_on_bit_for_bit(tmp_path):
    """A scene with bonds on later teeth, saved and restored into a fresh scene: the next steps as the uninterrupted
    scene's, to the last bit (teeth, stiffness, strengths, broken set, displacements)."""
    p = load_parameters(overrides=[*TINY, *SAW])
    a, pa = _scene(p)
    a.run(200)
    assert a.path.teeth.events > 0
    a.save(tmp_path / "scene.npz")
    a.run(150)
    b, pb = _scene(p)
    pb.set_axial_velocity(pa.velocity)
    b.restore(tmp_path / "scene.npz")
    b.run(150)
    assert a.path.teeth.events > int(np.load(tmp_path / "scene.npz")["bond_tooth_events"])   # teeth after the save
    assert b.steps == a.steps and np.array_equal(a.state.u, b.state.u) and np.array_equal(a.broken, b.broken)
    assert np.array_equal(a.path.teeth.tooth, b.path.teeth.tooth) and b.path.teeth.events == a.path.teeth.events
    assert np.array_equal(a.net.kn, b.net.kn) and np.array_equal(a.net.ks, b.net.ks)
    assert np.array_equal(a.path.jt, b.path.jt) and pa.axial_stress() == pb.axial_stress()


def _ucs_folder(tmp_path, name, *extra):
    from grainfrac_yade.commands.ucs import run_ucs_to_folder
    out = tmp_path / name
    summary = run_ucs_to_folder(load_parameters(overrides=[*TINY, *extra]), 1, out)
    return {k: v for k, v in summary.items() if k not in ("wall_s", "cpu_s", "params")}, out


def test_brittle_settings_are_the_default_law_and_teeth_are_counted_apart(tmp_path):
    """One tooth (or a ductility of 1) is the brittle bond: the same summary and cracks.csv as the default, bit for bit;
    with teeth the summary counts the tooth events apart and cracks.csv lists the real breaks alone."""
    base, o_base = _ucs_folder(tmp_path, "none")
    assert EVENTS_KEY not in base
    for name, extra in (("n1", ["numerics.static_softening_teeth=1"]),
                        ("mu1", ["numerics.static_softening_ductility=1"])):
        s, o = _ucs_folder(tmp_path, name, "numerics.static_softening=sawtooth", *extra)
        assert json.dumps(s, sort_keys=True, default=str) == json.dumps(base, sort_keys=True, default=str)
        assert (o / "cracks.csv").read_bytes() == (o_base / "cracks.csv").read_bytes()
    s, o = _ucs_folder(tmp_path, "saw", *SAW)
    assert s[EVENTS_KEY] > 0
    cracks = (o / "cracks.csv").read_text().strip().splitlines()
    assert len(cracks) - 1 == s["broken_total"]


@pytest.mark.slow        # a creep run on 4 x 8 mm and its resumed twin (about 1 min)
def test_creep_with_teeth_killed_and_resumed_gives_the_uninterrupted_run(tmp_path, monkeypatch):
    """Stress corrosion with teeth: a tooth scales the law's corroded strengths as the path's (the law then goes on
    from them), and a run killed at its fourth checkpoint and resumed is the uninterrupted run: history, events,
    break times, teeth."""
    p = load_parameters(overrides=["numerics.engine=static", "specimen.width=4e-3", "specimen.height=8e-3",
                                   "numerics.checkpoint_interval=1e-9", *SAW])
    whole, resumed = run_killed_and_resumed(tmp_path, monkeypatch, p, 1, 200e6, lambda run, written: written == 4)
    assert whole.n_events > 1 and whole.scene.path.teeth.events > 0
    assert_resumed_as_whole(resumed, whole)
    assert np.array_equal(resumed.scene.path.teeth.tooth, whole.scene.path.teeth.tooth)
    scene = whole.scene
    corr = next(d for d in scene.drivers if hasattr(d, "follow_tooth"))
    intact = ~scene.broken
    jt_law, jc_law = corr.strengths()
    assert np.array_equal(scene.bond_strengths()[0][intact], jt_law[intact])
    assert np.array_equal(scene.bond_strengths()[1][intact], jc_law[intact])
    # corrosion only lowers: no intact bond above its tooth's share of its intact strength (a law that missed a tooth
    # would give it back its corroded tooth-0 strength at its next write)
    tooth = scene.path.teeth.tooth[scene.canon]
    share = scene.path.teeth.strength[tooth]
    toothed = intact & (tooth > 0)
    assert toothed.any()
    assert np.all(jt_law[toothed] <= corr.tensile0[toothed] * share[toothed] * (1 + 1e-12))


@pytest.mark.parametrize("engine", ["yade", "hybrid"])
def test_softening_refused_on_the_dynamic_engines_in_one_line(capsys, tmp_path, engine):
    from grainfrac_yade.cli import main
    rc = main(["ucs", "--engine", engine, "--width", "3e-3", "--height", "6e-3", "--set",
               "numerics.static_softening=sawtooth", "--out", str(tmp_path / "x")])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "numerics.static_softening" in err and "fix:" in err
    assert not (tmp_path / "x").exists()
    p = load_parameters(overrides=[f"numerics.engine={engine}", "numerics.static_softening=sawtooth"])
    with pytest.raises(GrainfracError, match="static_softening"):
        engine_for(p).build_scene(None, p)


def test_inertial_relaxation_takes_one_tooth_per_step_and_breaks_at_the_last():
    """The inertial relaxation's contact law with teeth (engines/static/inertial.py): a bond pulled beyond every tooth
    at once (platens held open) takes one tooth per explicit step, its stiffness and strength as the closed form says,
    and breaks at the step after its last tooth; pulled just past its strength it takes one tooth and stays intact."""
    from grainfrac_yade.engines.static.inertial import FixedPlatens, InertialMotion, InertialRelaxation
    n, mu = 4, 3.0
    net = tension_pair()
    eq = Equilibrium(net, direction=-1.0)
    teeth = BondTeeth(net, sawtooth_teeth(n, mu))
    d0 = JT * net.area[0] / KN

    class Dynamics:         # what InertialMotion reads of an InertialRelaxation, with unit masses and no damping
        _rows, _state = InertialRelaxation._rows, InertialRelaxation._state

        def __init__(self):
            self.net, self.eq, self.masses, self.teeth = net, eq, np.ones(net.ndof), teeth
            self.dt, self.damping, self.failure = 1e-9, 0.0, BondFailure(net)

    path = Path(eq)
    motion = InertialMotion(Dynamics(), eq.solve(1.0001 * d0, eq.initial(0.0)), FixedPlatens(None), path.jt, path.jc,
                            None)
    motion.advance(2)
    assert teeth.tooth[0] == 1 and not motion.broken[0] and teeth.events == 1
    motion.closure = 2 * mu * d0
    k, f = sawtooth_teeth(n, mu)
    for i in range(2, n):
        motion.advance(1)
        assert teeth.tooth[0] == i and not motion.broken[0]
        assert net.kn[0] == pytest.approx(KN * k[i], rel=1e-14) and path.jt[0] == pytest.approx(JT * f[i], rel=1e-14)
    motion.advance(1)
    assert motion.broken[0] and teeth.events == n - 1 and motion.fn[0] == 0.0
