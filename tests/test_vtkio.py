"""XML VTK output: files read back with VTK's XML reader, .pvd collections, rigid motion of cell polygons,
the series of tiny creep and UCS runs, and the crack-growth animation of a tiny creep run."""
import json
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pandas as pd
import pytest

from conftest import ROOT, needs_yade
from grainfrac_yade.errors import GrainfracError
from grainfrac_yade.vtkio import (BOND_STATE_NAMES, cluster_rigid_motion, read_pvd, read_vtp, rigid_motion,
                                  time_field, write_polygons, write_pvd, write_segments)

SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
TRIANGLE = np.array([[2.0, 0.0], [3.0, 0.0], [2.0, 1.0]])
#: A tiny creep run (3 x 6 mm, 23 cells, 50 bonds; a few seconds): 225 MPa fails it after 2 events.
TINY_CREEP = ["creep", "--width", "3e-3", "--height", "6e-3", "--seed", "1", "--ratio", "0.9", "--ucs", "250",
              "--clock", "event", "--set", "stress_corrosion.creep_time_limit=1e30"]
TINY_UCS = ["ucs", "--width", "3e-3", "--height", "6e-3", "--seed", "1"]


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "grainfrac_yade", *map(str, args)], capture_output=True, text=True,
                          cwd=ROOT, env={**os.environ, "OMP_NUM_THREADS": "1"})


# ------------------------------------------------------------------------------------------- core writer
def test_polygons_and_segments_read_back_by_vtk(tmp_path):
    cells = write_polygons(tmp_path / "c.vtp", [SQUARE, TRIANGLE],
                           {"mineral": np.array([0, 3]), "mineral_name": np.array(["quartz", "biotite"]),
                            "area_m2": np.array([1.0, 0.5])},
                           {**time_field(12.5, "creep_time", "s"), "mineral_names": ["a", "b", "c", "d"]})
    bonds = write_segments(tmp_path / "b.vtp", np.array([[[0, 0], [1, 1]], [[1, 0], [2, 0]], [[0, 1], [3, 0]]]),
                           {"state": np.array([0, 1, 2]), "strength_pa": np.array([1e6, 0.0, np.nan])})
    c = read_vtp(cells)
    assert c["cells"] == [[0, 1, 2, 3], [4, 5, 6]]
    np.testing.assert_array_equal(c["points"][4:, :2], TRIANGLE)   # exact: doubles written as doubles
    assert c["cell_data"]["mineral"].dtype == np.int32 and list(c["cell_data"]["mineral"]) == [0, 3]
    assert c["cell_data"]["mineral_name"] == ["quartz", "biotite"]
    assert list(c["cell_data"]["area_m2"]) == [1.0, 0.5]
    assert c["field_data"]["TimeValue"][0] == 12.5 and c["field_data"]["time_unit"] == ["s"]
    assert c["field_data"]["mineral_names"] == ["a", "b", "c", "d"]
    b = read_vtp(bonds)
    assert len(b["cells"]) == 3 and all(len(x) == 2 for x in b["cells"]) and len(b["points"]) == 6
    s = b["cell_data"]["strength_pa"]
    assert s[0] == 1e6 and s[1] == 0.0 and np.isnan(s[2])   # NaN kept ("not yet")


def test_a_wrong_array_length_is_refused(tmp_path):
    with pytest.raises(GrainfracError, match="one value per item"):
        write_polygons(tmp_path / "c.vtp", [SQUARE], {"mineral": np.array([0, 1])})
    assert not list(tmp_path.iterdir())


