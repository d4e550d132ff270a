"""yade-batch tables: one run folder per row; a rerun skips finished rows; a bad row is one line."""
import json

import pytest

from conftest import ROOT, needs_yade
from grainfrac_yade.batchrun import run_batch, write_table

pytestmark = [needs_yade, pytest.mark.yade]

#: 6 x 12 mm specimens; ratios refer to 298 MPa, the 3-seed mean UCS of this size (tests/test_ucs.py).
ROW = {"specimen.width": 6e-3, "specimen.height": 12e-3, "ratio": 0.8, "ucs": 298e6,
       "stress_corrosion.creep_time_limit": 1e30}


def test_two_row_table_gives_two_run_folders(tmp_path):
    rows = [dict(ROW, seed=s, out=str(tmp_path / f"seed{s}")) for s in (1, 2)]
    table = write_table(tmp_path / "two.table", rows)
    seen = []
    run_batch(table, ROOT / "yade_scripts" / "creep.py", 2, tmp_path / "logs", watch=[r["out"] for r in rows],
              progress=seen.append, repo=ROOT)
    assert sorted(p.name for p in seen) == ["seed1", "seed2"]
    for r in rows:
        s = json.loads((tmp_path / r["out"] / "summary.json").read_text())
        assert s["seed"] == r["seed"] and s["driving_stress_ratio"] == pytest.approx(0.8)
        assert s["params"]["specimen"]["width"] == pytest.approx(6e-3)
    stamp = (tmp_path / "seed1" / "summary.json").stat().st_mtime_ns
    run_batch(table, ROOT / "yade_scripts" / "creep.py", 2, tmp_path / "logs2", repo=ROOT)
    assert (tmp_path / "seed1" / "summary.json").stat().st_mtime_ns == stamp   # finished rows are skipped
    assert "already finished, skipped" in "".join(p.read_text() for p in (tmp_path / "logs2").glob("*.log"))


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
    from grainfrac_yade.yade_adapter.batch import explicit_description_column
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
