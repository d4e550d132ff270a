"""Creep time of a bond whose strength-like variable y falls at an exponential rate of 1/y.

Both the area law (y = area fraction a) and the strength-normalised law (y = strength) have
dy/dt = -R(1/y), R(u) = e^(l1 + k1 u) + e^(l2 + k2 u) (the second channel may be absent: l2 = -inf).
With u = 1/y, du/dt = u^2 R(u), so the creep time for u to grow from u0 to u1 is

    t = int_{u0}^{u1} psi(u) du,   psi(u) = 1 / (u^2 R(u)),

positive and smooth.  ln R is the log of a sum of exponentials of u, so each channel is monotone in u
and R is bounded on any panel by its channels' values at the two ends: that gives cheap lower and
upper bounds (:func:`log_time_bounds`).  The exact value (:func:`log_time`) is composite
Gauss-Legendre on adaptive panels: a panel is integrated once the log of psi varies by at most
V_PANEL across it (|d ln psi/du| <= max|k| + 2/u), split otherwise, and dropped when its upper
bound is below e^-PRUNE of the bond's running total.  :func:`advance` inverts it (the u reached after
a creep time) by Newton's method on t(u) with the exact derivative psi(u), kept inside a bracket.

All results are logs of times, so nothing overflows; every exponent is clipped to +-LOG_LIMIT.
"""
import numpy as np

from ._common import LOG_LIMIT, logaddexp

GL_NODES = 10       # Gauss-Legendre nodes per panel
V_PANEL = 4.0       # largest variation of ln psi across a panel: 10-node GL error ~ 4^20 6e-31 < 1e-18
PRUNE = 50.0        # a panel whose upper bound is below e^-50 of its bond's total is dropped
TAIL_RATIO = 1e16   # u0 * TAIL_RATIO stands for u = inf (y = 0): the tail beyond lasts
                    # <= 1/(u0 TAIL_RATIO R_min) ~ 1e-16 of the time from u0 to 2 u0
DOMINANCE = 40.0    # a channel below e^-40 of the other does not shape psi (relative 4e-18)
MAX_SPLIT = 16      # pieces a panel is split into per round
MAX_ROUNDS = 400    # panel rounds (each at least halves every undecided panel's log-variation)
NEWTON_STEPS = 200  # Newton-bisection iterations of advance() (bisection alone needs < 120)
U_RELATIVE_TOL = 4 * np.finfo(float).eps

_XI, _W = np.polynomial.legendre.leggauss(GL_NODES)
_LOG_W = np.log(_W)


class Channels:
    """The rate channels of a set of bonds: R(u) = e^(l1 + k1 u) + e^(l2 + k2 u) (arrays of one length).

    ``l2 = -inf`` means a single channel.  ``k`` may be of either sign (a compressed bond's tensile
    channel slows down as it corrodes).
    """

    def __init__(self, l1, k1, l2=None, k2=None):
        if l2 is None:
            l2, k2 = -np.inf, 0.0
        self.l1, self.k1, self.l2, self.k2 = (np.array(x, dtype=float) for x in np.broadcast_arrays(
            np.atleast_1d(l1), np.atleast_1d(k1), np.atleast_1d(l2), np.atleast_1d(k2)))
        with np.errstate(invalid="ignore"):
            kmax = np.maximum(np.abs(self.k1), np.where(np.isneginf(self.l2), 0.0, np.abs(self.k2)))
        self.kmax = np.where(np.isfinite(kmax), kmax, np.finfo(float).max)

    def take(self, rows):
        out = Channels.__new__(Channels)
        out.l1, out.k1, out.l2, out.k2, out.kmax = (x[rows] for x in (self.l1, self.k1, self.l2, self.k2, self.kmax))
        return out


def _exponent(l, k, u):
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        e = l + k * u
    return np.where(np.isneginf(l), -np.inf, np.clip(np.nan_to_num(e, nan=-np.inf), -LOG_LIMIT, LOG_LIMIT))


def channel_exponents(ch, rows, u):
    """ln of each channel's rate at u (rows: which bonds)."""
    return _exponent(ch.l1[rows], ch.k1[rows], u), _exponent(ch.l2[rows], ch.k2[rows], u)


def log_rate(ch, rows, u):
    """ln R(u)."""
    e1, e2 = channel_exponents(ch, rows, u)
    return logaddexp(e1, e2)


def log_psi(ch, rows, u):
    """ln psi(u) = -ln R(u) - 2 ln u."""
    return -log_rate(ch, rows, u) - 2.0 * np.log(u)


