"""A new user's first hour: one unit for stresses, bad input in one line, no folder taken over,
batch tables checked before they run, ratios that keep their meaning, crack phases.

CLI calls go through :func:`grainfrac_yade.cli.main` in-process where nothing is simulated (the
refusals come before any run), and through a subprocess where the exit status of the whole
program matters."""
import json
import os
import subprocess
import sys

import pytest

from conftest import ROOT, needs_yade
from grainfrac_yade.cli import main
from grainfrac_yade.errors import GrainfracError
from grainfrac_yade.params import load_parameters

MPA = 1e6
#: 3 x 6 mm specimen (about 23 cells): a UCS test in about 2 s.
TINY = ["specimen.width=3e-3", "specimen.height=6e-3"]


def _one_line(capsys, *words):
    """The single stderr line of a refused command; it contains every one of ``words``."""
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    for w in words:
        assert w in err[0], err[0]
    return err[0]


def _cli(*args, cwd=ROOT, **kw):
    return subprocess.run([sys.executable, "-m", "grainfrac_yade", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, env=dict(os.environ, OMP_NUM_THREADS="1"), **kw)


# ------------------------------------------------------------------ one unit for stresses
def test_every_stress_flag_states_mpa_in_its_help():
    from grainfrac_yade.cli import build_parser
    parser = build_parser()
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction").choices
    flags = {"creep": ("--stress", "--ucs", "--confinement"), "ucs": ("--confinement",),
             "calibrate": ("--target-ucs",), "calibrate-lifetimes": ("--ucs",)}
    for command, names in flags.items():
        actions = {o: a for a in sub[command]._actions for o in a.option_strings}
        for name in names:
            assert "[MPa" in actions[name].help, (command, name)


def test_a_stress_given_in_pa_to_an_mpa_flag_is_refused_in_one_line(capsys):
    assert main(["creep", "--stress", "160e6", "--out", "/nonexistent/never"]) == 2
    _one_line(capsys, "--stress", "MPa", "fix:")


def test_a_confinement_given_in_pa_is_refused_before_it_runs(capsys):
    assert main(["ucs", "--confinement", "20e6", "--out", "/nonexistent/never"]) == 2
    _one_line(capsys, "--confinement", "reference strength", "fix:")


@pytest.mark.parametrize("value", ["0", "-5"])
def test_a_confinement_at_or_below_zero_is_refused(capsys, value):
    assert main(["creep", "--ratio", "0.5", "--confinement", value, "--out", "/nonexistent/never"]) == 2
    _one_line(capsys, "--confinement", "above 0")


def test_cli_stresses_are_mpa_and_batch_stresses_pa():
    from grainfrac_yade.commands._loads import resolve_stress
    p = load_parameters()
    assert resolve_stress(p, stress=160 * MPA, cli=True)[0] == 160 * MPA
    with pytest.raises(GrainfracError, match="column stress = 160 Pa is below 1 MPa, no creep load for granite; fix: "
                                             "CLI stress flags are in MPa, batch columns in Pa: e.g. stress 160e6"):
        resolve_stress(load_parameters(overrides=[("confinement.stress", 1e3)]), stress=160.0, ucs=258e6)
    with pytest.raises(GrainfracError, match="column stress = 1e\\+06 Pa: must be above the confining"):
        resolve_stress(load_parameters(overrides=[("confinement.stress", 2e6)]), stress=1e6, ucs=258e6)
    with pytest.raises(GrainfracError, match="above 0"):
        resolve_stress(p, stress=-1.0)
    with pytest.raises(GrainfracError, match="--ucs 2.58e\\+08 MPa is above 4 x the reference strength"):
        resolve_stress(p, ratio=0.5, ucs=258e12, cli=True)


@needs_yade
@pytest.mark.yade
def test_a_specimen_broken_apart_in_the_isotropic_stage_is_a_failure_not_a_ucs_of_zero(tmp_path):
    """1e6 times the intended 20 MPa (a unit slip, Pa given for MPa; the CLI refuses it, the adapter is called
    directly): every bond breaks in the isotropic stage; the run must say so and measure nothing."""
    from grainfrac_yade.protocols.ucs_output import run_ucs_to_folder
    params = load_parameters(overrides=TINY + [("confinement.stress", 20e12)])
    s = run_ucs_to_folder(params, 1, tmp_path / "run")
    assert s["failed_before_test"] is True and s["ucs_pa"] is None
    assert "broke apart in the isotropic stage" in s["end_reason"]


@needs_yade
@pytest.mark.yade
def test_a_creep_specimen_broken_apart_in_the_isotropic_stage_fails_before_the_test(tmp_path):
    """A 3 x 6 mm confined creep run (a few seconds) whose reference strength is set far up, so that the CLI
    accepts a confinement of 2e7 MPa: every bond breaks in the isotropic stage; the run ends there, one line
    and exit status 1, and its summary is no creep result (no lifetime, not a survival)."""
    out = tmp_path / "creep"
    res = _cli("creep", "--width", "3e-3", "--height", "6e-3", "--set", "calibration.reference_ucs=1e13",
               "--confinement", "2e7", "--ratio", "0.5", "--ucs", "3e7", "--out", out)
    assert res.returncode == 1, res.stderr
    last = res.stdout.strip().splitlines()[-1]
    assert "failed before the test (the specimen broke apart in the isotropic stage" in last and str(out) in last
    assert "Traceback" not in res.stderr
    s = json.loads((out / "summary.json").read_text())
    assert s["failed_before_test"] is True and s["failed"] is None and s["lifetime_s"] is None
    assert not s["numerical_failure"] and not s["failed_on_loading"] and s["n_events"] == 0
    assert "broke apart in the isotropic stage" in s["failure_reason"] and s["end_reason"] == s["failure_reason"]
    assert s["broken_ramp"] >= s["n_bonds"] / 2 and s["broken_creep"] == 0
    assert not (out / "history.csv").exists() and not (out / "checkpoint").exists()
    from grainfrac_yade.analysis.collect import collect_runs
    from grainfrac_yade.analysis.lifetimes import classify_runs
    assert list(classify_runs(collect_runs(tmp_path))["outcome"]) == ["failed before test"]


@needs_yade
@pytest.mark.yade
def test_a_cli_run_uses_one_yade_thread_unless_told_otherwise(tmp_path):
    """A command draws its figures with matplotlib, which loads the OpenMP runtime; the runtime reads
    OMP_NUM_THREADS once, so the one-thread default must be set before: else YADE imported after it ran 2
    threads (the README's UCS gave 280.4 and 282.0 MPa in two runs, at 16 x the CPU time)."""
    code = ("import sys; from grainfrac_yade.cli import main\n"
            f"main(['specimen', '--width', '3e-3', '--height', '6e-3', '--out', {str(tmp_path / 's')!r}])\n"
            "from grainfrac_yade.engines.yade import load_yade; load_yade(); from yade import O; print(O.numThreads)")
    env = {k: v for k, v in os.environ.items() if k != "OMP_NUM_THREADS"}
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, env=env)
    assert res.returncode == 0, res.stderr[-2000:]
    assert res.stdout.strip().splitlines()[-1] == "1", res.stdout


