"""Checkpoint and resume of long runs: a creep run killed with SIGKILL mid-creep or in its loading
ramp, and a UCS or Brazilian test killed mid-loading, resumed from the checkpoint give the
uninterrupted run's results, bit for bit (one thread, same seed); checkpoints change nothing a run
computes (the killed runs checkpoint at every safe point, the references never); a yade-batch rerun
resumes an unfinished creep or UCS row; one interval parameter for every test, its old key refused or
migrated; bad resumes and a folder holding a resumable run are one line naming the fix."""
import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pandas as pd
import pytest

from conftest import ROOT, needs_yade
from grainfrac_yade.params import load_parameters

#: 4 x 8 mm, seed 1, 0.5 x 300 MPa: 16 events between DEM steps 32.5k and 71k, then collapse (101k steps);
#: about 6 s alone.
SMALL = {"width": 4e-3, "height": 8e-3, "ratio": 0.5, "ucs": 300e6, "seed": 1}
#: 3 x 6 mm, 0.8 x 300 MPa: one event (tests/test_batch.py); about 3 s.
TINY = {"width": 3e-3, "height": 6e-3, "ratio": 0.8, "ucs": 300e6, "seed": 1}
#: Checkpoint at every safe point (test only): a kill always finds a recent one.
EVERY_SAFE_POINT = "numerics.checkpoint_interval=1e-6"
#: UCS test of 3 x 6 mm, seed 1: 61,800 DEM steps, 309 history rows, the first crack near step 45k,
#: 24 broken bonds at the end; about 3 s alone (12 s with a checkpoint before every row).
UCS_TINY = {"width": 3e-3, "height": 6e-3, "seed": 1}
def mid_creep(state):
    """A checkpoint inside creep, after the first event. TINY's event phase lasts one safe point (about 10 ms,
    too short for a poll to catch on a fast machine); the relaxation after it about 2 s (measured: ~190 polls)."""
    return state["phase"] in ("event", "relaxation") and state["loop"]["n_events"] >= 1


#: Columns that differ between two identical runs (wall time).
WALL = ["wall_s"]


def _cli(*args, **kw):
    return subprocess.run([sys.executable, "-m", "grainfrac_yade", "creep", *map(str, args)], capture_output=True,
                          text=True, cwd=ROOT, env=dict(os.environ, OMP_NUM_THREADS="1"), **kw)


def _creep_args(spec, out, *extra):
    return ["--width", spec["width"], "--height", spec["height"], "--seed", spec["seed"], "--ratio", spec["ratio"],
            "--ucs", spec["ucs"] / 1e6, "--set", "stress_corrosion.creep_time_limit=1e30", *extra, "--out", out]


def _state(folder):
    """The state of the checkpoint a resume would use (also between the renames of a rewrite)."""
    from grainfrac_yade.runs.runio import read_checkpoint_state
    return read_checkpoint_state(folder)


