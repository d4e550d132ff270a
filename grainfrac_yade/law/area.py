"""Area law: stress corrosion shrinks a bond's effective area (the idea of Potyondy 2007's
parallel-bond stress corrosion), with the rate of paper Eq. 7 on the stress that what remains
carries.

The effective bond area fraction a in (0, 1] shrinks; the intrinsic strengths J^T0, J^C0 stay.  With
the forces frozen, the stresses on what remains are sigma_eff = F_n/(a A0) = p/a, tau_eff = q/a,
p = F_n/A0 (tension positive), q = |F_s|/A0, and

    da/dt = -(beta1/J^T0) exp(beta2 p/a) - (beta1/J^C0) exp(beta2 q/a);

at a = 1 each channel is the paper's relative strength-loss rate.  Stiffness and capacity fall with
a (k = a k0, F_max = J0 a A0), so a corroding bond sheds load and its neighbours' stresses rise.

Failure under frozen forces comes at the largest a with sigma_eff >= J^T0 (a_T = p/J^T0) or
tau_eff >= J^C0 + s_n,eff tan(phi) (a_S = (q + p tan(phi))/J^C0); if neither can be met the bond
corrodes away (a -> 0, MODE_CORRODED).  Creep times are t = int du/(u^2 R(u)), u = 1/a
(:mod:`._time_integral`: cheap bounds, exact adaptive Gauss-Legendre, Newton with the exact
derivative); two channels have no closed form, one channel has (:func:`area_time_single_channel`).

Event clock: stiffness changes as a falls, so the clock stops whenever a bond has lost
``max_strength_loss_fraction`` of its INTACT area (or reached its failure point) and lets the DEM
redistribute the load: at most 1/fraction stops per bond.  (A cap on the CURRENT area, as this law
had before, cut the interval geometrically for a bond corroding towards a = 0, so the clock never got
past it.)  Only bonds whose lower bound on the time to their next stop is below the smallest upper
bound are integrated exactly.
"""
import math

import numpy as np
from scipy import special

from . import _time_integral as ti
from ._common import (LOG_LIMIT, MODE_CORRODED, MODE_SHEAR, MODE_TENSION, arr, check_dt, check_rate_constants,
                      check_shear, finite, time_from_log)
from ._interface import EVENT_REL_TOL, BondState, DegradationLaw

NAME = "area"
AREA_MIN = 1e-250   # a below this counts as 0: keeps u = 1/a finite
ASYMPTOTIC_X = 50.0  # x above which 1 - x e^x E1(x) uses its asymptotic series (e^x E1 overflows)
ASYMPTOTIC_TERMS = 40  # series terms: 40!/50^40 ~ 1e-20, far below float64 resolution
STOP_MARGIN = 1e-6  # a capped stop within 1e-6 of the cap above the failure point is the failure itself
BOUND_PIECES = 4    # geometric panels of the cheap bounds that pick the bonds integrated exactly


# ----------------------------------------------------------------------------- checks and channels
def _area_args(area_fraction, p, q, jt0, jc0, beta1, beta2):
    a = arr(area_fraction)
    if not np.all((a > 0) & (a <= 1)):
        raise ValueError("area_fraction must be in (0, 1]; drop bonds whose area reached 0")
    a = np.maximum(a, AREA_MIN)
    for name, v in (("tensile_strength0", jt0), ("cohesion0", jc0)):
        if not np.all((arr(v) > 0) & np.isfinite(arr(v))):
            raise ValueError(f"{name} must be finite and > 0 Pa (got {v!r})")
    p, q = finite(normal_force_per_area0=p, shear_force_per_area0=q)
    check_shear(q, "shear_force_per_area0")
    b1, b2 = check_rate_constants(beta1, beta2)
    return a, p, q, b1, b2


def channels(p, q, jt0, jc0, beta1, beta2) -> ti.Channels:
    """-da/dt = e^(l_t + k_t u) + e^(l_s + k_s u), u = 1/a: l = ln(beta1/J0), k = beta2 p (or q)."""
    with np.errstate(over="ignore", under="ignore"):  # inf is clipped downstream
        k_t, k_s = np.multiply(beta2, p), np.multiply(beta2, q)
    return ti.Channels(np.log(beta1) - np.log(arr(jt0)), k_t, np.log(beta1) - np.log(arr(jc0)), k_s)


def _flat(*xs):
    shape = np.broadcast_shapes(*(np.shape(x) for x in xs))
    return shape, [np.broadcast_to(arr(x), shape).ravel().copy() for x in xs]


