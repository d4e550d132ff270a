"""Checkpoint and resume of creep runs: a run killed with SIGKILL mid-creep and resumed from its
checkpoint gives the uninterrupted run's lifetime and history, row for row (one thread, same seed);
checkpoints change nothing a run computes; a yade-batch rerun resumes an unfinished row; bad resumes
are one line."""
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
EVERY_SAFE_POINT = "creep.checkpoint_interval=1e-6"
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
    from grainfrac_yade.runio import read_checkpoint_state
    return read_checkpoint_state(folder)


def _start_and_kill(spec, out, ready, timeout=120, extra=(), every_safe_point=True):
    """Start a creep run (CLI options ``extra`` added) with a checkpoint at every safe point (else only
    the shipped ones: at the end of the ramp, then every 600 s); SIGKILL it once ``ready(state)``."""
    interval = ["--set", EVERY_SAFE_POINT] if every_safe_point else []
    proc = subprocess.Popen([sys.executable, "-m", "grainfrac_yade", "creep",
                             *map(str, _creep_args(spec, out, *extra, *interval))],
                            cwd=ROOT, env=dict(os.environ, OMP_NUM_THREADS="1"),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    t0 = time.time()
    try:
        while proc.poll() is None and time.time() - t0 < timeout:
            state = _state(out)
            if state is not None and ready(state):
                break
            time.sleep(0.01)
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    assert proc.returncode == -signal.SIGKILL, "the run ended before it could be killed"
    assert not (out / "summary.json").exists()
    return _state(out)


def _reference(spec, out):
    """The uninterrupted run (this process, one thread; the shipped checkpoint interval)."""
    from grainfrac_yade.commands.creep import run_creep_to_folder
    p = load_parameters(overrides=[("specimen.width", spec["width"]), ("specimen.height", spec["height"]),
                                   "stress_corrosion.creep_time_limit=1e30"])
    s = run_creep_to_folder(p, spec["seed"], out, spec["ratio"] * spec["ucs"], spec["ratio"], spec["ucs"])
    assert not (out / "checkpoint").exists()   # removed once the run is finished
    return s


def _assert_same_run(a, b):
    sa, sb = (json.loads((f / "summary.json").read_text()) for f in (a, b))
    for key in ("lifetime_s", "failed", "failure_reason", "n_events", "broken_ramp", "broken_creep", "macrocracks",
                "dem_steps", "creep_time_end_s", "primary_end_s", "tertiary_start_s", "shear_stress_p99_pa"):
        assert sa[key] == sb[key], key
    ha, hb = (pd.read_csv(f / "history.csv").drop(columns=WALL) for f in (a, b))
    pd.testing.assert_frame_equal(ha, hb, check_exact=True)          # no row missing, none twice, every bit equal
    assert np.all(np.diff(hb["dem_steps"]) > 0) and np.all(np.diff(hb["creep_time_s"]) >= 0)
    for name in ("cracks.csv", "bond_stresses_start.csv"):
        assert (a / name).read_text() == (b / name).read_text(), name


@needs_yade
@pytest.mark.yade
def test_a_run_killed_mid_creep_resumes_to_the_uninterrupted_result(tmp_path):
    ref = tmp_path / "uninterrupted"
    s = _reference(SMALL, ref)
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
        assert full["dem_steps"].iloc[:len(partial)].tolist() == partial["dem_steps"].tolist()
    again = _cli("--resume", killed)                                 # finished: says so, changes nothing
    assert again.returncode == 0 and "already finished" in again.stdout


@needs_yade
@pytest.mark.yade
def test_a_yade_batch_rerun_resumes_an_unfinished_row(tmp_path):
    from grainfrac_yade.batchrun import run_batch, write_table
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
    from grainfrac_yade.runio import prepare_run_dir
    out = prepare_run_dir(path, "creep", params, values["seed"])
    (out / "checkpoint").mkdir()
    (out / "checkpoint" / "state.json").write_text(json.dumps(
        {"format": 1, "phase": phase, "loop": {}, "dem_steps": 10, "creep_time_s": 0.0,
         "run_values": dict(values, driving_stress_ratio=0.8, ucs_pa=3e8)}))
    return out


def test_a_batch_row_skips_resumes_or_starts_by_its_folder(tmp_path):
    from grainfrac_yade.runio import write_json
    from grainfrac_yade.yade_adapter.batch import row_plan
    params = load_parameters(overrides=["specimen.width=3e-3", "specimen.height=6e-3"])
    stop = {"on_change": "stop"}
    out = _unfinished(tmp_path / "a", params)
    assert row_plan(out, params, stop, VALUES) == (out, "resume", "")
    slower = load_parameters(overrides=["specimen.width=3e-3", "specimen.height=6e-3", "creep.checkpoint_interval=60"])
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
    from grainfrac_yade.runio import checkpoint_folder, commit_run_dir, prepare_run_dir
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
    from grainfrac_yade.runio import run_digest
    p = load_parameters()
    assert p.creep.checkpoint_interval == 600.0
    assert run_digest(load_parameters(overrides=["creep.checkpoint_interval=0"]), VALUES) == run_digest(p, VALUES)
    with pytest.raises(ParameterError, match="creep.checkpoint_interval: must be >= 0"):
        load_parameters(overrides=["creep.checkpoint_interval=-1"])


@pytest.mark.parametrize("case", ["no folder", "no checkpoint", "finished", "conflict", "ucs run"])
def test_a_bad_resume_is_one_line(tmp_path, case):
    from grainfrac_yade.runio import prepare_run_dir, write_json
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
    from grainfrac_yade.runio import CHECKPOINT, CHECKPOINT_STATE, checkpoint_differences
    p = _load()
    stored = p.to_dict()
    stored.pop("brazilian", None)
    stored["ucs"].pop(next(iter(stored["ucs"])))
    (tmp_path / "params.json").write_text(_json.dumps(stored))
    (tmp_path / CHECKPOINT).mkdir()
    (tmp_path / CHECKPOINT / CHECKPOINT_STATE).write_text(_json.dumps({"run_values": {"seed": 1}}))
    assert checkpoint_differences(tmp_path, p, {"seed": 1}) == []
    assert checkpoint_differences(tmp_path, p, {"seed": 2}) == ["seed: stored 1, now 2"]