# ------------------------------------------------------------------ shortcut flags named in their refusals
@pytest.mark.parametrize("argv, flag, words", [
    (["ucs", "--width", "-10e-3"], "--width", "specimen.width: must be > 0"),
    (["creep", "--ratio", "0.5", "--height", "0"], "--height", "specimen.height: must be > 0"),
    (["ucs", "--grain-size", "1"], "--grain-size", "at or above the specimen's width"),
    (["ucs", "--grain-size", "1e-9"], "--grain-size", "cells, more than this machine's memory holds"),
    (["ucs", "--spheres-per-cell", "0"], "--spheres-per-cell", "must be >= 1"),
    (["creep", "--ratio", "1.5"], "--ratio", "must lie in (0, 1); fix: e.g. --ratio 0.7"),
    (["creep", "--ratio", "0.5", "--ucs", "300", "--confinement", "2000"], "--confinement", "reference strength"),
    (["brazilian", "--diameter", "-1"], "--diameter", "brazilian.diameter: must be > 0"),
    (["elastic", "--nodes-per-face", "0"], "--nodes-per-face", "must be >= 1"),
    (["demo", "--width", "0"], "--width", "specimen.width: must be > 0"),
])
def test_a_shortcut_flags_refusal_names_the_flag_not_set(capsys, argv, flag, words):
    assert main(argv + ["--out", "/nonexistent/never"]) == 2
    line = _one_line(capsys, words, "fix:")
    assert line.startswith(f"error: {flag}") and "--set" not in line, line


