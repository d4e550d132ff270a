"""Reference creep runs of the default law (paper Eq. 7, strength degraded, rigid cells), stored per
machine fingerprint in tests/data/reference/<set>/ and compared bit for bit by
tests/test_reference_creep.py on a machine of the same fingerprint (tests/platform_fingerprint.py).

The set ``intel_xeon`` was made at commit 7e91240 (before the degradation laws became the package
``grainfrac_yade.law``); ``amd_epyc_avx512_icl`` at commit 8fd3e33, whose default model is the same
(the intel_xeon set passed its exact test there, on the Intel machine).  On a new machine, at a
commit known to keep the default model, ``/usr/bin/python3 tests/reference_creep.py write`` adds
this machine's set (the creep runs and the reproducible UCS run); ``check`` recomputes and compares.
One thread (OMP_NUM_THREADS=1), one run at a time.
"""
import os
import sys
from pathlib import Path

os.environ["OMP_NUM_THREADS"] = "1"
ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))
from platform_fingerprint import matching_set, set_name, this_platform, write_platform  # noqa: E402

#: name -> (seed, width [m], height [m], driving-stress ratio of 300 MPa, extra overrides)
RUNS = {
    "event_s1": (1, 4e-3, 8e-3, 0.5, []),
    "event_s2": (2, 4e-3, 8e-3, 0.5, []),
    # the paper clock records every 100 law applications (recording reads the scene, changes nothing)
    "paper_tiny_s1": (1, 3e-3, 6e-3, 0.8, ["stress_corrosion.clock=paper", "creep.record_period=100"]),
}
UCS = 300e6
#: summary.json keys compared (everything a run computes; not wall time)
SUMMARY_KEYS = ("lifetime_s", "failed", "failure_reason", "n_events", "broken_ramp", "broken_creep", "broken_total",
                "macrocracks", "n_bonds", "steps", "creep_time_end_s", "primary_end_s", "tertiary_start_s",
                "shear_stress_p99_pa", "shear_stress_max_pa", "shear_utilisation_max")
#: history.csv columns that differ between identical runs
WALL = ["wall_s"]


#: The stored runs ended by the failure "no equilibrium within creep.max_relaxation_steps" (the
#: collapse criterion came later): they are rerun with it off, and compared with it on apart.
WITHOUT_COLLAPSE = ["creep.collapse_strain_increment=0"]


def run(name, out, extra=WITHOUT_COLLAPSE):
    """Run reference ``name`` into folder ``out`` (``extra``: overrides after the reference's own);
    (summary dict, history frame, cracks frame)."""
    import json

    import pandas as pd

    sys.path.insert(0, str(ROOT))
    from grainfrac_yade.protocols.creep_output import run_creep_to_folder
    from grainfrac_yade.params import load_parameters
    seed, width, height, ratio, _ = RUNS[name]
    p = load_parameters(overrides=[("specimen.width", width), ("specimen.height", height),
                                   "stress_corrosion.creep_time_limit=1e30", "numerics.checkpoint_interval=0",
                                   *RUNS[name][4], *extra])
    run_creep_to_folder(p, seed, out, ratio * UCS, ratio, UCS, overwrite=True)
    out = Path(out)
    summary = json.loads((out / "summary.json").read_text())
    history = pd.read_csv(out / "history.csv", float_precision="round_trip").drop(columns=WALL)
    cracks = pd.read_csv(out / "cracks.csv", float_precision="round_trip")
    return {k: summary.get(k) for k in SUMMARY_KEYS}, history, stored_crack_format(cracks)


def stored_crack_format(cracks):
    """cracks.csv as the stored runs have it: the ramp's cracks at creep time -1.0 and no ``phase`` column
    (today's file: an empty creep time and phase "ramp"); every other value as written."""
    if "phase" not in cracks:
        return cracks
    out = cracks.copy()
    out["creep_time_s"] = out["creep_time_s"].where(out["phase"] != "ramp", -1.0)
    return out.drop(columns="phase")


def stored(name, folder):
    """(summary, history, cracks) of reference ``name`` in the stored set ``folder``, the stored files' older
    column and key names (``dem_steps``) read as today's (the stored data are not rewritten)."""
    import json

    import pandas as pd
    sys.path.insert(0, str(ROOT))
    from grainfrac_yade.runs.columns import history_as_today, summary_as_today
    summary = summary_as_today(json.loads((folder / f"reference_creep_{name}.json").read_text()))
    history = history_as_today(pd.read_csv(folder / f"reference_creep_{name}_history.csv",
                                           float_precision="round_trip"))
    cracks = pd.read_csv(folder / f"reference_creep_{name}_cracks.csv", float_precision="round_trip")
    return summary, history, cracks


def write(name, tmp, folder):
    import json
    summary, history, cracks = run(name, Path(tmp) / name)
    (folder / f"reference_creep_{name}.json").write_text(json.dumps(summary, indent=1) + "\n")
    history.to_csv(folder / f"reference_creep_{name}_history.csv", index=False)
    cracks.to_csv(folder / f"reference_creep_{name}_cracks.csv", index=False)
    print(name, summary["lifetime_s"], summary["n_events"], summary["steps"])


#: The reproducible UCS run of tests/test_reproducible.py (one thread).
UCS_COMMAND = ["ucs", "--width", "3e-3", "--height", "6e-3", "--seed", "1"]


def write_ucs(tmp, folder):
    import shutil
    import subprocess
    out = Path(tmp) / "ucs"
    subprocess.run([sys.executable, "-m", "grainfrac_yade", *UCS_COMMAND, "--out", str(out)], cwd=ROOT, check=True,
                   env={**os.environ, "OMP_NUM_THREADS": "1"})
    (folder / "reproducible_ucs").mkdir(exist_ok=True)
    for f in ("summary.json", "history.csv"):
        shutil.copy(out / f, folder / "reproducible_ucs" / f)


if __name__ == "__main__":
    import subprocess
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        if sys.argv[1] == "write":
            commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                                    cwd=ROOT).stdout.strip()
            folder = write_platform(matching_set() or ROOT / "tests" / "data" / "reference" / set_name(this_platform()),
                                    note=f"written by tests/reference_creep.py write at commit {commit}")
            for n in (sys.argv[2:] or RUNS):
                write(n, tmp, folder)
            if not sys.argv[2:]:
                write_ucs(tmp, folder)
        else:
            folder = matching_set()
            if folder is None:
                sys.exit("no stored set for this machine's fingerprint: `write` one at a commit known to be right")
            for n in (sys.argv[2:] or RUNS):
                a, b = run(n, Path(tmp) / n), stored(n, folder)
                print(n, a[0] == {k: b[0].get(k) for k in a[0]}, a[1].equals(b[1]), a[2].equals(b[2]))