def test_pvd_lists_files_at_increasing_times(tmp_path):
    write_pvd(tmp_path / "s.pvd", [0.0, 1.0, 1.0, 5.0], ["a.vtp", "b.vtp", "c.vtp", "d.vtp"])
    root = ET.parse(tmp_path / "s.pvd").getroot()
    assert root.get("type") == "Collection"
    # of two files at one time the later state is listed
    assert [(t, p.name) for t, p in read_pvd(tmp_path / "s.pvd")] == [(0.0, "a.vtp"), (1.0, "c.vtp"), (5.0, "d.vtp")]
    with pytest.raises(GrainfracError, match="decrease"):
        write_pvd(tmp_path / "x.pvd", [1.0, 0.5], ["a.vtp", "b.vtp"])


def test_rigid_motion_rotates_about_the_centroid_then_translates():
    centroid = SQUARE.mean(axis=0)
    moved = rigid_motion([SQUARE], [centroid], np.array([[5.0, 5.0, 0.0]]), np.array([np.pi / 2]))[0]
    assert np.allclose(moved.mean(axis=0), [5.0, 5.0])
    assert np.allclose(moved[0], [5.5, 4.5])   # corner (0,0) -> (-0.5,-0.5) rotated 90 deg -> (0.5,-0.5)


def test_cluster_rigid_motion_recovers_a_rotation_and_translation():
    """Points of two groups moved rigidly: the motion of each group, and of its polygon."""
    rng = np.random.default_rng(3)
    ref = rng.uniform(0, 1, (9, 2))
    group = np.array([0] * 5 + [1] * 4)
    weights = rng.uniform(0.5, 2, 9)
    centroids = np.array([[0.5, 0.5], [0.2, 0.8]])
    angle, shift = np.array([0.3, -1.2]), np.array([[1.0, 2.0], [-3.0, 0.5]])
    cur = np.empty_like(ref)
    for g in (0, 1):
        c, s = np.cos(angle[g]), np.sin(angle[g])
        cur[group == g] = ref[group == g] @ np.array([[c, -s], [s, c]]).T + shift[g]
    pos, ang = cluster_rigid_motion(ref, cur, group, weights, centroids)
    np.testing.assert_allclose(ang, angle, atol=1e-12)
    moved = rigid_motion([SQUARE, TRIANGLE], centroids, pos, ang)
    for g, poly in enumerate((SQUARE, TRIANGLE)):   # the polygon moves as its points do
        c, s = np.cos(angle[g]), np.sin(angle[g])
        np.testing.assert_allclose(moved[g], poly @ np.array([[c, -s], [s, c]]).T + shift[g], atol=1e-12)
    # one point: translation only
    pos, ang = cluster_rigid_motion(ref[:1], ref[:1] + 1.0, np.array([0]), np.ones(1), ref[:1] + 0.1)
    assert ang[0] == 0.0 and np.allclose(pos, ref[:1] + 1.1)


def test_frame_times_linear_and_logarithmic():
    from grainfrac_yade.analysis.animation import LOG_TIME_DECADES, frame_times
    lin = frame_times(8.0, 5)
    assert list(lin) == [0.0, 2.0, 4.0, 6.0, 8.0]
    log = frame_times(1e7, 7, log_time=True)
    assert log[-1] == pytest.approx(1e7, rel=1e-15) and log[0] == pytest.approx(1e7 * 10.0 ** -LOG_TIME_DECADES,
                                                                                 rel=1e-15)
    ratios = log[1:] / log[:-1]
    np.testing.assert_allclose(ratios, ratios[0], rtol=1e-12)   # geometric spacing, rounding only
    assert list(frame_times(3.0, 1)) == [3.0]
    with pytest.raises(GrainfracError, match="log"):
        frame_times(0.0, 4, log_time=True)


# ------------------------------------------------------------------------------------------- runs (YADE)
def _check_series(folder, name, n_items, time_name):
    """Every file of series ``name`` reads back with ``n_items`` items at its .pvd timestep; returns them."""
    entries = read_pvd(folder / f"{name}.pvd")
    times = [t for t, _ in entries]
    assert len(entries) >= 2 and all(b > a for a, b in zip(times, times[1:]))
    out = []
    for t, path in entries:
        assert path.is_file() and path.parent == folder
        d = read_vtp(path)
        assert len(d["cells"]) == n_items
        assert d["field_data"]["TimeValue"][0] == t and d["field_data"]["time_name"] == [time_name]
        out.append((t, d))
    return out


