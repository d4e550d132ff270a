"""calibrate-beta1: the factor is the geometric-mean lifetime at the paper's load over the paper's."""
import json
import subprocess
import sys

import pytest

from conftest import ROOT
from grainfrac_yade.analysis.labdata import paper_reference
from grainfrac_yade.params import load_parameters


def _run(folder, seed, stress, lifetime, clock="event", beta1=1e-3, n_events=10):
    folder.mkdir(parents=True)
    (folder / "run.json").write_text(json.dumps({"command": "creep", "seed": seed}))
    (folder / "params.json").write_text(json.dumps({"stress_corrosion": {"beta1": beta1, "clock": clock,
                                                                         "mode": "strength"}}))
    (folder / "summary.json").write_text(json.dumps({
        "lifetime_s": lifetime, "failed": True, "failed_on_loading": False, "stress_pa": stress,
        "clock": clock, "mode": "strength", "n_events": n_events, "seed": seed}))


def test_factor_is_the_geometric_mean_over_the_paper_lifetime(tmp_path):
    ref = paper_reference()
    study = tmp_path / "study"
    _run(study / "a", 1, ref.stress_pa, 1e7)
    _run(study / "b", 2, ref.stress_pa, 4e7)
    _run(study / "c", 3, ref.stress_pa, 1e3, clock="paper")     # other clock: not used
    _run(study / "d", 1, 0.8 * ref.stress_pa, 1e3)              # other load: not used
    _run(study / "e", 4, ref.stress_pa, 0.0, n_events=0)       # ran away at creep time 0: failed at load, not used
    out = tmp_path / "cal.toml"
    res = subprocess.run([sys.executable, "-m", "grainfrac_yade", "calibrate-beta1", str(study), "--out", str(out)],
                         capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 0, res.stderr
    expected = 1e-3 * 2e7 / ref.lifetime_s          # geometric mean of 1e7 and 4e7 is 2e7
    assert load_parameters(extra_files=[out]).stress_corrosion.beta1 == pytest.approx(expected, rel=1e-6)
    assert load_parameters(extra_files=[out]).stress_corrosion.beta2 == load_parameters().stress_corrosion.beta2


def test_one_seed_is_not_enough(tmp_path):
    ref = paper_reference()
    _run(tmp_path / "s" / "a", 1, ref.stress_pa, 1e7)
    res = subprocess.run([sys.executable, "-m", "grainfrac_yade", "calibrate-beta1", str(tmp_path / "s"),
                          "--out", str(tmp_path / "x.toml")], capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1 and "fix:" in res.stderr
    assert not (tmp_path / "x.toml").exists()
