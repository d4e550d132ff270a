"""Studies on SLURM: ``submit`` (one job-array task per table row), ``status``, the task wrapper, and
``analyze`` of a study that is still running.

The first tests need neither SLURM nor YADE (tables, scripts, row states from files, the task wrapper
with a stand-in command, the analysis of a half-done study).  The last two bring up a real
single-node SLURM (munged, slurmctld, slurmd in a temporary folder; :mod:`slurm_cluster`) and run
``params/slurm_tiny.table`` (3 x 6 mm specimens, 6-8 s a row): they skip, saying why, where SLURM
cannot start (packages missing, not root).  The node announces 2 CPUs; tasks take 1 CPU and the
array runs one task at a time (``--max-running 1``), so only one YADE process of the tests runs.
"""
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from conftest import ROOT, needs_yade
from grainfrac_yade.errors import GrainfracError
from grainfrac_yade.runs.slurm import (FAILED, SubmitOptions, compress_rows, frozen_table_text, read_batch_table,
                                  render_sbatch)
from grainfrac_yade.runs.slurm_states import QueueView, row_states

PYTHON = "/usr/bin/python3"
TINY = ROOT / "params" / "slurm_tiny.table"
#: Run folders of the tiny table's rows, as a local yade-batch row names them.
TINY_FOLDERS = [f"ratio=0.8_ucs=300000000.0_width=0.003_height=0.006_seed{s}" for s in (1, 2, 3)]
#: Longest wait for a study's rows [s] (a row takes 6-8 s on this machine; generous for a loaded one).
WAIT_S = 300


