"""The main job end to end on a tiny specimen (3 x 6 mm, the smallest the other YADE tests run; the physics at larger
sizes is tested in tests/test_ucs.py and tests/test_creep.py): UCS, creep through yade-batch, analysis report."""
import json
import subprocess
import sys

import pytest

from conftest import ROOT, needs_yade

pytestmark = [needs_yade, pytest.mark.yade]


def test_demo_runs_a_small_study_and_ends_with_the_report(tmp_path):
    out = tmp_path / "demo"
    res = subprocess.run([sys.executable, "-m", "grainfrac_yade", "demo", "--width", "3e-3", "--height", "6e-3",
                          "--ratios", "0.75,0.85", "--seeds", "1", "--jobs", "2", "--out", str(out)],
                         capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 0, res.stderr[-2000:]
    report = out / "creep" / "report" / "report.md"
    assert res.stdout.strip().splitlines()[-1].endswith(str(report))
    ucs = json.loads((out / "ucs" / "seed1" / "summary.json").read_text())["ucs_pa"]
    for ratio in (0.75, 0.85):
        s = json.loads((out / "creep" / f"ratio{ratio:g}_seed1" / "summary.json").read_text())
        assert s["ucs_pa"] == pytest.approx(ucs) and s["driving_stress_ratio"] == pytest.approx(ratio)
    assert (out / "creep" / "report" / "lifetime.png").stat().st_size > 10_000
    # a second run into the same folder is refused, and leaves the first one untouched
    again = subprocess.run([sys.executable, "-m", "grainfrac_yade", "demo", "--out", str(out)],
                           capture_output=True, text=True, cwd=ROOT)
    assert again.returncode == 2 and "already holds results" in again.stderr
    assert report.exists()
