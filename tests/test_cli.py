"""The CLI as a user calls it (subprocess, with the python3 first on PATH)."""
import json
import shutil
import subprocess

from conftest import ROOT


def test_specimen_command_writes_json_and_png(tmp_path):
    out = tmp_path / "sp"
    python = shutil.which("python3")  # may be another interpreter: the package re-executes under Debian's
    res = subprocess.run([python, "-m", "grainfrac_yade", "specimen", "--width", "10e-3", "--height", "20e-3",
                          "--grain-size", "1e-3", "--seed", "7", "--out", str(out)],
                         capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 0, res.stderr
    assert "cells" in res.stdout and "bonds" in res.stdout
    data = json.loads((out / "specimen.json").read_text())
    for key in ("n_cells", "n_faces", "n_bonds", "mineral_area_fractions", "n_bonds_inter", "n_bonds_intra", "seed"):
        assert key in data
    assert data["seed"] == 7 and data["n_bonds_inter"] + data["n_bonds_intra"] == data["n_bonds"]
    assert set(data["mineral_area_fractions"]) == {"biotite", "k_feldspar", "quartz", "plagioclase"}
    png = (out / "specimen.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000
    run = json.loads((out / "run.json").read_text())
    assert run["seed"] == 7 and run["code_version"]
    # a second run into the same folder is refused, the first one is kept
    res2 = subprocess.run([python, "-m", "grainfrac_yade", "specimen", "--seed", "8", "--out", str(out)],
                          capture_output=True, text=True, cwd=ROOT)
    assert res2.returncode == 2 and "already holds a run" in res2.stderr
    assert json.loads((out / "specimen.json").read_text())["seed"] == 7
