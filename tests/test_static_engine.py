"""The static engine through the scene interface: the UCS protocol drives it unchanged (pure, tiny specimens)."""
import json
import math

import numpy as np
import pytest

from conftest import needs_yade
from static_tiny import assert_resumed_as_whole, run_killed_and_resumed

from grainfrac_yade.engines import Scene
from grainfrac_yade.engines.registry import engine, engine_for
from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.params import load_parameters

TINY = ["specimen.width=3e-3", "specimen.height=6e-3", "numerics.engine=static"]
#: summary.json keys that measure the machine, not the run
MACHINE_KEYS = ("wall_s", "cpu_s")


def _params(*extra):
    return load_parameters(overrides=[*TINY, *extra])


def test_static_engine_module_and_scene_interface():
    """The registry's "static" module: no dynamics, a scene that implements the protocol's Scene."""
    p = _params()
    module = engine_for(p)
    assert module is engine("static") and module.name == "static" and module.dynamic is False
    assert "scipy" in module.version()
    scene = module.build_scene(build_specimen(p, 1), p)
    assert isinstance(scene, Scene)
    assert scene.steps >= 1 and scene.time == 0.0 and scene.dt > 0
    assert scene.counts()["n_bonds"] == scene.n_bonds == len(scene.broken)
    fn, fs = scene.bond_forces()
    assert fn.shape == fs.shape == (scene.n_bonds,) and np.all(fn == 0)


def test_run_breaks_bonds_and_keeps_them_within_strength():
    """run(n): the closure follows the platens' speed; after each increment no intact bond is beyond its
    strength (paper Eq. 4-5), and the bookkeeping is in the layout's order."""
    from grainfrac_yade.law import failed_now
    p = _params()
    scene = engine_for(p).build_scene(build_specimen(p, 1), p)
    pl = scene.attach_platens("free")
    pl.set_axial_velocity(p.ucs.strain_rate * pl.height)
    scene.run(250)     # 0.5 % axial strain
    assert pl.axial_strain() == pytest.approx(250 * p.ucs.record_strain_increment)
    assert scene.broken.sum() > 0 and np.all(scene.break_step[scene.broken] > 0)
    assert np.all(scene.break_step[~scene.broken] == -1)
    sigma, tau = scene.bond_stresses()
    jt, jc = scene.bond_strengths()
    tan_phi = scene.net.tan_friction[scene.canon]
    ten, sh = failed_now(jt, jc, sigma, tau, tan_phi)
    intact = ~scene.broken
    assert not np.any((ten | sh) & intact)
    assert pl.axial_stress() > 0 and math.isfinite(pl.lateral_strain())


def test_save_restore_goes_on_bit_for_bit(tmp_path):
    """A scene restored from save() computes what the uninterrupted one does, to the last bit."""
    p = _params()
    specimen = build_specimen(p, 1)
    a = engine_for(p).build_scene(specimen, p)
    pa = a.attach_platens("free")
    pa.set_axial_velocity(p.ucs.strain_rate * pa.height)
    a.run(150)
    a.save(tmp_path / "scene.npz")
    a.run(100)
    b = engine_for(p).build_scene(specimen, p)
    pb = b.attach_platens("free")
    pb.set_axial_velocity(pa.velocity)
    b.restore(tmp_path / "scene.npz")
    b.run(100)
    assert b.steps == a.steps and b.time == a.time
    assert np.array_equal(a.state.u, b.state.u) and np.array_equal(a.broken, b.broken)
    assert np.array_equal(a.break_step, b.break_step) and pa.axial_stress() == pb.axial_stress()