def test_a_set_override_is_still_named_set(capsys):
    assert main(["ucs", "--set", "specimen.width=0", "--out", "/nonexistent/never"]) == 2
    assert _one_line(capsys, "specimen.width: must be > 0").startswith("error: --set: ")


def test_a_flag_override_unpacks_as_a_pair_and_survives_a_copy():
    import copy
    import pickle
    from grainfrac_yade.params import FlagOverride, flat_values, override_origin
    o = FlagOverride("specimen.width", 3e-3, "--width")
    key, value = o
    assert (key, value) == ("specimen.width", 3e-3) and flat_values([], [o]) == {"specimen.width": 3e-3}
    for same in (copy.deepcopy(o), pickle.loads(pickle.dumps(o))):
        assert tuple(same) == tuple(o) and override_origin(same) == "--width"
    assert override_origin(("specimen.width", 1.0)) == override_origin("specimen.width=1") == "--set"


# ------------------------------------------------------------------ batch: rows checked before anything runs
BAD_CREEP_TABLE = """# one bad row per reason, and one good row (line 8)
ratio stress ucs specimen.width seed study
0.5 100e6 0 3e-3 1 'x'
1.2 0 0 3e-3 1 'x'
0.5 0 0 1 'x'
0.5 0 0 3e-3 1 x
0.5 0 0 -3e-3 1 'x'
0.5 0 0 3e-3 1 'x'
"""


