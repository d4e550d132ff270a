"""Fit a strength law's beta1, beta2 (and optionally its activation threshold) to lab lifetimes, in ln t,
by least squares (pure: the model is a function that returns lifetimes; no YADE here).

With a strength law and the event clock beta1 is an exact time scale (every creep time is proportional
to 1/beta1, :mod:`.rescale`): the model is run at the study's beta1_run once per beta2 and threshold,
and a trial beta1 shifts its ln t by -ln(beta1/beta1_run).  beta2 and the threshold change the
sequence of failures and need new runs; the caller's ``model(beta2, threshold)`` makes them.

The data: lab points (ratio r_i, lifetime t_i).  The model at a ratio: the geometric mean of its seeds'
lifetimes, or, where a seed did not fail by the creep-time limit, a lower bound (censored).  Residual
of point i: ln t_model(r_i) - ln(beta1/beta1_run) - ln t_i; a censored model value only says
"at least", so its residual is max(that, 0) (a lab life beyond the model's bound is no misfit).
The fit minimises the sum of squared residuals over ln(beta1/beta1_run) and ln beta2 by variable
projection: for any beta2 the best beta1 is exact (the mean residual of the uncensored points, as beta1
only shifts ln t), and :func:`scipy.optimize.least_squares` searches ln beta2 on those residuals; the
derivative is a secant through an earlier run of another beta2 within SECANT_RANGE, else one more set of
runs at beta2 e^FD_STEP.  A threshold is
fitted by trying each of the given values (the lifetime curve jumps with it: no derivative).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import GrainfracError

#: Step in ln beta2 of a finite difference (10 %: lifetimes move by whole events, a smaller step is noise).
FD_STEP = 0.1
#: An earlier run whose ln beta2 differs from the current one by this much gives the derivative (secant).
SECANT_RANGE = (0.02, 0.7)
#: beta2 is searched within [beta2_start / BOUND_FACTOR, beta2_start x BOUND_FACTOR].
BOUND_FACTOR = 100.0
#: Least-squares stopping: relative change of x, of the cost; most model evaluations (sets of runs).
XTOL, FTOL, MAX_EVALUATIONS = 1e-3, 1e-4, 12


@dataclass(frozen=True)
class ModelPoint:
    """The model at one driving-stress ratio: ln of the geometric-mean lifetime [ln s] at beta1_run, or of
    the lower bound if any seed did not fail (``censored``); seeds that failed on loading are left out."""
    ratio: float
    ln_t: float
    censored: bool
    n_seeds: int
    note: str = ""


@dataclass
class Trial:
    beta2: float
    threshold: float
    points: dict                 # ratio -> ModelPoint
    shift: float = math.nan      # fitted ln(beta1/beta1_run) at this trial
    cost: float = math.nan       # sum of squared residuals [ln s^2]


@dataclass
class CalibrationResult:
    beta1_run: float
    beta1: float
    beta2: float
    threshold: float
    before: Trial
    after: Trial
    lab: object                  # DataFrame driving_stress_ratio, lifetime_s, source
    trials: list = field(default_factory=list)

    def table(self, trial: Trial, beta1: float) -> list:
        """One row per lab point: ratio, lab and model lifetime [s], residual [ln s] (model at ``beta1``)."""
        shift = math.log(beta1 / self.beta1_run)
        rows = []
        for r, t in zip(self.lab["driving_stress_ratio"], self.lab["lifetime_s"]):
            p = trial.points.get(float(r))
            if p is None:
                rows.append({"ratio": float(r), "lab_s": float(t), "model_s": math.nan, "residual_ln": math.nan,
                             "censored": False, "note": "no model value"})
                continue
            res = residual(p, shift, math.log(t))
            rows.append({"ratio": float(r), "lab_s": float(t), "model_s": math.exp(p.ln_t - shift),
                         "residual_ln": res, "censored": p.censored, "note": p.note})
        return rows


def residual(point: ModelPoint, shift: float, ln_lab: float) -> float:
    r = point.ln_t - shift - ln_lab
    return max(r, 0.0) if point.censored else r


def lab_points(lab, points: dict):
    """(ln t_lab, ModelPoint) of the lab points whose ratio has a model value."""
    out = []
    for r, t in zip(lab["driving_stress_ratio"], lab["lifetime_s"]):
        p = points.get(float(r))
        if p is not None and math.isfinite(p.ln_t):
            out.append((math.log(t), p))
    return out


def profile_shift(lab, points: dict) -> float:
    """ln(beta1/beta1_run) that fits the uncensored points best (their mean residual at shift 0)."""
    pairs = [(ln_lab, p) for ln_lab, p in lab_points(lab, points) if not p.censored]
    if not pairs:
        raise GrainfracError("no lab ratio has a failed model run; fix: give lab ratios where the model fails within "
                             "stress_corrosion.creep_time_limit, or raise the limit")
    return float(np.mean([p.ln_t - ln_lab for ln_lab, p in pairs]))


def cost(lab, points: dict, shift: float) -> float:
    return float(sum(residual(p, shift, ln_lab) ** 2 for ln_lab, p in lab_points(lab, points)))


def _aligned(other: Trial, here: Trial, lab) -> np.ndarray:
    """``other``'s residuals (at its own fitted beta1) at the lab points where ``here`` has a model value."""
    out = []
    for ln_lab, p in lab_points(lab, here.points):
        q = other.points.get(p.ratio)
        out.append(residual(p, here.shift, ln_lab) if q is None else residual(q, other.shift, ln_lab))
    return np.array(out)