def test_state_round_trip():
    """export_state -> scene_from_state: the same broken set, strengths and forces (re-solved there)."""
    p = _params()
    specimen = build_specimen(p, 1)
    module = engine_for(p)
    a = module.build_scene(specimen, p)
    pl = a.attach_platens("free")
    pl.set_axial_velocity(p.ucs.strain_rate * pl.height)
    a.run(200)
    state = a.export_state(pl)
    b = module.scene_from_state(specimen, p, state)
    assert np.array_equal(b.broken, a.broken) and b.steps == a.steps and b.time == a.time
    fa, fb = a.bond_forces(), b.bond_forces()
    scale = np.abs(fa[0]).max()
    assert np.allclose(fa[0], fb[0], rtol=0, atol=1e-9 * scale) and np.allclose(fa[1], fb[1], rtol=0, atol=1e-9 * scale)
    assert np.array_equal(b.export_state(pl).bond_tensile_capacity, state.bond_tensile_capacity)


def _ucs_folder(tmp_path, name, *extra):
    from grainfrac_yade.commands.ucs import run_ucs_to_folder
    p = _params(*extra)
    out = tmp_path / name
    return run_ucs_to_folder(p, 1, out), out


def test_ucs_through_the_protocol_writes_a_run_folder(tmp_path):
    """protocols/ucs.py on the static engine: the usual run folder, finite values, the engine recorded."""
    summary, out = _ucs_folder(tmp_path, "a")
    for name in ("summary.json", "history.csv", "cracks.csv", "params.json", "stress_strain.png",
                 "crack_map_peak.png"):
        assert (out / name).exists(), name
    assert summary["numerical_failure"] is False and summary["peak_reached"] is True
    assert summary["ucs_pa"] > 0 and summary["engine"] == "static"
    # the inertial relaxation (the default) reads the integration's settings; the collider's none
    assert "numerics.verlet_fraction" in summary["settings_not_used"]
    assert "numerics.damping" not in summary["settings_not_used"]
    assert json.loads((out / "params.json").read_text())["numerics"]["engine"] == "static"
    text = (out / "history.csv").read_text() + (out / "summary.json").read_text() + (out / "cracks.csv").read_text()
    assert "nan" not in text.lower() and "infinity" not in text.lower()
    hist = np.genfromtxt(out / "history.csv", delimiter=",", names=True)
    assert np.all(np.isfinite(hist["axial_stress_pa"])) and len(hist) > 10


def test_ucs_row_twice_is_identical(tmp_path):
    """Determinism: the same row twice gives the same summary.json (but the machine's times) and cracks.csv."""
    s1, o1 = _ucs_folder(tmp_path, "one")
    s2, o2 = _ucs_folder(tmp_path, "two")
    for s in (s1, s2):
        for k in MACHINE_KEYS:
            s.pop(k, None)
    assert json.dumps(s1, sort_keys=True, default=str) == json.dumps(s2, sort_keys=True, default=str)
    assert (o1 / "cracks.csv").read_bytes() == (o2 / "cracks.csv").read_bytes()
    assert (o1 / "history.csv").read_bytes() == (o2 / "history.csv").read_bytes()


def test_confined_ucs_on_the_static_engine():
    """Confinement as a constant lateral traction: the isotropic stage reaches sigma_1 = sigma_3, then the
    deviator's peak."""
    from grainfrac_yade.protocols.ucs import run_ucs
    p = _params("confinement.stress=20e6")
    cols, result, scene, _ = run_ucs(build_specimen(p, 1), p)
    assert result["consolidated"] is True
    assert result["consolidation_axial_stress_pa"] == pytest.approx(20e6, rel=1e-6)
    assert result["numerical_failure"] is False and max(cols["axial_stress_pa"]) > 20e6


def _cli(capsys, *argv):
    from grainfrac_yade.cli import main
    rc = main(list(argv))
    return rc, capsys.readouterr()


def test_misspelt_engine_flag_is_one_line(capsys, tmp_path):
    rc, out = _cli(capsys, "ucs", "--engine", "statc", "--width", "3e-3", "--height", "6e-3",
                   "--out", str(tmp_path / "x"))
    assert rc == 2 and out.err.count("\n") == 1 and "--engine" in out.err and "'static'" in out.err
    assert not (tmp_path / "x").exists()


