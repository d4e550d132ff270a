"""Creep times of a study shown at another stress-corrosion rate beta1 (``analyze --beta1``).

With a strength law (paper Eq. 7: dJ/dt = -beta1 exp(beta2 sigma), or its strength-normalised form,
with or without an activation threshold) and the event clock, every
interval between bond failures is a strength margin divided by beta1 exp(beta2 sigma) under
frozen stresses, and the DEM relaxation in between does not know about time. So with beta2
unchanged the failure sequence is the same and every creep time is proportional to 1/beta1
(tests/test_creep.py checks lifetime(10 beta1) = lifetime / 10 to 1e-9 with YADE). A run made
with beta1_run therefore gives the run at beta1 exactly: t' = t * beta1_run / beta1.

Not exact, so refused (GrainfracError naming the run folder, the reason and the fix):

- the paper clock (Eq. 8): its steps dt_min, dt_max are absolute seconds and its step control
  depends on the unbalanced force, not on time, so the sequence changes with beta1;
- ``rate_form = "physical"``: beta1 and beta2 both come from Eq. 6 at a temperature;
- the area law: exact in principle, but no test checks it.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import GrainfracError
from ..law import scales_with_beta1, time_scaling_laws
from ..params import read_toml

#: Summary and table columns that are creep times [s] (wall_s is wall-clock time: not scaled).
TIME_COLUMNS = ("lifetime_s", "creep_time_end_s", "primary_end_s", "tertiary_start_s",
                "stress_corrosion.creep_time_limit")
#: Summary and table columns that are creep rates [1/s]: divided by the factor the times are multiplied by.
RATE_COLUMNS = ("min_creep_strain_rate_per_s",)
#: Per-run files' creep-time columns; negative values are markers (-1 = broken during the ramp).
HISTORY_TIME_COLUMNS = ("creep_time_s",)
CRACK_TIME_COLUMNS = ("creep_time_s", "macro_time_s")
WHY_EXACT = ("in strength mode with the event clock every creep time is proportional to 1/beta1 while the "
             "failure sequence is unchanged (Eq. 7 integrated under frozen stresses; tests/test_creep.py checks "
             "lifetime(10 beta1) = lifetime/10 to 1e-9), so t' = t * beta1_run / beta1 is the run at the new beta1")


def check_beta1(value, source: str = "--beta1") -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise GrainfracError(f"{source}: beta1 = {value!r} is not a number; fix: give beta1 in Pa/s, e.g. 1e-3") \
            from None
    if not (math.isfinite(v) and v > 0):
        raise GrainfracError(f"{source}: beta1 = {value!r} must be a finite positive rate; fix: give beta1 in "
                             "Pa/s, e.g. 1e-3")
    return v


def beta1_from_toml(path) -> float:
    """``[stress_corrosion] beta1`` of a TOML file (e.g. params/stress_corrosion_calibrated.toml)."""
    path = Path(path)
    data = read_toml(path)
    sc = data.get("stress_corrosion")
    if not isinstance(sc, dict) or "beta1" not in sc:
        raise GrainfracError(f"{path}: no [stress_corrosion] beta1; fix: add beta1 = ... [Pa/s] to its "
                             "[stress_corrosion] table (or use --beta1 VALUE)")
    return check_beta1(sc["beta1"], f"{path}: stress_corrosion.beta1")


def _text(v) -> str | None:
    return v if isinstance(v, str) else None


def not_rescalable(row: dict) -> str | None:
    """Why a run's times cannot be rescaled exactly (None if they can)."""
    clock = _text(row.get("stress_corrosion.clock"))
    law = _text(row.get("stress_corrosion.law"))
    form = _text(row.get("stress_corrosion.rate_form"))
    beta1 = pd.to_numeric(pd.Series([row.get("stress_corrosion.beta1")]), errors="coerce").iloc[0]
    if clock is None or law is None or not (beta1 > 0):
        return "params.json lacks stress_corrosion.clock, law or beta1, so the run's clock and rate are unknown"
    if clock != "event":
        return (f"clock = {clock!r}: the paper clock (Eq. 8) steps by absolute dt_min/dt_max seconds controlled "
                "by the unbalanced force, so its failure sequence changes with beta1")
    if form not in (None, "beta"):
        return f"rate_form = {form!r}: beta1 and beta2 both follow from Eq. 6, so beta2 is not held fixed"
    if not scales_with_beta1(law):
        return (f"law = {law!r}: only the laws whose times scale with 1/beta1 ({', '.join(time_scaling_laws())}) "
                "rescale exactly")
    return None


def time_factors(runs: pd.DataFrame, beta1: float, creep_outcomes) -> pd.Series:
    """Factor beta1_run / beta1 per run; GrainfracError (one line) if a creep run is not rescalable."""
    factors = pd.Series(np.nan, index=runs.index)
    bad = []
    for i, row in zip(runs.index, runs.to_dict("records")):
        if row.get("outcome") not in creep_outcomes:
            continue
        why = not_rescalable(row)
        if why:
            bad.append((row["folder"], why))
        else:
            factors[i] = float(row["stress_corrosion.beta1"]) / beta1
    if bad:
        folder, why = bad[0]
        more = f" (and {len(bad) - 1} more run(s))" if len(bad) > 1 else ""
        raise GrainfracError(f"{folder}: cannot rescale times to beta1 = {beta1:g} Pa/s{more}: {why}; fix: run "
                             "without --beta1, or analyze only event-clock runs of a strength law (rerun this one "
                             f"with --set stress_corrosion.beta1={beta1:g})")
    return factors


def scale_times(frame: pd.DataFrame | None, factor: float, columns) -> pd.DataFrame | None:
    """Copy of ``frame`` with the non-negative values of ``columns`` multiplied by ``factor``
    (negative values are markers such as -1 = during the ramp and stay)."""
    if frame is None or factor == 1.0 or not math.isfinite(factor):
        return frame
    frame = frame.copy()
    for c in columns:
        if c in frame:
            v = pd.to_numeric(frame[c], errors="coerce")
            frame[c] = v.where(~(v >= 0), v * factor)
    return frame


def rescale_runs(runs: pd.DataFrame, beta1: float, creep_outcomes) -> pd.DataFrame:
    """Runs with every creep-time column scaled to ``beta1``; adds ``beta1_run`` and ``time_factor``
    and sets ``stress_corrosion.beta1`` to ``beta1`` (runs that differed only in beta1 are then
    one model)."""
    factors = time_factors(runs, beta1, creep_outcomes)
    runs = runs.copy()
    runs["beta1_run"] = pd.to_numeric(runs.get("stress_corrosion.beta1"), errors="coerce")
    runs["time_factor"] = factors.fillna(1.0)
    ok = factors.notna()
    for c in TIME_COLUMNS:
        if c in runs:
            v = pd.to_numeric(runs[c], errors="coerce")
            runs[c] = v.where(~ok, v * runs["time_factor"])
    for c in RATE_COLUMNS:
        if c in runs:
            v = pd.to_numeric(runs[c], errors="coerce")
            runs[c] = v.where(~ok, v / runs["time_factor"])
    runs.loc[ok, "stress_corrosion.beta1"] = beta1
    return runs
