"""Creep-test results from a run's history (pure numpy): stages, damage index.

Creep stages (primary, secondary, tertiary) from a strain-time history that may
be step-like (the event clock moves strain only at events):

1. Normalise time by the lifetime, tau = t / t_f, and interpolate the strain
   linearly onto ``STAGE_GRID`` points of tau in [0, 1].
2. Strain rate at each grid point = slope of the least-squares line through the
   strain within a window of ``STAGE_WINDOW`` of the lifetime centred on it
   (a step inside the window becomes a finite rate, so steps do not make spikes).
   The slope is the closed form sum((x - mean x) (y - y_0)) / sum((x - mean x)^2):
   a window where the strain does not change has a rate of exactly 0.
3. Secondary creep is where the rate is within ``STAGE_RATE_FACTOR`` x its
   minimum, the minimum taken no lower than ``STAGE_RATE_FLOOR`` x the mean
   creep rate of the life: primary ends at the first such point, tertiary
   starts after the last.

The floor is what makes the stages a property of the curve rather than of its
last bits.  Between two events of the event clock the strain is constant, so the
smallest local rate is 0, or a rounding residue of 0 from the fit; "within
1.5 x the minimum" of a residue picks grid points at random, and a 1e-12 change
of the history (another CPU's rounding) moved the stages by 10 % of the life.

The stages are *not resolved* (None, with the reason) when the history before
the collapse has fewer than ``STAGE_MIN_EVENTS`` creep times after the start
(three per stage), when it shows no creep strain, or when no secondary stage
lies between primary and tertiary creep.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

STAGE_GRID = 201          # points on the normalised time axis
STAGE_WINDOW = 0.1        # fraction of the lifetime used for each local rate
STAGE_RATE_FACTOR = 1.5   # rate within this factor of the minimum counts as secondary creep
#: Smallest minimum rate, as a fraction of the mean creep rate over the life (see module doc).
STAGE_RATE_FLOOR = 0.1
#: Fewest creep times after the start (events, or records of the paper clock) for three stages:
#: three per stage.
STAGE_MIN_EVENTS = 9


class CreepStages(NamedTuple):
    """End of primary and start of tertiary creep [s], or None with ``unresolved`` saying why."""
    primary_end_s: float | None
    tertiary_start_s: float | None
    unresolved: str | None = None


def local_rates(time, strain, t_end=None):
    """(tau grid, strain rate [1/s]) on the normalised time grid (see module doc)."""
    time, strain = np.asarray(time, float), np.asarray(strain, float)
    t_end = float(time[-1]) if t_end is None else float(t_end)
    tau = np.linspace(0.0, 1.0, STAGE_GRID)
    eps = np.interp(tau * t_end, time, strain)
    half = STAGE_WINDOW / 2
    rate = np.full_like(tau, np.nan)
    for i, c in enumerate(tau):
        sel = (tau >= c - half) & (tau <= c + half)
        x, y = tau[sel] * t_end, eps[sel]
        dx = x - x.mean()
        sxx = float(np.dot(dx, dx))
        if sxx > 0:
            rate[i] = float(np.dot(dx, y - y[0])) / sxx
    return tau, rate


def resolve_creep_stages(time, strain, t_end=None) -> CreepStages:
    """Creep stages of a strain-time history (see module doc); ``t_end`` defaults to the last time."""
    time, strain = np.asarray(time, float), np.asarray(strain, float)
    if len(time) < 2 or not np.isfinite(time[-1]):
        return CreepStages(None, None, "no creep history")
    t_end = float(time[-1]) if t_end is None else float(t_end)
    if not np.isfinite(t_end) or t_end <= 0:
        return CreepStages(None, None, "no creep time")
    n_events = len(np.unique(time[(time > 0) & (time < t_end)]))
    if n_events < STAGE_MIN_EVENTS:
        return CreepStages(None, None, f"{n_events} creep times before the collapse, "
                                       f"at least {STAGE_MIN_EVENTS} needed for three stages")
    tau, rate = local_rates(time, strain, t_end)
    mean_rate = abs(float(np.interp(t_end, time, strain) - strain[0])) / t_end
    if not mean_rate > 0:
        return CreepStages(None, None, "no creep strain")
    inner = (tau >= STAGE_WINDOW / 2) & (tau <= 1 - STAGE_WINDOW / 2) & np.isfinite(rate)
    if not inner.any():
        return CreepStages(None, None, "no local strain rate")
    magnitude = np.abs(rate)
    rmin = max(float(np.min(magnitude[inner])), STAGE_RATE_FLOOR * mean_rate)
    secondary = np.flatnonzero(inner & (magnitude <= STAGE_RATE_FACTOR * rmin))
    if len(secondary) < 2:
        return CreepStages(None, None, "no secondary stage between primary and tertiary creep")
    return CreepStages(float(tau[secondary[0]] * t_end), float(tau[secondary[-1]] * t_end))


class MinimumCreepRate(NamedTuple):
    """Minimum (secondary) creep strain rate [1/s], or None with ``unresolved`` saying why."""
    rate_per_s: float | None
    unresolved: str | None = None


def minimum_creep_rate(time, strain, t_end=None) -> MinimumCreepRate:
    """The minimum (secondary) axial creep strain rate of a history [1/s]: the secant rate over the secondary
    stage of :func:`resolve_creep_stages`, (eps(t_t) - eps(t_p)) / (t_t - t_p) between the end of primary creep
    t_p and the start of tertiary creep t_t, the strain interpolated linearly in the history.

    The secondary stage is where the windowed rate (a least-squares slope over ``STAGE_WINDOW`` of the life)
    stays within ``STAGE_RATE_FACTOR`` x its floored minimum (module doc), so the window is one the history
    resolves: the primary stage and the tertiary one before failure are outside it, and a step-like history
    (the event clock moves strain only at events) gives the mean rate over its steps, not the 0 between two.
    None (with the reason) where the stages are not resolved.  ``time``, ``strain``: the hold's history before
    the collapse; ``t_end``: the lifetime."""
    stages = resolve_creep_stages(time, strain, t_end)
    if stages.unresolved:
        return MinimumCreepRate(None, stages.unresolved)
    time, strain = np.asarray(time, float), np.asarray(strain, float)
    t_p, t_t = stages.primary_end_s, stages.tertiary_start_s
    eps = np.interp([t_p, t_t], time, strain)
    return MinimumCreepRate(float((eps[1] - eps[0]) / (t_t - t_p)))


def creep_stages(time, strain, t_end=None):
    """(end of primary, start of tertiary creep) [s]; (None, None) when not resolved."""
    stages = resolve_creep_stages(time, strain, t_end)
    return stages.primary_end_s, stages.tertiary_start_s


def damage_index(broken_count, broken_at_failure):
    """Damage index D_n = N(t) / N(t_f) (paper Eq. 9), counting creep-phase breaks."""
    n = np.asarray(broken_count, float)
    return n / broken_at_failure if broken_at_failure > 0 else np.zeros_like(n)
