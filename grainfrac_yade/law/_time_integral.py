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
import functools

import numpy as np

from ._common import LOG_LIMIT


def logaddexp(x, y):
    """ln(e^x + e^y) (numpy's; callers run under :func:`_quiet`)."""
    return np.logaddexp(x, y)


def _quiet(function):
    """Run ``function`` with float warnings off: inf, 0 and -inf are meant (log space, clipped exponents)."""
    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with np.errstate(all="ignore"):
            return function(*args, **kwargs)
    return wrapper

GL_NODES = 10       # Gauss-Legendre nodes per panel
V_PANEL = 4.0       # largest variation of ln psi across a panel: 10-node GL error ~ 4^20 6e-31 < 1e-18
PRUNE = 50.0        # a panel whose upper bound is below e^-50 of its bond's total is dropped
TAIL_RATIO = 1e16   # u0 * TAIL_RATIO stands for u = inf (y = 0): the tail beyond lasts
                    # <= 1/(u0 TAIL_RATIO R_min) ~ 1e-16 of the time from u0 to 2 u0
DOMINANCE = 40.0    # a channel below e^-40 of the other does not shape psi (relative 4e-18)
MAX_SPLIT = 16      # pieces a panel is split into per round
MAX_ROUNDS = 400    # panel rounds (each at least halves every undecided panel's log-variation)
STOP_BOUND_PIECES = 8  # geometric panels of the upper bound that settles 'past the stop' for large changes
BRACKET_GROWTH = 16.0  # factor by which a bracket that is too short grows
BRACKET_GROWTHS = 200  # growths of the bracket (16^200 covers any float range)
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
        kmax = np.maximum(np.abs(self.k1), np.where(np.isneginf(self.l2), 0.0, np.abs(self.k2)))
        self.kmax = np.where(np.isfinite(kmax), kmax, np.finfo(float).max)

    def take(self, rows):
        out = Channels.__new__(Channels)
        out.l1, out.k1, out.l2, out.k2, out.kmax = (x[rows] for x in (self.l1, self.k1, self.l2, self.k2, self.kmax))
        return out


def _exponent(l, k, u):
    """l + k u clipped to +-LOG_LIMIT; -inf for an absent channel (l = -inf; the only way to get NaN)."""
    e = np.minimum(np.maximum(l + k * u, -LOG_LIMIT), LOG_LIMIT)
    return np.where(l == -np.inf, -np.inf, e)


def _channel_exponents(ch, rows, u):
    return _exponent(ch.l1[rows], ch.k1[rows], u), _exponent(ch.l2[rows], ch.k2[rows], u)


def _log_rate(ch, rows, u):
    return logaddexp(*_channel_exponents(ch, rows, u))


def _log_psi(ch, rows, u):
    return -_log_rate(ch, rows, u) - 2.0 * np.log(u)


@_quiet
def channel_exponents(ch, rows, u):
    """ln of each channel's rate at u (rows: which bonds)."""
    return _channel_exponents(ch, rows, u)


@_quiet
def log_rate(ch, rows, u):
    """ln R(u)."""
    return _log_rate(ch, rows, u)


@_quiet
def log_psi(ch, rows, u):
    """ln psi(u) = -ln R(u) - 2 ln u."""
    return _log_psi(ch, rows, u)


def _gl(ch, rows, a, b):
    """ln of the 10-node Gauss-Legendre value of int_a^b psi (one panel per row)."""
    half = 0.5 * (b - a)
    u = (0.5 * (a + b))[:, None] + half[:, None] * _XI
    lp = _log_psi(ch, rows[:, None], u) + _LOG_W + np.log(np.where(half > 0, half, 1.0))[:, None]
    m = np.max(lp, axis=1)
    m = np.where(np.isfinite(m), m, 0.0)
    s = np.sum(np.exp(lp - m[:, None]), axis=1)
    return np.where(half > 0, np.log(s) + m, -np.inf)