def cli(*args, cwd=ROOT, env=None):
    env = dict(os.environ if env is None else env)
    env["PYTHONPATH"] = str(ROOT) + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    return subprocess.run([PYTHON, "-m", "grainfrac_yade", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, env=env, timeout=600)


def one_error_line(res):
    assert res.returncode == 2, res.stdout + res.stderr
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: ") and "fix:" in lines[0], res.stderr
    assert "Traceback" not in res.stderr
    return lines[0]


# ---------------------------------------------------------------- tables and scripts (no SLURM)

def test_table_reader_reads_every_shipped_table_as_yade_does():
    from grainfrac_yade.engines.yade import load_yade
    try:
        load_yade()
        from yade.utils import TableParamReader
    except Exception:
        TableParamReader = None
    for path in sorted((ROOT / "params").glob("*.table")):
        table = read_batch_table(path)
        assert [r.row for r in table.rows] == list(range(1, len(table.rows) + 1))
        if TableParamReader is not None:
            yade_rows = TableParamReader(str(path)).paramDict()
            assert sorted(yade_rows) == [r.line for r in table.rows], path
            for r in table.rows:
                assert {k: v for k, v in yade_rows[r.line].items() if k in r.cells} == r.cells


def test_repeats_comments_and_line_numbers(tmp_path):
    path = tmp_path / "t.table"
    path.write_text("# a study\n\nratio seed study   # columns\n0.7 1 'x'\n= 2 =  # same ratio\n\n0.8 = 'y'\n")
    table = read_batch_table(path)
    assert table.columns == ("ratio", "seed", "study") and table.header_line == 3
    assert [(r.row, r.line, r.cells) for r in table.rows] == [
        (1, 4, {"ratio": "0.7", "seed": "1", "study": "'x'"}), (2, 5, {"ratio": "0.7", "seed": "2", "study": "'x'"}),
        (3, 7, {"ratio": "0.8", "seed": "2", "study": "'y'"})]
    frozen = tmp_path / "f.table"
    frozen.write_text(frozen_table_text(table, "mine"))
    again = read_batch_table(frozen)
    assert [r.line for r in again.rows] == [4, 5, 7]                   # YADE_BATCH lines stay the source's
    assert [r.cells["study"] for r in again.rows] == ["'mine'"] * 3
    assert [r.cells["seed"] for r in again.rows] == ["1", "2", "2"]
    plain = tmp_path / "plain.table"
    plain.write_text("ratio seed\n0.7 1\n")
    assert read_batch_table(plain).columns == ("ratio", "seed")
    plain.write_text(frozen_table_text(read_batch_table(plain), "s"))
    assert read_batch_table(plain).rows[0].cells == {"ratio": "0.7", "seed": "1", "study": "'s'"}


@pytest.mark.parametrize("text, message", [
    ("", "no column names"), ("# only a comment\n", "no column names"), ("ratio seed\n", "no rows"),
    ("ratio seed\n0.7\n", ":2: 1 cells but 2 columns"), ("ratio seed\n= 1\n", "'=' in the first row"),
    ("seed seed\n1 2\n", "named twice")])
def test_a_malformed_table_is_one_line(tmp_path, text, message):
    path = tmp_path / "bad.table"
    path.write_text(text)
    with pytest.raises(GrainfracError, match=message):
        read_batch_table(path)


def test_options_are_validated():
    SubmitOptions(study="a_b-1.2", partition="compute,debug", time="1-12:00:00", cpus_per_task=2, max_running=3)
    for kwargs, message in ((dict(study="../x"), "--study"), (dict(study="a/b"), "--study"),
                            (dict(study="s", time="2h"), "--time"), (dict(study="s", partition="a b"), "--partition"),
                            (dict(study="s", cpus_per_task=0), "--cpus-per-task"),
                            (dict(study="s", max_running=0), "--max-running")):
        with pytest.raises(GrainfracError, match=message):
            SubmitOptions(**kwargs)
    assert compress_rows([5, 1, 2, 3, 7, 8]) == "1-3,5,7-8"


def test_the_sbatch_script_runs_row_k_as_a_local_batch_row(tmp_path):
    table = read_batch_table(TINY)
    opts = SubmitOptions(study="tiny", partition="debug", time="10:00", cpus_per_task=1, max_running=1)
    text = render_sbatch(study_dir=Path("results/tiny"), options=opts, rows=table.rows[1:], all_rows=table.rows,
                         frozen_table=tmp_path / "results/tiny/slurm/tiny.table", script=ROOT / "yade_scripts/creep.py",
                         command="creep", workdir=tmp_path, repo=ROOT, source_table="params/slurm_tiny.table",
                         submission=2)
    for line in ("#SBATCH --array=2-3%1", "#SBATCH --cpus-per-task=1", "#SBATCH --time=10:00",
                 "#SBATCH --partition=debug", f"#SBATCH --chdir={tmp_path}",
                 f"#SBATCH --output={tmp_path}/results/tiny/slurm/logs/row%a_job%A.log",
                 "LINES=([1]=8 [2]=9 [3]=10)   # table line of each row",
                 'export YADE_BATCH="results/tiny/slurm/tiny.table:${LINES[$SLURM_ARRAY_TASK_ID]}"',
                 "export OMP_NUM_THREADS=1"):
        assert line in text.splitlines() or any(ln.startswith(line) for ln in text.splitlines()), line
    assert text.splitlines()[-1] == (f'exec {PYTHON} -m grainfrac_yade.runs.slurmtask results/tiny "$SLURM_ARRAY_TASK_ID" '
                                     f"creep -- yade -n -x {ROOT}/yade_scripts/creep.py")
    # the script is valid bash and maps task ids to table lines
    check = subprocess.run(["bash", "-n"], input=text, text=True, capture_output=True)
    assert check.returncode == 0, check.stderr


def test_dry_run_prints_the_script_and_writes_nothing(tmp_path):
    res = cli("submit", TINY, "--study", "dry", "--time", "5:00", "--dry-run", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "#SBATCH --array=1-3" in res.stdout and "#SBATCH --time=5:00" in res.stdout
    assert "3 row(s) 1 (line 8), 2 (line 9), 3 (line 10)" in res.stdout
    assert not (tmp_path / "results").exists()


def test_bad_input_is_one_line(tmp_path):
    assert "batch table not found" in one_error_line(cli("submit", tmp_path / "none.table", "--study", "x",
                                                         cwd=tmp_path))
    typo = tmp_path / "typo.table"
    typo.write_text("ratio ucs stress_corosion.beta1 seed\n0.8 300e6 2e-3 1\n")
    assert "unknown column 'stress_corosion.beta1'; fix: did you mean stress_corrosion.beta1?" in one_error_line(
        cli("submit", typo, "--study", "x", "--dry-run", cwd=tmp_path))
    assert "--time '3 hours'" in one_error_line(cli("submit", TINY, "--study", "x", "--time", "3 hours",
                                                    cwd=tmp_path))
    outside = tmp_path / "out.table"
    outside.write_text("ratio ucs seed out\n0.8 300e6 1 '/tmp/elsewhere'\n")
    assert "puts the run outside results/x" in one_error_line(cli("submit", outside, "--study", "x", cwd=tmp_path))
    no_sbatch = dict(os.environ, PATH=str(tmp_path))         # no sbatch on PATH
    assert one_error_line(cli("submit", TINY, "--study", "x", cwd=tmp_path, env=no_sbatch)).startswith(
        "error: sbatch not found on PATH; fix:")
    assert "study folder not found" in one_error_line(cli("status", tmp_path / "results" / "nothing", cwd=tmp_path))
    (tmp_path / "results" / "local").mkdir(parents=True)
    assert "no SLURM study record" in one_error_line(cli("status", "results/local", cwd=tmp_path))


# ---------------------------------------------------------------- row states from files (no SLURM)

def _record(tmp_path, rows=4, jobs=(("10", [1, 2, 3, 4]),)):
    study = tmp_path / "results" / "s"
    (study / "slurm" / "tasks").mkdir(parents=True)
    record = {"study": "s", "source_table": "t.table", "table": "results/s/slurm/s.table", "script": "creep.py",
              "command": "creep", "workdir": str(tmp_path),
              "rows": [{"row": k, "line": k + 1, "cells": {"ratio": "0.8", "seed": str(k)}} for k in range(1, rows + 1)],
              "submissions": [{"job_id": j, "rows": r} for j, r in jobs]}
    (study / "slurm" / "study.json").write_text(json.dumps(record))
    return study, record


def _task(study, row, job="10", **kw):
    (study / "slurm" / "tasks" / f"row{row}.json").write_text(json.dumps({"row": row, "array_job_id": job, **kw}))


def _folder(study, row, name, files=("run.json",)):
    d = study / name
    d.mkdir()
    for f in files:
        (d / f).write_text(json.dumps({"command": "creep", "seed": row, "error": f"boom {row}"}))
    (study / "slurm" / "tasks" / f"row{row}_folder.json").write_text(json.dumps({"folder": str(d)}))
    return d


def test_row_states_come_from_the_files_first_then_the_queue(tmp_path):
    study, record = _record(tmp_path, rows=6, jobs=(("10", [1, 2, 3, 4, 5, 6]),))
    _folder(study, 1, "r1", ("run.json", "summary.json"))
    _task(study, 1, state="finished")
    _folder(study, 2, "r2", ("run.json", FAILED))
    _task(study, 2, state="failed", error="boom 2")
    _task(study, 3, state="failed", error="batch table row x: unknown column")       # before any folder
    _folder(study, 4, "r4")
    _task(study, 4, state="running")
    queue = QueueView({("10", 4): ("RUNNING", "None"), ("10", 5): ("PENDING", "JobArrayTaskLimit")}, True, "squeue")
    states = {s.row: s for s in row_states(study, record, queue)}
    assert {k: s.state for k, s in states.items()} == {1: "finished", 2: "failed", 3: "failed", 4: "running",
                                                      5: "pending", 6: "failed"}
    assert states[2].detail == "boom 2" and "unknown column" in states[3].detail
    assert "JobArrayTaskLimit" in states[5].detail and "left the queue without starting" in states[6].detail
    assert states[1].job == "10_1" and states[1].folder == str(study / "r1")
    # the task of row 4 gone from the queue without recording its end: killed
    states = {s.row: s for s in row_states(study, record, QueueView({}, True, "squeue"))}
    assert states[4].state == "failed" and "without recording its end" in states[4].detail
    # without squeue: what the files say, unconfirmed
    states = {s.row: s for s in row_states(study, record, QueueView(note="squeue not found on PATH"))}
    assert states[4].state == "running" and "not confirmed" in states[4].detail
    assert states[5].state == "pending" and "not confirmed" in states[5].detail
    assert states[1].state == "finished" and states[2].state == "failed"
    # accounting says how a task without record ended
    acct = QueueView({("10", 6): ("CANCELLED", "0:15")}, True, "sacct")
    assert row_states(study, record, QueueView({}, True, "squeue"), acct)[5].detail.startswith("SLURM state CANCELLED")


def test_a_resubmitted_row_ignores_the_record_of_its_earlier_task(tmp_path):
    study, record = _record(tmp_path, rows=1, jobs=(("10", [1]), ("12", [1])))
    _folder(study, 1, "r1", ("run.json", FAILED))
    _task(study, 1, job="10", state="failed", error="boom 1")
    queue = QueueView({("12", 1): ("PENDING", "Priority")}, True, "squeue")
    (state,) = row_states(study, record, queue)
    assert state.state == "pending" and state.job == "12_1"


# ---------------------------------------------------------------- the task wrapper (no SLURM)

CHILD = """
import json, os, sys, time
from pathlib import Path
folder = Path(sys.argv[1])
Path(os.environ["GRAINFRAC_ROW_FOLDER_FILE"]).write_text(json.dumps({"folder": str(folder)}))
print("child started", flush=True)
if sys.argv[2] == "ok":
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "summary.json").write_text("{}")
elif sys.argv[2] == "error":
    print("error: results/x: holds something; fix: do this")
    sys.exit(2)
elif sys.argv[2] == "crash":
    raise ValueError("a bad value")
else:
    time.sleep(60)
"""


def _wrapper(tmp_path, row, mode, **popen):
    study = tmp_path / "results" / "s"
    child = tmp_path / "child.py"
    child.write_text(CHILD)
    env = dict(os.environ, PYTHONPATH=str(ROOT), SLURM_ARRAY_JOB_ID="77", SLURM_ARRAY_TASK_ID=str(row),
               SLURM_JOB_ID="78", YADE_BATCH=f"results/s/slurm/s.table:{row + 1}")
    cmd = [PYTHON, "-m", "grainfrac_yade.runs.slurmtask", str(study), str(row), "creep", "--", PYTHON, str(child),
           str(study / f"run{row}"), mode]
    return subprocess.Popen(cmd, cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            **popen), study


@pytest.mark.parametrize("mode, error", [("error", "results/x: holds something; fix: do this"),
                                         ("crash", "ValueError: a bad value")])
def test_a_row_ending_without_summary_writes_failed_json_with_its_error_line(tmp_path, mode, error):
    proc, study = _wrapper(tmp_path, 1, mode)
    out, _ = proc.communicate(timeout=60)
    assert proc.returncode != 0 and "child started" in out
    failed = json.loads((study / "run1" / FAILED).read_text())
    assert failed["error"] == error and failed["row"] == 1 and failed["table_line"] == 2 and failed["job"] == "77_1"
    assert failed["command"] == "creep" and failed["log"].endswith("logs/row1_job77.log")
    task = json.loads((study / "slurm" / "tasks" / "row1.json").read_text())
    assert task["state"] == "failed" and task["error"] == error and task["folder"] == str(study / "run1")
    assert not list(study.rglob("*.tmp"))                                   # written atomically
    # the row runs again and finishes: the stale failed.json goes
    proc, _ = _wrapper(tmp_path, 1, "ok")
    proc.communicate(timeout=60)
    assert proc.returncode == 0 and not (study / "run1" / FAILED).exists()
    assert json.loads((study / "slurm" / "tasks" / "row1.json").read_text())["state"] == "finished"


def test_sigterm_marks_the_row_failed_and_ends_the_yade_process(tmp_path):
    proc, study = _wrapper(tmp_path, 2, "sleep", start_new_session=True)
    assert proc.stdout.readline().strip() == "child started"
    os.kill(proc.pid, signal.SIGTERM)                       # the wrapper only: it forwards SIGTERM
    t0 = time.time()
    proc.communicate(timeout=30)
    assert time.time() - t0 < 10
    failed = json.loads((study / "run2" / FAILED).read_text())
    assert failed["signal"] == "SIGTERM" and failed["error"].startswith("terminated by SIGTERM (scancel")
    assert json.loads((study / "slurm" / "tasks" / "row2.json").read_text())["state"] == "failed"


def test_a_batch_row_records_its_folder_for_the_wrapper(tmp_path, monkeypatch):
    from grainfrac_yade.runs import slurm
    from grainfrac_yade.engines.yade import batch
    assert batch.ROW_FOLDER_ENV == slurm.ROW_FOLDER_ENV
    target = tmp_path / "tasks" / "row1_folder.json"
    monkeypatch.setenv(slurm.ROW_FOLDER_ENV, str(target))
    monkeypatch.chdir(tmp_path)
    folder, done = batch.row_folder("results/s/run", None, {}, {})
    assert not done and json.loads(target.read_text()) == {"folder": str(tmp_path / "results/s/run")}


# ---------------------------------------------------------------- analysis of a half-done study (no SLURM)

def test_analyze_lists_unfinished_failed_and_pending_rows_of_a_running_study(tmp_path):
    sys.path.insert(0, str(ROOT / "tests"))
    from test_analysis import write_run
    study, record = _record(tmp_path, rows=5, jobs=(("10", [1, 2, 3, 4, 5]),))
    for row, ratio in ((1, 0.7), (2, 0.8)):
        d = write_run(study, f"r{row}", ratio, row, lifetime=1e6 / row)
        (study / "slurm" / "tasks" / f"row{row}_folder.json").write_text(json.dumps({"folder": str(d)}))
    d = write_run(study, "r3", 0.9, 3, lifetime=1e5, finished=False)                       # running
    (study / "slurm" / "tasks" / "row3_folder.json").write_text(json.dumps({"folder": str(d)}))
    (d / FAILED).write_text(json.dumps({"error": "terminated by SIGTERM", "command": "creep"}))   # ... or failed
    _task(study, 4, state="failed", error="unknown column 'x'")                             # before its folder
    res = cli("analyze", study)                                                             # row 5: not started
    assert res.returncode == 0, res.stderr
    runs = pd.read_csv(study / "report" / "runs.csv")
    got = dict(zip(runs["run"], zip(runs["status"], runs["outcome"])))
    assert got == {"r1": ("finished", "failed"), "r2": ("finished", "failed"), "r3": ("failed", "run error"),
                   "slurm row 4 (table line 5)": ("failed", "run error"),
                   "slurm row 5 (table line 6)": ("pending", "unfinished")}
    problems = dict(zip(runs["run"], runs["problem"]))
    assert problems["r3"].startswith("run failed: terminated by SIGTERM")
    assert "unknown column 'x'" in problems["slurm row 4 (table line 5)"]
    assert "not started" in problems["slurm row 5 (table line 6)"]
    report = (study / "report" / "report.md").read_text()
    assert "2 failed" in report and "2 run error" in report and "1 unfinished" in report
    # nothing run yet: every row listed as unfinished, no error
    study2, _ = _record(tmp_path / "b", rows=3)
    res = cli("analyze", study2)
    assert res.returncode == 0, res.stderr
    assert list(pd.read_csv(study2 / "report" / "runs.csv")["outcome"]) == ["unfinished"] * 3


# ---------------------------------------------------------------- a real single-node SLURM

@pytest.fixture(scope="module")
def slurm(tmp_path_factory):
    from slurm_cluster import LocalSlurm, why_not
    why = why_not()
    if why:
        pytest.skip(why)
    cluster = LocalSlurm(tmp_path_factory.mktemp("slurm"))
    why = cluster.start()
    if why:
        pytest.skip(f"SLURM could not start: {why}")
    yield cluster
    cluster.stop()


def _status(cluster, study_dir):
    """What ``status --json`` prints, asked in this process (cheaper than a CLI call every second)."""
    from grainfrac_yade.commands.status import status_report
    old = os.environ.get("SLURM_CONF")
    os.environ["SLURM_CONF"] = str(cluster.conf)
    try:
        return json.loads(json.dumps(status_report(study_dir)))
    finally:
        if old is None:
            del os.environ["SLURM_CONF"]
        else:
            os.environ["SLURM_CONF"] = old


def _wait(work, cluster, study, done, what):
    t_end = time.time() + WAIT_S
    while time.time() < t_end:
        rep = _status(cluster, work / "results" / study)
        if done(rep):
            return rep
        time.sleep(1.0)
    logs = "\n".join(p.read_text()[-1500:] for p in sorted((work / "results" / study / "slurm" / "logs").glob("*")))
    pytest.fail(f"{what} not reached within {WAIT_S} s: {json.dumps(rep['rows'])}\n{logs}")


def _finished(rep):
    return rep["counts"]["finished"] == len(rep["rows"])


def _settled(rep):
    return rep["counts"]["running"] == 0 and rep["counts"]["pending"] == 0


@needs_yade
@pytest.mark.yade
def test_a_three_row_study_runs_through_slurm_as_local_batch_rows(slurm, tmp_path):
    work = tmp_path
    res = cli("submit", TINY, "--study", "tiny", "--cpus-per-task", "1", "--max-running", "1", cwd=work, env=slurm.env)
    assert res.returncode == 0, res.stderr
    study = work / "results" / "tiny"
    record = json.loads((study / "slurm" / "study.json").read_text())
    (sub,) = record["submissions"]
    assert sub["rows"] == [1, 2, 3] and f"submitted job {sub['job_id']}" in res.stdout
    assert "#SBATCH --array=1-3%1" in (study / "slurm" / "submit_1.sbatch").read_text()
    early = cli("analyze", study, cwd=work)                    # while the array runs: rows listed, no failure
    assert early.returncode == 0, early.stderr
    assert len(pd.read_csv(study / "report" / "runs.csv")) == 3
    rep = _wait(work, slurm, "tiny", _finished, "3 finished rows")
    assert sorted(Path(r["folder"]).name for r in rep["rows"]) == TINY_FOLDERS
    assert [r["job"] for r in rep["rows"]] == [f"{sub['job_id']}_{k}" for k in (1, 2, 3)]
    for name, seed in zip(TINY_FOLDERS, (1, 2, 3)):
        run = study / name
        for f in ("run.json", "params.json", "summary.json", "history.csv", "cracks.csv", "strain_time.png"):
            assert (run / f).is_file(), run / f
        assert not (run / FAILED).exists()
        s = json.loads((run / "summary.json").read_text())
        assert s["seed"] == seed and s["driving_stress_ratio"] == pytest.approx(0.8)
        assert s["params"]["specimen"]["width"] == pytest.approx(3e-3)
    task = json.loads((study / "slurm" / "tasks" / "row2.json").read_text())
    assert task["state"] == "finished" and task["node"] == slurm.host and task["table_line"] == 9
    assert "creep 240.0 MPa" in (study / "slurm" / "logs" / f"row2_job{sub['job_id']}.log").read_text()
    res = cli("analyze", study, cwd=work)
    assert res.returncode == 0, res.stderr
    runs = pd.read_csv(study / "report" / "runs.csv")
    assert sorted(runs["run"]) == TINY_FOLDERS and set(runs["outcome"]) == {"failed"}
    res = cli("submit", TINY, "--study", "tiny", cwd=work, env=slurm.env)
    assert res.returncode == 0 and "nothing to submit: 3 finished" in res.stdout


@pytest.mark.slow   # about 21 s: the default suite stays under about 10 min
@needs_yade
@pytest.mark.yade
def test_a_cancelled_task_is_the_only_row_submit_runs_again(slurm, tmp_path):
    work = tmp_path
    res = cli("submit", TINY, "--study", "cancel", "--max-running", "1", cwd=work, env=slurm.env)
    assert res.returncode == 0, res.stderr
    study = work / "results" / "cancel"
    job = json.loads((study / "slurm" / "study.json").read_text())["submissions"][0]["job_id"]
    folder_file = study / "slurm" / "tasks" / "row1_folder.json"
    t_end = time.time() + WAIT_S
    while not folder_file.exists() and time.time() < t_end:   # row 1 has chosen its run folder: cancel it
        time.sleep(0.05)
    subprocess.run(["scancel", f"{job}_1"], env=slurm.env, check=True)
    rep = _wait(work, slurm, "cancel", _settled, "rows 2 and 3 ended")
    states = {r["row"]: r for r in rep["rows"]}
    assert [states[k]["state"] for k in (1, 2, 3)] == ["failed", "finished", "finished"]
    assert "terminated by SIGTERM" in states[1]["detail"]
    run1 = study / TINY_FOLDERS[0]
    failed = json.loads((run1 / FAILED).read_text())
    assert failed["signal"] == "SIGTERM" and failed["job"] == f"{job}_1" and not (run1 / "summary.json").exists()
    early = cli("analyze", study, cwd=work)
    assert early.returncode == 0, early.stderr
    runs = pd.read_csv(study / "report" / "runs.csv").set_index("run")
    assert runs.loc[TINY_FOLDERS[0], "outcome"] == "run error" and runs.loc[TINY_FOLDERS[0], "seed"] == 1
    assert list(runs.loc[TINY_FOLDERS[1:], "outcome"]) == ["failed", "failed"]
    stamps = {name: (study / name / "summary.json").stat().st_mtime_ns for name in TINY_FOLDERS[1:]}
    res = cli("submit", TINY, "--study", "cancel", "--max-running", "1", cwd=work, env=slurm.env)
    assert res.returncode == 0, res.stderr
    assert "2 finished, 0 running, 0 pending; submitting the other 1 row(s)" in res.stdout
    subs = json.loads((study / "slurm" / "study.json").read_text())["submissions"]
    assert [s["rows"] for s in subs] == [[1, 2, 3], [1]]
    assert "#SBATCH --array=1%1" in (study / "slurm" / "submit_2.sbatch").read_text()
    rep = _wait(work, slurm, "cancel", _finished, "row 1 finished again")
    assert {r["row"]: r["job"] for r in rep["rows"]} == {1: f"{subs[1]['job_id']}_1", 2: f"{job}_2", 3: f"{job}_3"}
    assert not (run1 / FAILED).exists() and (run1 / "summary.json").exists()
    assert {name: (study / name / "summary.json").stat().st_mtime_ns for name in TINY_FOLDERS[1:]} == stamps