def fit(model: Callable[[float, float], dict], lab, beta1_run: float, beta2_start: float,
        thresholds=(0.0,), threshold_start: float = 0.0, progress=None) -> CalibrationResult:
    """Fit beta1 and beta2 for each threshold in ``thresholds``; keep the best (least cost).

    ``model(beta2, threshold)`` returns {ratio: ModelPoint} at every lab ratio it can (runs at beta1_run);
    "before" is the model at (beta1_run, beta2_start, threshold_start).
    """
    from scipy.optimize import least_squares
    say = progress or (lambda msg: None)
    cache = {}

    def trial(ln_b2, threshold):
        key = (round(ln_b2, 9), threshold)
        if key not in cache:
            # the start exactly as given; other trials to 12 digits (their runs' tables and folders are exact)
            b2 = beta2_start if key[0] == round(math.log(beta2_start), 9) else float(f"{math.exp(ln_b2):.12g}")
            t = Trial(b2, threshold, model(b2, threshold))
            t.shift = profile_shift(lab, t.points)
            t.cost = cost(lab, t.points, t.shift)
            cache[key] = t
            say(f"beta2 {b2:.5g}, threshold {threshold:g}: cost {t.cost:.4g} ln-s^2 at beta1 = beta1_run x "
                f"{math.exp(t.shift):.4g}")
        return cache[key]

    def vector(points, shift):
        return np.array([residual(p, shift, ln_lab) for ln_lab, p in lab_points(lab, points)])

    before = trial(math.log(beta2_start), float(threshold_start))
    best = None
    for threshold in thresholds:
        threshold = float(threshold)
        lo, hi = math.log(beta2_start / BOUND_FACTOR), math.log(beta2_start * BOUND_FACTOR)
        start = trial(math.log(beta2_start), threshold)

        def fun(x):
            t = trial(x[0], threshold)
            return vector(t.points, t.shift)

        def jac(x):
            here = trial(x[0], threshold)
            others = [t for (k, th), t in cache.items() if th == threshold
                      and SECANT_RANGE[0] <= abs(k - x[0]) <= SECANT_RANGE[1]]
            if others:
                other = min(others, key=lambda t: abs(math.log(t.beta2) - x[0]))
            else:
                other = trial(x[0] + (FD_STEP if x[0] + FD_STEP <= hi else -FD_STEP), threshold)
            d_ln = math.log(other.beta2) - x[0]
            a, b = vector(here.points, here.shift), _aligned(other, here, lab)
            return ((b - a) / d_ln)[:, None]

        n_points = len(lab_points(lab, start.points))
        if n_points < 2:
            raise GrainfracError(f"{n_points} lab point(s) with a model value; fix: at least 2 lab points at ratios "
                                 "the model can run (below its UCS) are needed to fit beta1 and beta2")
        sol = least_squares(fun, np.array([math.log(beta2_start)]), jac=jac, bounds=([lo], [hi]), method="trf",
                            xtol=XTOL, ftol=FTOL, max_nfev=MAX_EVALUATIONS)
        final = trial(float(sol.x[0]), threshold)
        # the best run seen (least_squares may end on a step it then rejects)
        seen = [t for (k, th), t in cache.items() if th == threshold]
        final = min(seen + [final], key=lambda t: t.cost)
        if best is None or final.cost < best.cost:
            best = final
    return CalibrationResult(beta1_run, beta1_run * math.exp(best.shift), best.beta2, best.threshold, before, best,
                             lab, list(cache.values()))
