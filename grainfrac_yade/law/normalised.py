"""Stress corrosion on strength with the exponent on stress normalised by strength (the form of
Potyondy 2007's parallel-bond stress-corrosion model), with an optional activation threshold.

Each channel's strength Y falls at

    dY/dt = -beta1 exp(beta2 s / Y),

tension: Y = J^T, s = sigma; shear: Y = J^C + s_n tan(phi) (the Mohr-Coulomb strength), s = tau.
beta2 is dimensionless here: the slope of the lifetime curve then does not depend on how strong each
mineral pair's contacts are.  As Y falls, s/Y rises and corrosion accelerates (the feedback that
Potyondy gets from a shrinking bond); failure comes at Y = s (s/Y = 1), exactly paper Eq. 4-5.
Only a positive driving stress corrodes (a compressed bond does not corrode in tension), and, with
the activation threshold, only while s >= threshold_ratio Y and s >= threshold_stress.

Closed form (k = beta2 s > 0): t(Y0 -> Y1) = (F(Y0) - F(Y1)) / beta1 with
F(Y) = Y e^(-k/Y) G(k/Y), G(x) = 1 - x e^x E1(x) (E1: exponential integral), so the time to
failure is (F(Y) - F(s)) / beta1.  Short intervals are integrated by Gauss-Legendre instead (no
cancellation), and the strength after an interval comes from Newton's method with the exact
derivative (:mod:`._time_integral`).  Stiffness does not change: the event clock jumps exactly, and
every time is proportional to 1/beta1.
"""
import numpy as np

from . import _time_integral as ti
from ._common import LOG_LIMIT, check_dt, check_rate_constants, check_shear, finite, shear_strength, time_from_log
from .area import _one_minus_x_ex_e1
from .hillig_charles import StrengthLaw, earliest

NAME = "normalised"


def log_antiderivative(y, k):
    """ln F(y), F(y) = y e^(-k/y) G(k/y) = int_0^y e^(-k/z) dz (k > 0, y > 0)."""
    x = k / y
    with np.errstate(divide="ignore"):
        return np.log(y) - x + np.log(_one_minus_x_ex_e1(x))


def closed_form_time(y_from, y_to, stress, beta1, beta2):
    """Creep time for a strength to fall from y_from to y_to > 0 at dY/dt = -beta1 exp(beta2 s/Y) [s]
    (closed form with the exponential integral; a reference for tests and long intervals)."""
    k = np.multiply(beta2, stress)
    l0, l1 = log_antiderivative(np.asarray(y_from, float), k), log_antiderivative(np.asarray(y_to, float), k)
    with np.errstate(under="ignore", divide="ignore"):
        log_t = l0 + np.log1p(-np.exp(np.minimum(l1 - l0, 0.0))) - np.log(beta1)
    return time_from_log(log_t)


def channel_time(strength, stress, floor, active, beta1, beta2):
    """Creep time to failure of one channel (strength Y, driving stress s, floor of Y)."""
    y, s, fl = (np.asarray(x, float) for x in (strength, stress, floor))
    t = np.where(y <= s, 0.0, np.inf)
    go = np.flatnonzero(active & (y > s) & (s > 0) & (s >= fl))
    if go.size:
        k = np.minimum(beta2 * s[go], np.finfo(float).max)
        ch = ti.Channels(np.full(go.size, np.log(beta1)), k)
        u0, u1 = 1.0 / y[go], 1.0 / s[go]
        variation = (np.minimum(k, 1e300) + 2.0 / u0) * (u1 - u0)
        short = variation <= ti.V_PANEL
        log_t = np.empty(go.size)
        if short.any():
            log_t[short] = ti.log_time(ch, u0[short], u1[short], np.flatnonzero(short))
        if (~short).any():
            lo = ~short
            l0, l1 = log_antiderivative(y[go][lo], k[lo]), log_antiderivative(s[go][lo], k[lo])
            with np.errstate(under="ignore", divide="ignore"):
                log_t[lo] = np.clip(l0 + np.log1p(-np.exp(np.minimum(l1 - l0, 0.0))) - np.log(beta1),
                                    -np.inf, LOG_LIMIT)
        t[go] = time_from_log(log_t)
    return t


