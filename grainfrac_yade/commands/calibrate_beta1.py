"""``calibrate-beta1``: one factor on beta1 so that the model's lifetime at the paper's reference
load (160 MPa, paper section 4.1) matches the paper's UDEC lifetime (1.62e4 s); writes
``params/stress_corrosion_calibrated.toml``.

Why one factor is enough: with a strength law (paper Eq. 7) and the event clock every time to
failure is (J - s) / (beta1 exp(beta2 s)) and the degradation of every other bond over that interval
is beta1 exp(beta2 s) dt, independent of beta1; so the whole failure sequence is unchanged and all
creep times scale exactly as 1/beta1 (tests/test_creep.py checks this to 1e-9). The factor is the
geometric mean of the seeds' lifetimes at the paper's load over the paper's lifetime.  Never tuned
per run: the file is used as it is for every load (``--params``).  To fit beta2 and an activation
threshold too, against lab lifetimes at several loads: ``calibrate-lifetimes``.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..errors import GrainfracError
from ..law import scales_with_beta1
from ..params import write_parameter_file
from ..runs.runio import code_version

#: Relative tolerance on the creep stress when selecting runs at the paper's load.
STRESS_MATCH_RTOL = 1e-6


def register(sub, common):
    p = sub.add_parser("calibrate-beta1", help="fit one factor on beta1 to the paper's lifetime at 160 MPa")
    p.add_argument("folder", help="study folder with event-clock, strength-mode creep runs at the paper's load")
    p.add_argument("--out", default=None, help="TOML to write (default params/stress_corrosion_calibrated.toml)")
    p.add_argument("--reference", default=None, help="folder holding paper_values.csv (default params/reference: copies of the reference values the project ships)")
    p.set_defaults(func=cmd_calibrate_beta1)


def beta1_factor(lifetimes, target_s: float) -> dict:
    """Factor on beta1 making the geometric-mean lifetime equal ``target_s`` (lifetime ~ 1/beta1)."""
    t = np.asarray(lifetimes, float)
    log_t = np.log(t)
    geo = float(np.exp(log_t.mean()))
    return {"factor": geo / target_s, "geometric_mean_s": geo,
            "log10_sd": float(np.std(np.log10(t), ddof=1)) if len(t) > 1 else float("nan")}


def select_reference_runs(runs, stress_pa: float):
    """Event-clock creep runs of a strength law at ``stress_pa`` that failed in creep: a positive lifetime,
    as the lifetime analysis classifies them (a run that ran away at creep time 0 failed at load)."""
    from ..analysis.lifetimes import classify_runs
    need = ("stress_pa", "lifetime_s", "failed", "clock", "law")
    if runs.empty or any(c not in runs for c in need):
        raise GrainfracError("no finished creep runs in the folder; fix: run params/lifetime_ldb.table first")
    runs = classify_runs(runs)
    sel = runs[(runs["outcome"] == "failed")
               & np.isclose(runs["stress_pa"].astype(float), stress_pa, rtol=STRESS_MATCH_RTOL, atol=0)
               & (runs["clock"] == "event") & runs["law"].map(scales_with_beta1).astype(bool)]
    if len(sel) < 2:
        raise GrainfracError(f"{len(sel)} failed event-clock strength-law run(s) at {stress_pa / 1e6:g} MPa; "
                             "fix: at least 2 seeds at the paper's load are needed (params/lifetime_ldb.table)")
    betas = sel["stress_corrosion.beta1"].astype(float).unique()
    if len(betas) != 1:
        raise GrainfracError(f"runs at {stress_pa / 1e6:g} MPa used different beta1 {list(betas)}; fix: one study, one beta1")
    return sel, float(betas[0])


def cmd_calibrate_beta1(args) -> int:
    from ..analysis.collect import collect_runs
    from ..analysis.labdata import paper_reference
    folder = Path(args.folder)
    if not folder.is_dir():
        raise GrainfracError(f"{folder}: study folder not found; fix: give the folder of the creep study")
    ref = paper_reference(args.reference)
    runs, beta1_run = select_reference_runs(collect_runs(folder), ref.stress_pa)
    fit = beta1_factor(runs["lifetime_s"].astype(float), ref.lifetime_s)
    beta1 = beta1_run * fit["factor"]
    out = Path(args.out or Path(__file__).resolve().parents[2] / "params" / "stress_corrosion_calibrated.toml")
    header = [
        "Calibrated stress-corrosion rate: ONE factor on beta1, the same for every load.",
        f"Use: --params {out.name if out.parent.name == 'params' else out}   (merged over params/stress_corrosion.toml)",
        f"Written by: python3 -m grainfrac_yade calibrate-beta1 {folder}   ({code_version()})",
        f"Target: the paper's UDEC lifetime {ref.lifetime_s:.6g} s at {ref.stress_pa / 1e6:g} MPa ({ref.values_file.name}).",
        f"Model runs at that load (event clock, strength law, beta1 = {beta1_run:g} Pa/s):",
        *(f"  seed {int(r['seed'])}: lifetime {r['lifetime_s']:.4g} s, {int(r['n_events'])} events ({r['run']})"
          for _, r in runs.sort_values("seed").iterrows()),
        f"Geometric mean {fit['geometric_mean_s']:.4g} s (sd of log10 t: {fit['log10_sd']:.2f}) -> factor {fit['factor']:.4g}.",
        "Exact for the event clock with a strength law: every creep time scales as 1/beta1 (tests/test_creep.py).",
        "beta2 stays the paper's value: the factor is a time scale, not a change of stress sensitivity.",
    ]
    write_parameter_file(out, {"stress_corrosion.beta1": beta1}, header,
                         {"stress_corrosion.beta1": f"= {beta1_run:g} x {fit['factor']:.6g} (fitted; paper: {beta1_run:g})"})
    print(f"beta1 factor {fit['factor']:.4g} (geometric mean {fit['geometric_mean_s']:.4g} s over {len(runs)} seeds "
          f"vs paper {ref.lifetime_s:.4g} s) -> beta1 = {beta1:.4g} Pa/s written to {out}")
    return 0