def _panel_bounds(ch, rows, a, b):
    """(ln lower, ln upper) bounds of int_a^b psi: each channel is monotone in u."""
    ea1, ea2 = _channel_exponents(ch, rows, a)
    eb1, eb2 = _channel_exponents(ch, rows, b)
    log_r_min = logaddexp(np.minimum(ea1, eb1), np.minimum(ea2, eb2))
    log_r_max = logaddexp(np.maximum(ea1, eb1), np.maximum(ea2, eb2))
    log_w = np.log(b - a)
    return log_w - log_r_max - 2.0 * np.log(b), log_w - log_r_min - 2.0 * np.log(a)


def _clipped(ea, eb):
    """A channel's exponent clipped at the same limit at both ends (so across the whole panel)."""
    return ((ea >= LOG_LIMIT) & (eb >= LOG_LIMIT)) | ((ea <= -LOG_LIMIT) & (eb <= -LOG_LIMIT))


def _slope_bound(ch, rows, a, b):
    """Bound on |d ln R/du| over [a, b]: d ln R/du is a weighted mean of k1 and k2; where one channel
    exceeds the other by more than DOMINANCE at both ends (their gap is linear in u, so everywhere
    between), the other's weight is below e^-DOMINANCE and the slope is the dominant channel's k."""
    ea1, ea2 = _channel_exponents(ch, rows, a)
    eb1, eb2 = _channel_exponents(ch, rows, b)
    gap_lo = np.minimum(ea1 - ea2, eb1 - eb2)
    gap_hi = np.maximum(ea1 - ea2, eb1 - eb2)
    k1 = np.where(_clipped(ea1, eb1), 0.0, np.abs(ch.k1[rows]))   # clipped across the panel: flat
    k2 = np.where(_clipped(ea2, eb2), 0.0, np.abs(ch.k2[rows]))
    both = np.minimum(np.maximum(k1, k2), np.finfo(float).max)
    return np.where(gap_lo > DOMINANCE, k1, np.where(gap_hi < -DOMINANCE, k2, both))


def _log_tail_upper_bound(ch, rows, u0):
    """ln of an upper bound on t(u0 -> inf).  R(u) >= e^(l_c + k_c u) for a channel c with k_c > 0, so
    t <= int_{u0}^inf e^-(l_c + k_c u) / u0^2 du = e^-(l_c + k_c u0) / (u0^2 k_c); where the exponent is
    clipped at +LOG_LIMIT, R >= e^LOG_LIMIT and t <= e^-LOG_LIMIT / u0.  inf without such a channel."""
    out = np.full(len(u0), np.inf)
    for e, k in zip(_channel_exponents(ch, rows, u0), (ch.k1[rows], ch.k2[rows])):
        growing = (k > 0) & (e > -LOG_LIMIT)
        bound = np.where(e >= LOG_LIMIT, -LOG_LIMIT - np.log(u0),
                         -e - np.log(np.where(growing, k, 1.0)) - 2.0 * np.log(u0))
        out = np.minimum(out, np.where(growing, bound, np.inf))
    return out


def _finite_end(u0, u1):
    return np.where(np.isfinite(u1), u1, u0 * TAIL_RATIO)


@_quiet
def log_time_bounds(ch, u0, u1, pieces=1):
    """(ln lower, ln upper) bounds of t(u0 -> u1) from ``pieces`` geometric panels (cheap)."""
    return _log_time_bounds(ch, u0, u1, pieces)


def _log_time_bounds(ch, u0, u1, pieces=1):
    """:func:`log_time_bounds` without its float-warning guard."""
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


@_quiet
def log_time(ch, u0, u1, rows=None):
    """ln t(u0 -> u1) = ln int_{u0}^{u1} psi du for each bond (u1 >= u0; inf: up to u0 TAIL_RATIO).

    ``rows``: the bonds of ``ch`` these u0, u1 belong to (default: all, in order). -inf for u1 == u0.
    """
    return _log_time(ch, u0, u1, rows)