@pytest.fixture(scope="module")
def creep_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("vtk") / "creep"
    res = _cli(*TINY_CREEP, "--vtk-times", "0", "--vtk-every", "1", "--vtk-fractions", "--out", out)
    assert res.returncode == 0, res.stderr
    return out


@needs_yade
@pytest.mark.yade
def test_creep_series_in_creep_time(creep_run):
    s = json.loads((creep_run / "summary.json").read_text())
    cracks = pd.read_csv(creep_run / "cracks.csv", float_precision="round_trip")
    hist = pd.read_csv(creep_run / "history.csv", float_precision="round_trip")
    n_cells = 23   # the 3 x 6 mm specimen of seed 1
    cells = _check_series(creep_run / "vtk", "cells", n_cells, "creep_time")
    bonds = _check_series(creep_run / "vtk", "bonds", s["n_bonds"], "creep_time")
    # every event wrote one (--vtk-every 1): one snapshot per distinct history time, the last at failure
    assert [t for t, _ in bonds] == sorted(set(hist["creep_time_s"]))
    assert bonds[-1][0] == s["lifetime_s"]
    c = cells[-1][1]
    assert set(c["cell_data"]) >= {"mineral", "mineral_name", "cell_id", "clump"}
    names = c["field_data"]["mineral_names"]
    assert [names[m] for m in c["cell_data"]["mineral"]] == c["cell_data"]["mineral_name"]
    for t, b in bonds:
        data = b["cell_data"]
        assert set(data) >= {"state", "state_name", "inter", "tensile_strength_pa", "cohesion_pa",
                             "tensile_strength_fraction", "normal_stress_pa", "shear_stress_pa", "break_time_s", "macro"}
        assert b["field_data"]["bond_state_names"] == list(BOND_STATE_NAMES)
        broken = data["state"] > 0
        assert int(broken.sum()) == int(((cracks["phase"] == "ramp") | (cracks["creep_time_s"] <= t)).sum())   # cracks.csv's count then
        assert np.all(data["tensile_strength_pa"][broken] == 0) and np.all(np.isnan(data["break_time_s"][~broken]))
        assert [BOND_STATE_NAMES[k] for k in data["state"]] == data["state_name"]
    last = bonds[-1][1]["cell_data"]
    assert int((last["state"] == 2).sum()) == int((cracks["mode"] == "shear").sum())
    np.testing.assert_array_equal(np.sort(np.flatnonzero(last["state"] > 0)), np.sort(cracks["bond"]))


@needs_yade
@pytest.mark.yade
def test_life_fraction_series_written_at_the_end(creep_run):
    s = json.loads((creep_run / "summary.json").read_text())
    cracks = pd.read_csv(creep_run / "cracks.csv", float_precision="round_trip")
    life = _check_series(creep_run / "vtk", "life_bonds", s["n_bonds"], "creep_time")
    assert [b["field_data"]["life_fraction"][0] for _, b in life] == [0.1, 0.5, 0.9, 1.0]
    for t, b in life:
        assert t == pytest.approx(b["field_data"]["life_fraction"][0] * s["lifetime_s"], rel=1e-15)
        assert int((b["cell_data"]["state"] > 0).sum()) == int(((cracks["phase"] == "ramp") | (cracks["creep_time_s"] <= t)).sum())