# ----------------------------------------------------------------------------- functions of the law
def area_rate(area_fraction, normal_force_per_area0, shear_force_per_area0, tensile_strength0, cohesion0,
              beta1, beta2):
    """Area-fraction loss rate -da/dt = (beta1/J^T0) e^(beta2 p/a) + (beta1/J^C0) e^(beta2 q/a) [1/s].

    Each channel is capped at RATE_CAP (exponents clipped to +-LOG_LIMIT).
    """
    a, p, q, b1, b2 = _area_args(area_fraction, normal_force_per_area0, shear_force_per_area0,
                                 tensile_strength0, cohesion0, beta1, beta2)
    shape, (a, p, q, jt0, jc0) = _flat(a, p, q, tensile_strength0, cohesion0)
    ch = channels(p, q, jt0, jc0, b1, b2)
    return np.exp(ti.log_rate(ch, np.arange(a.size), 1.0 / a)).reshape(shape)


def _area_limits(p, q, jt0, jc0, tan_friction):
    """Per-channel failure area fractions (-inf: channel never met for a > 0)."""
    p, q, jt0, jc0, tphi = np.broadcast_arrays(*finite(
        normal_force_per_area0=p, shear_force_per_area0=q, tensile_strength0=jt0, cohesion0=jc0,
        tan_friction=tan_friction))
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        a_t = np.where(p > 0, p / jt0, -np.inf)        # p/a >= J^T0
        need = q + p * tphi                            # = tau0 - s_n0 tan(phi)
        a_s = np.where(need > 0, need / jc0, -np.inf)  # q/a >= J^C0 - (p/a) tan(phi)
    return a_t, a_s


def area_failure_point(normal_force_per_area0, shear_force_per_area0, tensile_strength0, cohesion0, tan_friction):
    """Largest area fraction at which a failure criterion is met under frozen forces.

    Returns
    -------
    a_fail : ndarray
        [-]; 0 where neither criterion can be met: the bond corrodes away (MODE_CORRODED).
    mode : ndarray of int
        MODE_TENSION (also on ties), MODE_SHEAR or MODE_CORRODED.
    """
    a_t, a_s = _area_limits(normal_force_per_area0, shear_force_per_area0, tensile_strength0, cohesion0,
                            tan_friction)
    a_fail = np.maximum(a_t, a_s)
    mode = np.where(a_t >= a_s, MODE_TENSION, MODE_SHEAR)
    corroded = np.isneginf(a_fail)
    return np.where(corroded, 0.0, a_fail), np.where(corroded, MODE_CORRODED, mode)


def failed_now_area(area_fraction, normal_force_per_area0, shear_force_per_area0, tensile_strength0, cohesion0,
                    tan_friction):
    """Area-law criteria sigma_eff >= J^T0, tau_eff >= J^C0 + s_n,eff tan(phi), as a <= a_T, a <= a_S."""
    a_t, a_s = _area_limits(normal_force_per_area0, shear_force_per_area0, tensile_strength0, cohesion0,
                            tan_friction)
    a = arr(area_fraction)
    return a <= a_t, a <= a_s


def area_time(area_from, area_to, normal_force_per_area0, shear_force_per_area0, tensile_strength0, cohesion0,
              beta1, beta2):
    """Creep time for the area fraction to fall from a_from to a_to under frozen forces [s].

    a_to below a_from/TAIL_RATIO counts as 0 (the dropped tail lasts at most 1e-16 of the time to
    half the area).  Always finite: |da/dt| >= beta1/J^C0 > 0.
    """
    a, p, q, b1, b2 = _area_args(area_from, normal_force_per_area0, shear_force_per_area0, tensile_strength0,
                                 cohesion0, beta1, beta2)
    shape, (a, a_to, p, q, jt0, jc0) = _flat(a, area_to, p, q, tensile_strength0, cohesion0)
    a_to = np.clip(a_to, 0.0, a)
    ch = channels(p, q, jt0, jc0, b1, b2)
    with np.errstate(divide="ignore"):
        u1 = np.where(a_to > 0, 1.0 / np.maximum(a_to, AREA_MIN), np.inf)
    return time_from_log(ti.log_time(ch, 1.0 / a, u1)).reshape(shape)


def time_to_failure_area(area_fraction, normal_force_per_area0, shear_force_per_area0, tensile_strength0,
                         cohesion0, tan_friction, beta1, beta2):
    """Creep time to failure under frozen forces: :func:`area_time` to a_fail (0 if a <= a_fail).

    Returns
    -------
    t_fail : ndarray
        [s], finite (the area law has no 'never': the bond corrodes away at worst).
    mode : ndarray of int
        MODE_TENSION, MODE_SHEAR or MODE_CORRODED.
    """
    a_fail, mode = area_failure_point(normal_force_per_area0, shear_force_per_area0, tensile_strength0,
                                      cohesion0, tan_friction)
    a = arr(area_fraction)
    t = area_time(a, np.minimum(a_fail, a), normal_force_per_area0, shear_force_per_area0, tensile_strength0,
                  cohesion0, beta1, beta2)
    t = np.where(a <= a_fail, 0.0, t)
    return t, np.broadcast_to(mode, t.shape).copy()


