"""What a user typed and what the commands say back: inputs that ended in a traceback or were accepted silently
end in one line with exit status 2; a run without a result exits 3 with one line and is counted as such by
``batch`` and ``analyze``; the words say what the engine counts; lifetimes read in a unit beside seconds, the
minimum creep strain rate is measured, and the fits name the runs they leave out.

Through the command line (``main`` with captured output); no YADE (the static engine runs the few runs here,
4 x 8 mm, about a second each).  Exact lines where the line is the point.
"""
import json

import numpy as np
import pandas as pd
import pytest

from conftest import ROOT
from test_analysis import make_study, write_run
from grainfrac_yade.cli import ENGINE_HELP, build_parser, main
from grainfrac_yade.engines.registry import ENGINE_NAMES
from grainfrac_yade.errors import EXIT_NUMERICAL_FAILURE, NumericalFailure
from grainfrac_yade.params.schema import PARAMS_DIR

TINY = ["--width", "4e-3", "--height", "8e-3"]
SHIPPED = PARAMS_DIR / "ldb_granite.toml"


def _one_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


# ------------------------------------------------------------------ tracebacks
@pytest.mark.parametrize("command", [["ucs"], ["specimen"]])
def test_a_width_whose_cell_count_overflows_is_one_line_naming_the_flag(tmp_path, capsys, command):
    assert main([*command, "--width", "1e308", "--out", str(tmp_path / "r")]) == 2
    assert _one_line(capsys) == ("error: --width: specimen.width: 1e+308 m makes a specimen of more cells than a "
                                 "float counts (grain size 0.001 m); fix: give the width in m (paper: 31.7 x 63.4 mm, "
                                 "i.e. 31.7e-3 x 63.4e-3)")
    assert not (tmp_path / "r").exists()


def test_analyze_ucs_on_a_creep_study_is_one_line_pointing_to_analyze(tmp_path, capsys):
    write_run(tmp_path, "ratio0.7", 0.7, lifetime=1e6)
    assert main(["analyze-ucs", str(tmp_path)]) == 2
    assert _one_line(capsys) == (f"error: {tmp_path}: no finished UCS runs (run folders: 1 creep); fix: analyze a "
                                 f"creep study with python3 -m grainfrac_yade analyze {tmp_path}")
    assert not (tmp_path / "report").exists()


# ------------------------------------------------------------------ accepted silently
def _table(tmp_path, text):
    table = tmp_path / "t.table"
    table.write_text(text)
    return table


def test_a_repeated_batch_row_is_refused_before_anything_runs(tmp_path, capsys):
    table = _table(tmp_path, "ratio seed study\n0.7 1 'dup'\n0.8 1 'dup'\n0.7 1 'dup'\n")
    assert main(["batch", str(table), "--log-dir", str(tmp_path / "logs")]) == 2
    assert _one_line(capsys) == (f"error: {table}: 1 bad row, nothing run: {table}:4: repeats line 2 (the same run "
                                 "twice: the second would only skip it); fix: remove one, or give it another seed")
    assert not (tmp_path / "logs").exists()


@pytest.mark.parametrize("columns, rows", [
    ("ratio seed out", ["0.7 1 '{d}/x'", "0.8 1 '{d}/x'"]),                   # one out for two runs
    ("ratio seed description out", ["0.7 1 'a' ''", "0.8 1 'a' ''"]),         # one description: one folder name
])
def test_two_batch_rows_in_one_folder_are_refused_before_anything_runs(tmp_path, capsys, monkeypatch, columns, rows):
    monkeypatch.chdir(tmp_path)
    table = _table(tmp_path, columns + "\n" + "\n".join(r.format(d=tmp_path) for r in rows) + "\n")
    assert main(["batch", str(table), "--log-dir", str(tmp_path / "logs")]) == 2
    folder = tmp_path / "x" if "out" == columns.split()[-1] and "description" not in columns else \
        tmp_path / "results" / "default" / "a_seed1"
    assert _one_line(capsys) == (f"error: {table}: 1 bad row, nothing run: {table}:3: runs into {folder}, as line 2 "
                                 "does (two runs cannot share a folder); fix: give each row its own out (or "
                                 "description)")
    assert not (tmp_path / "logs").exists() and not (tmp_path / "results").exists()


