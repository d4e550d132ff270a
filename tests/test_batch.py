"""yade-batch tables: one run folder per row; a rerun skips finished rows with the same parameters and
stops on changed ones; a bad row is one line. One YADE process at a time (jobs = 1)."""
import json

import pytest

from conftest import ROOT, needs_yade
from grainfrac_yade.runs.batchrun import run_batch, write_table

pytestmark = [needs_yade, pytest.mark.yade]

#: 3 x 6 mm specimens (a creep run takes about 3 s): ratio 0.8 of 300 MPa fails after one event.
ROW = {"specimen.width": 3e-3, "specimen.height": 6e-3, "ratio": 0.8, "ucs": 300e6,
       "stress_corrosion.creep_time_limit": 1e30}


def test_two_row_table_gives_two_run_folders(tmp_path):
    rows = [dict(ROW, seed=s, out=str(tmp_path / f"seed{s}")) for s in (1, 2)]
    table = write_table(tmp_path / "two.table", rows)
    seen = []
    run_batch(table, ROOT / "yade_scripts" / "creep.py", 1, tmp_path / "logs", watch=[r["out"] for r in rows],
              progress=seen.append, repo=ROOT)
    assert sorted(p.name for p in seen) == ["seed1", "seed2"]
    for r in rows:
        s = json.loads((tmp_path / r["out"] / "summary.json").read_text())
        assert s["seed"] == r["seed"] and s["driving_stress_ratio"] == pytest.approx(0.8)
        assert s["params"]["specimen"]["width"] == pytest.approx(3e-3)
    stamp = (tmp_path / "seed1" / "summary.json").stat().st_mtime_ns
    run_batch(table, ROOT / "yade_scripts" / "creep.py", 1, tmp_path / "logs2", repo=ROOT)
    assert (tmp_path / "seed1" / "summary.json").stat().st_mtime_ns == stamp   # finished rows are skipped
    assert "already finished, skipped" in "".join(p.read_text() for p in (tmp_path / "logs2").glob("*.log"))


def _log_lines(folder):
    log = "".join(p.read_text() for p in sorted(folder.glob("*.log")))
    assert "Traceback" not in log
    return log, [line for line in log.splitlines() if line.startswith("error:")]


#: one row of ``ROW`` (seed 1) without the creep time limit.
TINY_ROW = {k: v for k, v in ROW.items() if k != "stress_corrosion.creep_time_limit"} | {"seed": 1}


@pytest.mark.slow   # about 16 s: the default suite stays under about 10 min
def test_a_rerun_after_a_parameter_edit_stops_or_runs_into_a_new_folder(tmp_path):
    out = tmp_path / "row"
    script = ROOT / "yade_scripts" / "creep.py"
    run_batch(write_table(tmp_path / "a.table", [dict(TINY_ROW, out=str(out))]), script, 1, tmp_path / "l1", repo=ROOT)
    summary = (out / "summary.json").read_text()
    edited = dict(TINY_ROW, out=str(out), **{"stress_corrosion.beta1": 2e-3})
    run_batch(write_table(tmp_path / "b.table", [edited]), script, 1, tmp_path / "l2", repo=ROOT)
    _, errors = _log_lines(tmp_path / "l2")
    assert errors == [f"error: {out}: holds a finished run with other parameters (stress_corrosion.beta1: stored "
                      "0.001, now 0.002); fix: give the row another out or study, remove the folder, or add a column "
                      "on_change with 'new_folder' to run it into a new folder"]
    assert (out / "summary.json").read_text() == summary          # the stale result was neither kept silently
    run_batch(write_table(tmp_path / "c.table", [dict(edited, on_change="new_folder")]), script, 1, tmp_path / "l3",
              repo=ROOT)                                          # ... nor overwritten: a new folder
    (new,) = [p for p in tmp_path.glob("row_*") if p.is_dir()]
    s = json.loads((new / "summary.json").read_text())
    assert s["params"]["stress_corrosion"]["beta1"] == 2e-3 and (out / "summary.json").read_text() == summary
    run_batch(write_table(tmp_path / "d.table", [dict(edited, on_change="new_folder")]), script, 1, tmp_path / "l4",
              repo=ROOT)
    log, errors = _log_lines(tmp_path / "l4")
    assert not errors and f"creep row already finished, skipped: {new}" in log


def test_a_misspelt_column_is_one_line_naming_the_nearest_key(tmp_path):
    row = dict(TINY_ROW, out=str(tmp_path / "bad"), **{"stress_corosion.beta1": 2e-3})
    table = write_table(tmp_path / "typo.table", [row])
    run_batch(table, ROOT / "yade_scripts" / "creep.py", 1, tmp_path / "logs", repo=ROOT)
    _, errors = _log_lines(tmp_path / "logs")
    assert errors == [f"error: batch table {table}:2: unknown column 'stress_corosion.beta1'; fix: did you mean "
                      "stress_corrosion.beta1?"]
    assert not (tmp_path / "bad").exists()


def test_a_row_without_load_is_one_clear_line(tmp_path):
    row = {k: v for k, v in ROW.items() if k != "ratio"}
    table = write_table(tmp_path / "bad.table", [dict(row, seed=1, out=str(tmp_path / "bad"))])
    run_batch(table, ROOT / "yade_scripts" / "creep.py", 1, tmp_path / "logs", repo=ROOT)
    log = "".join(p.read_text() for p in (tmp_path / "logs").glob("*.log"))
    errors = [line for line in log.splitlines() if line.startswith("error:")]
    assert len(errors) == 1 and "ratio" in errors[0] and "fix:" in errors[0]
    assert "Traceback" not in log
    assert not (tmp_path / "bad" / "run.json").exists()


def test_only_an_explicit_description_column_names_the_folder(tmp_path, monkeypatch):
    from grainfrac_yade.engines.yade.batch import explicit_description_column
    named = tmp_path / "named.table"
    named.write_text("# a comment\ndescription ratio seed\n'slow_ramp' 0.7 1\n")
    plain = tmp_path / "plain.table"
    plain.write_text("ratio seed\n0.7 1\n")
    monkeypatch.setenv("YADE_BATCH", f"{named}:3")
    assert explicit_description_column()
    monkeypatch.setenv("YADE_BATCH", f"{plain}:2")
    assert not explicit_description_column()
    monkeypatch.delenv("YADE_BATCH")
    assert not explicit_description_column()
