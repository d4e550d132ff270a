"""Static-fatigue laws fitted to lifetimes (least squares in ln t; pure numpy/scipy).

Two laws of lifetime t_f against the driving-stress ratio r = sigma / sigma_c (paper Fig. 4):

- exponential (static-fatigue line, straight on a semi-log plot): ln t_f = a - b r
- power law: t_f = A r^(-n), i.e. ln t_f = ln A - n ln r

Both are ordinary least squares of a straight line y = c0 + c1 x with y = ln t_f. The
parameter covariance is s^2 (X^T X)^-1 with s^2 = SSR / (N - 2); standard errors, the 95 %
confidence intervals of the coefficients and the confidence band of the mean line use
Student's t with N - 2 degrees of freedom. With exactly two points the line is exact and no
error estimate exists (standard errors NaN, no band).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import stats

from ..errors import GrainfracError

#: Confidence level of the coefficient intervals and of the band of the mean line.
CONFIDENCE = 0.95
#: Ratios equal to this many decimals count as one load level (0.7 * ucs / ucs may be 0.7000000000000001).
RATIO_DECIMALS = 6


@dataclass(frozen=True)
class LineFit:
    """Least-squares line y = intercept + slope x with its parameter covariance."""
    intercept: float
    slope: float
    cov: np.ndarray          # 2 x 2 covariance of (intercept, slope); NaN if dof == 0
    r2: float                # coefficient of determination (NaN if y is constant)
    n: int                   # number of points
    residual_sd: float       # s = sqrt(SSR / dof); NaN if dof == 0

    @property
    def dof(self) -> int:
        return self.n - 2

    @property
    def intercept_se(self) -> float:
        return float(np.sqrt(self.cov[0, 0]))

    @property
    def slope_se(self) -> float:
        return float(np.sqrt(self.cov[1, 1]))

    def t_quantile(self, level: float = CONFIDENCE) -> float:
        """Two-sided Student-t quantile for ``level`` with N - 2 degrees of freedom (NaN if none)."""
        return float(stats.t.ppf(0.5 + level / 2, self.dof)) if self.dof > 0 else float("nan")

    def predict(self, x):
        return self.intercept + self.slope * np.asarray(x, float)

    def band(self, x, level: float = CONFIDENCE):
        """(lower, upper) confidence band of the mean line at ``x``: y_hat -+ t sqrt([1 x] C [1 x]^T)."""
        x = np.asarray(x, float)
        var = self.cov[0, 0] + 2 * x * self.cov[0, 1] + x * x * self.cov[1, 1]
        half = self.t_quantile(level) * np.sqrt(np.maximum(var, 0.0))
        y = self.predict(x)
        return y - half, y + half


def fit_line(x, y) -> LineFit:
    """Ordinary least squares y = c0 + c1 x; needs at least two distinct x."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) != len(y) or len(x) < 2 or np.ptp(x) == 0:
        raise GrainfracError(f"line fit needs at least two distinct x values (got {len(np.unique(x))}); "
                             "fix: give lifetimes at two or more driving-stress ratios")
    X = np.column_stack([np.ones_like(x), x])
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    resid = y - X @ coef
    ssr = float(resid @ resid)
    sst = float(np.sum((y - y.mean()) ** 2))
    dof = len(x) - 2
    if dof > 0:
        s2 = ssr / dof
        cov = s2 * np.linalg.inv(X.T @ X)
        sd = float(np.sqrt(s2))
    else:
        cov, sd = np.full((2, 2), np.nan), float("nan")
    r2 = 1.0 - ssr / sst if sst > 0 else float("nan")
    return LineFit(float(coef[0]), float(coef[1]), cov, r2, len(x), sd)


def check_lifetimes(ratio, lifetime, source: str):
    """Finite positive ratios and lifetimes, else GrainfracError naming ``source``."""
    ratio, lifetime = np.asarray(ratio, float), np.asarray(lifetime, float)
    for name, values in (("driving_stress_ratio", ratio), ("lifetime_s", lifetime)):
        bad = np.flatnonzero(~np.isfinite(values) | (values <= 0))
        if len(bad):
            raise GrainfracError(f"{source}: {name} must be a finite positive number, {len(bad)} value(s) are not "
                                 f"(first: point {bad[0] + 1}, value {values[bad[0]]!r}); fix: remove or correct "
                                 "these points (a lifetime fit is in ln t)")
    return ratio, lifetime


def distinct_ratios(ratio) -> int:
    return len(np.unique(np.round(np.asarray(ratio, float), RATIO_DECIMALS)))


@dataclass(frozen=True)
class LifetimeFit:
    """Both static-fatigue laws fitted to one data set.

    ``exponential``: ln t = c0 + c1 r with a = c0, b = -c1 (ln t_f = a - b r).
    ``power``: ln t = c0 + c1 ln r with ln A = c0, n = -c1 (t_f = A r^-n).
    """
    exponential: LineFit
    power: LineFit
    n_ratios: int

    @property
    def a(self) -> float:
        return self.exponential.intercept

    @property
    def b(self) -> float:
        return -self.exponential.slope

    @property
    def n(self) -> float:
        return -self.power.slope

    @property
    def ln_A(self) -> float:
        return self.power.intercept

    def lifetime_exponential(self, ratio):
        """t_f = exp(a - b r) [s]."""
        return np.exp(self.exponential.predict(ratio))

    def lifetime_power(self, ratio):
        """t_f = A r^-n [s]."""
        return np.exp(self.power.predict(np.log(np.asarray(ratio, float))))

    def band_exponential(self, ratio, level: float = CONFIDENCE):
        lo, hi = self.exponential.band(ratio, level)
        return np.exp(lo), np.exp(hi)

    def band_power(self, ratio, level: float = CONFIDENCE):
        lo, hi = self.power.band(np.log(np.asarray(ratio, float)), level)
        return np.exp(lo), np.exp(hi)


def fit_lifetimes(ratio, lifetime, source: str = "lifetimes"):
    """Fit ln t_f = a - b r and ln t_f = ln A - n ln r; None with fewer than two distinct ratios."""
    ratio, lifetime = check_lifetimes(ratio, lifetime, source)
    k = distinct_ratios(ratio)
    if k < 2:
        return None
    y = np.log(lifetime)
    return LifetimeFit(fit_line(ratio, y), fit_line(np.log(ratio), y), k)


def coefficient_row(label: str, fit: LifetimeFit, level: float = CONFIDENCE) -> dict:
    """One row of the coefficient table (units in the names; ``*_ci95`` = half-width of the interval)."""
    e, p = fit.exponential, fit.power
    te, tp = e.t_quantile(level), p.t_quantile(level)
    return {
        "dataset": label, "n_points": e.n, "n_ratios": fit.n_ratios,
        "a_ln_s": fit.a, "a_se": e.intercept_se, "a_ci95": te * e.intercept_se,
        "b": fit.b, "b_se": e.slope_se, "b_ci95": te * e.slope_se, "r2_exponential": e.r2,
        "n": fit.n, "n_se": p.slope_se, "n_ci95": tp * p.slope_se,
        "ln_A_ln_s": fit.ln_A, "ln_A_se": p.intercept_se, "A_s": float(np.exp(fit.ln_A)), "r2_power": p.r2,
    }


def coefficient_table(fits: dict) -> pd.DataFrame:
    """Rows of :func:`coefficient_row` for ``{label: LifetimeFit}`` (labels whose fit is None skipped)."""
    return pd.DataFrame([coefficient_row(label, f) for label, f in fits.items() if f is not None])
