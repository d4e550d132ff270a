"""Study analysis (lifetime studies, paper Fig. 4-9): lifetime fits, run outcomes, figures and report, the analyze CLI.

All on synthetic run folders written here (no YADE): lifetimes follow ln t = a - b r exactly
(or with seeded noise), so the fits must return the generating coefficients.
"""
import hashlib
import json
import subprocess

import numpy as np
import pandas as pd
import pytest
from conftest import ROOT

from grainfrac_yade.analysis import classify_runs, collect_runs, fit_lifetimes, fit_line, lifetime_stats
from grainfrac_yade.analysis.crackmaps import crack_segments, cracks_at
from grainfrac_yade.analysis.labdata import paper_reference, read_lab_csv
from grainfrac_yade.errors import GrainfracError
from grainfrac_yade.analysis.study import first_creep_crack

PYTHON = "/usr/bin/python3"
A_TRUE, B_TRUE = 32.0, 28.0          # ln t = a - b r of the synthetic model runs
RATIOS = (0.6, 0.7, 0.8, 0.9)
WIDTH, HEIGHT, GRAIN = 10e-3, 20e-3, 1e-3
FIGURES = ("lifetime.png", "strain_time.png", "strain_time_normalised.png", "bonds_strain.png",
           "crack_maps_mode.png", "crack_maps_kind.png", "damage_index.png")
MIN_PNG_BYTES = 10_000


def true_lifetime(r):
    return float(np.exp(A_TRUE - B_TRUE * r))


BETA1_RUN = 1e-3