def _gl(ch, rows, a, b):
    """ln of the 10-node Gauss-Legendre value of int_a^b psi (one panel per row)."""
    half = 0.5 * (b - a)
    u = (0.5 * (a + b))[:, None] + half[:, None] * _XI
    lp = log_psi(ch, rows[:, None], u) + _LOG_W + np.log(np.where(half > 0, half, 1.0))[:, None]
    m = np.max(lp, axis=1)
    m = np.where(np.isfinite(m), m, 0.0)
    with np.errstate(under="ignore"):
        s = np.sum(np.exp(lp - m[:, None]), axis=1)
    with np.errstate(divide="ignore"):
        return np.where(half > 0, np.log(s) + m, -np.inf)


def _panel_bounds(ch, rows, a, b):
    """(ln lower, ln upper) bounds of int_a^b psi: each channel is monotone in u."""
    ea1, ea2 = channel_exponents(ch, rows, a)
    eb1, eb2 = channel_exponents(ch, rows, b)
    log_r_min = logaddexp(np.minimum(ea1, eb1), np.minimum(ea2, eb2))
    log_r_max = logaddexp(np.maximum(ea1, eb1), np.maximum(ea2, eb2))
    with np.errstate(divide="ignore"):
        log_w = np.log(b - a)
    return log_w - log_r_max - 2.0 * np.log(b), log_w - log_r_min - 2.0 * np.log(a)


def _clipped(ea, eb):
    """A channel's exponent clipped at the same limit at both ends (so across the whole panel)."""
    return ((ea >= LOG_LIMIT) & (eb >= LOG_LIMIT)) | ((ea <= -LOG_LIMIT) & (eb <= -LOG_LIMIT))


def _slope_bound(ch, rows, a, b):
    """Bound on |d ln R/du| over [a, b]: d ln R/du is a weighted mean of k1 and k2; where one channel
    exceeds the other by more than DOMINANCE at both ends (their gap is linear in u, so everywhere
    between), the other's weight is below e^-DOMINANCE and the slope is the dominant channel's k."""
    ea1, ea2 = channel_exponents(ch, rows, a)
    eb1, eb2 = channel_exponents(ch, rows, b)
    with np.errstate(invalid="ignore"):
        gap_lo = np.minimum(ea1 - ea2, eb1 - eb2)
        gap_hi = np.maximum(ea1 - ea2, eb1 - eb2)
    k1 = np.where(_clipped(ea1, eb1), 0.0, np.abs(ch.k1[rows]))   # clipped across the panel: flat
    k2 = np.where(_clipped(ea2, eb2), 0.0, np.abs(ch.k2[rows]))
    both = np.minimum(np.maximum(k1, k2), np.finfo(float).max)
    return np.where(np.nan_to_num(gap_lo, nan=np.inf) > DOMINANCE, k1,
                    np.where(np.nan_to_num(gap_hi, nan=-np.inf) < -DOMINANCE, k2, both))


def _finite_end(u0, u1):
    return np.where(np.isfinite(u1), u1, u0 * TAIL_RATIO)


def log_time_bounds(ch, u0, u1, pieces=1):
    """(ln lower, ln upper) bounds of t(u0 -> u1) from ``pieces`` geometric panels (cheap)."""
    u0, u1 = np.asarray(u0, float), _finite_end(np.asarray(u0, float), np.asarray(u1, float))
    rows = np.arange(len(u0))
    lo = np.full(len(u0), -np.inf)
    hi = np.full(len(u0), -np.inf)
    ratio = u1 / u0
    for j in range(pieces):
        a = u0 * ratio ** (j / pieces)
        b = u1 if j == pieces - 1 else u0 * ratio ** ((j + 1) / pieces)
        b = np.maximum(b, a)
        pl, pu = _panel_bounds(ch, rows, a, b)
        lo, hi = logaddexp(lo, pl), logaddexp(hi, pu)
    return lo, hi


