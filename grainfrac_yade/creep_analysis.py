"""Creep-test results from a run's history (pure numpy): stages, damage index.

Creep stages (primary, secondary, tertiary) from a strain-time history that may
be step-like (the event clock moves strain only at events):

1. Normalise time by the lifetime, tau = t / t_f, and interpolate the strain
   linearly onto ``STAGE_GRID`` points of tau in [0, 1].
2. Strain rate at each grid point = slope of a least-squares line through the
   strain within a window of ``STAGE_WINDOW`` of the lifetime centred on it
   (a step inside the window becomes a finite rate, so steps do not make spikes).
3. Secondary creep is where the rate is within ``STAGE_RATE_FACTOR`` x its
   minimum: primary ends at the first such point, tertiary starts after the last.
"""
from __future__ import annotations

import numpy as np

STAGE_GRID = 201          # points on the normalised time axis
STAGE_WINDOW = 0.1        # fraction of the lifetime used for each local rate
STAGE_RATE_FACTOR = 1.5   # rate within this factor of the minimum counts as secondary creep


def local_rates(time, strain, t_end=None):
    """(tau grid, strain rate [1/s]) on the normalised time grid (see module doc)."""
    time, strain = np.asarray(time, float), np.asarray(strain, float)
    t_end = float(time[-1]) if t_end is None else float(t_end)
    tau = np.linspace(0.0, 1.0, STAGE_GRID)
    eps = np.interp(tau * t_end, time, strain)
    half = STAGE_WINDOW / 2
    rate = np.empty_like(tau)
    for i, c in enumerate(tau):
        sel = (tau >= c - half) & (tau <= c + half)
        x = tau[sel] * t_end
        rate[i] = np.polyfit(x, eps[sel], 1)[0] if np.ptp(x) > 0 else np.nan
    return tau, rate


def creep_stages(time, strain, t_end=None):
    """Ends of primary and start of tertiary creep [s]; (None, None) if too few points."""
    time = np.asarray(time, float)
    if len(time) < 3 or not np.isfinite(time[-1]) or time[-1] <= 0:
        return None, None
    t_end = float(time[-1]) if t_end is None else float(t_end)
    tau, rate = local_rates(time, strain, t_end)
    inner = (tau >= STAGE_WINDOW / 2) & (tau <= 1 - STAGE_WINDOW / 2)
    r = np.where(inner, rate, np.nan)
    if not np.any(np.isfinite(r)):
        return None, None
    rmin = np.nanmin(np.abs(r))
    secondary = np.flatnonzero(inner & (np.abs(rate) <= STAGE_RATE_FACTOR * max(rmin, 1e-300)))
    if not len(secondary):
        return None, None
    return float(tau[secondary[0]] * t_end), float(tau[secondary[-1]] * t_end)


def damage_index(broken_count, broken_at_failure):
    """Damage index D_n = N(t) / N(t_f) (paper Eq. 9), counting creep-phase breaks."""
    n = np.asarray(broken_count, float)
    return n / broken_at_failure if broken_at_failure > 0 else np.zeros_like(n)