def degrade_area(area_fraction, normal_force_per_area0, shear_force_per_area0, tensile_strength0, cohesion0, dt,
                 beta1, beta2):
    """Area fraction after creep time dt under frozen forces (exact inverse of :func:`area_time`).

    Newton's method on the creep time with its exact derivative 1/|da/dt|; 0 if dt reaches full
    corrosion.  Failure is not checked (see :func:`failed_now_area`).
    """
    a, p, q, b1, b2 = _area_args(area_fraction, normal_force_per_area0, shear_force_per_area0, tensile_strength0,
                                 cohesion0, beta1, beta2)
    d = check_dt(dt)
    shape, (a, d, a_in, p, q, jt0, jc0) = _flat(a, d, area_fraction, p, q, tensile_strength0, cohesion0)
    out = a_in.astype(float)
    move = np.flatnonzero(d > 0)
    if move.size:
        ch = channels(p[move], q[move], jt0[move], jc0[move], b1, b2)
        u, reached = ti.advance(ch, 1.0 / a[move], np.full(move.size, np.inf), np.log(d[move]))
        out[move] = np.where(reached, 0.0, np.minimum(1.0 / u, a_in[move]))
    return out.reshape(shape)


def _one_minus_x_ex_e1(x):
    """G(x) = 1 - x e^x E1(x) for x >= 0 (G(0) = 1); asymptotic series above ASYMPTOTIC_X."""
    small = x <= ASYMPTOTIC_X
    xs = np.where(small & (x > 0), x, 1.0)
    direct = np.where(x > 0, 1.0 - xs * np.exp(xs) * special.exp1(xs), 1.0)
    xl = np.where(small, 2.0 * ASYMPTOTIC_X, x)
    term, series = np.ones_like(xl), np.zeros_like(xl)
    for n in range(1, ASYMPTOTIC_TERMS + 1):  # sum_{n>=1} (-1)^(n+1) n!/x^n
        term = term * n / xl
        series = series + (-1.0) ** (n + 1) * term
    return np.where(small, direct, series)


def area_time_single_channel(area_from, area_to, force_per_area0, strength0, beta1, beta2):
    """Closed form of :func:`area_time` with ONE channel (the other's rate neglected).

    t = (J0/beta1) int_{a_to}^{a_from} e^{-k/a} da, k = beta2 p >= 0, with the antiderivative
    F(a) = a e^{-k/a} - k E1(k/a) = a e^{-k/a} G(k/a), G(x) = 1 - x e^x E1(x) (exponential
    integral E1).  A reference for tests: accurate while k/a_to < ~LOG_LIMIT.
    """
    b1, b2 = check_rate_constants(beta1, beta2)
    force, = finite(force_per_area0=force_per_area0)
    with np.errstate(over="ignore"):  # beta2 p beyond the float range: inf, clipped below
        k = b2 * force
    if np.any(k < 0):
        raise ValueError("force_per_area0 must be >= 0 Pa for the single-channel closed form")

    def antiderivative(a):
        x = k / np.where(a > 0, a, 1.0)
        with np.errstate(under="ignore"):  # e^-x G(x) below 1e-308: the time is 0 to float precision
            return np.where(a > 0, a * np.exp(-np.minimum(x, LOG_LIMIT)) * _one_minus_x_ex_e1(x), 0.0)

    a0, a1 = arr(area_from), arr(area_to)
    return arr(strength0) / b1 * (antiderivative(a0) - antiderivative(a1))