def test_the_folder_a_row_is_checked_for_is_the_one_its_script_names():
    """Folder names from the parameters in the shipped files' order (YADE's reader), whatever the column order."""
    from grainfrac_yade.commands.batch import row_out
    from grainfrac_yade.runs.batchrun import RUN_COLUMNS
    controls = dict(RUN_COLUMNS, ratio=0.7, stress=0.0, ucs=0.0, study="s", seed=2)
    overrides = [("specimen.height", 8e-3), ("specimen.width", 4e-3)]
    assert row_out("creep", overrides, controls).name == "ratio=0.7_width=0.004_height=0.008_seed2"


@pytest.mark.parametrize("argv, line", [
    (["--set", "numerics.engine=static", "--engine", "yade"],
     "error: --engine: numerics.engine: also given as --set numerics.engine=static: two values ('static' and "
     "'yade'); fix: give numerics.engine once: drop one of the two"),
    (["--set", "specimen.width=nan", "--width", "4e-3"],
     "error: --set: specimen.width: nan is not finite; fix: give a finite number [m]"),
    (["--set", "specimen.width=5e-3", "--width", "4e-3"],
     "error: --width: specimen.width: also given as --set specimen.width=0.005: two values (0.005 and 0.004); fix: "
     "give specimen.width once: drop one of the two"),
])
def test_one_key_given_two_values_or_a_hidden_bad_one_is_refused(tmp_path, capsys, argv, line):
    assert main(["ucs", *argv, "--out", str(tmp_path / "r")]) == 2
    assert _one_line(capsys) == line
    assert not (tmp_path / "r").exists()


def test_the_same_value_twice_is_fine(tmp_path):
    from grainfrac_yade.commands._args import load_params_from_args
    args = build_parser().parse_args(["ucs", "--set", "numerics.engine=static", "--engine", "static"])
    assert load_params_from_args(args).numerics.engine == "static"


@pytest.mark.parametrize("argv, line", [
    (["--stress", "1e-6"], "error: --stress 1e-06 MPa is below 1 MPa, no creep load for granite; fix: CLI stress "
                           "flags are in MPa, batch columns in Pa: e.g. --stress 160"),
    (["--ratio", "1e-9"], "error: --ratio 1e-09 gives 2.363e-07 MPa, below 1 MPa, no creep load for granite; fix: "
                          "e.g. --ratio 0.7"),
])
def test_a_creep_load_below_one_mpa_is_refused(tmp_path, capsys, argv, line):
    assert main(["creep", *TINY, *argv, "--out", str(tmp_path / "r")]) == 2
    assert _one_line(capsys) == line
    assert not (tmp_path / "r").exists()


def test_a_batch_stress_in_mpa_where_pa_is_meant_is_refused(tmp_path, capsys):
    table = _table(tmp_path, "stress seed\n160 1\n")
    assert main(["batch", str(table), "--log-dir", str(tmp_path / "logs")]) == 2
    assert _one_line(capsys) == (f"error: {table}: 1 bad row, nothing run: batch table {table}:2: column stress = 160 Pa "
                                 "is below 1 MPa, no creep load for granite; fix: CLI stress flags are in MPa, batch "
                                 "columns in Pa: e.g. stress 160e6")


def test_a_confined_test_stopped_before_its_peak_reports_a_lower_bound_and_no_crack_damage(tmp_path, capsys):
    """500 MPa of confinement on the static engine: the 2 % strain cap comes before any peak; the largest stress is
    a lower bound ("at least"), and the last point is no crack damage stress (CD "-")."""
    out = tmp_path / "r"
    assert main(["ucs", "--engine", "static", *TINY, "--confinement", "500", "--out", str(out)]) == 0
    line = capsys.readouterr().out.strip().splitlines()[-1]
    s = json.loads((out / "summary.json").read_text())
    assert s["peak_reached"] is False and s["crack_damage_pa"] is None
    assert line.startswith(f"peak axial stress at confinement 500 MPa: at least {s['ucs_pa'] / 1e6:.1f} MPa,"), line
    assert ", CD - MPa," in line and "lower bound" in line


