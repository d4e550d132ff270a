"""Axial creep strain rate against time of a study's failed runs (``analyze``): strain_rate.csv and strain_rate.png.

The rate at each point is the windowed least-squares slope of :func:`.creep_analysis.local_rates` (a window of
``STAGE_WINDOW`` of the lifetime on the normalised time grid, the history before the collapse row), the same
rates the creep stages and the minimum creep strain rate come from; only where the history resolves the stages
(:func:`.creep_analysis.resolve_creep_stages`): a history of a few events has no rate curve to tell.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from .creep_analysis import local_rates, resolve_creep_stages
from .figures import _save, _title
from .plotting import plt

#: Columns of strain_rate.csv.
COLUMNS = ("run", "variant", "seed", "driving_stress_ratio", "normalised_time", "creep_time_s",
           "axial_strain_rate_per_s")


def rate_curve(history: pd.DataFrame, lifetime: float) -> pd.DataFrame | None:
    """(normalised time, creep time [s], axial strain rate [1/s]) of a failed run's history, or None where the
    history does not resolve its creep stages."""
    t = history["creep_time_s"].to_numpy(float)[:-1]
    eps = history["axial_strain"].to_numpy(float)[:-1]
    if resolve_creep_stages(t, eps, lifetime).unresolved:
        return None
    tau, rate = local_rates(t, eps, lifetime)
    keep = np.isfinite(rate)
    return pd.DataFrame({"normalised_time": tau[keep], "creep_time_s": tau[keep] * lifetime,
                         "axial_strain_rate_per_s": rate[keep]})


def strain_rate_table(runs: pd.DataFrame, read_history) -> pd.DataFrame:
    """One block of :func:`rate_curve` rows per failed run whose history resolves it (``read_history(row)``:
    the run's history, its times as the report shows them, or None)."""
    blocks = []
    for r in runs[runs["outcome"] == "failed"].to_dict("records"):
        hist = read_history(r)
        life = float(pd.to_numeric(pd.Series([r.get("lifetime_s")]), errors="coerce").iloc[0])
        if hist is None or len(hist) < 3 or not np.isfinite(life) or life <= 0:
            continue
        curve = rate_curve(hist, life)
        if curve is not None:
            blocks.append(curve.assign(run=r["run"], variant=r.get("variant"), seed=r.get("seed"),
                                       driving_stress_ratio=r.get("driving_stress_ratio")))
    if not blocks:
        return pd.DataFrame(columns=list(COLUMNS))
    return pd.concat(blocks, ignore_index=True)[list(COLUMNS)]


def strain_rate_figure(path, table: pd.DataFrame, runs: pd.DataFrame) -> None:
    """Axial creep strain rate (log) against t / t_f of the runs named in ``runs`` (one per load; a run's label
    by run name), its minimum creep strain rate as a dashed line (column ``min_creep_strain_rate_per_s`` of
    ``runs``, a DataFrame of those runs)."""
    fig, ax = plt.subplots(figsize=(7, 4.6))
    cmap = plt.cm.plasma
    rows = runs.to_dict("records")
    for k, r in enumerate(rows):
        g = table[table["run"] == r["run"]]
        positive = g["axial_strain_rate_per_s"] > 0   # a log axis: a window without strain change has rate 0
        colour = cmap(0.85 * k / max(len(rows) - 1, 1))
        ax.plot(g.loc[positive, "normalised_time"], g.loc[positive, "axial_strain_rate_per_s"], color=colour,
                lw=1.1, label=f"r = {r['driving_stress_ratio']:.3f}, seed {r.get('seed')}")
        rate = r.get("min_creep_strain_rate_per_s")
        if rate is not None and np.isfinite(rate) and rate > 0:
            ax.axhline(rate, color=colour, lw=0.8, ls="--")
    ax.set_yscale("log")
    ax.set_xlim(0, 1.02)
    ax.set_xlabel("normalised creep time t / t_f [-]")
    ax.set_ylabel("axial creep strain rate [1/s]")
    _title(ax, "Axial creep strain rate vs time (window of 0.1 t_f); dashed: minimum (secondary) rate")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=6, loc="upper center")
    _save(fig, path)