def test_paper_clock_refused_in_one_line(capsys, tmp_path):
    """The paper clock needs dynamics (the static creep hold runs with the event clock)."""
    common = ["--engine", "static", "--width", "3e-3", "--height", "6e-3", "--stress", "100",
              "--out", str(tmp_path / "x")]
    rc, out = _cli(capsys, "creep", *common, "--set", "stress_corrosion.clock=paper")
    assert rc == 2 and out.err.count("\n") == 1 and "paper clock" in out.err and "fix:" in out.err
    assert not (tmp_path / "x").exists()


#: A tiny creep row on the static engine: 4 x 8 mm, seed 1, at 160 MPa (about 0.68 x its UCS: fails after a few
#: events, in about a second).
CREEP_ROW = ["--engine", "static", "--width", "4e-3", "--height", "8e-3", "--stress", "160", "--seed", "1"]
#: summary.json keys that name the code or measure the machine, not the run
NOT_THE_RUN = ("code_version", "wall_s", "cpu_s")


def _creep_cli(capsys, out):
    rc, _ = _cli(capsys, "creep", *CREEP_ROW, "--out", str(out))
    assert rc == 0
    return json.loads((out / "summary.json").read_text())


def test_creep_runs_through_the_protocol_with_the_event_clock(capsys, tmp_path):
    """creep --engine static: the protocol's ramp, hold and event clock on the static scene; the usual run
    folder with finite values, and a lifetime from the core's failure rule (or a stated end)."""
    import pandas as pd
    s = _creep_cli(capsys, tmp_path / "a")
    for name in ("summary.json", "history.csv", "cracks.csv"):
        assert (tmp_path / "a" / name).is_file(), name
    assert s["numerical_failure"] is False and s["failed_on_loading"] is False
    assert s["failed"] is True and s["lifetime_s"] > 0 and math.isfinite(s["lifetime_s"]) and s["failure_reason"]
    assert s["n_events"] >= 1 and s["broken_creep"] >= 1
    hist = pd.read_csv(tmp_path / "a" / "history.csv")
    assert np.isfinite(hist.select_dtypes("number").to_numpy()).all()
    held = hist["axial_stress_pa"].to_numpy()[1:-1]   # the ramp's end (overshoot) and the failed row aside
    assert np.allclose(held, 160e6, rtol=1e-6)
    assert hist["creep_time_s"].is_monotonic_increasing
    cracks = pd.read_csv(tmp_path / "a" / "cracks.csv")
    assert len(cracks) == s["broken_total"] and np.isfinite(cracks.select_dtypes("number").to_numpy()).all()


def test_creep_row_twice_is_identical(capsys, tmp_path):
    """Deterministic: the same row twice gives the same summary (but for the machine's times) and cracks."""
    a, b = _creep_cli(capsys, tmp_path / "a"), _creep_cli(capsys, tmp_path / "b")
    for k in NOT_THE_RUN:
        a.pop(k, None), b.pop(k, None)
    assert json.dumps(a, sort_keys=True, default=str) == json.dumps(b, sort_keys=True, default=str)
    assert (tmp_path / "a" / "cracks.csv").read_bytes() == (tmp_path / "b" / "cracks.csv").read_bytes()


def test_creep_hold_failure_is_the_core_rule():
    """Under the held stress a run's relaxation is one solve to it (Path.hold); once the failure rule says the
    load cannot be regained the scene is out of equilibrium and the servo saturated closing."""
    from grainfrac_yade.protocols.creep import run_creep
    p = _params("specimen.width=4e-3", "specimen.height=8e-3")
    run = run_creep(build_specimen(p, 1), p, 160e6)
    scene, servo = run.scene, run.servo
    assert run.failed and scene.hold_failure.startswith(("collapse", "no equilibrium"))
    assert scene.unbalanced(1.0)[1] == math.inf and servo.clipped == 1 and servo.closing_clipped_steps > 0
    assert run.rows[-2]["axial_stress_pa"] == pytest.approx(160e6, rel=1e-9)