def channel_degrade(strength, stress, floor, active, dt, beta1, beta2):
    """Strength of one channel after dt (Newton with the exact derivative), not below its floor."""
    y, s, fl = (np.asarray(x, float) for x in (strength, stress, floor))
    out = y.copy()
    go = np.flatnonzero(active & (s > 0) & (y > np.maximum(fl, 0.0)) & (np.asarray(dt) > 0))
    if go.size:
        k = np.minimum(beta2 * s[go], np.finfo(float).max)
        ch = ti.Channels(np.full(go.size, np.log(beta1)), k)
        stop = np.maximum(fl[go], 0.0)
        with np.errstate(divide="ignore"):
            u_stop = np.where(stop > 0, 1.0 / stop, np.inf)
        u, reached = ti.advance(ch, 1.0 / y[go], u_stop, np.log(np.broadcast_to(dt, y.shape)[go]))
        out[go] = np.where(reached, stop, np.minimum(1.0 / u, y[go]))
    return out


class Normalised(StrengthLaw):
    """dY/dt = -beta1 exp(beta2 s/Y) per channel (Potyondy 2007's normalised exponent), on strength."""
    name = NAME

    def __init__(self, beta1, beta2_normalised, threshold_ratio=0.0, threshold_stress=0.0):
        super().__init__(threshold_ratio, threshold_stress)
        b1, b2 = check_rate_constants(beta1, beta2_normalised, beta2_unit="(dimensionless)",
                                      beta2_paper="none (Potyondy 2007's form)")
        self.beta1, self.beta2 = float(b1), float(b2)

    def describe(self):
        return (f"Hillig-Charles on strength with the exponent on stress/strength (Potyondy 2007): beta1 "
                f"{self.beta1:g} Pa/s, beta2 {self.beta2:g} (dimensionless)" + self._threshold_text())

    def _parts(self, state, stresses):
        jt, jc = finite(tensile_strength=state["tensile_strength"], cohesion=state["cohesion"])
        sigma, tau = finite(normal_stress=stresses.normal, shear_stress=stresses.shear)
        check_shear(tau)
        tphi = state.tan_friction
        ten, sh = self.active(state, stresses)
        y_s = shear_strength(jc, sigma, tphi)
        floor_s = shear_strength(0.0, sigma, tphi)   # J^C = 0
        return (jt, sigma, np.zeros_like(jt), ten & (sigma > 0)), (y_s, tau, floor_s, sh & (tau > 0))

    def rate(self, state, stresses):
        out = []
        for y, s, _, act in self._parts(state, stresses):
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                e = np.clip(np.log(self.beta1) + self.beta2 * s / y, -LOG_LIMIT, LOG_LIMIT)
            out.append(np.where(act, np.where(y > 0, np.exp(e), np.exp(LOG_LIMIT)), 0.0))
        return tuple(out)

    def channel_times(self, state, stresses):
        return tuple(channel_time(y, s, fl, act, self.beta1, self.beta2)
                     for y, s, fl, act in self._parts(state, stresses))

    def time_to_failure(self, state, stresses):
        # activity (threshold and s > 0) is part of the channel times already
        return earliest(*self.channel_times(state, stresses))

    def degrade(self, state, stresses, dt):
        d = check_dt(dt)
        (yt, st, ft, at), (ys, ss, fs, as_) = self._parts(state, stresses)
        new_t = channel_degrade(yt, st, ft, at, d, self.beta1, self.beta2)
        new_ys = channel_degrade(ys, ss, fs, as_, d, self.beta1, self.beta2)
        cohesion = np.maximum(new_ys - fs, 0.0)        # J^C = Y - s_n tan(phi)
        cohesion = np.where(new_ys == ys, state["cohesion"], np.minimum(cohesion, state["cohesion"]))
        return {"tensile_strength": np.maximum(new_t, 0.0), "cohesion": cohesion}


#: The law this module builds (its class attributes, e.g. ``time_scales_with_beta1``, are the law's own).
LAW = Normalised


def build(sc) -> Normalised:
    """The normalised law from ``[stress_corrosion]`` (beta1 [Pa/s], beta2_normalised [1], thresholds)."""
    return Normalised(sc.beta1, sc.beta2_normalised, sc.threshold_ratio, sc.threshold_stress)
