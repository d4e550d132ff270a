"""The ``engine`` column of every table that lists runs (analyze, analyze-ucs): params.json's ``numerics.engine``, else
summary.json's ``engine``, else "yade" for runs written before the engine existed.  Fake run folders (no YADE), and
one real static UCS run on 3 x 6 mm (about a second)."""
import json

import pandas as pd
import pytest

from test_analysis import RATIOS, true_lifetime, write_run
from test_grain_model_runs import SMALL, UCS_SUMMARY, write_run_folder

from grainfrac_yade.analysis import collect_runs
from grainfrac_yade.analysis.collect import ENGINE_BEFORE_THE_KEY, ENGINE_COLUMN, run_engine
from grainfrac_yade.params import load_parameters


def _ucs_folder(folder, engine=None, summary=None, drop_engine=False):
    """A UCS run folder of the small specimen; ``engine``: numerics.engine of its params.json (None: the default),
    ``drop_engine``: params.json older than the key."""
    params = load_parameters(overrides=SMALL + ([f"numerics.engine={engine}"] if engine else []))
    return write_run_folder(folder, params, summary=summary if summary is not None else dict(UCS_SUMMARY),
                            drop=("numerics.engine",) if drop_engine else ())


def test_run_engine_reads_params_then_summary_then_the_older_default():
    assert run_engine({"numerics": {"engine": "static"}}, {"engine": "yade"}) == "static"
    assert run_engine({"numerics": {}}, {"engine": "static"}) == "static"
    assert run_engine({"specimen": {"width": 1e-2}}, {"ucs_pa": 1.0}) == ENGINE_BEFORE_THE_KEY == "yade"
    assert run_engine(None, {"engine": "static"}) == "static"
    assert run_engine({}, None) == "yade"
    assert run_engine(None, None) is None


def test_collect_runs_has_the_engine_of_every_run(tmp_path):
    """One row per folder: the engine next to the command, from params.json, from summary.json where params.json
    predates the key, "yade" where neither says, and nothing where no file was written yet."""
    _ucs_folder(tmp_path / "yade_run")
    _ucs_folder(tmp_path / "static_run", engine="static", summary=dict(UCS_SUMMARY, engine="static"))
    _ucs_folder(tmp_path / "older_run", drop_engine=True)
    _ucs_folder(tmp_path / "older_params_static_summary", drop_engine=True, summary=dict(UCS_SUMMARY, engine="static"))
    started = tmp_path / "started"
    started.mkdir()
    (started / "run.json").write_text(json.dumps({"command": "ucs", "seed": 1}))
    for all_params in (False, True):
        runs = collect_runs(tmp_path, all_params=all_params).set_index("run")
        assert runs[ENGINE_COLUMN].to_dict() == {"older_params_static_summary": "static", "older_run": "yade",
                                                "started": None, "static_run": "static", "yade_run": "yade"}
        columns = list(runs.reset_index().columns)
        assert columns.index(ENGINE_COLUMN) == columns.index("command") + 1


def test_analyze_ucs_keeps_the_engines_apart(tmp_path, capsys):
    """ucs_runs.csv lists each run's engine; ucs_stats (csv and md) and the envelope group by it first: a static and a
    YADE run of the same model are never averaged together."""
    from grainfrac_yade.cli import main
    _ucs_folder(tmp_path / "yade1", summary=dict(UCS_SUMMARY, ucs_pa=300e6))
    _ucs_folder(tmp_path / "yade2", drop_engine=True, summary=dict(UCS_SUMMARY, ucs_pa=310e6))   # older: YADE
    _ucs_folder(tmp_path / "static1", engine="static", summary=dict(UCS_SUMMARY, ucs_pa=500e6, engine="static"))
    assert main(["analyze-ucs", str(tmp_path)]) == 0
    runs = pd.read_csv(tmp_path / "report" / "ucs_runs.csv").set_index("run")
    assert runs[ENGINE_COLUMN].to_dict() == {"static1": "static", "yade1": "yade", "yade2": "yade"}
    stats = pd.read_csv(tmp_path / "report" / "ucs_stats.csv").set_index(ENGINE_COLUMN)
    assert list(stats.columns)[:1] == ["resolution.spheres_per_cell"] and len(stats) == 2
    assert stats.loc["yade", "ucs_pa_count"] == 2 and stats.loc["yade", "ucs_pa_mean"] == pytest.approx(305e6)
    assert stats.loc["static", "ucs_pa_count"] == 1 and stats.loc["static", "ucs_pa_mean"] == 500e6
    table = (tmp_path / "report" / "ucs_stats.md").read_text().splitlines()
    head = [c.strip() for c in table[0].strip("|").split("|")]
    assert head[:2] == ["engine", "cells"] and table[1].count("---") == len(head)
    rows = {line.split("|")[1].strip(): line for line in table[2:4]}
    assert set(rows) == {"static", "yade"} and "| 500.0 |" in rows["static"] and "| 305.0 +- 7.1 |" in rows["yade"]