@needs_yade
@pytest.mark.yade
def test_ucs_series_in_axial_strain(tmp_path):
    out = tmp_path / "ucs"
    res = _cli(*TINY_UCS, "--vtk-every", "5", "--out", out)
    assert res.returncode == 0, res.stderr
    s = json.loads((out / "summary.json").read_text())
    hist = pd.read_csv(out / "history.csv", float_precision="round_trip")   # the doubles the run wrote
    bonds = _check_series(out / "vtk", "bonds", s["n_bonds"], "axial_strain")
    strain = hist["axial_strain"].to_numpy()
    expect = list(strain[4::5]) + ([strain[-1]] if len(strain) % 5 else [])   # every 5th row and the end
    assert [t for t, _ in bonds] == expect   # exact: the .pvd timestep is written with repr
    assert int((bonds[-1][1]["cell_data"]["state"] > 0).sum()) == s["broken_total"]


@needs_yade
@pytest.mark.yade
def test_animation_has_the_asked_frames(creep_run):
    from PIL import Image
    res = _cli("animate", creep_run, "--frames", "7", "--fps", "5", "--log-time")
    assert res.returncode == 0, res.stderr
    with Image.open(creep_run / "animation.gif") as gif:
        assert gif.n_frames == 7
        assert gif.info["duration"] == 200   # 1000 ms / 5 fps
    assert (creep_run / "animation_frame.png").stat().st_size > 10_000
    if shutil.which("ffprobe"):
        probe = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                                "stream=nb_read_frames", "-of", "csv=p=0", str(creep_run / "animation.mp4")],
                               capture_output=True, text=True)
        assert probe.stdout.strip() == "7"


def test_animate_refuses_a_folder_without_a_creep_run(tmp_path):
    res = _cli("animate", tmp_path)
    assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1
    assert "run.json" in res.stderr and "fix:" in res.stderr


def test_report_links_the_focus_runs_animation_when_it_has_one(tmp_path):
    from grainfrac_yade.analysis.study import animation_note
    run, report = tmp_path / "study" / "r0.7_seed1", tmp_path / "study" / "report"
    run.mkdir(parents=True)
    assert animation_note(run, report) is None   # no animation: no line (reports of such studies unchanged)
    (run / "animation.gif").write_bytes(b"GIF89a")
    assert animation_note(run, report).endswith("[animation.gif](../r0.7_seed1/animation.gif).")
    (run / "animation.mp4").write_bytes(b"")
    assert "[animation.mp4](../r0.7_seed1/animation.mp4)" in animation_note(run, report)


@needs_yade
@pytest.mark.yade
@pytest.mark.slow   # two 4 x 8 mm runs and a resume: about 30 s on a shared 2-core machine
def test_a_resumed_run_goes_on_with_its_vtk_series(tmp_path):
    """Killed mid-creep and resumed: the same .pvd entries and bond states as the uninterrupted run."""
    from test_resume import SMALL, _cli as creep_cli, _creep_args, _start_and_kill
    vtk = ("--vtk-every", "3", "--vtk-fractions", "0.5,1")
    ref = tmp_path / "uninterrupted"
    res = creep_cli(*_creep_args(SMALL, ref, *vtk))
    assert res.returncode == 0, res.stderr
    killed = tmp_path / "killed"
    _start_and_kill(SMALL, killed, lambda st: st["phase"] == "event" and st["loop"]["n_events"] >= 8, extra=vtk)
    res = creep_cli("--resume", killed)
    assert res.returncode == 0, res.stderr
    for name in ("cells", "bonds", "life_bonds"):
        a, b = (read_pvd(f / "vtk" / f"{name}.pvd") for f in (ref, killed))
        assert [(t, p.name) for t, p in a] == [(t, p.name) for t, p in b] and len(a) >= 2
    for (_, pa), (_, pb) in zip(read_pvd(ref / "vtk" / "bonds.pvd"), read_pvd(killed / "vtk" / "bonds.pvd")):
        da, db = read_vtp(pa)["cell_data"], read_vtp(pb)["cell_data"]
        for key in ("state", "break_time_s", "tensile_strength_pa", "normal_stress_pa"):
            np.testing.assert_array_equal(da[key], db[key])   # one thread: the resumed run is bit-identical
