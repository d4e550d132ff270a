"""Convergence of a result in a discretisation: paired changes between successive refinements and the
three-point (Richardson) extrapolation.

With a spacing h (here the node spacing on a face, h ~ 1 / K for K bonds per face) and a result that behaves as

    U(h) = U_inf + C h^p                                                     (asymptotic range)

three results U_1, U_2, U_3 at spacings h_1 > h_2 > h_3 fix p through

    (U_1 - U_2) / (U_2 - U_3) = (h_1^p - h_2^p) / (h_2^p - h_3^p),

solved by bisection (any ratios of the spacings, not only a constant one), then C and U_inf follow
(Roache 1998, *Verification and Validation in Computational Science and Engineering*, ch. 5: the generalised
Richardson extrapolation and the observed order of accuracy). The extrapolation exists only where the two changes
have the same sign and shrink (monotone convergence); otherwise it returns None and says why.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: The interval of the observed order p searched by bisection [1].
ORDER_RANGE = (1e-3, 20.0)


@dataclass(frozen=True)
class Extrapolation:
    """U(h) = limit + coefficient h^order fitted exactly through three results."""
    limit: float
    coefficient: float
    order: float

    def value(self, h):
        """U(h) of the fitted asymptotic form (array in, array out)."""
        return self.limit + self.coefficient * np.asarray(h, dtype=float) ** self.order

    def spacing_within(self, relative_error: float) -> float:
        """The largest spacing h at which |U(h) - limit| <= relative_error |limit|."""
        return (relative_error * abs(self.limit) / abs(self.coefficient)) ** (1.0 / self.order)


def paired_changes(values) -> np.ndarray:
    """Relative change of each result from the previous (coarser) one: U_i / U_(i-1) - 1; NaN for the first."""
    u = np.asarray(values, dtype=float)
    out = np.full(u.shape, np.nan)
    out[1:] = u[1:] / u[:-1] - 1.0
    return out


def log_changes(values) -> np.ndarray:
    """Change of each result's logarithm from the previous (coarser) one: ln(U_i / U_(i-1)); NaN for the first.
    For results that span decades (lifetimes), the study's criterion reads its magnitude |d ln U|."""
    u = np.asarray(values, dtype=float)
    out = np.full(u.shape, np.nan)
    out[1:] = np.log(u[1:] / u[:-1])
    return out


def _ratio(p: float, h1: float, h2: float, h3: float) -> float:
    return (h1 ** p - h2 ** p) / (h2 ** p - h3 ** p)


def extrapolate(spacings, values) -> tuple[Extrapolation | None, str]:
    """The three-point extrapolation through the last three (finest) of ``values`` at ``spacings``
    (coarse to fine, strictly decreasing), and a sentence on it.

    Returns (None, why) where the changes do not converge monotonically (they change sign or do not shrink
    in the ratio some order p in ``ORDER_RANGE`` gives).
    """
    h = np.asarray(spacings, dtype=float)
    u = np.asarray(values, dtype=float)
    if h.shape != u.shape or len(h) < 3:
        return None, "fewer than three results"
    if np.any(np.diff(h) >= 0.0):
        raise ValueError("spacings must decrease strictly from coarse to fine")
    (h1, h2, h3), (u1, u2, u3) = h[-3:], u[-3:]
    d12, d23 = u1 - u2, u2 - u3
    if d23 == 0.0 or d12 == 0.0 or (d12 > 0.0) != (d23 > 0.0):
        return None, "the changes between the three finest change sign or vanish: not monotone"
    target = d12 / d23
    lo, hi = ORDER_RANGE
    f_lo, f_hi = _ratio(lo, h1, h2, h3) - target, _ratio(hi, h1, h2, h3) - target
    if (f_lo > 0.0) == (f_hi > 0.0):
        return None, (f"the change ratio {target:.3g} needs an order outside {lo:g}-{hi:g}: "
                      "not in the asymptotic range")
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        f_mid = _ratio(mid, h1, h2, h3) - target
        if (f_mid > 0.0) == (f_lo > 0.0):
            lo, f_lo = mid, f_mid
        else:
            hi = mid
    p = 0.5 * (lo + hi)
    c = d23 / (h2 ** p - h3 ** p)
    fit = Extrapolation(limit=u3 - c * h3 ** p, coefficient=c, order=p)
    return fit, f"observed order {p:.2f}, limit {fit.limit:.4g}"


def finest_within(values, relative_change: float) -> bool:
    """True where the paired change between the two finest results is below ``relative_change`` in size
    (the study's criterion: the paired UCS change between the two finest discretisations < 5 %)."""
    changes = paired_changes(values)
    return len(changes) >= 2 and bool(math.isfinite(changes[-1]) and abs(changes[-1]) < relative_change)