def test_creep_hold_bad_target_is_one_line():
    from grainfrac_yade.errors import GrainfracError
    p = _params()
    pl = engine_for(p).build_scene(build_specimen(p, 1), p).attach_platens("free")
    with pytest.raises(GrainfracError, match="fix:") as exc:
        pl.hold_stress(-1.0, 70e9, 100, 1.0)
    assert "\n" not in str(exc.value)


def test_creep_with_a_law_that_changes_stiffness_is_one_line():
    """The area law changes the bonds' stiffness, which the static creep hold does not follow: refused."""
    from grainfrac_yade.errors import GrainfracError
    p = _params("stress_corrosion.law=area")
    scene = engine_for(p).build_scene(build_specimen(p, 1), p)
    with pytest.raises(GrainfracError, match="fix:") as exc:
        engine_for(p).stress_corrosion(scene, p.stress_corrosion)
    assert "\n" not in str(exc.value)


@pytest.mark.slow        # the same path as tests/test_static_checkpoints.py's creep runs (killed at the fifth checkpoint)
def test_creep_killed_and_resumed_gives_the_uninterrupted_run(tmp_path, monkeypatch):
    """Checkpoints at every safe point (ramp, events, relaxations), the run killed after the sixth and resumed from
    it: history (but for wall times), events, failure and break times as the uninterrupted run's."""
    p = _params("specimen.width=4e-3", "specimen.height=8e-3", "numerics.checkpoint_interval=1e-9")
    whole, resumed = run_killed_and_resumed(tmp_path, monkeypatch, p, 1, 160e6, lambda run, written: written == 6)
    assert whole.n_events > 1
    assert_resumed_as_whole(resumed, whole)
    assert np.array_equal(resumed.scene.broken, whole.scene.broken)


def test_dynamic_only_setting_warns_once():
    from grainfrac_yade.engines.static.engine import warn_dynamic_only
    given = ["numerics.damping=0.5", "specimen.width=3e-3", ("creep.servo_response_steps", 5),
             "numerics.verlet_fraction=0.2"]
    lines = warn_dynamic_only(given, _params("numerics.static_relaxation=none"))
    assert len(lines) == 3 and all("\n" not in s and s.startswith("warning:") for s in lines)
    # the inertial relaxation reads damping and the servo: only the collider's setting is left unused
    lines = warn_dynamic_only(given, _params("numerics.static_relaxation=inertial"))
    assert len(lines) == 1 and "numerics.verlet_fraction" in lines[0]


def test_engine_flag_is_the_parameter():
    """--engine NAME is --set numerics.engine=NAME (recorded in params.json like any parameter)."""
    from grainfrac_yade.cli import build_parser
    from grainfrac_yade.commands._args import overrides_from_args
    args = build_parser().parse_args(["ucs", "--engine", "static"])
    assert ("numerics.engine", "static") in [tuple(o) for o in overrides_from_args(args) if not isinstance(o, str)]


def test_ucs_resumed_from_a_checkpoint_is_bit_identical(tmp_path):
    """A checkpoint before every history row (the static scene saved as an .npz): resuming from the last one
    gives the uninterrupted test's history and result."""
    from grainfrac_yade.protocols.ucs import resume_ucs, run_ucs
    p = _params("numerics.checkpoint_interval=1e-9")
    specimen = build_specimen(p, 1)
    cols, result, _, _ = run_ucs(specimen, p, checkpoint_folder=tmp_path, run_values={"seed": 1})
    assert (tmp_path / "checkpoint").is_dir()
    cols2, result2, _, _ = resume_ucs(specimen, p, tmp_path)
    assert cols2 == cols
    for k in ("steps", "broken_total", "end_reason", "peak_reached"):
        assert result2[k] == result[k], k