def test_analyze_ucs_envelope_per_engine(tmp_path):
    """Confined tests of two engines: one envelope each, its engine in envelope.csv and in its label."""
    from grainfrac_yade.cli import main
    for engine in ("yade", "static"):
        for k, s3 in enumerate((0.0, 20e6, 40e6)):
            p = load_parameters(overrides=SMALL + [f"numerics.engine={engine}", f"confinement.stress={s3}"])
            write_run_folder(tmp_path / f"{engine}{k}", p,
                             summary=dict(UCS_SUMMARY, ucs_pa=(250e6 if engine == "yade" else 400e6) + 4 * s3))
    assert main(["analyze-ucs", str(tmp_path)]) == 0
    env = pd.read_csv(tmp_path / "report" / "envelope.csv").set_index(ENGINE_COLUMN)
    assert sorted(env.index) == ["static", "yade"] and list(env["n_tests"]) == [3, 3]
    assert env.loc["static", "mc_unconfined_strength_pa"] == pytest.approx(400e6, rel=1e-9)
    assert env.loc["yade", "mc_unconfined_strength_pa"] == pytest.approx(250e6, rel=1e-9)
    assert env.loc["static", "variant"].startswith("static engine, rigid cells")


def _creep_params(engine):
    return {"specimen": {"width": 10e-3, "height": 20e-3, "grain_size": 1e-3},
            "stress_corrosion": {"clock": "event", "law": "hillig_charles", "beta1": 1e-3, "rate_form": "beta"},
            "numerics": {"engine": engine} if engine else {}}   # {}: a params.json older than the key


def test_analyze_lists_the_engine_in_runs_and_crack_phases(tmp_path):
    """A creep study of YADE runs (one written before the key) and static runs: runs.csv, the report's run table
    and crack_phases list each run's engine; the two engines are two variants, fitted apart."""
    from grainfrac_yade.analysis.study import analyze_study
    study = tmp_path / "study"
    for r in RATIOS:
        write_run(study, f"yade_r{r}", r, lifetime=true_lifetime(r), params=_creep_params("yade" if r < 0.8 else None))
        write_run(study, f"static_r{r}", r, lifetime=10 * true_lifetime(r), params=_creep_params("static"))
    report = analyze_study(study)
    runs = pd.read_csv(report.parent / "runs.csv").set_index("run")
    assert {k: v for k, v in runs[ENGINE_COLUMN].items()} == {
        **{f"yade_r{r}": "yade" for r in RATIOS}, **{f"static_r{r}": "static" for r in RATIOS}}
    columns = list(runs.reset_index().columns)
    assert columns.index(ENGINE_COLUMN) == columns.index("command") + 1
    assert set(runs["variant"]) == {"engine=yade", "engine=static"}
    text = report.read_text()
    runs_table = text[text.index("## Runs"):text.index("## Lifetime vs")]
    assert "| run | engine | seed |" in runs_table and "| static |" in runs_table and "| yade |" in runs_table
    phases = pd.read_csv(report.parent / "crack_phases.csv")
    assert list(phases.columns[:3]) == ["run", ENGINE_COLUMN, "seed"]
    assert all(phases.loc[phases["run"] == run, ENGINE_COLUMN].eq(engine).all() for run, engine in
               runs[ENGINE_COLUMN].items())
    assert "| run | engine | seed |" in (report.parent / "crack_phases.md").read_text()


def test_confinement_table_has_the_engine():
    """Lifetimes against confinement per law, engine, ratio and sigma_3 (a table without an engine column: YADE)."""
    from grainfrac_yade.analysis.lifetimes import confinement_lifetimes, with_confinement_columns
    runs = pd.DataFrame({"outcome": ["failed"] * 4, "ratio": [0.8] * 4, "confinement.stress": [0.0, 0.0, 20e6, 20e6],
                         "stress_corrosion.law": ["hillig_charles"] * 4, "lifetime_s": [1e6, 1e3, 10.0, 100.0],
                         ENGINE_COLUMN: ["yade", "static", "yade", "static"]})
    t = confinement_lifetimes(with_confinement_columns(runs))
    assert list(t.columns[:2]) == ["law", ENGINE_COLUMN] and len(t) == 4
    assert t.set_index([ENGINE_COLUMN, "confining_stress_mpa"]).loc[("static", 0.0), "lifetime_geomean_s"] == pytest.approx(1e3)
    older = confinement_lifetimes(with_confinement_columns(runs.drop(columns=ENGINE_COLUMN)))
    assert set(older[ENGINE_COLUMN]) == {"yade"} and list(older["n"]) == [2, 2]


def test_a_real_static_run_reads_static(tmp_path):
    """A static UCS run on 3 x 6 mm through the protocol: its folder reads as "static" in collect_runs."""
    from grainfrac_yade.protocols.ucs_output import run_ucs_to_folder
    p = load_parameters(overrides=["specimen.width=3e-3", "specimen.height=6e-3", "numerics.engine=static"])
    run_ucs_to_folder(p, 1, tmp_path / "static_ucs")
    runs = collect_runs(tmp_path)
    assert list(runs[ENGINE_COLUMN]) == ["static"] and list(runs["status"]) == ["finished"]