def test_a_batch_table_is_checked_row_by_row_before_anything_runs(tmp_path, capsys):
    table = tmp_path / "bad.table"
    table.write_text(BAD_CREEP_TABLE)
    assert main(["batch", str(table), "--log-dir", str(tmp_path / "logs")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert "5 bad row(s), nothing run" in err[0]
    expected = {3: "both ratio and stress", 4: "must lie in (0, 1)", 5: "5 cells for 6 columns",
                6: "column study takes quoted text", 7: "specimen.width: must be > 0"}
    assert len(err) == 1 + len(expected)
    for (line, words), text in zip(expected.items(), err[1:]):
        assert f"bad.table:{line}:" in text and words in text, text
    assert not (tmp_path / "logs").exists()   # nothing made, nothing run


def test_an_unknown_batch_column_names_the_close_key(tmp_path, capsys):
    table = tmp_path / "typo.table"
    table.write_text("ratio specimen.widht seed\n0.5 3e-3 1\n")
    assert main(["batch", str(table)]) == 2
    assert "did you mean specimen.width?" in capsys.readouterr().err


def test_the_demo_refuses_a_ratio_at_or_above_one_before_it_simulates(tmp_path, capsys):
    assert main(["demo", "--ratios", "0.7,1.2", "--out", str(tmp_path / "demo")]) == 2
    _one_line(capsys, "--ratios 0.7,1.2", "(0, 1)")
    assert not (tmp_path / "demo").exists()


@needs_yade
@pytest.mark.yade
def test_batch_runs_the_rows_and_exits_non_zero_naming_the_row_that_failed(tmp_path):
    """Three 3 x 6 mm UCS rows (about 5 s each with YADE's start): line 3 runs; line 4's folder holds a finished
    run of other parameters, line 5's a specimen run (a take-over of another run's folder), so both stop with their one
    line;
    the batch names lines 4 and 5 and exits 1; the specimen folder is left as it was."""
    from grainfrac_yade.runs.runio import prepare_run_dir, write_json
    taken = tmp_path / "taken"
    prepare_run_dir(taken, "ucs", load_parameters(), 1)
    write_json(taken / "summary.json", {"seed": 1, "ucs_pa": 1.0})
    specimen = tmp_path / "specimen"
    assert main(["specimen", "--width", "3e-3", "--height", "6e-3", "--out", str(specimen)]) == 0
    before = {p.name: p.read_bytes() for p in specimen.iterdir()}
    table = tmp_path / "ucs.table"
    table.write_text("# tiny UCS rows\nspecimen.width specimen.height seed out\n"
                     f"3e-3 6e-3 1 '{tmp_path / 'ok'}'\n3e-3 6e-3 1 '{taken}'\n3e-3 6e-3 1 '{specimen}'\n")
    res = _cli("batch", table, "--jobs", "1", "--log-dir", tmp_path / "logs", timeout=300)
    lines = res.stdout.strip().splitlines()
    assert res.returncode == 1, res.stdout + res.stderr
    assert any(l.startswith("line 3: ok: UCS") for l in lines), lines
    assert any(l.startswith("line 4: FAILED: error:") and "holds a finished run with other parameters" in l
               for l in lines), lines
    assert any(l.startswith("line 5: FAILED: error:") and "holds a 'specimen' run, not a 'ucs' run" in l
               for l in lines), lines
    assert lines[-1] == f"2 of 3 rows failed: lines 4, 5 of {table}"
    assert (tmp_path / "ok" / "summary.json").exists()
    assert {p.name: p.read_bytes() for p in specimen.iterdir()} == before


# ------------------------------------------------------------------ no folder taken over or mixed
def test_a_folder_of_another_kind_of_run_is_refused_even_with_overwrite(tmp_path):
    from grainfrac_yade.runs.runio import prepare_run_dir
    params = load_parameters(overrides=TINY)
    out = prepare_run_dir(tmp_path / "r", "specimen", params, 1)
    for overwrite in (False, True):
        with pytest.raises(GrainfracError, match="holds a 'specimen' run, not a 'ucs' run"):
            prepare_run_dir(out, "ucs", params, 1, overwrite=overwrite)
    assert json.loads((out / "run.json").read_text())["command"] == "specimen"


def test_a_folder_of_other_files_is_refused(tmp_path):
    from grainfrac_yade.runs.runio import prepare_run_dir
    (tmp_path / "r").mkdir()
    (tmp_path / "r" / "history.csv").write_text("a\n1\n")
    with pytest.raises(GrainfracError, match="holds files of something else than a run"):
        prepare_run_dir(tmp_path / "r", "ucs", load_parameters(overrides=TINY), 1, overwrite=True)


def test_an_unfinished_run_with_a_checkpoint_is_refused_naming_resume(tmp_path):
    from grainfrac_yade.runs.runio import prepare_run_dir
    params = load_parameters(overrides=TINY)
    out = prepare_run_dir(tmp_path / "r", "creep", params, 1)
    (out / "checkpoint").mkdir()
    (out / "checkpoint" / "state.json").write_text("{}")
    with pytest.raises(GrainfracError, match=f"creep --resume {out}"):
        prepare_run_dir(out, "creep", params, 1)


def test_a_failed_overwrite_leaves_the_old_run_as_it_was(tmp_path, capsys):
    """``--overwrite --grain-size 1e-9`` must leave the old run whole. The cell count is
    refused before any folder is made; a failure later in a replacing run (here: the specimen build refusing
    after the folder was prepared) leaves the old folder byte for byte."""
    from grainfrac_yade.commands.specimen import run_specimen
    out = tmp_path / "s"
    assert main(["specimen", "--width", "3e-3", "--height", "6e-3", "--out", str(out)]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    capsys.readouterr()
    assert main(["specimen", "--overwrite", "--grain-size", "1e-9", "--out", str(out)]) == 2
    _one_line(capsys, "cells", "more than this machine's memory holds")
    with pytest.raises(GrainfracError, match="cells"):
        run_specimen(load_parameters(overrides=["specimen.grain_size=1e-9"]), 1, out, overwrite=True)
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert main(["specimen", "--width", "3e-3", "--height", "6e-3", "--seed", "2", "--overwrite",
                 "--out", str(out)]) == 0   # a replacement that succeeds takes the old run's place
    assert json.loads((out / "run.json").read_text())["seed"] == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s"]   # nothing left beside it


# ------------------------------------------------------------------ one line, no traceback
@pytest.mark.parametrize("argv, words", [
    (["specimen", "--seed", "-1"], ("--seed", "from 0 to 4294967295")),
    (["specimen", "--width", "-10e-3"], ("--width: specimen.width", "must be > 0")),
    (["specimen", "--width", "3e-3", "--height", "6e-3", "--out", "/proc/x"], ("/proc/x", "cannot write")),
    (["creep", "--stress", "abc"], ("--stress", "invalid float value")),
])
def test_bad_input_is_one_line_without_traceback(argv, words):
    res = _cli(*argv)
    assert res.returncode == 2, res.stderr
    err = [l for l in res.stderr.strip().splitlines() if not l.startswith("Using python")]
    assert len(err) == 1 and "Traceback" not in res.stderr, res.stderr
    for w in words:
        assert w in err[0], err[0]


def test_an_out_below_a_file_is_one_line(tmp_path, capsys):
    (tmp_path / "file").write_text("x")
    assert main(["specimen", "--width", "3e-3", "--height", "6e-3", "--out", str(tmp_path / "file" / "run")]) == 2
    _one_line(capsys, "cannot write the run folder", "writable --out")


def test_an_unexpected_error_is_one_line_with_the_traceback_in_a_log(tmp_path, monkeypatch, capsys):
    from grainfrac_yade.commands import specimen as specimen_command

    def broken(*args, **kw):
        raise ZeroDivisionError("a bug")
    monkeypatch.setattr(specimen_command, "run_specimen", broken)
    monkeypatch.chdir(tmp_path)
    assert main(["specimen", "--out", str(tmp_path / "s")]) == 1
    line = _one_line(capsys, "specimen failed unexpectedly: ZeroDivisionError: a bug", "--debug")
    log = line.split("traceback in ")[1].split(" (or rerun")[0]
    assert "Traceback" in open(log).read() and "a bug" in open(log).read()
    with pytest.raises(ZeroDivisionError):
        main(["specimen", "--debug", "--out", str(tmp_path / "s")])


def test_a_row_with_a_missing_cell_is_one_line_in_the_row_script_too(tmp_path):
    """yade-batch run by hand (no pre-check): YADE's own table reader would end in an IndexError."""
    table = tmp_path / "short.table"
    table.write_text("specimen.width specimen.height seed\n3e-3 6e-3 1\n3e-3 6e-3\n")
    from grainfrac_yade.runs.batchrun import read_table_rows
    columns, rows, problems = read_table_rows(table)
    assert list(rows) == [2] and len(problems) == 1 and "short.table:3: 2 cells for 3 columns" in problems[0]


@needs_yade
@pytest.mark.yade
def test_truncated_and_garbage_checkpoints_are_one_line(tmp_path):
    """A tiny creep run killed mid-creep (test_resume's helper, a few seconds); its checkpoint's scene cut in
    half, then every checkpoint file replaced by garbage: each resume is one line naming what is wrong."""
    import shutil
    from test_resume import TINY as CREEP_TINY, _start_and_kill, mid_creep
    out = tmp_path / "killed"
    _start_and_kill(CREEP_TINY, out, mid_creep)
    keep = tmp_path / "copy"
    shutil.copytree(out, keep)
    scene = out / "checkpoint" / "scene.yade.gz"
    scene.write_bytes(scene.read_bytes()[: scene.stat().st_size // 2])
    res = _cli("creep", "--resume", out)
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert "the checkpoint's scene is unreadable" in res.stderr and "gzip" in res.stderr
    shutil.rmtree(out)
    shutil.copytree(keep, out)
    for f in (out / "checkpoint").iterdir():
        f.write_bytes(b"garbage\x00\x01")
    res = _cli("creep", "--resume", out)
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert "state file (checkpoint/state.json) is unreadable" in res.stderr


# ------------------------------------------------------------------ ratios keep their meaning; crack phases
def test_the_calibrated_reference_lists_what_differs_from_its_calibration():
    from grainfrac_yade.protocols.creep_output import UCS_FROM_CALIBRATION, reference_differences, ucs_reference
    assert reference_differences(load_parameters()) == []
    edited = load_parameters(overrides=["contacts.quartz/quartz.tensile_strength=1e6", "specimen.width=3e-3",
                                        "stress_corrosion.beta1=2e-3"])   # beta1 changes no UCS: not listed
    diffs = reference_differences(edited)
    keys = {d.split(":")[0] for d in diffs}   # the mixed quartz pairs average quartz/quartz (section 3.1): listed too
    assert {"contacts.quartz/quartz.tensile_strength", "specimen.width"} <= keys
    assert all(k.startswith(("contacts.", "specimen.")) and "quartz" in k or k == "specimen.width" for k in keys)
    assert ucs_reference(edited, "--ucs") == {"ucs_source": "--ucs", "ucs_reference_differences": []}
    assert ucs_reference(edited, UCS_FROM_CALIBRATION)["ucs_reference_differences"] == diffs


def test_read_cracks_maps_the_ramp_phase_to_the_analysis_convention(tmp_path):
    from grainfrac_yade.analysis.crack_phases import RAMP_TIME
    from grainfrac_yade.analysis.study import read_cracks
    (tmp_path / "cracks.csv").write_text("bond,creep_time_s,phase,mode,kind,x_m,y_m,face_normal_angle_deg\n"
                                         "1,,ramp,tensile,inter,0,0,0\n2,5.0,creep,shear,intra,0,0,0\n")
    c = read_cracks(tmp_path)
    assert c["creep_time_s"].tolist() == [RAMP_TIME, 5.0]


@needs_yade
@pytest.mark.yade
def test_a_creep_run_records_its_reference_ucs_and_the_phase_of_each_crack(tmp_path):
    """3 x 6 mm, ratio 0.8 of the calibrated reference (a few seconds): the reference was calibrated on the
    paper-size specimen, so the run warns and lists the size; cracks.csv has no sentinel times."""
    import pandas as pd
    out = tmp_path / "creep"
    res = _cli("creep", "--width", "3e-3", "--height", "6e-3", "--seed", "1", "--ratio", "0.8", "--set",
               "stress_corrosion.creep_time_limit=1e30", "--out", out, timeout=300)
    assert res.returncode == 0, res.stderr
    assert "warning: the ratio refers to calibration.reference_ucs, calibrated with other parameters" in res.stderr
    s = json.loads((out / "summary.json").read_text())
    assert s["ucs_source"] == "calibration.reference_ucs" and s["ucs_pa"] == load_parameters().calibration.reference_ucs
    assert "specimen.width: calibrated 0.0317, run 0.003" in s["ucs_reference_differences"]
    c = pd.read_csv(out / "cracks.csv")
    assert list(c.columns[:3]) == ["bond", "creep_time_s", "phase"]
    assert set(c["phase"]) <= {"ramp", "creep"} and (c["phase"] == "creep").any()
    assert c["creep_time_s"].isna().tolist() == (c["phase"] == "ramp").tolist()
    assert (c.loc[c["phase"] == "creep", "creep_time_s"] >= 0).all()
    assert len(c) == s["broken_total"] and s["broken_ramp"] == int((c["phase"] == "ramp").sum())


def test_row_outcomes_judge_a_row_by_its_finished_run_not_by_yade_batch(tmp_path):
    """yade-batch reports a row that printed "Yade: normal exit." as done whatever its status: the batch and the
    demo judge each row by the summary.json of the folder it recorded, else by the reason in its log."""
    from grainfrac_yade.runs.batchrun import ROW_RECORDS, row_outcomes
    from grainfrac_yade.runs.runio import write_json
    logs = tmp_path / "logs"
    (logs / ROW_RECORDS).mkdir(parents=True)
    done, broken = tmp_path / "done", tmp_path / "broken"
    done.mkdir()
    broken.mkdir()
    write_json(done / "summary.json", {"ucs_pa": 2e8})
    write_json(broken / "summary.json", {"ucs_pa": None, "failed_before_test": True, "end_reason": "broke apart"})
    for line, folder in ((3, done), (4, broken)):
        write_json(logs / ROW_RECORDS / f"{line}.json", {"folder": str(folder)})
    (logs / "5.log").write_text("Using python\nerror: batch table t:5: unknown column 'x'; fix: ...\nYade: normal exit.\n")
    (logs / "6.log").write_text("Traceback (most recent call last):\n  File x\nIndexError: list index out of range\n")
    got = {o.line: o for o in row_outcomes(tmp_path / "t.table", logs, [3, 4, 5, 6, 7])}
    assert [got[n].ok for n in (3, 4, 5, 6, 7)] == [True, False, False, False, False]
    assert got[4].text.startswith("broke apart")
    assert got[5].text.startswith("error: batch table t:5: unknown column")
    assert got[6].text.startswith("IndexError: list index out of range")
    assert got[7].text.startswith("the row did not run (no log)")