@needs_yade
@pytest.mark.yade
@pytest.mark.parametrize("model, tol", [("fem", 1e-9), ("rigid", 1e-2)])
def test_static_state_hands_over_to_yade(model, tol):
    """A static state after bonds broke, through SceneState into a YADE scene: YADE's bond forces equal the
    static ones, and stay so after one DEM step (fem cells to round-off; rigid cells within 1 % of the largest
    force: measured 0.16 %, YADE's current contact geometry against the static small-strain rows)."""
    p = _params(f"resolution.grain_model={model}")
    specimen = build_specimen(p, 1)
    static = engine("static").build_scene(specimen, p)
    pl = static.attach_platens("free")
    pl.set_axial_velocity(p.ucs.strain_rate * pl.height)
    static.run(150)
    yade = engine("yade").scene_from_state(specimen, p, static.export_state(pl))
    assert np.array_equal(yade.broken, static.broken)
    yade.attach_platens("free")
    yade.run(1)
    intact = ~static.broken
    fs, fy = static.bond_forces()[0], yade.bond_forces()[0]
    assert np.abs(fs[intact] - fy[intact]).max() <= tol * np.abs(fs).max()


def test_creep_resumed_through_the_command_line(capsys, tmp_path, monkeypatch):
    """`creep --resume DIR` on a static run killed after its first checkpoint: the checkpoint's scene (the static
    engine's npz, not a YADE gzip) passes the pre-load check (a truncated one is named in one line), and the run
    ends with the uninterrupted run's lifetime, events, breaks and cracks."""
    import grainfrac_yade.protocols.checkpoints as checkpoints
    whole = _creep_cli(capsys, tmp_path / "whole")
    write = checkpoints.Checkpointer.write

    def killed(self, *args, **kwargs):
        write(self, *args, **kwargs)
        raise KeyboardInterrupt
    monkeypatch.setattr(checkpoints.Checkpointer, "write", killed)
    rc, _ = _cli(capsys, "creep", *CREEP_ROW, "--out", str(tmp_path / "cut"))
    assert rc == 130                # the command's own report of an interrupt
    monkeypatch.setattr(checkpoints.Checkpointer, "write", write)
    assert not (tmp_path / "cut" / "summary.json").exists()
    import shutil
    shutil.copytree(tmp_path / "cut", tmp_path / "broken")
    scene = tmp_path / "broken" / "checkpoint" / engine("static").scene_file
    scene.write_bytes(scene.read_bytes()[:200])           # a truncated npz: one line, nothing written
    rc, out = _cli(capsys, "creep", "--resume", str(tmp_path / "broken"))
    assert rc == 2 and out.err.count("\n") == 1 and "static scene is unreadable" in out.err and "fix:" in out.err
    assert not (tmp_path / "broken" / "summary.json").exists()
    rc, out = _cli(capsys, "creep", "--resume", str(tmp_path / "cut"))
    assert rc == 0, out.err
    resumed = json.loads((tmp_path / "cut" / "summary.json").read_text())
    for k in ("lifetime_s", "n_events", "failed", "broken_total", "failure_reason"):
        assert resumed[k] == whole[k], k
    assert (tmp_path / "cut" / "cracks.csv").read_bytes() == (tmp_path / "whole" / "cracks.csv").read_bytes()


@pytest.mark.parametrize("model", ["rigid", "fem"])
def test_the_grain_model_says_whether_its_bonds_lie_on_their_faces(model):
    """The static scene reads the grain model's ``bonds_on_faces`` (no model name inside the engine): fem bonds carry
    their face's unit normal in an exported state and a reference gap along it; rigid bonds neither."""
    from grainfrac_yade.grains import grain_model
    p = _params(f"resolution.grain_model={model}")
    scene = engine("static").build_scene(build_specimen(p, 1), p)
    normal = scene.export_state().bond_plane_normal
    on_faces = grain_model(model).bonds_on_faces
    assert on_faces == (model == "fem")
    if on_faces:
        assert np.allclose(np.linalg.norm(normal, axis=1), 1.0)
    else:
        assert not normal.any()
