"""Lifetimes of creep runs: which runs enter a fit, which are lower bounds; scatter per load level.

Outcome of each run folder (column ``outcome``):

- ``failed``: the specimen failed at creep time t_f > 0 (a point of the lifetime fit);
- ``failed at load``: failed at creep time 0 (no creep life; ln 0 is undefined, so not in the fit);
- ``not failed``: the run ended at ``creep_time_end_s`` without failure: a lower bound of the
  lifetime, drawn but not fitted;
- ``numerical failure``: the run stopped on NaN/inf numbers or a stalled clock (summary key
  ``numerical_failure``): no result, listed with its reason, never a lifetime or a lower bound;
- ``failed before test``: a confined specimen broke apart in the isotropic stage (summary key
  ``failed_before_test``): no creep test, listed with its reason, never a lifetime or a lower bound;
- ``unfinished``: no summary.json yet (running, killed or crashed, or a SLURM row not started yet);
- ``run error``: no summary.json, and the batch task that ran it recorded an error (failed.json);
- ``unreadable``: a JSON file that cannot be parsed, or a summary that contradicts itself;
- ``not creep``: another command's run in the same folder (e.g. a UCS test), ignored.
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ..law.hillig_charles import NAME as PAPER_LAW

from .collect import ENGINE_BEFORE_THE_KEY, ENGINE_COLUMN
from .durations import readable_duration
from .fits import RATIO_DECIMALS

#: Minimum number of failed runs at one ratio for a scatter statistic (three seeds per ratio, as the lifetime studies run).
MIN_SEEDS_FOR_STATS = 3


def _num(value) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        return float("nan")
    return value


def outcome(row) -> str:
    """Outcome of one row of :func:`~grainfrac_yade.analysis.collect.collect_runs` (see module doc)."""
    if row.get("status") == "unreadable":
        return "unreadable"
    if row.get("command") != "creep":
        return "not creep"
    if row.get("status") == "failed":
        return "run error"
    if row.get("status") != "finished":
        return "unfinished"
    if row.get("numerical_failure") in (True, 1):
        return "numerical failure"
    if row.get("failed_before_test") in (True, 1):
        return "failed before test"
    failed = row.get("failed")
    if failed is True or failed == 1:
        if row.get("failed_on_loading") is True:
            return "failed at load"
        life = _num(row.get("lifetime_s"))
        if not math.isfinite(life) or life < 0:
            return "unreadable"
        return "failed" if life > 0 else "failed at load"
    if failed is False or failed == 0:
        return "not failed" if math.isfinite(_num(row.get("creep_time_end_s"))) else "unreadable"
    return "unreadable"


def classify_runs(runs: pd.DataFrame) -> pd.DataFrame:
    """Copy of ``runs`` with ``outcome`` and a load-level column ``ratio`` (rounded driving-stress ratio)."""
    runs = runs.copy()
    if runs.empty:
        runs["outcome"] = pd.Series(dtype=object)
        runs["ratio"] = pd.Series(dtype=float)
        return runs
    runs["outcome"] = [outcome(r) for r in runs.to_dict("records")]
    ratio = runs["driving_stress_ratio"] if "driving_stress_ratio" in runs else pd.Series(np.nan, index=runs.index)
    runs["ratio"] = pd.to_numeric(ratio, errors="coerce").round(RATIO_DECIMALS)
    return runs


def lifetime_stats(ratio, lifetime, min_count: int = MIN_SEEDS_FOR_STATS) -> pd.DataFrame:
    """Scatter of lifetimes per ratio with at least ``min_count`` points.

    Geometric mean 10^mean(log10 t) (also in a readable unit, :func:`.durations.readable_duration`), standard
    deviation of log10 t (sample, ddof 1), min, max and the spread log10(max / min) in decades.
    """
    frame = pd.DataFrame({"ratio": np.round(np.asarray(ratio, float), RATIO_DECIMALS),
                          "log10_t": np.log10(np.asarray(lifetime, float))})
    rows = []
    for r, g in frame.groupby("ratio"):
        if len(g) < min_count:
            continue
        lg = g["log10_t"].to_numpy()
        rows.append({"driving_stress_ratio": r, "n": len(lg), "geomean_lifetime_s": 10 ** lg.mean(),
                     "geomean_lifetime_readable": readable_duration(10 ** lg.mean()),
                     "sd_log10_lifetime": lg.std(ddof=1), "min_lifetime_s": 10 ** lg.min(),
                     "max_lifetime_s": 10 ** lg.max(), "spread_decades": lg.max() - lg.min()})
    columns = ["driving_stress_ratio", "n", "geomean_lifetime_s", "geomean_lifetime_readable", "sd_log10_lifetime",
               "min_lifetime_s", "max_lifetime_s", "spread_decades"]
    return pd.DataFrame(rows, columns=columns)


def representatives(runs: pd.DataFrame) -> pd.DataFrame:
    """One run per (variant, ratio): the failed run with the median lifetime, else the longest
    not-failed run, else the failed-at-load run with the lowest seed."""
    keep = []
    usable = runs[runs["outcome"].isin(["failed", "not failed", "failed at load"]) & runs["ratio"].notna()]
    for _, g in usable.groupby(["variant", "ratio"], sort=True):
        failed = g[g["outcome"] == "failed"].sort_values("lifetime_s")
        if len(failed):
            keep.append(failed.index[(len(failed) - 1) // 2])
            continue
        survived = g[g["outcome"] == "not failed"].sort_values("creep_time_end_s")
        keep.append(survived.index[-1] if len(survived) else g.sort_values("seed").index[0])
    return runs.loc[keep].sort_values(["variant", "ratio"])


#: Columns of the lifetime-against-confinement table.
CONFINEMENT_COLUMNS = ("law", "engine", "ratio", "confining_stress_mpa", "n", "n_failed", "lifetime_geomean_s",
                       "lifetime_min_s", "lifetime_max_s")


def with_confinement_columns(runs: pd.DataFrame) -> pd.DataFrame:
    """Copy of ``runs`` with ``confining_stress_mpa`` (confinement.stress in MPa; 0 where a run's
    params.json predates the key: it was uniaxial) and ``law_label`` (stress_corrosion.law; the
    paper's law where missing, the only one there was) and ``engine_label`` (the run's engine, :data:`.collect.
    ENGINE_COLUMN`; YADE where a table has no such column, the only engine there was)."""
    out = runs.copy()
    engine = out[ENGINE_COLUMN] if ENGINE_COLUMN in out else pd.Series(ENGINE_BEFORE_THE_KEY, index=out.index)
    out["engine_label"] = engine.fillna(ENGINE_BEFORE_THE_KEY)
    s3 = out["confinement.stress"] if "confinement.stress" in out else pd.Series(0.0, index=out.index)
    out["confining_stress_mpa"] = pd.to_numeric(s3, errors="coerce").fillna(0.0) / 1e6
    law = out["stress_corrosion.law"] if "stress_corrosion.law" in out else pd.Series(PAPER_LAW, index=out.index)
    out["law_label"] = law.fillna(PAPER_LAW)
    return out


def confinement_lifetimes(runs: pd.DataFrame) -> pd.DataFrame:
    """Creep lifetimes per degradation law, engine, driving-stress ratio and confining stress sigma_3 of
    ``runs`` (with :func:`with_confinement_columns`): runs (``outcome`` failed, failed at load or not
    failed), failed ones, and the geometric mean, minimum and maximum of the failed runs' lifetimes
    (a lifetime of 0, failed at load, gives a mean of 0)."""
    usable = runs[runs["outcome"].isin(["failed", "not failed", "failed at load"]) & runs["ratio"].notna()]
    rows = []
    for (law, engine, ratio, s3), g in usable.groupby(["law_label", "engine_label", "ratio", "confining_stress_mpa"]):
        failed = g[g["outcome"].isin(["failed", "failed at load"])]
        t = pd.to_numeric(failed["lifetime_s"], errors="coerce").to_numpy(float)
        geo = float(np.exp(np.mean(np.log(t)))) if len(t) and np.all(t > 0) else (0.0 if len(t) else np.nan)
        rows.append((law, engine, ratio, s3, len(g), len(failed), geo, t.min() if len(t) else np.nan,
                     t.max() if len(t) else np.nan))
    return pd.DataFrame(rows, columns=CONFINEMENT_COLUMNS)
