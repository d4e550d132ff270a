"""Checkpoints never change a static run: writing one only reads the scene, and a resumed run rebuilds the solver's
kept factor as it was (pure: no YADE; tiny specimens, seconds each)."""
import json

import numpy as np
import pytest

from static_tiny import assert_resumed_as_whole, run_killed_and_resumed

from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.params import load_parameters
from grainfrac_yade.protocols.creep import run_creep

#: summary.json keys that name the code, the parameters (the checkpoint interval differs), the run's checkpoints or
#: measure the machine, not the run
NOT_THE_RUN = ("params", "code_version", "wall_s", "cpu_s", "static_relaxation_cpu_s", "checkpoints", "checkpoint_write_s",
               "resumed_from")
#: the 4 x 8 mm creep at 160 MPa of each grain model on the static engine with the inertial relaxation
MODELS = {"rigid": [], "fem": ["resolution.grain_model=fem"]}


def _params(model, *extra):
    return load_parameters(overrides=["numerics.engine=static", "numerics.static_relaxation=inertial",
                                      "specimen.width=4e-3", "specimen.height=8e-3", *MODELS[model], *extra])


def _rows(run):
    return [{k: v for k, v in r.items() if k != "wall_s"} for r in run.rows]


@pytest.mark.parametrize("columns", ["changes", "rows"])
def test_factor_state_rebuilds_the_kept_factor_bit_for_bit(columns):
    """A static UCS path half way (low-rank updates of a kept factor in use, their columns made either way,
    ``numerics.static_update_columns``): a second equilibrium given the first's factor_state answers the next steps
    as the first does, to the last bit; one that drops the factor instead does not in general (the fast path's
    answers depend on the kept factor at round-off)."""
    from grainfrac_yade.engines.registry import engine
    p = _params("rigid", f"numerics.static_update_columns={columns}")
    scene = engine("static").build_scene(build_specimen(p, 1), p)
    pl = scene.attach_platens("free")
    pl.set_axial_velocity(p.ucs.strain_rate * pl.height)
    scene.run(120)
    assert scene.broken.any() and scene.eq._lr is not None      # past the first breaks, a reference factor kept
    saved = {k: v.copy() if isinstance(v, np.ndarray) else v for k, v in scene.eq.factor_state().items()}
    assert "reference_columns" in saved
    from grainfrac_yade.engines.static.solver import Equilibrium, solver_options
    twin = Equilibrium(scene.net, **solver_options(p))
    assert twin.update_columns == scene.eq.update_columns == columns
    twin.restore_factor_state(saved)
    state = scene.state
    for closure in (state.closure * 1.0001, state.closure * 1.0003):
        a, b = scene.eq.solve(closure, state), twin.solve(closure, state)
        assert np.array_equal(a.u, b.u) and np.array_equal(a.status, b.status)
    assert set(twin.factor_state()) == set(scene.eq.factor_state())


@pytest.mark.parametrize("model", sorted(MODELS))
def test_creep_with_checkpoints_is_the_creep_without(tmp_path, monkeypatch, model):
    """The same creep run with a checkpoint at every safe point, with none but the ramp's, and killed at the fifth
    checkpoint and resumed: the same history (wall times aside), events, break times and broken set, bit for bit."""
    p0 = _params(model, "numerics.checkpoint_interval=0")
    plain = run_creep(build_specimen(p0, 1), p0, 160e6, checkpoint_folder=tmp_path / "plain", run_values={"seed": 1})
    p = _params(model, "numerics.checkpoint_interval=1e-9")
    whole, resumed = run_killed_and_resumed(tmp_path, monkeypatch, p, 1, 160e6, lambda run, written: written == 5)
    assert plain.n_events > 1 and len(whole.checkpointer.write_s) > 5
    assert_resumed_as_whole(resumed, whole)
    assert_resumed_as_whole(resumed, plain)
    assert _rows(whole) == _rows(plain)
    assert (whole.n_events, whole.failed, whole.failure_reason) == (plain.n_events, plain.failed,
                                                                    plain.failure_reason)
    assert np.array_equal(whole.break_time, plain.break_time, equal_nan=True)
    assert np.array_equal(resumed.scene.broken, plain.scene.broken)