def test_crack_damage_is_not_read_off_a_curve_that_ends_at_its_peak():
    from grainfrac_yade.analysis.ucs_analysis import crack_damage_stress
    ea = np.linspace(0, 0.02, 50)
    s, el = 80e9 * ea, -0.2 * ea   # still rising at the last point: no peak, no volumetric reversal
    assert np.isnan(crack_damage_stress(s, ea, el))
    el_rev = el.copy()
    el_rev[30:] -= 2.0 * (ea[30:] - ea[30])   # dilation from point 30: the reversal is seen before the end
    assert crack_damage_stress(s, ea, el_rev) == pytest.approx(s[30])


# ------------------------------------------------------------------ misleading words
def test_a_height_below_the_grain_size_names_the_flag_not_the_file(tmp_path, capsys):
    assert main(["specimen", "--height", "1e-5", "--out", str(tmp_path / "r")]) == 2
    assert _one_line(capsys) == ("error: --height: specimen.height: 1e-05 m is at or below the grain size "
                                 f"(specimen.grain_size = 0.001 m, {SHIPPED}); fix: give a height above the grain size "
                                 "(paper: 31.7 x 63.4 mm with 1 mm grains; e.g. 10e-3 m), or a smaller grain size")


def test_the_engine_flag_names_every_engine():
    assert all(name in ENGINE_HELP for name in ENGINE_NAMES)
    for command in ("ucs", "creep", "brazilian"):
        text = build_parser()._subparsers._group_actions[0].choices[command].format_help()
        assert "hybrid" in " ".join(text.split()), command


def test_the_analyze_report_says_failed_means_a_lifetime(tmp_path):
    from grainfrac_yade.analysis.study import analyze_study
    make_study(tmp_path, extra=False)
    text = analyze_study(tmp_path, grains=False).read_text()
    assert "4 run folder(s): 4 failed by creep (a lifetime each)." in text