def write_run(root, name, ratio, seed=1, lifetime=None, failed=True, finished=True, end=None, segments=True,
              clock="event", mode="strength", params=None, n_bonds=700):
    """A creep run folder as run_creep_to_folder writes it (small history and crack list).
    ``params``: a full params.json tree (else a minimal one with ``clock`` and ``mode``)."""
    d = root / name
    d.mkdir(parents=True)
    (d / "run.json").write_text(json.dumps({"command": "creep", "seed": seed}))
    if params is None:
        params = {"specimen": {"width": WIDTH, "height": HEIGHT, "grain_size": GRAIN},
                  "stress_corrosion": {"clock": clock, "mode": mode, "beta1": BETA1_RUN, "rate_form": "beta"}}
    (d / "params.json").write_text(json.dumps(params))
    t_end = lifetime if failed else end
    rng = np.random.default_rng(seed)
    n = 12
    t = np.linspace(0.0, t_end, n)
    strain = 2e-3 + 1e-4 * (t / t_end) + 3e-4 * (t / t_end) ** 6
    broken = np.round(60 * (t / t_end) ** 3).astype(int)
    if failed:
        strain[-1], broken[-1] = 1e-2, 200   # collapse row
    pd.DataFrame({"creep_time_s": t, "axial_strain": strain, "lateral_strain": -0.25 * strain,
                  "axial_stress_pa": ratio * 250e6, "broken_total": 100 + broken, "broken_creep": broken,
                  "damage_index": broken / broken[-1], "macrocracks": broken // 2}
                 ).to_csv(d / "history.csv", index=False)
    c = 40
    x, y = rng.uniform(0, WIDTH, c), rng.uniform(0, HEIGHT, c)
    ang = rng.uniform(0, 180, c)
    times = np.where(rng.random(c) < 0.2, -1.0, rng.uniform(0, t_end, c))
    cracks = pd.DataFrame({"bond": np.arange(c), "creep_time_s": times,
                           "mode": np.where(rng.random(c) < 0.7, "tensile", "shear"),
                           "kind": np.where(rng.random(c) < 0.6, "inter", "intra"),
                           "x_m": x, "y_m": y, "face_normal_angle_deg": ang})
    if segments:
        along = np.radians(ang + 90)
        h = 0.3e-3
        cracks = cracks.assign(x0_m=x - h * np.cos(along), y0_m=y - h * np.sin(along),
                               x1_m=x + h * np.cos(along), y1_m=y + h * np.sin(along),
                               macro_time_s=np.where(rng.random(c) < 0.5, times + 0.01 * t_end, np.nan))
    cracks.to_csv(d / "cracks.csv", index=False)
    if finished:
        summary = {"lifetime_s": lifetime if failed else None, "failed": failed,
                   "failure_reason": "strain runs away" if failed else None, "creep_time_end_s": t_end,
                   "stress_pa": ratio * 250e6, "driving_stress_ratio": ratio, "ucs_pa": 250e6, "clock": "event",
                   "mode": "strength", "n_events": 10, "broken_ramp": 100, "broken_creep": int(broken[-1]),
                   "broken_total": int(100 + broken[-1]), "macrocracks": int(broken[-1] // 2), "n_bonds": n_bonds,
                   "dem_steps": 1000, "wall_s": 1.0, "primary_end_s": 0.2 * t_end if failed else None,
                   "tertiary_start_s": 0.8 * t_end if failed else None, "seed": seed, "params": params}
        (d / "summary.json").write_text(json.dumps(summary))
    return d


def make_study(root, seeds=(1,), ratios=RATIOS, extra=True, segments=True):
    """Failed runs with t = exp(a - b r) (one per ratio and seed), plus an unfinished run, a run
    that did not fail and a run with a broken summary.json."""
    for r in ratios:
        for s in seeds:
            write_run(root, f"ratio{r}_seed{s}", r, s, lifetime=true_lifetime(r), segments=segments)
    if extra:
        write_run(root, "unfinished_run", 0.65, 1, lifetime=1e7, finished=False)
        write_run(root, "survivor_run", 0.55, 1, failed=False, end=3e8)
        broken = write_run(root, "broken_json_run", 0.75, 1, lifetime=1e6)
        (broken / "summary.json").write_text('{"lifetime_s": 1e6, "fail')
    return root


def folder_digest(root):
    """Hash of every file under ``root`` except the report folder (run folders must stay unchanged)."""
    h = hashlib.sha256()
    for p in sorted(root.rglob("*")):
        if p.is_file() and "report" not in p.relative_to(root).parts:
            h.update(str(p.relative_to(root)).encode() + p.read_bytes())
    return h.hexdigest()


def run_cli(*args):
    return subprocess.run([PYTHON, "-m", "grainfrac_yade", "analyze", *map(str, args)],
                          capture_output=True, text=True, cwd=ROOT)


# ---------------------------------------------------------------- fits

def test_exponential_and_power_law_recover_noiseless_coefficients():
    r = np.repeat([0.55, 0.65, 0.75, 0.85, 0.95], 2)
    f = fit_lifetimes(r, np.exp(A_TRUE - B_TRUE * r))
    assert f.a == pytest.approx(A_TRUE, abs=1e-9) and f.b == pytest.approx(B_TRUE, abs=1e-9)
    assert f.exponential.r2 == pytest.approx(1.0, abs=1e-12)
    assert f.exponential.slope_se == pytest.approx(0.0, abs=1e-6)
    n_true, ln_a = 17.0, 9.5
    p = fit_lifetimes(r, np.exp(ln_a - n_true * np.log(r)))
    assert p.n == pytest.approx(n_true, abs=1e-9) and p.ln_A == pytest.approx(ln_a, abs=1e-9)
    assert p.lifetime_power(0.7) == pytest.approx(np.exp(ln_a) * 0.7 ** -n_true, rel=1e-9)


def test_noisy_fit_contains_truth_in_reported_interval_and_band():
    rng = np.random.default_rng(2024)
    r = np.repeat([0.6, 0.7, 0.8, 0.9, 0.95], 4)
    life = np.exp(A_TRUE - B_TRUE * r + rng.normal(0, 0.8, len(r)))
    f = fit_lifetimes(r, life)
    t = f.exponential.t_quantile()
    assert t == pytest.approx(2.1009, abs=1e-3)   # Student t, 95 %, 18 dof
    assert 0 < f.exponential.intercept_se and abs(f.a - A_TRUE) <= t * f.exponential.intercept_se
    assert abs(f.b - B_TRUE) <= t * f.exponential.slope_se
    assert abs(f.a - A_TRUE) > 1e-3   # the noise did move the estimate
    lo, hi = f.band_exponential(np.array([0.6, 0.78, 0.95]))
    truth = np.exp(A_TRUE - B_TRUE * np.array([0.6, 0.78, 0.95]))
    assert np.all(lo < truth) and np.all(truth < hi)
    width = np.log(hi / lo)
    assert width[1] < width[0] and width[1] < width[2]   # narrowest near the mean ratio
    n_true = 15.0
    p = fit_lifetimes(r, np.exp(8.0 - n_true * np.log(r) + rng.normal(0, 0.5, len(r))))
    assert abs(p.n - n_true) <= p.power.t_quantile() * p.power.slope_se


def test_line_fit_by_hand_and_two_point_limits():
    f = fit_line([0, 1, 2, 3], [1, 3, 2, 4])   # slope 0.8, intercept 1.3, SSR 1.8
    assert (f.intercept, f.slope) == pytest.approx((1.3, 0.8))
    assert f.slope_se == pytest.approx(np.sqrt(1.8 / 2 / 5.0))
    two = fit_line([0.6, 0.8], [10.0, 5.0])
    assert two.slope == pytest.approx(-25.0) and np.isnan(two.slope_se)
    assert fit_lifetimes([0.7, 0.7, 0.7], [1e3, 1e4, 1e5]) is None   # one ratio: no fit


@pytest.mark.parametrize("life", [np.nan, 0.0, -5.0])
def test_bad_lifetime_raises_one_line(life):
    with pytest.raises(GrainfracError, match="lifetime_s") as err:
        fit_lifetimes([0.6, 0.7, 0.8], [1e6, life, 1e4], source="my.csv")
    assert "my.csv" in str(err.value) and "\n" not in str(err.value)


def test_lifetime_stats_geometric_mean_and_spread():
    s = lifetime_stats([0.7, 0.7, 0.7, 0.8, 0.8], [1e2, 1e3, 1e4, 5.0, 6.0])
    assert list(s["driving_stress_ratio"]) == [0.7]   # 0.8 has only 2 points
    row = s.iloc[0]
    assert row["geomean_lifetime_s"] == pytest.approx(1e3) and row["spread_decades"] == pytest.approx(2.0)
    assert row["sd_log10_lifetime"] == pytest.approx(1.0) and row["n"] == 3


# ---------------------------------------------------------------- inputs

def test_lab_csv_reader_and_paper_reference(tmp_path):
    lab = tmp_path / "lab.csv"
    lab.write_text("# comment\ndriving_stress_ratio,lifetime_s\n0.8,100\n0.9,10\n")
    frame = read_lab_csv(lab)
    assert list(frame["source"]) == ["lab.csv", "lab.csv"] and frame["lifetime_s"].tolist() == [100, 10]
    bad = tmp_path / "bad.csv"
    bad.write_text("driving_stress_ratio,lifetime_s\n0.8,-3\n")
    with pytest.raises(GrainfracError, match="bad.csv.*lifetime_s"):
        read_lab_csv(bad)
    ref = paper_reference()
    values = pd.read_csv(ref.values_file).set_index("quantity")["value"]
    assert ref.lifetime_s == float(values["lifetime_at_160mpa"])
    assert ref.ratio == pytest.approx(160e6 / float(values["ucs_simulated"]))
    with pytest.raises(GrainfracError, match="paper_values.csv"):
        paper_reference(tmp_path)


def test_crack_segments_fallback_and_times():
    cracks = pd.DataFrame({"creep_time_s": [-1.0, 5.0, 20.0], "x_m": [1e-3, 2e-3, 3e-3], "y_m": [1e-3, 1e-3, 1e-3],
                           "face_normal_angle_deg": [0.0, 90.0, 45.0], "macro_time_s": [np.nan, 6.0, -1.0]})
    seg = crack_segments(cracks, grain_size=1e-3)
    assert np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1) == pytest.approx([1e-3] * 3)
    assert seg[0, :, 0] == pytest.approx([1e-3, 1e-3])          # normal along x -> face along y
    assert np.mean(seg, axis=1) == pytest.approx(cracks[["x_m", "y_m"]].to_numpy())
    micro, macro = cracks_at(cracks, 5.5)
    assert micro.tolist() == [True, True, False] and macro.tolist() == [False, False, False]
    micro, macro = cracks_at(cracks, 30.0)
    assert macro.tolist() == [False, True, True]


# ---------------------------------------------------------------- study

def test_unfinished_not_failed_and_unreadable_runs_are_listed_not_fitted(tmp_path):
    from grainfrac_yade.analysis.study import analyze_study
    study = make_study(tmp_path / "study")
    runs = classify_runs(collect_runs(study))
    outcome = dict(zip(runs["run"], runs["outcome"]))
    assert outcome["unfinished_run"] == "unfinished" and outcome["survivor_run"] == "not failed"
    assert outcome["broken_json_run"] == "unreadable" and outcome["ratio0.6_seed1"] == "failed"
    assert runs.set_index("run").loc["broken_json_run", "status"] == "unreadable"
    before = folder_digest(study)
    report = analyze_study(study, map_fractions=(0.5, 1.0))
    assert folder_digest(study) == before
    text = report.read_text()
    for name, state in (("unfinished_run", "unfinished"), ("survivor_run", "not failed"),
                        ("broken_json_run", "unreadable")):
        line = next(line for line in text.splitlines() if f"[{name}]" in line)
        assert f"| {state} |" in line
    assert "lower bound" in text and "not used in the fit" in text
    coef = pd.read_csv(report.parent / "lifetime_fits.csv")
    row = coef.set_index("dataset").loc["model"]
    assert row["n_points"] == len(RATIOS)   # only the failed runs
    assert row["a_ln_s"] == pytest.approx(A_TRUE, abs=1e-9) and row["b"] == pytest.approx(B_TRUE, abs=1e-9)
    listed = pd.read_csv(report.parent / "runs.csv")
    assert len(listed) == len(RATIOS) + 3


def test_one_ratio_skips_fit_but_gives_scatter(tmp_path):
    from grainfrac_yade.analysis.study import analyze_study
    study = make_study(tmp_path / "one", seeds=(1, 2, 3), ratios=(0.7,), extra=False, segments=False)
    for s, t in ((1, 1e4), (2, 1e5), (3, 1e7)):   # scatter of three decades
        f = study / f"ratio0.7_seed{s}" / "summary.json"
        f.write_text(f.read_text().replace(f'"lifetime_s": {true_lifetime(0.7)!r}', f'"lifetime_s": {t!r}'))
    report = analyze_study(study, map_fractions=(1.0,))
    text = report.read_text()
    assert "fit skipped" in text and "No data set had lifetimes at two or more distinct ratios" in text
    stats = pd.read_csv(report.parent / "lifetime_stats.csv")
    assert stats["n"].tolist() == [3] and stats["spread_decades"].iloc[0] == pytest.approx(3.0)
    assert "comparable with the lab's scatter" in text


def test_report_folder_inside_a_run_folder_is_refused(tmp_path):
    from grainfrac_yade.analysis.study import analyze_study
    study = make_study(tmp_path / "s", ratios=(0.7, 0.8), extra=False)
    with pytest.raises(GrainfracError, match="inside the run folder"):
        analyze_study(study, out=study / "ratio0.7_seed1" / "rep")


# ---------------------------------------------------------------- CLI

def _check_png(path):
    import matplotlib.image as mpimg
    assert path.stat().st_size > MIN_PNG_BYTES, path
    img = mpimg.imread(path)
    assert img.ndim == 3 and float(img[..., :3].std()) > 0.01, path


def test_cli_analyze_writes_report_and_all_figures(tmp_path):
    study = make_study(tmp_path / "study", seeds=(1, 2, 3))
    before = folder_digest(study)
    res = run_cli(study)
    assert res.returncode == 0, res.stderr
    report = study / "report" / "report.md"
    assert res.stdout.strip().endswith(str(report)) and report.exists()
    text = report.read_text()
    for name in FIGURES:
        _check_png(study / "report" / name)
        assert f"]({name})" in text
    assert "paper_values.csv" in text and "Lajtai & Schmidtke (1986)" in text and "none are drawn or invented" in text
    # cracks by phase of the life: every failed run's cracks, each counted once over ramp + four phases
    phases = pd.read_csv(study / "report" / "crack_phases.csv")
    assert "](crack_phases.md)" in text and (study / "report" / "crack_phases.md").exists()
    failed = sorted(f"ratio{r}_seed{s}" for r in RATIOS for s in (1, 2, 3))
    assert sorted(phases["run"].unique()) == failed
    for run, block in phases.groupby("run"):
        n_cracks = len(pd.read_csv(study / run / "cracks.csv"))
        assert block["cracks"].iloc[:5].sum() == n_cracks, run
    assert folder_digest(study) == before


def test_cli_lab_file_is_fitted_into_the_coefficient_table(tmp_path):
    study = make_study(tmp_path / "study", ratios=(0.6, 0.8), extra=False, segments=False)
    a_lab, b_lab = 40.0, 36.0
    r = np.array([0.7, 0.7, 0.8, 0.9])
    lab = tmp_path / "lab.csv"
    pd.DataFrame({"driving_stress_ratio": r, "lifetime_s": np.exp(a_lab - b_lab * r),
                  "source": ["test lab A", "test lab A", "test lab B", "test lab B"]}).to_csv(lab, index=False)
    res = run_cli(study, "--lab", lab, "--out", tmp_path / "rep")
    assert res.returncode == 0, res.stderr
    coef = pd.read_csv(tmp_path / "rep" / "lifetime_fits.csv").set_index("dataset")
    assert coef.loc["lab", "a_ln_s"] == pytest.approx(a_lab, abs=1e-6)
    assert coef.loc["lab", "b"] == pytest.approx(b_lab, abs=1e-6) and coef.loc["lab", "n_points"] == 4
    assert coef.loc["model", "b"] == pytest.approx(B_TRUE, abs=1e-9)
    text = (tmp_path / "rep" / "report.md").read_text()
    assert str(lab) in text and "| quantity | model | lab |" in text
    _check_png(tmp_path / "rep" / "lifetime.png")


def test_cli_lab_file_missing_column_exits_2_with_one_line(tmp_path):
    study = make_study(tmp_path / "study", ratios=(0.6, 0.8), extra=False)
    lab = tmp_path / "lab_no_life.csv"
    lab.write_text("driving_stress_ratio,time\n0.8,100\n")
    res = run_cli(study, "--lab", lab)
    assert res.returncode == 2
    err = res.stderr.strip()
    assert len(err.splitlines()) == 1 and "lab_no_life.csv" in err and "lifetime_s" in err
    assert not (study / "report").exists()


def test_cli_missing_study_and_empty_study_exit_2(tmp_path):
    from grainfrac_yade.cli import main
    assert main(["analyze", str(tmp_path / "nope")]) == 2
    (tmp_path / "empty").mkdir()
    assert main(["analyze", str(tmp_path / "empty")]) == 2


# ---------------------------------------------------------------- rescaling to another beta1

def test_rescaling_event_clock_study_divides_every_time_by_k(tmp_path):
    from grainfrac_yade.analysis.study import analyze_study, load_study, read_cracks, read_history
    study = make_study(tmp_path / "study", seeds=(1, 2), extra=False)
    write_run(study, "survivor_run", 0.55, 1, failed=False, end=3e8)
    k = 7.0
    base = analyze_study(study, out=tmp_path / "base", map_fractions=(1.0,), grains=False)
    fast = analyze_study(study, out=tmp_path / "fast", map_fractions=(1.0,), grains=False, beta1=k * BETA1_RUN)
    runs0 = pd.read_csv(base.parent / "runs.csv").set_index("run")
    runs1 = pd.read_csv(fast.parent / "runs.csv").set_index("run")
    for col in ("lifetime_s", "creep_time_end_s", "primary_end_s", "tertiary_start_s"):
        both = runs0[col].notna()
        assert both.sum() >= 1 and np.allclose(runs1.loc[both, col], runs0.loc[both, col] / k, rtol=1e-12, atol=0)
    assert runs1.loc["survivor_run", "creep_time_end_s"] == pytest.approx(3e8 / k, rel=1e-12)
    assert np.allclose(runs1["time_factor"], 1 / k, rtol=1e-15) and (runs1["beta1_run"] == BETA1_RUN).all()
    c0 = pd.read_csv(base.parent / "lifetime_fits.csv").set_index("dataset").loc["model"]
    c1 = pd.read_csv(fast.parent / "lifetime_fits.csv").set_index("dataset").loc["model"]
    assert c1["a_ln_s"] == pytest.approx(c0["a_ln_s"] - np.log(k), abs=1e-9)    # exp(a) / k
    assert c1["A_s"] == pytest.approx(c0["A_s"] / k, rel=1e-9)
    assert c1["b"] == pytest.approx(c0["b"], abs=1e-9) and c1["n"] == pytest.approx(c0["n"], abs=1e-9)
    assert c1["b_se"] == pytest.approx(c0["b_se"], rel=1e-9)
    # per-run files: history and crack times scaled, the ramp marker -1 kept
    runs = load_study(study, beta1=k * BETA1_RUN)
    folder = str(study / "ratio0.7_seed1")
    f = runs.set_index("folder").loc[folder, "time_factor"]
    h0, h1 = read_history(folder), read_history(folder, f)
    assert np.allclose(h1["creep_time_s"], h0["creep_time_s"] / k, rtol=1e-12, atol=0)
    cr0, cr1 = read_cracks(folder), read_cracks(folder, f)
    ramp = cr0["creep_time_s"] < 0
    assert ramp.any() and (cr1.loc[ramp, "creep_time_s"] == -1).all()
    assert np.allclose(cr1.loc[~ramp, "creep_time_s"], cr0.loc[~ramp, "creep_time_s"] / k, rtol=1e-12, atol=0)
    text = fast.read_text()
    head = text.split("## Runs")[0]
    assert "All creep times in this report are rescaled" in head and f"to beta1 = {k * BETA1_RUN:g} Pa/s" in head
    assert f"{BETA1_RUN:g} Pa/s" in head and "exact" in head
    assert "rescaled" not in base.read_text()


@pytest.mark.parametrize("clock,mode,reason", [("paper", "strength", "paper clock"),
                                               ("event", "area", "only the laws whose times scale with 1/beta1")])
def test_rescaling_refuses_paper_clock_and_area_runs(tmp_path, clock, mode, reason):
    from grainfrac_yade.analysis.study import analyze_study
    study = make_study(tmp_path / "study", ratios=(0.7, 0.8), extra=False)
    write_run(study, "odd_run", 0.75, 1, lifetime=1e6, clock=clock, mode=mode)
    with pytest.raises(GrainfracError) as err:
        analyze_study(study, out=tmp_path / "rep", beta1=2e-3)
    msg = str(err.value)
    assert "odd_run" in msg and reason in msg and "fix:" in msg and "\n" not in msg
    assert not (tmp_path / "rep").exists()
    analyze_study(study, out=tmp_path / "rep", map_fractions=(1.0,), grains=False)   # without --beta1: fine


def test_cli_beta1_file_and_its_errors(tmp_path, capsys):
    study = make_study(tmp_path / "study", ratios=(0.6, 0.8), extra=False, segments=False)
    toml = tmp_path / "calibrated.toml"
    toml.write_text("[stress_corrosion]\nbeta1 = 4e-3\n")
    res = run_cli(study, "--beta1-file", toml, "--out", tmp_path / "rep", "--map-fractions", "1")
    assert res.returncode == 0, res.stderr
    coef = pd.read_csv(tmp_path / "rep" / "lifetime_fits.csv").set_index("dataset")
    assert coef.loc["model", "a_ln_s"] == pytest.approx(A_TRUE - np.log(4.0), abs=1e-9)
    assert "--beta1-file" in (tmp_path / "rep" / "report.md").read_text()
    from grainfrac_yade.cli import main
    none = tmp_path / "none.toml"
    none.write_text("[stress_corrosion]\nbeta2 = 1e-7\n")
    for args, words in (([ "--beta1-file", str(tmp_path / "missing.toml")], ("missing.toml", "not found")),
                        (["--beta1-file", str(none)], ("none.toml", "beta1")), (["--beta1", "-1"], ("positive",))):
        capsys.readouterr()
        assert main(["analyze", str(study), "--out", str(tmp_path / "rep2"), *args]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and all(w in err for w in words), err
    assert not (tmp_path / "rep2").exists()


# ---------------------------------------------------------------- grains under the crack maps

SMALL = ["specimen.width=6e-3", "specimen.height=12e-3"]


@pytest.fixture(scope="module")
def real_run():
    """A real parameter set (small specimen), its specimen and layout as the run would build them."""
    from grainfrac_yade.grains.rigid import build_layout
    from grainfrac_yade.params import load_parameters
    from grainfrac_yade.geometry.specimen import build_specimen
    params = load_parameters(overrides=SMALL)
    seed = 5
    specimen = build_specimen(params, seed)
    return params, seed, specimen, build_layout(specimen, params.resolution.spheres_per_cell)


def write_real_run(root, real_run, name="real_run", n_bonds=None):
    """A synthetic creep run whose params.json is a real one and whose cracks sit on real bonds."""
    params, seed, specimen, layout = real_run
    tree = json.loads(json.dumps(params.to_dict()))
    d = write_run(root, name, 0.7, seed, lifetime=true_lifetime(0.7), params=tree,
                  n_bonds=layout.n_bonds if n_bonds is None else n_bonds)
    cracks = pd.read_csv(d / "cracks.csv")
    bond = np.arange(len(cracks)) * (layout.n_bonds // len(cracks))
    cracks["bond"] = bond
    cracks["x_m"], cracks["y_m"] = layout.bond_point[bond, 0], layout.bond_point[bond, 1]
    cracks.to_csv(d / "cracks.csv", index=False)
    return d


def test_parameters_from_json_round_trips_and_fills_older_files(tmp_path, real_run):
    from grainfrac_yade.analysis.runparams import load_run_parameters, parameters_from_json, rebuild_specimen
    from grainfrac_yade.grains.rigid import build_layout
    params, seed, specimen, layout = real_run
    d = write_real_run(tmp_path, real_run)
    assert parameters_from_json(d / "params.json") == params      # contacts "a/b", friction in degrees
    assert parameters_from_json(d) == params
    rebuilt = rebuild_specimen(d, seed, n_bonds=layout.n_bonds, cracks=pd.read_csv(d / "cracks.csv"))
    assert rebuilt.specimen.n_cells == specimen.n_cells
    assert np.array_equal(rebuilt.specimen.mineral, specimen.mineral)
    assert build_layout(rebuilt.specimen, params.resolution.spheres_per_cell).n_bonds == layout.n_bonds
    assert len(rebuilt.checks) == 2 and not rebuilt.run_params.filled
    # an older params.json without a key added later
    tree = json.loads((d / "params.json").read_text())
    del tree["stress_corrosion"]["rate_form"]
    (d / "params.json").write_text(json.dumps(tree))
    with pytest.raises(GrainfracError, match="rate_form"):
        parameters_from_json(d)
    old = load_run_parameters(d, fill_missing=True)
    assert old.filled == ("stress_corrosion.rate_form",) and old.params == params
    assert rebuild_specimen(d, seed).specimen.n_cells == specimen.n_cells
    del tree["specimen"]["lloyd_iterations"]   # shapes the tessellation: no rebuild
    (d / "params.json").write_text(json.dumps(tree))
    with pytest.raises(GrainfracError, match="lloyd_iterations"):
        rebuild_specimen(d, seed)
    with pytest.raises(GrainfracError, match="bonds"):
        rebuild_specimen(write_real_run(tmp_path, real_run, "other"), seed, n_bonds=layout.n_bonds + 1)


def _colours(path):
    import matplotlib.image as mpimg
    img = (mpimg.imread(path)[..., :3] * 255).astype(np.uint8)
    return len(np.unique(img.reshape(-1, 3), axis=0))


def test_crack_maps_drawn_on_the_rebuilt_grains_or_outline_with_reason(tmp_path, real_run):
    from grainfrac_yade.analysis.study import analyze_study
    study = tmp_path / "study"
    write_real_run(study, real_run)
    write_real_run(study, real_run, "real_run_2", n_bonds=None).joinpath("summary.json").write_text(
        (study / "real_run" / "summary.json").read_text().replace('"driving_stress_ratio": 0.7',
                                                                   '"driving_stress_ratio": 0.8'))
    report = analyze_study(study, out=tmp_path / "grains", map_fractions=(0.5, 1.0), focus_ratio=0.7)
    text = report.read_text()
    assert "Crack maps drawn on the run's grains" in text and "verified:" in text
    for by in ("mode", "kind"):
        _check_png(report.parent / f"crack_maps_{by}.png")
    plain = analyze_study(study, out=tmp_path / "plain", map_fractions=(0.5, 1.0), focus_ratio=0.7, grains=False)
    assert _colours(report.parent / "crack_maps_mode.png") > 2 * _colours(plain.parent / "crack_maps_mode.png")
    # a run whose records do not match its params.json: outline, the reason in the report, no crash
    summary = study / "real_run" / "summary.json"
    summary.write_text(summary.read_text().replace(f'"n_bonds": {real_run[3].n_bonds}', '"n_bonds": 3'))
    bad = analyze_study(study, out=tmp_path / "bad", map_fractions=(0.5, 1.0), focus_ratio=0.7)
    line = next(t for t in bad.read_text().splitlines() if "grains not drawn" in t)
    assert "real_run" in line and "3" in line and "outline" in line
    _check_png(bad.parent / "crack_maps_mode.png")


# ---------------------------------------------------------------- several studies, titles

def test_several_studies_fitted_separately_side_by_side(tmp_path, capsys):
    first = make_study(tmp_path / "alpha", ratios=(0.6, 0.8), extra=False, segments=False)
    second = tmp_path / "beta"
    for r in (0.6, 0.7, 0.9):
        write_run(second, f"r{r}", r, 1, lifetime=float(np.exp(20.0 - 10.0 * r)), segments=False)
    res = run_cli(first, second, "--out", tmp_path / "rep", "--map-fractions", "1", "--no-grains")
    assert res.returncode == 0, res.stderr
    coef = pd.read_csv(tmp_path / "rep" / "lifetime_fits.csv").set_index("dataset")
    assert coef.loc["alpha", "a_ln_s"] == pytest.approx(A_TRUE, abs=1e-9)
    assert coef.loc["beta", "a_ln_s"] == pytest.approx(20.0, abs=1e-9) and coef.loc["beta", "b"] == pytest.approx(10.0)
    text = (tmp_path / "rep" / "report.md").read_text()
    assert "| quantity | alpha | beta |" in text and "[alpha/ratio0.6_seed1]" in text
    from grainfrac_yade.cli import main
    assert main(["analyze", str(first), str(second)]) == 2
    assert "--out" in capsys.readouterr().err


def test_long_titles_are_wrapped_inside_the_figure():
    from grainfrac_yade.analysis.figures import _title
    from grainfrac_yade.analysis.plotting import plt
    fig, ax = plt.subplots(figsize=(4, 3))
    t = _title(ax, "Axial strain vs creep time (normalised) (paper Fig. 5); failure leaves the top of the axis")
    r = fig.canvas.get_renderer()
    assert "\n" in t.get_text()
    box = t.get_window_extent(r)
    assert box.x0 >= 0 and box.x1 <= fig.bbox.width
    short = _title(ax, "Damage index")
    assert "\n" not in short.get_text()
    plt.close(fig)


def test_a_run_that_failed_on_loading_is_its_own_outcome():
    from grainfrac_yade.analysis.lifetimes import outcome
    base = {"status": "finished", "command": "creep", "failed": True}
    assert outcome(dict(base, lifetime_s=0.0, failed_on_loading=True)) == "failed at load"
    assert outcome(dict(base, lifetime_s=0.0)) == "failed at load"          # older runs without the key
    assert outcome(dict(base, lifetime_s=12.5, failed_on_loading=False)) == "failed"


def test_first_creep_crack_is_the_earliest_bond_broken_at_the_held_load(tmp_path):
    """Ramp cracks (phase ramp, empty creep time) do not count; the time factor of a rescaled study applies; a run
    without creep cracks or without cracks.csv has none (NaN)."""
    cols = "bond,creep_time_s,phase,mode,kind,x_m,y_m,face_normal_angle_deg\n"
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "cracks.csv").write_text(cols + "0,,ramp,tensile,inter,0,0,0\n1,2.5,creep,shear,intra,0,0,0\n"
                                               "2,0.75,creep,tensile,inter,0,0,0\n")
    assert first_creep_crack(tmp_path / "a") == 0.75
    assert first_creep_crack(tmp_path / "a", time_factor=4.0) == 3.0
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / "cracks.csv").write_text(cols + "0,,ramp,tensile,inter,0,0,0\n")
    assert np.isnan(first_creep_crack(tmp_path / "b")) and np.isnan(first_creep_crack(tmp_path / "c"))


def test_an_integer_key_older_runs_lack_is_filled_as_the_newer_runs_read_it():
    """A key added with an integer default (a newer params.json has it, an older one not): the newer runs' column
    has gaps, so pandas reads it as floats; the filled default must read the same, or one model looks like two."""
    import pandas as pd
    from grainfrac_yade.analysis.study_runs import fill_missing_params, variant_labels
    runs = pd.DataFrame({"outcome": ["failed", "failed"], "specimen.width": [0.01, 0.01],
                         "numerics.static_low_rank_contacts": [None, 128]})
    runs["numerics.static_low_rank_contacts"] = runs["numerics.static_low_rank_contacts"].astype(float)
    filled, counts = fill_missing_params(runs)
    assert counts == {"numerics.static_low_rank_contacts": 1}
    assert filled["numerics.static_low_rank_contacts"].astype(str).nunique() == 1
    assert list(variant_labels(filled)) == ["model", "model"]