def log_time(ch, u0, u1, rows=None):
    """ln t(u0 -> u1) = ln int_{u0}^{u1} psi du for each bond (u1 >= u0; inf: up to u0 TAIL_RATIO).

    ``rows``: the bonds of ``ch`` these u0, u1 belong to (default: all, in order). -inf for u1 == u0.
    """
    u0 = np.asarray(u0, float)
    n = len(u0)
    rows_all = np.arange(n) if rows is None else np.asarray(rows)
    out = np.full(n, -np.inf)
    lo, hi = u0.copy(), _finite_end(u0, np.asarray(u1, float))
    owner = np.arange(n)
    for _ in range(MAX_ROUNDS):
        keep = hi > lo
        owner, lo, hi = owner[keep], lo[keep], hi[keep]
        if not owner.size:
            break
        bond = rows_all[owner]
        variation = (_slope_bound(ch, bond, lo, hi) + 2.0 / lo) * (hi - lo)
        tiny = (hi - lo) <= 8 * np.spacing(hi)          # cannot be split further in floating point
        fine = (variation <= V_PANEL) | tiny
        if fine.any():
            np.logaddexp.at(out, owner[fine], _gl(ch, bond[fine], lo[fine], hi[fine]))
        coarse = ~fine
        owner, lo, hi, bond, variation = owner[coarse], lo[coarse], hi[coarse], bond[coarse], variation[coarse]
        if not owner.size:
            break
        log_lb, log_ub = _panel_bounds(ch, bond, lo, hi)
        total_lb = out.copy()
        np.logaddexp.at(total_lb, owner, log_lb)
        keep = log_ub > total_lb[owner] - PRUNE
        owner, lo, hi, variation = owner[keep], lo[keep], hi[keep], variation[keep]
        geometric = hi > 2.0 * lo
        m = np.where(geometric, np.minimum(np.ceil(np.log2(hi / lo)), MAX_SPLIT),
                     np.minimum(np.ceil(variation / V_PANEL), MAX_SPLIT)).astype(int)
        m = np.maximum(m, 2)
        reps = np.repeat(np.arange(len(owner)), m)
        j = np.arange(reps.size) - np.repeat(np.cumsum(m) - m, m)
        mm = m[reps].astype(float)
        a, b = lo[reps], hi[reps]
        with np.errstate(over="ignore", invalid="ignore"):
            geo_a, geo_b = a * (b / a) ** (j / mm), a * (b / a) ** ((j + 1) / mm)
        lin_a, lin_b = a + (b - a) * (j / mm), a + (b - a) * ((j + 1) / mm)
        g = geometric[reps]
        new_lo, new_hi = np.where(g, geo_a, lin_a), np.where(g, geo_b, lin_b)
        last = j == m[reps] - 1
        new_hi = np.where(last, b, new_hi)
        new_lo = np.where(j == 0, a, new_lo)
        owner, lo, hi = owner[reps], new_lo, new_hi
    return out


def advance(ch, u0, u_stop, log_dt, rows=None):
    """(u1, reached): u1 with t(u0 -> u1) = dt, or u_stop and True if dt takes the bond past u_stop.

    ``u_stop`` may be inf (y = 0).  Newton's method on g(u) = t(u0 -> u)/dt - 1 with the exact
    derivative psi(u)/dt, inside a bracket that bisection narrows whenever a Newton step leaves it;
    t(u0 -> u) is accumulated from exact integrals (:func:`log_time`) over each step.
    """
    u0 = np.asarray(u0, float)
    n = len(u0)
    rows = np.arange(n) if rows is None else np.asarray(rows)
    u_stop = np.asarray(u_stop, float)
    log_dt = np.broadcast_to(np.asarray(log_dt, float), (n,)).copy()
    stop_end = _finite_end(u0, u_stop)
    # past the stop? decide with bounds, integrate exactly only where they do not settle it
    lb, ub = log_time_bounds(ch.take(rows), u0, stop_end, pieces=2)
    reached = ub <= log_dt
    unsure = ~reached & (lb < log_dt)
    if unsure.any():
        total = log_time(ch, u0[unsure], stop_end[unsure], rows[unsure])
        reached[unsure] = total <= log_dt[unsure]
    u = u0.copy()
    u[reached] = u_stop[reached]
    todo = np.flatnonzero(~reached & np.isfinite(log_dt))
    if not todo.size:
        return u, reached
    bond, cur, lo_b, hi_b, ldt = rows[todo], u0[todo].copy(), u0[todo].copy(), stop_end[todo].copy(), log_dt[todo]
    g = np.full(todo.size, -1.0)
    active = np.ones(todo.size, bool)
    for _ in range(NEWTON_STEPS):
        k = np.flatnonzero(active)
        if not k.size:
            break
        with np.errstate(over="ignore", under="ignore"):
            slope = np.exp(np.clip(log_psi(ch, bond[k], cur[k]) - ldt[k], -LOG_LIMIT, LOG_LIMIT))
            step = -g[k] / slope
        new = cur[k] + step
        outside = ~((new > lo_b[k]) & (new < hi_b[k]))
        wide = hi_b[k] > 2.0 * lo_b[k]
        bisect = np.where(wide, np.sqrt(lo_b[k] * hi_b[k]), 0.5 * (lo_b[k] + hi_b[k]))
        new = np.where(outside, bisect, new)
        a, b = np.minimum(cur[k], new), np.maximum(cur[k], new)
        inc = log_time(ch, a, b, bond[k])
        with np.errstate(over="ignore", under="ignore"):
            ratio = np.exp(np.clip(inc - ldt[k], -LOG_LIMIT, LOG_LIMIT))
        g_new = g[k] + np.where(new >= cur[k], ratio, -ratio)
        done = (np.abs(new - cur[k]) <= U_RELATIVE_TOL * new) | (g_new == 0)
        lo_b[k] = np.where(g_new < 0, new, lo_b[k])
        hi_b[k] = np.where(g_new >= 0, new, hi_b[k])
        collapsed = hi_b[k] - lo_b[k] <= U_RELATIVE_TOL * hi_b[k]
        cur[k], g[k] = new, g_new
        active[k] = ~(done | collapsed)
    u[todo] = cur
    return u, reached
