"""Bad input a new user still met after the first round (a binary parameter file, a file value hidden by a flag,
an empty --out, a seed beyond 32 bits, a text that is no batch table, a cell of the wrong type, an out folder
that cannot be written, broken checkpoints): each ends in one line naming the file or flag, the key and the fix,
exit status 2, nothing written.  Pure unless marked yade."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import ROOT, needs_yade
from grainfrac_yade.cli import main
from grainfrac_yade.params.schema import PARAMS_DIR


def _one_line(capsys):
    """The single stderr line of a refused command."""
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


def _cli(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "grainfrac_yade", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, env=dict(os.environ, OMP_NUM_THREADS="1"))


# ------------------------------------------------------------------ parameter files and flags
@pytest.mark.parametrize("content, argv, message", [
    (b"\x89PNG\r\n\x1a\n\x00\xff\xfe", [],
     "error: {f}: (file): not a text file (byte 0 is not UTF-8); fix: give a TOML parameter file (UTF-8 text), "
     "e.g. " + str(PARAMS_DIR / "presets" / "fem.toml")),
    (b'[specimen]\nwidth = "ten"\n', ["--width", "3e-3"],
     "error: {f}: specimen.width: 'ten' is not a number; fix: give a number [m]"),
    (b'[specimen]\nwidth = "ten"\n', ["--set", "specimen.width=3e-3"],
     "error: {f}: specimen.width: 'ten' is not a number; fix: give a number [m]"),
    (b'[specimen]\nseed_typo = 1\n', [],
     "error: {f}: specimen.seed_typo: unknown key; fix: remove it or correct the spelling"),
])
def test_a_bad_params_file_is_one_line_whatever_overrides_it(tmp_path, capsys, content, argv, message):
    f = tmp_path / "p.toml"
    f.write_bytes(content)
    out = tmp_path / "out"
    assert main(["specimen", "--params", str(f), *argv, "--out", str(out)]) == 2
    assert _one_line(capsys).startswith(message.format(f=f))
    assert not out.exists()


def test_a_folder_given_as_params_file_is_one_line(tmp_path, capsys):
    assert main(["specimen", "--params", str(tmp_path), "--out", str(tmp_path / "out")]) == 2
    assert _one_line(capsys) == (f"error: {tmp_path}: (file): a folder, not a file; fix: give a TOML parameter file; "
                                 f"shipped files are in {PARAMS_DIR}")


@pytest.mark.parametrize("out", ["", "  "])
@pytest.mark.parametrize("command", [["specimen"], ["ucs"], ["creep", "--ratio", "0.5"]])
def test_an_empty_out_is_refused_not_taken_for_the_default(tmp_path, capsys, monkeypatch, command, out):
    monkeypatch.chdir(tmp_path)
    assert main([*command, "--out", out]) == 2
    assert _one_line(capsys) == (f"error: --out {out!r}: an empty folder name; fix: give a folder (e.g. --out "
                                 "results/run1), or leave --out out for the command's default folder")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("seed, ok", [("4294967295", True), ("4294967296", False),
                                      ("100000000000000000000000", False), ("-1", False)])
def test_a_seed_is_limited_to_the_32_bit_range(capsys, seed, ok):
    from grainfrac_yade.cli import build_parser
    argv = ["specimen", "--seed", seed]
    if ok:
        assert build_parser().parse_args(argv).seed == int(seed)
        return
    with pytest.raises(SystemExit) as exc:
        build_parser().parse_args(argv)
    assert exc.value.code == 2
    assert _one_line(capsys) == (f"error: python3 -m grainfrac_yade specimen: argument --seed: {int(seed)}: "
                                 "a seed is a whole number from 0 to 4294967295 (the range of a 32-bit seed; "
                                 "e.g. 1); fix: see python3 -m grainfrac_yade specimen --help")


@pytest.mark.parametrize("argv", [["demo", "--seeds", "1,4294967296"], ["calibrate-lifetimes", "s", "--lab", "x.csv",
                                                                       "--seeds", "1,4294967296"]])
def test_seed_lists_keep_the_same_32_bit_range(capsys, argv):
    from grainfrac_yade.cli import build_parser
    with pytest.raises(SystemExit) as exc:
        build_parser().parse_args(argv)
    assert exc.value.code == 2
    assert _one_line(capsys) == (f"error: python3 -m grainfrac_yade {argv[0]}: argument --seeds: 4294967296: a seed is "
                                 "a whole number from 0 to 4294967295 (the range of a 32-bit seed; e.g. 1,2); fix: "
                                 f"see python3 -m grainfrac_yade {argv[0]} --help")


# ------------------------------------------------------------------ batch tables
def test_a_file_that_is_no_table_is_one_line_saying_what_a_table_looks_like(capsys):
    assert main(["batch", str(ROOT / "README.md")]) == 2
    assert _one_line(capsys) == (
        f"error: {ROOT / 'README.md'}:3: not a batch table: its first line is not column names ('**time-dependent', "
        "'rock**'); fix: a batch table is a first line of column names (parameter paths such as specimen.width, "
        "ratio or stress, seed, study, out), then one line of values per run, e.g. `ratio seed` then `0.7 1`")


def test_a_table_with_many_bad_rows_lists_ten_and_counts_the_rest(tmp_path, capsys):
    table = tmp_path / "many.table"
    table.write_text("seed specimen.width\n" + "".join(f"{i} abc\n" for i in range(1, 31)))
    assert main(["batch", str(table)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[0] == f"error: {table}: 30 bad row(s), nothing run; fix each:"
    assert len(err) == 12 and err[-1] == "... and 20 more bad rows (fix the ones above first)"


@pytest.mark.parametrize("columns, cell, fix", [
    ("specimen.width seed", "ten 1", "column specimen.width takes a number [m], e.g. 0.0317"),
    ("seed", "ten", "column seed takes a whole number, e.g. 1"),
    ("resolution.grain_model seed", "fem 1", "column resolution.grain_model takes quoted text, one of 'rigid', 'fem'"),
    ("numerics.keep_intact_joints seed", "yes 1", "column numerics.keep_intact_joints takes True or False"),
    ("resolution.spheres_per_cell seed", "one 1", "column resolution.spheres_per_cell takes a whole number, e.g. 1"),
    ("study seed", "mine 1", "column study takes quoted text, e.g. 'default'"),
    ("ratio seed", "high 1", "column ratio takes a number, e.g. 0.0"),
])
def test_a_cell_of_the_wrong_type_names_the_type_its_column_takes(tmp_path, capsys, columns, cell, fix):
    table = tmp_path / "t.table"
    table.write_text(f"{columns}\n{cell}\n")
    assert main(["batch", str(table)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    bad = [c for c in cell.split() if not c[0].isdigit()][0]
    col = columns.split()[cell.split().index(bad)]
    assert err == [f"error: {table}: 1 bad row, nothing run: batch table {table}:2: column {col}: {bad!r} is not a "
                   f"number or a quoted text; fix: {fix}"]


def test_a_row_whose_out_cannot_be_made_is_refused_with_the_rows(tmp_path, capsys):
    a_file = tmp_path / "a_file"
    a_file.write_text("")
    table = tmp_path / "t.table"
    table.write_text(f"seed out\n1 '{tmp_path / 'fine'}'\n2 '{a_file / 'run'}'\n")
    assert main(["batch", str(table), "--log-dir", str(tmp_path / "logs")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"error: {table}: 1 bad row, nothing run: batch table {table}:3: out = '{a_file / 'run'}': "
                   f"{a_file} is a file, not a folder; fix: give the row an out below a folder"]
    assert not (tmp_path / "logs").exists() and not (tmp_path / "fine").exists()


def test_a_row_finished_before_the_batch_says_skipped_not_ok(tmp_path):
    from grainfrac_yade.runs.batchrun import ROW_RECORDS, ROW_SKIPPED, row_outcomes
    from grainfrac_yade.runs.runio import write_json
    logs = tmp_path / "logs"
    (logs / ROW_RECORDS).mkdir(parents=True)
    for line in (2, 3):
        folder = tmp_path / f"run{line}"
        folder.mkdir()
        write_json(folder / "summary.json", {"ucs_pa": 2e8})
        write_json(logs / ROW_RECORDS / f"{line}.json", {"folder": str(folder)})
    (logs / "2.log").write_text(f"Using python version: 3\nUCS {ROW_SKIPPED}: {tmp_path / 'run2'}\n")
    (logs / "3.log").write_text("Using python version: 3\n")
    got = {o.line: str(o) for o in row_outcomes(tmp_path / "t.table", logs, [2, 3])}
    assert got[2] == f"line 2: skipped (finished): finished -> {tmp_path / 'run2'}"
    assert got[3] == f"line 3: ok: finished -> {tmp_path / 'run3'}"


@pytest.mark.parametrize("module", ["creep", "ucs", "brazilian"])
def test_each_row_script_prints_the_skip_line_the_batch_looks_for(module):
    """The batch tells a skipped row by this phrase in its log: every row script must print it."""
    source = (ROOT / "grainfrac_yade" / "commands" / f"{module}.py").read_text()
    assert "{ROW_SKIPPED}: {out}" in source


# ------------------------------------------------------------------ the console holds the project's own lines
@needs_yade
@pytest.mark.yade
def test_yades_banner_stays_off_the_console(tmp_path):
    res = _cli("ucs", "--set", "specimen.width=3e-3", "--set", "specimen.height=6e-3", "--out", tmp_path / "u")
    assert res.returncode == 0, res.stderr
    assert "Using python version" not in res.stdout + res.stderr
    assert "UCS" in res.stdout


# ------------------------------------------------------------------ broken checkpoints (refused before YADE loads)
def _fake_unfinished_run(folder, command):
    """A run folder as a killed run leaves it: run.json and a complete checkpoint (files of the right formats;
    no YADE needed, the refusals come before any scene is loaded)."""
    import gzip
    import json
    import numpy as np
    (folder / "checkpoint").mkdir(parents=True)
    (folder / "run.json").write_text(json.dumps({"command": command}))
    (folder / "checkpoint" / "state.json").write_text(json.dumps({"format": 1, "run_values": {"seed": 1}}))
    np.savez(folder / "checkpoint" / "arrays.npz", broken=np.zeros(100, bool), break_step=np.arange(100))
    with gzip.open(folder / "checkpoint" / "scene.yade.gz", "wb") as fh:
        fh.write(bytes(range(256)) * 400)


def _truncate(path):
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])


@pytest.mark.parametrize("command", ["ucs", "brazilian", "creep"])
@pytest.mark.parametrize("damage, message", [
    (lambda c: _truncate(c / "arrays.npz"),
     "error: {c}/arrays.npz: the checkpoint's arrays are unreadable (truncated or not numpy's npz; BadZipFile: "),
    (lambda c: (c / "state.json").write_bytes(b"garbage\x00\x01"),
     "error: {c}: the checkpoint's state file (checkpoint/state.json) is unreadable (not the JSON this code "
     "writes: garbage or truncated; "),
    (lambda c: _truncate(c / "scene.yade.gz"),
     "error: {c}/scene.yade.gz: the checkpoint's scene is unreadable (truncated gzip or not a YADE scene; EOFError: "),
])
def test_a_broken_checkpoint_file_is_named_in_one_line(tmp_path, capsys, command, damage, message):
    run = tmp_path / "run"
    _fake_unfinished_run(run, command)
    damage(run / "checkpoint")
    before = sorted(p.name for p in run.rglob("*"))
    assert main([command, "--resume", str(run)]) == 2
    line = _one_line(capsys)
    assert line.startswith(message.format(c=run / "checkpoint")), line
    assert line.endswith("fix: start the run again with the same command (run.json) and --overwrite")
    assert sorted(p.name for p in run.rglob("*")) == before


# ------------------------------------------------------------------ README and reference
def _subcommands():
    from grainfrac_yade.cli import build_parser
    parser = build_parser()
    return next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction").choices


def test_the_readme_names_exactly_the_commands_that_take_params_and_set():
    import re
    readme = (ROOT / "README.md").read_text()
    sentence = readme[readme.index("The commands that build or run a model"):]
    sentence = sentence[: sentence.index(") take `--params FILE`")]
    listed = set(re.findall(r"`([a-z0-9-]+)`", sentence))
    taking = {name for name, p in _subcommands().items()
              if {"--params", "--set"} <= {o for a in p._actions for o in a.option_strings}}
    assert listed == taking


def test_the_commands_reference_gives_vtk_fractions_as_off_unless_given():
    from grainfrac_yade.analysis.figures import MAP_FRACTIONS
    from grainfrac_yade.commands.creep import LIFE_FRACTIONS
    assert LIFE_FRACTIONS == MAP_FRACTIONS
    page = (ROOT / "docs" / "reference" / "commands.md").read_text()
    row = next(l for l in page.splitlines() if l.startswith("| `--vtk-fractions`"))
    assert row.split(" | ")[1] == "off; the flag alone: 0.1,0.5,0.9,1"
    args = _subcommands()["creep"].parse_args(["--vtk-fractions"])
    assert args.vtk_fractions == [0.1, 0.5, 0.9, 1.0]
    assert _subcommands()["creep"].parse_args([]).vtk_fractions is False


# ------------------------------------------------------------------ what the demo's report shows
def _capture(monkeypatch, module, name):
    """Keep the figure that ``module.name`` (a save or close function taking the figure first) receives."""
    kept = []
    original = getattr(module, name)

    def keep(fig, *args, **kw):
        kept.append(fig)
        return original(fig, *args, **kw)
    monkeypatch.setattr(module, name, keep)
    return kept


def test_a_run_with_one_creep_time_is_drawn_in_the_strain_time_figure(tmp_path, monkeypatch):
    """The event clock can jump from the load straight to failure: one positive creep time, no curve on a log
    axis; the run must still be drawn (a dashed line at its time), not only listed in the legend."""
    import pandas as pd
    from grainfrac_yade.analysis import figures
    kept = _capture(monkeypatch, figures, "_save")
    one = figures.Curve("ratio 0.9, seed 1", pd.DataFrame({"creep_time_s": [0.0, 9999.0],
                                                          "axial_strain": [2e-3, 9e-3]}), True, 9999.0)
    many = figures.Curve("ratio 0.7, seed 1", pd.DataFrame({"creep_time_s": [0.0, 10.0, 1e3, 1e5],
                                                           "axial_strain": [2e-3, 2.1e-3, 2.2e-3, 9e-3]}), True, 1e5)
    figures.strain_time_figure(tmp_path / "st.png", [many, one])
    ax = kept[0].axes[0]
    drawn = {l.get_label(): l for l in ax.get_lines()}
    line = drawn["ratio 0.9, seed 1: one creep time, t = 9999 s (no curve on a log axis)"]
    assert list(line.get_xdata()) == [9999.0, 9999.0]
    assert len(drawn["ratio 0.7, seed 1"].get_xdata()) == 3


def test_the_lifetime_figure_says_which_ucs_each_ratio_divides_by(tmp_path, monkeypatch):
    import numpy as np
    from grainfrac_yade.analysis import figures
    from grainfrac_yade.analysis.labdata import paper_reference
    kept = _capture(monkeypatch, figures, "_save")
    s = figures.LifetimeSet("default", np.array([0.7, 0.8]), np.array([1e4, 1e3]), ucs_pa=np.array([265e6, 265e6]))
    figures.lifetime_figure(tmp_path / "l.png", [s], reference=paper_reference())
    labels = [t.get_text() for t in kept[0].axes[0].get_legend().get_texts()]
    assert "default: failed runs (2); r = sigma / 265.0 MPa (its runs' UCS)" in labels
    assert any(l.startswith("paper (UDEC): 160 MPa, r = 160 / 234.5 MPa (UDEC's UCS) = 0.682") for l in labels)
    assert figures.ratio_reference([258e6, 282e6, np.nan]) == "r = sigma / 258.0-282.0 MPa"


def test_crack_maps_count_cracks_and_the_macrocracks_among_them(tmp_path, monkeypatch):
    import numpy as np
    import pandas as pd
    from grainfrac_yade.analysis import crackmaps
    kept = _capture(monkeypatch, crackmaps.plt, "close")
    cracks = pd.DataFrame({"creep_time_s": [-1.0, 5.0, 20.0], "x_m": [1e-3, 2e-3, 3e-3], "y_m": [1e-3] * 3,
                           "face_normal_angle_deg": [0.0, 90.0, 45.0], "macro_time_s": [np.nan, 6.0, -1.0],
                           "mode": ["tensile", "shear", "tensile"], "kind": ["inter", "intra", "inter"]})
    crackmaps.crack_maps_figure(tmp_path / "m.png", cracks, [5.5, 30.0], ["(a)", "(b)"], 4e-3, 4e-3, 1e-3)
    titles = [ax.get_title() for ax in kept[0].axes]
    assert titles == ["(a)\n2 cracks, 0 of them macro", "(b)\n3 cracks, 2 of them macro"]
    page = (ROOT / "docs" / "reference" / "output_files.md").read_text()
    assert "### Crack counts: one definition each" in page and "macrocracks <= cracks" in page
    from grainfrac_yade.analysis.report import CRACK_COUNTS, RUN_COLUMNS
    assert list(RUN_COLUMNS).index("broken_total") < list(RUN_COLUMNS).index("macrocracks")
    assert "a subset of the cracks" in CRACK_COUNTS
    assert not (ROOT / "docs" / "output_files.md").exists()


def test_the_animation_draws_strain_in_percent_and_no_legend_line_it_never_draws(monkeypatch):
    import numpy as np
    import pandas as pd
    from grainfrac_yade.analysis import animation
    cracks = pd.DataFrame({"creep_time_s": [1.0, 2.0], "mode": ["tensile", "shear"],
                           "macro_time_s": [np.nan, np.nan]})
    seg = np.array([[[0, 0], [1e-3, 0]], [[0, 1e-3], [1e-3, 1e-3]]], float)
    hist = pd.DataFrame({"creep_time_s": [0.0, 1.0, 2.0], "axial_strain": [1e-3, 2e-3, 3e-3]})
    r = animation._Renderer(None, (3e-3, 6e-3), cracks, seg, hist, 2.0, False, "t")
    try:
        inset = r.fig.axes[1]
        assert inset.get_ylabel() == "axial strain [%]"
        assert list(inset.get_lines()[0].get_ydata()) == pytest.approx([0.1, 0.2, 0.3])
        r.frame(2.0, 2.0)
        assert list(r.marker.get_ydata()) == pytest.approx([0.3])
        assert r.text.get_text().endswith("\n2 cracks, 0 of them macro")
        legend = [t.get_text() for t in r.fig.legends[0].get_texts()]
        assert "macrocrack: none in this run (or times not recorded)" in legend
    finally:
        r.close()
    assert animation.macro_legend([np.nan, 3.0]) == "macrocrack (face fully separated): thick, in its mode's colour"


# ------------------------------------------------------------------ --vtk-times that fall into one frame
def test_requested_times_due_at_one_row_are_one_frame():
    from grainfrac_yade.vtkio import due_times, merged_frame_note
    assert due_times([0.0, 1e6, 2e6, 3e6], 0.0) == ([0.0], [1e6, 2e6, 3e6])
    assert due_times([1e6, 2e6, 3e6], 2.5e6) == ([1e6, 2e6], [3e6])
    assert due_times([3e6], 2.5e6) == ([], [3e6])
    assert merged_frame_note([1e6, 2e6], 2.5e6) == ("VTK: requested creep times 1e+06, 2e+06 s fell into one frame "
                                                     "at 2.5e+06 s (the clock stepped over them: there is no state "
                                                     "in between to write)")


@needs_yade
@pytest.mark.yade
def test_a_creep_run_says_which_requested_vtk_times_fell_into_one_frame(tmp_path):
    """A tiny creep run (seconds): 1e-9 and 2e-9 s both lie before its first event, so the event clock steps over
    both to one frame; 1e30 s lies after its end."""
    import json
    out = tmp_path / "creep"
    res = _cli("creep", "--width", "3e-3", "--height", "6e-3", "--seed", "1", "--ratio", "0.9", "--ucs", "250",
               "--clock", "event", "--vtk-times", "0,1e-9,2e-9,1e30", "--out", out)
    assert res.returncode == 0, res.stderr
    s = json.loads((out / "summary.json").read_text())
    [merged] = s["vtk_merged_times"]
    assert merged["requested_s"] == [1e-9, 2e-9] and merged["frame_s"] > 2e-9
    assert merged["frame_s"] in s["vtk_creep_times_s"]
    assert s["vtk_times_not_reached_s"] == [1e30]
    assert "VTK: requested creep times 1e-09, 2e-09 s fell into one frame at" in res.stdout
    assert "Using python version" not in res.stdout + res.stderr


def test_parameters_docs_and_tests_speak_of_the_model_not_of_issue_numbers():
    import re
    pattern = re.compile(r"[Ii]ssue ?#?[0-9]+")
    found = []
    for top in ("params", "docs", "tests", "grainfrac_yade", "studies", "yade_scripts"):
        for path in (ROOT / top).rglob("*"):
            if path.suffix in (".md", ".py", ".toml", ".table", ".sh", ".csv") and path.is_file():
                text = path.read_text(errors="replace")
                found += [f"{path.relative_to(ROOT)}:{m.group(0)}" for m in pattern.finditer(text)]
    found += [f"README.md:{m.group(0)}" for m in pattern.finditer((ROOT / "README.md").read_text())]
    assert found == []


def test_the_readme_gives_one_calibrated_ucs_the_one_ratios_divide_by():
    """README and the calibration study name the parameter every --ratio divides by, and the tour's own ratio of
    it to the tour specimen's UCS (step 2's 280.6 MPa, measured 2026-12-03) is what it says."""
    import re
    from grainfrac_yade.params import load_parameters
    ref_mpa = round(load_parameters().calibration.reference_ucs / 1e6, 1)
    readme = (ROOT / "README.md").read_text()
    assert f"**calibrated UCS {ref_mpa} MPa** (`calibration.reference_ucs`" in readme
    assert f"`--ratio` alone divides by the calibrated {ref_mpa} MPa" in readme
    own = float(re.search(r"--ucs ([0-9.]+) --out results/tour/creep_own", readme).group(1))
    assert f"{0.7 * ref_mpa / own:.2f} of this smaller specimen's" in readme
    study = (ROOT / "docs" / "studies" / "ucs_calibration.md").read_text()
    assert f"## The calibrated UCS: one number\n\n**{ref_mpa} MPa**, `calibration.reference_ucs`" in study