# ----------------------------------------------------------------------------- the law
class AreaLaw(DegradationLaw):
    """Corrosion shrinks the bond area (Potyondy 2007's idea) at the rate of paper Eq. 7 on the
    effective stresses.  State: ``area_fraction`` a [-]."""
    name = NAME
    state_names = ("area_fraction",)
    exact_jump = False

    def __init__(self, beta1, beta2):
        self.beta1, self.beta2 = (float(x) for x in check_rate_constants(beta1, beta2))

    def describe(self):
        return (f"area law (Potyondy 2007 idea, rate of paper Eq. 7): beta1 {self.beta1:g} Pa/s, beta2 "
                f"{self.beta2:g} 1/Pa")

    def initial_state(self, tensile_strength0, cohesion0, tan_friction):
        jt0 = np.asarray(tensile_strength0, float)
        return BondState(jt0, np.asarray(cohesion0, float), np.asarray(tan_friction, float),
                         {"area_fraction": np.ones(len(jt0))})

    def _channels(self, state, stresses):
        return channels(stresses.normal, stresses.shear, state.tensile_strength0, state.cohesion0,
                        self.beta1, self.beta2)

    def rate(self, state, stresses):
        a, p, q, b1, b2 = _area_args(state["area_fraction"], stresses.normal, stresses.shear,
                                     state.tensile_strength0, state.cohesion0, self.beta1, self.beta2)
        ch = self._channels(state, stresses)
        e_t, e_s = ti.channel_exponents(ch, np.arange(len(a)), 1.0 / a)
        return np.exp(e_t), np.exp(e_s)

    def strengths(self, state):
        a = state["area_fraction"]
        return state.tensile_strength0 * a, state.cohesion0 * a, a

    def failure_point(self, state, stresses):
        return area_failure_point(stresses.normal, stresses.shear, state.tensile_strength0, state.cohesion0,
                                  state.tan_friction)

    def failed_now(self, state, stresses):
        return failed_now_area(state["area_fraction"], stresses.normal, stresses.shear, state.tensile_strength0,
                               state.cohesion0, state.tan_friction)

    def time_to_failure(self, state, stresses):
        return time_to_failure_area(state["area_fraction"], stresses.normal, stresses.shear,
                                    state.tensile_strength0, state.cohesion0, state.tan_friction, self.beta1,
                                    self.beta2)

    def degrade(self, state, stresses, dt):
        a = state["area_fraction"]
        out = a.copy()
        left = np.flatnonzero(a > 0)          # a bond corroded to 0 (paper clock) has nothing left to lose
        out[left] = degrade_area(a[left], stresses.normal[left], stresses.shear[left], state.tensile_strength0[left],
                                 state.cohesion0[left], np.broadcast_to(dt, a.shape)[left], self.beta1, self.beta2)
        return {"area_fraction": out}

    def step(self, state, stresses, dt, positions, modes):
        """Degrade the bonds that do not fail (the failing ones go straight to their failure point)."""
        rest = np.setdiff1d(np.arange(len(state)), positions)
        new = {"area_fraction": state["area_fraction"].copy()}
        new["area_fraction"][rest] = self.degrade(state.subset(rest), stresses.take(rest), dt)["area_fraction"]
        return self.at_failure(new, state, stresses, positions, modes)

    def at_failure(self, new, state, stresses, positions, modes):
        a = state["area_fraction"]
        out = new["area_fraction"].copy()
        a_fail, _ = self.failure_point(state.subset(positions), stresses.take(positions))
        out[positions] = np.where(a[positions] > a_fail, a_fail, out[positions])  # already failed: keep
        return {"area_fraction": out}

    def interval(self, state, stresses, time_left, cap_fraction):
        """Next stop: the earliest failure, or the earliest bond to lose ``cap_fraction`` of its intact
        area, or ``time_left``.  Bounds pick the candidates; only they are integrated exactly."""
        a_now = np.asarray(state["area_fraction"], float)
        n = len(a_now)
        if n == 0:
            return time_left, np.empty(0, np.int64), np.empty(0, int)
        a, p, q, b1, b2 = _area_args(np.where(a_now > 0, a_now, 1.0), stresses.normal, stresses.shear,
                                     state.tensile_strength0, state.cohesion0, self.beta1, self.beta2)
        a = np.where(a_now > 0, a, AREA_MIN)
        a_fail, modes = self.failure_point(state, stresses)
        # the next stop: a - fraction, unless the failure point comes first or within a hair of it
        a_stop = np.where(a - cap_fraction > a_fail + STOP_MARGIN * cap_fraction, a - cap_fraction, a_fail)
        fails = a_stop == a_fail
        now = a_now <= a_fail
        ch = self._channels(state, stresses)
        u0 = 1.0 / a
        with np.errstate(divide="ignore"):
            u_stop = np.where(a_stop > 0, 1.0 / np.maximum(a_stop, AREA_MIN), np.inf)
        u_stop = np.maximum(u_stop, u0)
        log_lb, log_ub = ti.log_time_bounds(ch, u0, u_stop, pieces=BOUND_PIECES)
        log_lb, log_ub = np.where(now, -np.inf, log_lb), np.where(now, -np.inf, log_ub)
        cand = np.flatnonzero(log_lb <= np.min(log_ub) + math.log1p(1e-9))
        log_t = log_lb.copy()
        todo = cand[~now[cand]]
        if todo.size:
            log_t[todo] = ti.log_time(ch, u0[todo], u_stop[todo], todo)
        t = time_from_log(log_t)
        dt = min(float(np.min(t[cand])), time_left)
        failing = cand[fails[cand] & (t[cand] <= dt * (1 + EVENT_REL_TOL))]
        return dt, failing, modes[failing]


#: The law this module builds (its class attributes, e.g. ``time_scales_with_beta1``, are the law's own).
LAW = AreaLaw


def build(sc) -> AreaLaw:
    """The area law from ``[stress_corrosion]`` parameters (beta1 [Pa/s], beta2 [1/Pa])."""
    return AreaLaw(sc.beta1, sc.beta2)
