"""A committed run's results are what today's code gives for the same row.

``tests/data/reference/<set>/reproducible_ucs/`` holds the summary.json and history.csv of
``python3 -m grainfrac_yade ucs --width 3e-3 --height 6e-3 --seed 1`` (one thread), one set per
machine fingerprint (``platform.json``: CPU model, numpy's SIMD target, glibc, Python, numpy and
the YADE package; tests/platform_fingerprint.py).  A fresh run of the same command must give:

* on a machine of a stored fingerprint: **exactly** every value of the history and every number of
  the summary but those derived by least-squares fits (``FIT_KEYS``: Young's modulus and Poisson's
  ratio, within ``FIT_REL`` relative, the rounding of a fit over the same values by another BLAS
  or SIMD path).  One thread and one seed make a YADE run deterministic on a machine (same seed
  twice: identical, tests/test_reliability.py), so any change is a change of the model; a change
  meant to move results must regenerate the sets (``/usr/bin/python3 tests/reference_creep.py
  write``);
* on another machine: Young's modulus within 1e-6 relative (the elastic part of the test is
  linear and smooth: rounding differences stay rounding differences; measured Intel Xeon against
  AMD EPYC with AVX-512: 1.7e-8, the fit window's ends moving with the peak), the UCS within 5 %
  and the broken-bond count within 20 %.  Past the first bond break the DEM is chaotic, so a
  different libm or SIMD width, changing the last bit of one force, moves the peak as a different
  seed would (two OpenMP threads moved a 6 x 12 mm peak by 5 %: params, ``DEFAULT_THREADS``).
"""
import json
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from conftest import needs_yade
# parameter keys added after the stored run was made, with the value the stored run had by construction
from grainfrac_yade.params import ADDED_KEYS as ADDED_PARAMS
# step columns and keys renamed after the stored run was made (read as today's; the stored files stay)
from grainfrac_yade.runs.columns import history_as_today, summary_as_today
from platform_fingerprint import FINGERPRINT_KEYS, matching_set, stored_sets
from reference_creep import UCS_COMMAND

ROOT = Path(__file__).resolve().parents[1]
#: Summary keys that depend on the machine's load or the code's identity, not on the model.
NOT_COMPARED = {"wall_s", "cpu_s", "code_version"}
#: Parameter sections compared between the stored and the fresh run.
MODEL_SECTIONS = ("specimen", "composition", "grains", "contacts", "calibration")
#: Summary keys added after the stored run was made, with the value a default run must give them.
ADDED_KEYS = {"confining_stress_pa": 0.0, "failed_before_test": False, "bonds_erased_by_sliding": 0, "engine": "yade",
              "steps_counted": "DEM steps"}
#: History columns not compared (wall time).
HISTORY_NOT_COMPARED = {"wall_s"}
#: Summary keys derived by least-squares fits, and their tolerance on a matching machine (module doc).
FIT_KEYS = ("young_pa", "poisson")
FIT_REL = 1e-12
#: Other software: tolerances and why (module doc).
CROSS_PLATFORM_YOUNG_REL = 1e-6
CROSS_PLATFORM_UCS_REL = 0.05
CROSS_PLATFORM_BROKEN_REL = 0.20


@pytest.fixture(scope="module")
def fresh_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("repro") / "ucs"
    cmd = [sys.executable, "-m", "grainfrac_yade", *UCS_COMMAND, "--out", str(out)]
    res = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, env={**_env(), "OMP_NUM_THREADS": "1"})
    assert res.returncode == 0, res.stderr[-2000:]
    return json.loads((out / "summary.json").read_text()), pd.read_csv(out / "history.csv")


def _env():
    import os
    return dict(os.environ)


def _numbers(summary: dict) -> dict:
    return {k: v for k, v in summary.items()
            if k not in NOT_COMPARED and isinstance(v, (int, float, bool, str)) and not isinstance(v, dict)}


@needs_yade
@pytest.mark.yade
def test_committed_ucs_run_is_reproduced(fresh_run):
    summary, history = fresh_run
    folder = matching_set()
    if folder is not None:
        stored = summary_as_today(json.loads((folder / "reproducible_ucs" / "summary.json").read_text()))
        stored_history = history_as_today(pd.read_csv(folder / "reproducible_ucs" / "history.csv"))
        exact = {k: v for k, v in _numbers(summary).items() if k not in FIT_KEYS}
        assert exact == {k: v for k, v in {**_numbers(stored), **ADDED_KEYS}.items() if k not in FIT_KEYS}
        for key in FIT_KEYS:
            assert summary[key] == pytest.approx(stored[key], rel=FIT_REL), key
        # the sections that define the specimen and its contacts (others gain keys as the code grows,
        # and `sources` holds the clone's absolute paths)
        for section in MODEL_SECTIONS:
            added = {k.split(".")[1]: v for k, v in ADDED_PARAMS.items() if k.split(".")[0] == section}
            assert summary["params"][section] == {**stored["params"][section], **added}, section
        cols = [c for c in stored_history.columns if c not in HISTORY_NOT_COMPARED]
        assert list(history.columns) == list(stored_history.columns)
        pd.testing.assert_frame_equal(history[cols], stored_history[cols], check_exact=True)
    else:
        for folder in stored_sets():
            stored = json.loads((folder / "reproducible_ucs" / "summary.json").read_text())
            assert summary["young_pa"] == pytest.approx(stored["young_pa"], rel=CROSS_PLATFORM_YOUNG_REL)
            assert summary["ucs_pa"] == pytest.approx(stored["ucs_pa"], rel=CROSS_PLATFORM_UCS_REL)
            assert summary["broken_total"] == pytest.approx(stored["broken_total"], rel=CROSS_PLATFORM_BROKEN_REL)


def test_every_stored_set_records_its_software():
    assert stored_sets()
    for folder in stored_sets():
        recorded = json.loads((folder / "platform.json").read_text())
        assert all(recorded.get(k) for k in FINGERPRINT_KEYS), folder
        assert (folder / "reproducible_ucs" / "summary.json").exists(), folder


def test_analysis_warns_when_a_study_mixes_code_versions():
    from grainfrac_yade.analysis.collect import code_version_note
    mixed = pd.DataFrame({"status": ["finished", "finished", "finished", "unfinished"],
                          "code_version": ["0.1.0+aaa", "0.1.0+aaa", "0.1.0+bbb-dirty", "0.1.0+ccc"]})
    note = code_version_note(mixed)
    assert "2 code versions" in note and "0.1.0+bbb-dirty: 1 run(s)" in note
    assert code_version_note(mixed.iloc[:2]) is None


def test_code_version_is_read_once_per_process(monkeypatch):
    """A run's summary names the code its process imported, even if the checkout changes meanwhile."""
    from grainfrac_yade.runs import runio
    first = runio.code_version()
    calls = []
    monkeypatch.setattr(runio.subprocess, "run", lambda *a, **k: calls.append(a) or (_ for _ in ()).throw(OSError))
    assert runio.code_version() == first and calls == []