def _kill_when_ready(argv, out, ready, timeout):
    """Start ``python3 -m grainfrac_yade *argv`` (writing into ``out``) and SIGKILL it once
    ``ready(state)`` of its checkpoint; the state the kill left."""
    proc = subprocess.Popen([sys.executable, "-m", "grainfrac_yade", *map(str, argv)],
                            cwd=ROOT, env=dict(os.environ, OMP_NUM_THREADS="1"),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    t0 = time.time()
    try:
        while proc.poll() is None and time.time() - t0 < timeout:
            state = _state(out)
            if state is not None and ready(state):
                break
            time.sleep(0.002)   # an event phase holds its checkpoint for about 10 ms
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    assert proc.returncode == -signal.SIGKILL, "the run ended before it could be killed"
    assert not (out / "summary.json").exists()
    return _state(out)


def _start_and_kill(spec, out, ready, timeout=120, extra=(), every_safe_point=True):
    """Start a creep run (CLI options ``extra`` added) with a checkpoint at every safe point (else only
    the shipped ones: at the end of the ramp, then every 600 s); SIGKILL it once ``ready(state)``."""
    interval = ["--set", EVERY_SAFE_POINT] if every_safe_point else []
    return _kill_when_ready(["creep", *_creep_args(spec, out, *extra, *interval)], out, ready, timeout)


def _reference(spec, out):
    """The uninterrupted run (this process, one thread; the shipped checkpoint interval)."""
    from grainfrac_yade.protocols.creep_output import run_creep_to_folder
    p = load_parameters(overrides=[("specimen.width", spec["width"]), ("specimen.height", spec["height"]),
                                   "stress_corrosion.creep_time_limit=1e30"])
    s = run_creep_to_folder(p, spec["seed"], out, spec["ratio"] * spec["ucs"], spec["ratio"], spec["ucs"])
    assert not (out / "checkpoint").exists()   # removed once the run is finished
    return s


@pytest.fixture(scope="module")
def small_reference(tmp_path_factory):
    """``SMALL``'s uninterrupted run, once for the module's kills inside its creep (they only read it)."""
    ref = tmp_path_factory.mktemp("small") / "uninterrupted"
    return ref, _reference(SMALL, ref)


def _assert_same_run(a, b):
    sa, sb = (json.loads((f / "summary.json").read_text()) for f in (a, b))
    for key in ("lifetime_s", "failed", "failure_reason", "n_events", "broken_ramp", "broken_creep", "macrocracks",
                "steps", "creep_time_end_s", "primary_end_s", "tertiary_start_s", "shear_stress_p99_pa"):
        assert sa[key] == sb[key], key
    ha, hb = (pd.read_csv(f / "history.csv").drop(columns=WALL) for f in (a, b))
    pd.testing.assert_frame_equal(ha, hb, check_exact=True)          # no row missing, none twice, every bit equal
    assert np.all(np.diff(hb["step"]) > 0) and np.all(np.diff(hb["creep_time_s"]) >= 0)
    for name in ("cracks.csv", "bond_stresses_start.csv"):
        assert (a / name).read_text() == (b / name).read_text(), name


@pytest.mark.slow   # the kill inside a relaxation (below) resumes this run mid-creep, after 8 events, to the same
#                     bit-for-bit comparison; a finished run's resume: test_a_bad_resume_is_one_line[finished]
@needs_yade
@pytest.mark.yade
def test_a_run_killed_mid_creep_resumes_to_the_uninterrupted_result(tmp_path, small_reference):
    ref, s = small_reference
    assert s["failed"] and s["n_events"] >= 10 and "resumed_from" not in s
    killed = tmp_path / "killed"
    state = _start_and_kill(SMALL, killed, lambda st: st["phase"] == "event" and st["loop"]["n_events"] >= 8)
    assert state["phase"] == "event" and 0 < state["creep_time_s"] < s["lifetime_s"]
    partial = pd.read_csv(killed / "history.csv") if (killed / "history.csv").exists() else None
    res = _cli("--resume", killed)
    assert res.returncode == 0, res.stderr
    assert "resumed" in res.stdout
    _assert_same_run(ref, killed)
    resumed = json.loads((killed / "summary.json").read_text())
    assert [r["dem_steps"] for r in resumed["resumed_from"]] == [state["dem_steps"]]
    assert not (killed / "checkpoint").exists()
    if partial is not None:   # the partial history the killed run left is a prefix of the final one
        full = pd.read_csv(killed / "history.csv")
        assert full["step"].iloc[:len(partial)].tolist() == partial["step"].tolist()
    again = _cli("--resume", killed)                                 # finished: says so, changes nothing
    assert again.returncode == 0 and "already finished" in again.stdout


@needs_yade
@pytest.mark.yade
def test_a_yade_batch_rerun_resumes_an_unfinished_row(tmp_path):
    from grainfrac_yade.runs.batchrun import run_batch, write_table
    ref = tmp_path / "uninterrupted"
    _reference(TINY, ref)
    out = tmp_path / "row"
    # only the ramp's checkpoint: with one at every safe point the first event's replaces it within
    # about 10 ms, shorter than a poll can be sure to see
    state = _start_and_kill(TINY, out, lambda st: st["phase"] == "ramp", every_safe_point=False)
    assert state["phase"] == "ramp"
    row = {"specimen.width": TINY["width"], "specimen.height": TINY["height"], "ratio": TINY["ratio"],
           "ucs": TINY["ucs"], "seed": TINY["seed"], "stress_corrosion.creep_time_limit": 1e30, "out": str(out)}
    run_batch(write_table(tmp_path / "rerun.table", [row]), ROOT / "yade_scripts" / "creep.py", 1, tmp_path / "logs",
              repo=ROOT)
    log = "".join(p.read_text() for p in (tmp_path / "logs").glob("*.log"))
    assert f"creep row unfinished, resumed from its checkpoint: {out}" in log, log[-2000:]
    _assert_same_run(ref, out)


# ------------------------------------------------------------------ without YADE: decisions and errors
VALUES = {"seed": 1, "stress_pa": 2.4e8}


def _unfinished(path, params, values=VALUES, phase="event"):
    """A run folder as a killed creep run leaves it: run.json, params.json and a checkpoint's state."""
    from grainfrac_yade.runs.runio import prepare_run_dir
    out = prepare_run_dir(path, "creep", params, values["seed"])
    (out / "checkpoint").mkdir()
    (out / "checkpoint" / "state.json").write_text(json.dumps(
        {"format": 1, "phase": phase, "loop": {}, "dem_steps": 10, "creep_time_s": 0.0,
         "run_values": dict(values, driving_stress_ratio=0.8, ucs_pa=3e8)}))
    return out


def test_a_batch_row_skips_resumes_or_starts_by_its_folder(tmp_path):
    from grainfrac_yade.runs.runio import write_json
    from grainfrac_yade.engines.yade.batch import row_plan
    params = load_parameters(overrides=["specimen.width=3e-3", "specimen.height=6e-3"])
    stop = {"on_change": "stop"}
    out = _unfinished(tmp_path / "a", params)
    assert row_plan(out, params, stop, VALUES) == (out, "resume", "")
    slower = load_parameters(overrides=["specimen.width=3e-3", "specimen.height=6e-3", "numerics.checkpoint_interval=60"])
    assert row_plan(out, slower, stop, VALUES) == (out, "resume", "")   # the interval changes no result
    edited = load_parameters(overrides=["specimen.width=3e-3", "specimen.height=6e-3", "stress_corrosion.beta1=2e-3"])
    folder, action, note = row_plan(out, edited, stop, VALUES)
    assert (folder, action) == (out, "run") and "stress_corrosion.beta1: stored 0.001, now 0.002" in note
    folder, action, note = row_plan(out, params, stop, dict(VALUES, seed=2))
    assert action == "run" and "seed: stored 1, now 2" in note
    bare = tmp_path / "b"
    bare.mkdir()
    assert row_plan(bare, params, stop, VALUES) == (bare, "run", "")
    write_json(out / "summary.json", dict(VALUES, failed=True))
    assert row_plan(out, params, stop, VALUES) == (out, "skip", "")


def test_checkpoint_folder_survives_a_kill_between_the_renames(tmp_path):
    from grainfrac_yade.runs.runio import checkpoint_folder, commit_run_dir, prepare_run_dir
    params = load_parameters(overrides=["specimen.width=3e-3", "specimen.height=6e-3"])
    out = _unfinished(tmp_path / "r", params)
    (out / "checkpoint.tmp").mkdir()                    # a new one half written: not used
    assert checkpoint_folder(out) == out / "checkpoint"
    os.replace(out / "checkpoint", out / "checkpoint.old")   # killed between the two renames
    assert checkpoint_folder(out) == out / "checkpoint.old"
    (out / "checkpoint.tmp" / "state.json").write_text("{}")  # ... with the new one complete
    assert checkpoint_folder(out) == out / "checkpoint.tmp"
    new = prepare_run_dir(out, "creep", params, 1, overwrite=True)   # a replaced run never resumes the old one
    assert checkpoint_folder(new) is None and not any(p.name.startswith("checkpoint") for p in new.iterdir())
    assert commit_run_dir(new) == out and checkpoint_folder(out) is None


def test_checkpoint_interval_is_a_checked_parameter_that_no_run_comparison_sees(tmp_path):
    from grainfrac_yade.errors import ParameterError
    from grainfrac_yade.runs.runio import run_digest
    p = load_parameters()
    assert p.numerics.checkpoint_interval == 600.0
    assert run_digest(load_parameters(overrides=["numerics.checkpoint_interval=0"]), VALUES) == run_digest(p, VALUES)
    with pytest.raises(ParameterError, match="numerics.checkpoint_interval: must be >= 0"):
        load_parameters(overrides=["numerics.checkpoint_interval=-1"])


def test_the_old_interval_key_is_refused_in_one_line_and_migrated_in_older_runs(tmp_path):
    """``creep.checkpoint_interval`` moved to ``numerics.checkpoint_interval`` (one interval for every test):
    a parameter file, --set or batch column with the old key gets one line naming the new one; an older
    run's params.json is read with its value under the new key, and its checkpoint still continues a row."""
    from grainfrac_yade.analysis.runparams import load_run_parameters
    from grainfrac_yade.errors import GrainfracError, ParameterError
    from grainfrac_yade.params import migrate_tree
    from grainfrac_yade.runs.runio import checkpoint_differences
    from grainfrac_yade.engines.yade.batch import check_columns
    for given in (["creep.checkpoint_interval=60"], ):
        with pytest.raises(ParameterError, match="moved to numerics.checkpoint_interval"):
            load_parameters(overrides=given)
    old_file = tmp_path / "old.toml"
    old_file.write_text("[creep]\ncheckpoint_interval = 60.0\n")
    with pytest.raises(ParameterError, match="old.toml: creep.checkpoint_interval: renamed key.*numerics"):
        load_parameters(extra_files=[old_file])
    res = subprocess.run([sys.executable, "-m", "grainfrac_yade", "ucs", "--set", "creep.checkpoint_interval=60",
                          "--out", str(tmp_path / "x")], capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1
    assert "fix:" in res.stderr and "numerics.checkpoint_interval" in res.stderr
    with pytest.raises(GrainfracError, match="renamed key; fix: .*numerics.checkpoint_interval"):
        check_columns(["creep.checkpoint_interval"], {"numerics.checkpoint_interval": 600.0}, "t.table:2")
    tree = load_parameters(overrides=["numerics.checkpoint_interval=60"]).to_dict()
    tree["creep"]["checkpoint_interval"] = tree["numerics"].pop("checkpoint_interval")   # as older code wrote it
    moved = json.loads(json.dumps(tree))
    assert migrate_tree(moved) == ["creep.checkpoint_interval = 60.0 read as numerics.checkpoint_interval = 60.0"]
    assert "checkpoint_interval" not in moved["creep"] and moved["numerics"]["checkpoint_interval"] == 60.0
    folder = tmp_path / "older_run"
    folder.mkdir()
    (folder / "params.json").write_text(json.dumps(tree))
    assert load_run_parameters(folder).params.numerics.checkpoint_interval == 60.0
    (folder / "checkpoint").mkdir()
    (folder / "checkpoint" / "state.json").write_text(json.dumps({"run_values": {"seed": 1}}))
    assert checkpoint_differences(folder, load_parameters(), {"seed": 1}) == []


def test_a_folder_holding_a_resumable_run_is_refused_naming_resume(tmp_path):
    from grainfrac_yade.errors import GrainfracError
    from grainfrac_yade.runs.runio import prepare_run_dir
    params = load_parameters(overrides=["specimen.width=3e-3", "specimen.height=6e-3"])
    out = _unfinished(tmp_path / "killed", params)   # a creep run's folder
    with pytest.raises(GrainfracError) as exc:
        prepare_run_dir(out, "creep", params, 1)
    assert f"unfinished creep run with a checkpoint; fix: `python3 -m grainfrac_yade creep --resume {out}` goes " \
           "on with it" in str(exc.value) and "--overwrite" in str(exc.value)
    with pytest.raises(GrainfracError) as exc:     # another command never takes the folder over
        prepare_run_dir(out, "ucs", params, 1)
    assert "holds a 'creep' run, not a 'ucs' run" in str(exc.value)
    plain = prepare_run_dir(tmp_path / "no_checkpoint", "ucs", params, 1)
    with pytest.raises(GrainfracError) as exc:
        prepare_run_dir(plain, "ucs", params, 1)
    assert "--resume" not in str(exc.value)


@pytest.mark.parametrize("case", ["no folder", "no checkpoint", "finished", "conflict", "ucs run"])
def test_a_bad_resume_is_one_line(tmp_path, case):
    """creep --resume."""
    from grainfrac_yade.runs.runio import prepare_run_dir, write_json
    params = load_parameters(overrides=["specimen.width=3e-3", "specimen.height=6e-3"])
    out = tmp_path / "run"
    args = ["--resume", out]
    if case == "no checkpoint":
        prepare_run_dir(out, "creep", params, 1)
    elif case == "finished":
        _unfinished(out, params)
        write_json(out / "summary.json", dict(VALUES, failed=True))
    elif case == "conflict":
        _unfinished(out, params)
        args += ["--stress", "100"]
    elif case == "ucs run":
        prepare_run_dir(out, "ucs", params, 1)
    res = _cli(*args)
    if case == "finished":
        assert res.returncode == 0 and res.stdout.strip() == (f"creep run already finished (summary.json): {out}; "
                                                              "nothing to resume")
        return
    assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1, res.stderr
    expected = {"no folder": "no run here", "no checkpoint": "no checkpoint to resume from",
                "conflict": "fix: drop --stress", "ucs run": "not a creep run"}[case]
    assert expected in res.stderr and "fix:" in res.stderr


def test_a_checkpoint_older_than_a_parameter_section_still_matches(tmp_path):
    """A key missing from an older params.json counts as the shipped default: a checkpoint written
    before a section existed is resumed, not restarted."""
    import json as _json
    from grainfrac_yade.params import load_parameters as _load
    from grainfrac_yade.runs.runio import CHECKPOINT, CHECKPOINT_STATE, checkpoint_differences
    p = _load()
    stored = p.to_dict()
    stored.pop("brazilian", None)
    stored["ucs"].pop(next(iter(stored["ucs"])))
    (tmp_path / "params.json").write_text(_json.dumps(stored))
    (tmp_path / CHECKPOINT).mkdir()
    (tmp_path / CHECKPOINT / CHECKPOINT_STATE).write_text(_json.dumps({"run_values": {"seed": 1}}))
    assert checkpoint_differences(tmp_path, p, {"seed": 1}) == []
    assert checkpoint_differences(tmp_path, p, {"seed": 2}) == ["seed: stored 1, now 2"]


@pytest.mark.parametrize("command", ["ucs", "brazilian"])
@pytest.mark.parametrize("case", ["no folder", "no checkpoint", "finished", "conflict", "creep run"])
def test_a_bad_resume_of_a_loading_test_is_one_line(tmp_path, command, case):
    from grainfrac_yade.runs.runio import prepare_run_dir, write_json
    params = load_parameters(overrides=["specimen.width=3e-3", "specimen.height=6e-3"])
    out = tmp_path / "run"
    args = [command, "--resume", out]
    if case == "no checkpoint":
        prepare_run_dir(out, command, params, 1)
    elif case in ("finished", "conflict"):
        prepare_run_dir(out, command, params, 1)
        (out / "checkpoint").mkdir()
        (out / "checkpoint" / "state.json").write_text(json.dumps({"format": 1, "test": command, "phase": "loading",
                                                                   "run_values": {"seed": 1}}))
        if case == "finished":
            write_json(out / "summary.json", {"seed": 1})
        else:
            args += ["--set", "ucs.strain_rate=1", "--out", tmp_path / "other"]
    elif case == "creep run":
        _unfinished(out, params)
    res = subprocess.run([sys.executable, "-m", "grainfrac_yade", *map(str, args)], capture_output=True, text=True,
                         cwd=ROOT)
    if case == "finished":
        assert res.returncode == 0 and "already finished (summary.json)" in res.stdout
        return
    assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1, res.stderr
    expected = {"no folder": "no run here", "no checkpoint": "no checkpoint to resume from",
                "conflict": "fix: drop --set, --out", "creep run": f"fix: resume it with `creep --resume {out}`"}[case]
    assert expected in res.stderr and "fix:" in res.stderr


# ------------------------------------------------------------------ loading tests and the creep ramp
def _start_and_kill_command(command, args, out, ready, timeout=180):
    """Start ``command`` (a checkpoint at every safe point) and SIGKILL it once ``ready(state)``."""
    return _kill_when_ready([command, *args, "--set", EVERY_SAFE_POINT, "--out", out], out, ready, timeout)


#: summary.json keys that differ between a resumed run and the uninterrupted one by design.
RESUME_ONLY = {"wall_s", "cpu_s", "resumed_from", "params"}


def _assert_same_loading_test(a, b):
    """Every summary number (but wall and CPU time), history.csv and cracks.csv to the last bit; the
    parameters equal but the checkpoint interval."""
    sa, sb = (json.loads((f / "summary.json").read_text()) for f in (a, b))
    assert {k: v for k, v in sa.items() if k not in RESUME_ONLY} == {k: v for k, v in sb.items() if k not in RESUME_ONLY}
    for s in (sa, sb):
        s["params"]["numerics"].pop("checkpoint_interval")
    assert sa["params"] == sb["params"]
    for name in ("history.csv", "cracks.csv"):
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    assert not any(p.name.startswith("checkpoint") for p in b.iterdir())   # removed once finished


def _ucs_reference(out, spec=UCS_TINY):
    from grainfrac_yade.protocols.ucs_output import run_ucs_to_folder
    p = load_parameters(overrides=[("specimen.width", spec["width"]), ("specimen.height", spec["height"])])
    s = run_ucs_to_folder(p, spec["seed"], out)
    assert not (out / "checkpoint").exists() and "resumed_from" not in s
    return s


def _ucs_mid_loading(state):
    """Killed once bonds have broken (the break bookkeeping and the peak snapshot go with the checkpoint)."""
    return state["phase"] == "loading" and state["scene"]["cracks_seen"] >= 1


@needs_yade
@pytest.mark.yade
def test_a_ucs_test_killed_mid_loading_resumes_to_the_uninterrupted_result(tmp_path):
    ref = tmp_path / "uninterrupted"
    s = _ucs_reference(ref)
    assert s["peak_reached"] and s["broken_total"] > 10
    killed = tmp_path / "killed"
    state = _start_and_kill_command("ucs", ["--width", UCS_TINY["width"], "--height", UCS_TINY["height"]], killed,
                                    _ucs_mid_loading)
    assert state["test"] == "ucs" and state["phase"] == "loading" and 0 < state["dem_steps"] < s["steps"]
    refused = subprocess.run([sys.executable, "-m", "grainfrac_yade", "ucs", "--out", str(killed)],
                             capture_output=True, text=True, cwd=ROOT)
    assert refused.returncode == 2 and f"ucs --resume {killed}" in refused.stderr
    res = subprocess.run([sys.executable, "-m", "grainfrac_yade", "ucs", "--resume", str(killed)], capture_output=True,
                         text=True, cwd=ROOT, env=dict(os.environ, OMP_NUM_THREADS="1"))
    assert res.returncode == 0, res.stderr
    assert "resumed from the checkpoint" in res.stdout
    _assert_same_loading_test(ref, killed)
    resumed = json.loads((killed / "summary.json").read_text())
    assert [r["dem_steps"] for r in resumed["resumed_from"]] == [state["dem_steps"]]


@needs_yade
@pytest.mark.yade
def test_a_run_killed_inside_a_relaxation_resumes_to_the_uninterrupted_result(tmp_path, small_reference):
    """A relaxation after a creep step has safe points between its checks (a collapse at paper size
    relaxes for hours): killed there, the run resumes inside it, with the servo's clip count and the
    collapse watch as they were, to the uninterrupted run's results bit for bit."""
    ref, s = small_reference
    killed = tmp_path / "killed"
    state = _start_and_kill(SMALL, killed, lambda st: st["phase"] == "relaxation" and st["loop"]["n_events"] >= 8
                            and st["loop"]["relaxation"]["done"] >= 500)
    assert state["phase"] == "relaxation" and state["loop"]["relaxation"]["done"] >= 500
    assert "closing_clipped_steps" in state["servo"]
    res = _cli("--resume", killed)
    assert res.returncode == 0, res.stderr
    _assert_same_run(ref, killed)
    resumed = json.loads((killed / "summary.json").read_text())
    assert [(r["dem_steps"], r["phase"]) for r in resumed["resumed_from"]] == [(state["dem_steps"], "relaxation")]
    assert resumed["n_events"] == s["n_events"]


@pytest.mark.slow   # about 9 s: the default suite stays under about 10 min
@needs_yade
@pytest.mark.yade
def test_a_creep_run_killed_in_its_ramp_resumes_to_the_uninterrupted_result(tmp_path):
    ref = tmp_path / "uninterrupted"
    s = _reference(TINY, ref)
    assert s["failed"] and s["broken_ramp"] >= 1
    killed = tmp_path / "killed"
    target = TINY["ratio"] * TINY["ucs"]
    # halfway up the ramp: far from its end, so the kill lands in it (the ramp is about 44k DEM steps)
    state = _start_and_kill(TINY, killed, lambda st: st["phase"] == "loading" and st["loop"]["peak"] > 0.5 * target)
    assert state["phase"] == "loading" and state["loop"]["peak"] < target and not state["run"]["rows"]
    res = _cli("--resume", killed)
    assert res.returncode == 0, res.stderr
    _assert_same_run(ref, killed)
    resumed = json.loads((killed / "summary.json").read_text())
    assert [(r["dem_steps"], r["phase"]) for r in resumed["resumed_from"]] == [(state["dem_steps"], "loading")]


@pytest.mark.slow   # about 9 s: the default suite stays under about 10 min
@needs_yade
@pytest.mark.yade
def test_a_yade_batch_rerun_resumes_an_unfinished_ucs_row(tmp_path):
    from grainfrac_yade.runs.batchrun import run_batch, write_table
    ref = tmp_path / "uninterrupted"
    _ucs_reference(ref)
    out = tmp_path / "row"
    _start_and_kill_command("ucs", ["--width", UCS_TINY["width"], "--height", UCS_TINY["height"]], out,
                            _ucs_mid_loading)
    # the row has the shipped interval, the killed run one at every safe point: the interval changes no result
    row = {"specimen.width": UCS_TINY["width"], "specimen.height": UCS_TINY["height"], "seed": UCS_TINY["seed"],
           "out": str(out)}
    run_batch(write_table(tmp_path / "rerun.table", [row]), ROOT / "yade_scripts" / "ucs.py", 1, tmp_path / "logs",
              repo=ROOT)
    log = "".join(p.read_text() for p in (tmp_path / "logs").glob("*.log"))
    assert f"UCS row unfinished, resumed from its checkpoint: {out}" in log, log[-2000:]
    _assert_same_loading_test(ref, out)


@needs_yade
@pytest.mark.yade
@pytest.mark.slow
def test_a_brazilian_test_killed_mid_loading_resumes_to_the_uninterrupted_result(tmp_path):
    """6 mm disc, seed 1: 100,947 DEM steps, 41 broken bonds; about 9 s alone, 45 s with a checkpoint
    before every row."""
    from grainfrac_yade.protocols.brazilian_output import run_brazilian_to_folder
    ref = tmp_path / "uninterrupted"
    run_brazilian_to_folder(load_parameters(overrides=["brazilian.diameter=6e-3"]), 1, ref)
    killed = tmp_path / "killed"
    state = _start_and_kill_command("brazilian", ["--diameter", 6e-3], killed,
                                    lambda st: st["phase"] == "loading" and st["scene"]["cracks_seen"] >= 1)
    assert state["test"] == "brazilian"
    res = subprocess.run([sys.executable, "-m", "grainfrac_yade", "brazilian", "--resume", str(killed)],
                         capture_output=True, text=True, cwd=ROOT, env=dict(os.environ, OMP_NUM_THREADS="1"))
    assert res.returncode == 0, res.stderr
    _assert_same_loading_test(ref, killed)


def test_only_finite_element_cells_are_flagged_as_resuming_inexactly():
    from grainfrac_yade.protocols.checkpoints import inexact_note
    assert inexact_note(load_parameters()) == ""
    assert "memory address" in inexact_note(load_parameters(overrides=["resolution.grain_model=fem"]))