def _log_time(ch, u0, u1, rows=None):
    """:func:`log_time` without its float-warning guard (callers hold it)."""
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
                     np.minimum(np.ceil(variation / V_PANEL), MAX_SPLIT))
        m = np.nan_to_num(m, nan=2.0).astype(int)
        m = np.maximum(m, 2)
        reps = np.repeat(np.arange(len(owner)), m)
        j = np.arange(reps.size) - np.repeat(np.cumsum(m) - m, m)
        mm = m[reps].astype(float)
        a, b = lo[reps], hi[reps]
        geo_a, geo_b = a * (b / a) ** (j / mm), a * (b / a) ** ((j + 1) / mm)
        lin_a, lin_b = a + (b - a) * (j / mm), a + (b - a) * ((j + 1) / mm)
        g = geometric[reps]
        new_lo, new_hi = np.where(g, geo_a, lin_a), np.where(g, geo_b, lin_b)
        last = j == m[reps] - 1
        new_hi = np.where(last, b, new_hi)
        new_lo = np.where(j == 0, a, new_lo)
        owner, lo, hi = owner[reps], new_lo, new_hi
    return out


@_quiet
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
    # bracket the root: [u0, u_try] with t(u0 -> u_try) >= dt by a cheap lower bound, u_try growing from
    # twice the Euler step; only where u_try reaches the stop is the whole integral needed (past it or not)
    euler = np.exp(np.clip(log_dt - _log_psi(ch, rows, u0), -LOG_LIMIT, LOG_LIMIT))
    u_try = np.minimum(np.maximum(u0 + 2.0 * euler, u0 * (1.0 + 1e-15)), stop_end)
    reached = np.zeros(n, bool)
    open_ = np.isfinite(log_dt)
    # past the stop already?  t(u0 -> inf) <= 1/(u0^2 R_c(u0) k_c) for each channel c with k_c > 0 (R >= R_c);
    # for large changes also the panel bounds up to the stop
    past = open_ & (_log_tail_upper_bound(ch, rows, u0) <= log_dt)
    big = np.flatnonzero(open_ & ~past & (euler > u0))
    if big.size:
        _, ub = _log_time_bounds(ch.take(rows[big]), u0[big], stop_end[big], pieces=STOP_BOUND_PIECES)
        past[big[ub <= log_dt[big]]] = True
    reached[past], open_[past] = True, False
    for _ in range(BRACKET_GROWTHS):
        k = np.flatnonzero(open_)
        if not k.size:
            break
        lb, ub = _log_time_bounds(ch.take(rows[k]), u0[k], u_try[k])
        ok = lb >= log_dt[k]
        loose = np.flatnonzero(~ok & (ub >= log_dt[k]))   # the bounds do not settle it: integrate exactly
        if loose.size:
            j = k[loose]
            ok[loose] = _log_time(ch, u0[j], u_try[j], rows[j]) >= log_dt[j]
        at_stop = ~ok & (u_try[k] >= stop_end[k])
        past = at_stop & (ub <= log_dt[k])
        unsure = at_stop & ~past
        if unsure.any():
            j = k[unsure]
            total = _log_time(ch, u0[j], stop_end[j], rows[j])
            past[unsure] = total <= log_dt[j]
        reached[k[past]] = True
        open_[k[ok | at_stop]] = False
        grow = k[~ok & ~at_stop]
        u_try[grow] = np.minimum(u0[grow] + BRACKET_GROWTH * (u_try[grow] - u0[grow]), stop_end[grow])
    stop_end = np.where(reached, stop_end, u_try)
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
        slope = np.exp(np.clip(_log_psi(ch, bond[k], cur[k]) - ldt[k], -LOG_LIMIT, LOG_LIMIT))
        step = -g[k] / slope
        new = cur[k] + step
        settled = np.abs(step) <= U_RELATIVE_TOL * cur[k]     # Newton's correction below resolution: done
        active[k[settled]] = False
        keep = ~settled
        k, new = k[keep], new[keep]
        if not k.size:
            break
        outside = ~((new >= lo_b[k]) & (new <= hi_b[k]))
        wide = hi_b[k] > 2.0 * lo_b[k]
        bisect = np.where(wide, np.sqrt(lo_b[k]) * np.sqrt(hi_b[k]), 0.5 * (lo_b[k] + hi_b[k]))
        new = np.where(outside, bisect, new)
        a, b = np.minimum(cur[k], new), np.maximum(cur[k], new)
        inc = _log_time(ch, a, b, bond[k])
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