def _as_older_code_wrote_it(folder):
    """Make the checkpoint of run ``folder`` as code before each engine named its scene file wrote it: the static
    scene's npz under YADE's name, state.json naming no scene file."""
    from grainfrac_yade.runs.runio import CHECKPOINT, CHECKPOINT_STATE, LEGACY_SCENE_FILE, SCENE_FILE_KEY
    ck = folder / CHECKPOINT
    state = json.loads((ck / CHECKPOINT_STATE).read_text())
    assert state.pop(SCENE_FILE_KEY) == "scene.npz" and not (ck / LEGACY_SCENE_FILE).exists()
    (ck / "scene.npz").rename(ck / LEGACY_SCENE_FILE)
    (ck / CHECKPOINT_STATE).write_text(json.dumps(state, indent=1) + "\n")


def test_a_checkpoint_written_by_older_code_resumes_to_the_uninterrupted_run(tmp_path, monkeypatch):
    """A static run's checkpoint with its scene in scene.yade.gz (as every engine's was before each named its own
    file) resumes as one written today: the same history (wall times aside), events, break times and broken set."""
    p = _params("rigid", "numerics.checkpoint_interval=1e-9")
    whole, resumed = run_killed_and_resumed(tmp_path, monkeypatch, p, 1, 160e6, lambda run, written: written == 5,
                                            before_resume=_as_older_code_wrote_it)
    assert whole.n_events > 1 and resumed.resumes
    assert_resumed_as_whole(resumed, whole)
    assert np.array_equal(resumed.scene.broken, whole.scene.broken)


def _creep_cli(capsys, out, *extra):
    from grainfrac_yade.cli import main
    rc = main(["creep", "--engine", "static", "--width", "4e-3", "--height", "8e-3", "--stress", "160", "--seed", "1",
               "--set", "numerics.static_relaxation=inertial", *extra, "--out", str(out)])
    capsys.readouterr()
    return rc


@pytest.mark.slow   # the same run with and without checkpoints: test_creep_with_checkpoints_is_the_creep_without[rigid]
#                     (bit for bit); the command line's static creep with a checkpoint against the uninterrupted one
#                     (summary keys, cracks.csv byte for byte): test_static_engine.py's creep resumed through the command line
def test_creep_command_with_a_tiny_checkpoint_interval_gives_the_same_files(capsys, tmp_path):
    """Through the command line: a checkpoint at every safe point against the default interval (none in a run this
    short but the ramp's): summary.json (the code, the machine's times and the checkpoint record aside) and
    cracks.csv the same, bit for bit."""
    assert _creep_cli(capsys, tmp_path / "default") == 0
    assert _creep_cli(capsys, tmp_path / "tiny", "--set", "numerics.checkpoint_interval=1e-6") == 0
    a, b = (json.loads((tmp_path / n / "summary.json").read_text()) for n in ("default", "tiny"))
    assert {k: v for k, v in a.items() if k not in NOT_THE_RUN} == {k: v for k, v in b.items() if k not in NOT_THE_RUN}
    assert a["n_events"] > 1
    assert (tmp_path / "default" / "cracks.csv").read_bytes() == (tmp_path / "tiny" / "cracks.csv").read_bytes()


def test_a_state_file_naming_no_plain_scene_file_is_one_line(tmp_path):
    """The scene file a checkpoint's state.json names must be a file of the checkpoint folder: a path elsewhere, or
    no name, is refused in one line naming the fix; a state.json naming none is the older code's scene.yade.gz."""
    from grainfrac_yade.errors import GrainfracError
    from grainfrac_yade.runs.runio import LEGACY_SCENE_FILE, scene_file_of
    assert scene_file_of({}, tmp_path) == LEGACY_SCENE_FILE
    assert scene_file_of({"scene_file": "scene.npz"}, tmp_path) == "scene.npz"
    for bad in ("../scene.npz", "/tmp/scene.npz", "", None, 3):
        with pytest.raises(GrainfracError) as err:
            scene_file_of({"scene_file": bad}, tmp_path)
        assert str(err.value).count("\n") == 0 and "fix:" in str(err.value)