# ------------------------------------------------------------------ a run without a result
@pytest.fixture
def failing_creep_step(monkeypatch):
    """The event clock's second creep step raises a NumericalFailure (as a blown-up DEM or statuses that do not
    settle would), whatever the engine does: the run ends as a numerical failure after one event."""
    from grainfrac_yade.protocols import creep_loops
    real, calls = creep_loops.creep_step, []

    def step(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise NumericalFailure("forced in the test")
        return real(*args, **kwargs)
    monkeypatch.setattr(creep_loops, "creep_step", step)


def test_a_numerical_failure_exits_3_with_one_line_and_keeps_its_files(tmp_path, capsys, failing_creep_step):
    out = tmp_path / "r"
    status = main(["creep", "--engine", "static", *TINY, "--ratio", "0.9", "--out", str(out)])
    captured = capsys.readouterr()
    s = json.loads((out / "summary.json").read_text())
    assert status == EXIT_NUMERICAL_FAILURE == 3
    assert s["numerical_failure"] is True and s["lifetime_s"] is None and s["lifetime_readable"] is None
    err = [l for l in captured.err.splitlines() if not l.startswith("warning:")]
    assert err == [f"numerical failure: creep {s['stress_pa'] / 1e6:.1f} MPa after 1 events, static engine: no result "
                   f"(forced in the test); exit status 3, summary.json says numerical_failure: true -> {out}"]
    assert "equilibria solved" in captured.out and "DEM steps" not in captured.out
    hist = pd.read_csv(out / "history.csv")   # no t_f: no D_n = N(t) / N(t_f), never drawn to 1
    assert len(hist) >= 2 and "broken_creep" in hist and "damage_index" not in hist


def test_batch_and_analyze_count_a_numerical_failure_as_such(tmp_path, capsys, monkeypatch):
    """yade-batch replaced by one that leaves row 2 a finished run and row 3 a numerical failure."""
    from grainfrac_yade.commands import batch
    from grainfrac_yade.analysis.study import analyze_study
    table = _table(tmp_path, f"ratio seed out\n0.7 1 '{tmp_path}/study/a'\n0.8 1 '{tmp_path}/study/b'\n")

    def fake_batch(table_path, script, jobs, log_dir, repo=None, on_row_end=None):
        for line, name, numerical in ((2, "a", False), (3, "b", True)):
            folder = write_run(tmp_path / "study", name, 0.7 + 0.1 * (line - 2), lifetime=1e6)
            summary = json.loads((folder / "summary.json").read_text())
            if numerical:
                summary.update(numerical_failure=True, failed=None, lifetime_s=None,
                               failure_reason="numerical failure: forced")
            (folder / "summary.json").write_text(json.dumps(summary))
            (log_dir / "rows").mkdir(parents=True, exist_ok=True)
            (log_dir / "rows" / f"{line}.json").write_text(json.dumps({"folder": str(folder)}))
            (log_dir / f"{line}.log").write_text("")
            on_row_end(line)
        return 3
    monkeypatch.setattr(batch, "run_batch", fake_batch)
    assert main(["batch", str(table), "--log-dir", str(tmp_path / "logs")]) == EXIT_NUMERICAL_FAILURE
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[1].startswith("line 2: ok: creep 175.0 MPa: lifetime 1e+06 s (12 d) -> ")
    assert lines[2].startswith("line 3: numerical failure: creep 200.0 MPa: no result (numerical failure: forced) -> ")
    assert lines[-1] == f"1 of 2 rows ended as a numerical failure (no result): lines 3 of {table}"
    text = analyze_study(tmp_path / "study", grains=False).read_text()
    assert "2 run folder(s): 1 failed by creep (a lifetime each), 1 numerical failure (no result)." in text


# ------------------------------------------------------------------ what a rock mechanician reads
@pytest.mark.parametrize("seconds, words", [(0.05, "0.05 s"), (11520, "3.2 h"), (1.2e7, "140 d"),
                                            (1.23e8, "3.9 yr"), (90, "1.5 min"), (None, None), (float("nan"), None)])
def test_a_lifetime_reads_in_the_unit_that_suits_it(seconds, words):
    from grainfrac_yade.analysis.durations import readable_duration
    assert readable_duration(seconds) == words


def _three_stage_history(t_f, n=401, secondary=2e-9):
    """(t, strain) of a creep curve with primary (decelerating), secondary (exactly ``secondary`` [1/s]) and, after
    0.8 t_f, tertiary (accelerating) creep."""
    t = np.linspace(0, t_f, n)
    tau = t / t_f
    return t, 1e-3 + secondary * t + 4e-4 * (1 - np.exp(-tau / 0.05)) + 6e-4 * np.clip(tau - 0.8, 0, None) ** 2 / 0.04


def test_the_minimum_creep_rate_is_the_secondary_stages_secant_rate():
    """The secant of the curve between the stage ends :func:`resolve_creep_stages` finds (grid points here: the
    interpolation is exact, so 1e-12 is round-off), and by the stages' definition (windowed rates within 1.5 x the
    minimum) between the true secondary rate and 1.5 x it (here +4 %: the secant takes in the ends of the band)."""
    from grainfrac_yade.analysis.creep_analysis import minimum_creep_rate, resolve_creep_stages
    t_f, secondary = 1e6, 2e-9
    t, eps = _three_stage_history(t_f, secondary=secondary)
    stages = resolve_creep_stages(t, eps, t_f)
    i, j = (int(np.flatnonzero(np.isclose(t, x, rtol=0, atol=1e-6))[0]) for x in (stages.primary_end_s,
                                                                                   stages.tertiary_start_s))
    rate = minimum_creep_rate(t, eps, t_f)
    assert rate.unresolved is None
    assert rate.rate_per_s == pytest.approx((eps[j] - eps[i]) / (t[j] - t[i]), rel=1e-12)
    assert secondary <= rate.rate_per_s <= 1.5 * secondary
    few = minimum_creep_rate(t[:5], eps[:5], t_f)
    assert few.rate_per_s is None and "at least 9 needed" in few.unresolved


def test_a_creep_summary_gives_the_readable_lifetime_the_minimum_rate_and_what_steps_count(tmp_path):
    from grainfrac_yade.analysis.durations import readable_duration
    out = tmp_path / "r"
    status = main(["creep", "--engine", "static", *TINY, "--ratio", "0.9", "--out", str(out)])
    s = json.loads((out / "summary.json").read_text())
    assert status == (EXIT_NUMERICAL_FAILURE if s["numerical_failure"] else 0)
    assert s["engine"] == "static" and s["steps_counted"] == "equilibria solved"
    assert s["lifetime_readable"] == readable_duration(s["lifetime_s"])
    assert "min_creep_strain_rate_per_s" in s and isinstance(s["min_creep_strain_rate"], str)
    assert isinstance(s["failed_in_first_relaxation"], bool)


def test_a_static_ucs_stores_its_load_increment_not_a_dem_step(tmp_path):
    out = tmp_path / "r"
    main(["ucs", "--engine", "static", *TINY, "--set", "ucs.max_strain=0.002", "--out", str(out)])
    s = json.loads((out / "summary.json").read_text())
    assert "dem_timestep_s" not in s and s["load_increment_s"] > 0
    assert s["engine"] == "static" and s["steps_counted"] == "equilibria solved"


def test_the_fits_leave_out_a_run_that_failed_in_its_first_relaxation_and_say_so(tmp_path):
    from grainfrac_yade.analysis.study import analyze_study
    make_study(tmp_path, extra=False)
    first = write_run(tmp_path, "ratio0.95_first", 0.95, lifetime=0.05)
    summary = json.loads((first / "summary.json").read_text())
    summary["n_events"] = 1   # an older summary without failed_in_first_relaxation: read from the event count
    (first / "summary.json").write_text(json.dumps(summary))
    report = analyze_study(tmp_path, grains=False)
    fits = pd.read_csv(report.parent / "lifetime_fits.csv")
    assert int(fits["n_points"].iloc[0]) == 4
    assert ("; 1 left out of the fit (failed in the relaxation after its first creep event: no creep life): "
            "ratio0.95_first (t = 0.05 s)") in report.read_text()
    runs = pd.read_csv(report.parent / "runs.csv").set_index("run")
    assert runs.loc["ratio0.95_first", "fit_left_out"].startswith("failed in the relaxation")
    assert runs["fit_left_out"].drop("ratio0.95_first").isna().all()
    assert runs.loc["ratio0.95_first", "lifetime_readable"] == "0.05 s"


def test_older_runs_get_their_minimum_creep_rate_from_their_history(tmp_path):
    """A run folder written before the keys: the analysis measures the rate from history.csv as a run would, and
    draws the rate against time of the runs whose history resolves it (here one of five)."""
    from grainfrac_yade.analysis.creep_analysis import minimum_creep_rate
    from grainfrac_yade.analysis.study import analyze_study
    make_study(tmp_path, extra=False)   # histories of 12 rows without a secondary stage: no rate
    life = 2e6
    folder = write_run(tmp_path, "resolved", 0.65, lifetime=life)
    t, eps = _three_stage_history(life, n=41)
    hist = pd.read_csv(folder / "history.csv").iloc[[0] * 41 + [-1]].reset_index(drop=True)
    hist.loc[:40, "creep_time_s"], hist.loc[:40, "axial_strain"] = t * (1 - 1e-9), eps   # then the collapse row
    hist.to_csv(folder / "history.csv", index=False)
    report = analyze_study(tmp_path, grains=False)
    runs = pd.read_csv(report.parent / "runs.csv").set_index("run")
    expected = minimum_creep_rate(hist["creep_time_s"][:-1], hist["axial_strain"][:-1], life)
    assert expected.rate_per_s is not None
    assert runs.loc["resolved", "min_creep_strain_rate_per_s"] == pytest.approx(expected.rate_per_s, rel=1e-12)
    assert runs.loc["resolved", "min_creep_strain_rate"] == "resolved"
    assert runs.drop("resolved")["min_creep_strain_rate"].eq("no secondary stage between primary and tertiary "
                                                              "creep").all()
    rates = pd.read_csv(report.parent / "strain_rate.csv")
    assert set(rates["run"]) == {"resolved"} and (report.parent / "strain_rate.png").stat().st_size > 0
    assert "min creep rate [1/s]" in report.read_text()


def test_the_docs_name_the_new_summary_keys_and_the_report_folder_of_analyze_ucs():
    text = (ROOT / "docs" / "reference" / "output_files.md").read_text()
    for key in ("min_creep_strain_rate_per_s", "lifetime_readable", "failed_in_first_relaxation", "steps_counted",
                "load_increment_s", "strain_rate.csv", "fit_left_out"):
        assert f"`{key}`" in text, key
    assert "analyze-ucs results/resolution       # report/ucs_stats.md" in (ROOT / "docs" / "guide.md").read_text()
