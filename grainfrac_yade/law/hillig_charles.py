"""Hillig-Charles stress corrosion on strength, paper Eq. 7 (the default law), with an optional
activation threshold (Potyondy 2007).

    dJ^T/dt = -beta1 exp(beta2 sigma),   dJ^C/dt = -beta1 exp(beta2 tau),   J >= 0,

sigma = F_n/A0 (tension positive), tau = |F_s|/A0, beta1 [Pa/s], beta2 [1/Pa] (paper section 4.1:
1e-3 Pa/s and 1e-7 1/Pa).  Failure (paper Eq. 4-5): sigma >= J^T, or tau >= J^C + s_n tan(phi).  The
stresses in the rate are the bond's own or its face's (``stress_corrosion.reading``, :mod:`.readings`); the
criteria read the bond's own.
Stiffness does not change, so under frozen stresses each rate is constant: the time to failure is a
closed form (computed in log space, no overflow for any finite input) and the event clock jumps
exactly from failure to failure.  beta1 is then an exact time scale: every time is proportional to
1/beta1 and the sequence of failures does not depend on it.

Activation threshold (off by default): a channel corrodes only while its driving stress is at least
``threshold_ratio`` times its strength (tension: sigma >= r J^T; shear: tau >= r (J^C + s_n
tan(phi))) and at least ``threshold_stress`` [Pa].  Potyondy's parallel-bond stress-corrosion model
has such an activation stress, below which bonds never corrode: it gives the material a long-term
strength.  Under frozen stresses a channel's activity does not change during an interval (an active
channel's strength only falls, so stress/strength only rises), so the times stay exact.
"""
import numpy as np

from ._common import (MODE_NEVER, MODE_SHEAR, MODE_TENSION, check_dt, check_rate_constants, check_shear, failed_now,
                      finite, log_rate, loss, quotient, shear_strength)
from ._interface import BondState, DegradationLaw

NAME = "hillig_charles"


def degradation_rate(stress, beta1, beta2):
    """Strength-loss rate beta1 exp(beta2 stress) of paper Eq. 7 [Pa/s], exponent clipped to +-LOG_LIMIT."""
    b1, b2 = check_rate_constants(beta1, beta2)
    stress, = finite(stress=stress)
    return np.exp(log_rate(stress, b1, b2))


def degrade(tensile_strength, cohesion, normal_stress, shear_stress, dt, beta1, beta2, active=None):
    """Strengths after creep time dt under frozen stresses (paper Eq. 7, exact for constant rate).

    J^T <- max(J^T - beta1 exp(beta2 sigma) dt, 0), J^C <- max(J^C - beta1 exp(beta2 tau) dt, 0).
    ``active``: optional (tension, shear) masks of the channels that corrode (activation threshold);
    inactive channels keep their strength.  Failure is not checked here (see :func:`failed_now`).

    Returns
    -------
    new_tensile_strength, new_cohesion : ndarray
        [Pa], never below 0.
    """
    b1, b2 = check_rate_constants(beta1, beta2)
    jt, jc, sigma, tau = finite(tensile_strength=tensile_strength, cohesion=cohesion,
                                normal_stress=normal_stress, shear_stress=shear_stress)
    check_shear(tau)
    d = check_dt(dt)
    loss_t, loss_c = loss(log_rate(sigma, b1, b2), d), loss(log_rate(tau, b1, b2), d)
    if active is not None:
        loss_t, loss_c = np.where(active[0], loss_t, 0.0), np.where(active[1], loss_c, 0.0)
    with np.errstate(over="ignore"):  # only for strengths near -1.8e308, clipped to 0 below
        jt = jt - loss_t
        jc = jc - loss_c
    return np.maximum(jt, 0.0), np.maximum(jc, 0.0)


def channel_times(tensile_strength, cohesion, normal_stress, shear_stress, tan_friction, beta1, beta2,
                  rate_normal=None, rate_shear=None):
    """Closed-form creep times to tensile and to shear failure under frozen stresses (paper Eq. 5, 7).

    Tension: t_T = (J^T - sigma) / (beta1 exp(beta2 sigma_r)); 0 if sigma >= J^T; inf ('never') if
    sigma < 0, because J^T cannot fall below 0.  Shear: the cohesion must fall to J^C* = tau - s_n
    tan(phi), so t_S = (J^C - J^C*) / (beta1 exp(beta2 tau_r)); 0 if already failed; inf ('never') if
    J^C* < 0 (friction alone carries tau).  sigma_r, tau_r: the stresses that drive the rate
    (``rate_normal``, ``rate_shear``; :mod:`.readings`), sigma and tau unless given.  Finite times are in
    [0, TIME_CAP] (log space, clipped).
    """
    b1, b2 = check_rate_constants(beta1, beta2)
    jt, jc, sigma, tau, tphi = np.broadcast_arrays(*finite(
        tensile_strength=tensile_strength, cohesion=cohesion, normal_stress=normal_stress,
        shear_stress=shear_stress, tan_friction=tan_friction))
    check_shear(tau)
    sigma_r = sigma if rate_normal is None else np.broadcast_to(finite(rate_normal=rate_normal)[0], sigma.shape)
    tau_r = tau if rate_shear is None else np.broadcast_to(finite(rate_shear=rate_shear)[0], tau.shape)
    check_shear(tau_r, "rate_shear")
    with np.errstate(over="ignore"):  # inf only where sigma < 0 ('never' anyway)
        gap_t = jt - sigma
        gap_s = shear_strength(jc, sigma, tphi) - tau  # cohesion still to lose; +inf: never
    t_t = np.where(gap_t <= 0, 0.0, np.where(
        sigma >= 0, quotient(gap_t, log_rate(sigma_r, b1, b2)), np.inf))
    t_s = np.where(gap_s <= 0, 0.0, np.where(
        gap_s > jc, np.inf, quotient(gap_s, log_rate(tau_r, b1, b2))))
    return t_t, t_s


def earliest(t_t, t_s):
    """(t, mode): the earlier channel; MODE_TENSION on ties, MODE_NEVER if both are inf."""
    mode = np.where(t_t <= t_s, MODE_TENSION, MODE_SHEAR)
    mode = np.where(np.isinf(t_t) & np.isinf(t_s), MODE_NEVER, mode)
    return np.minimum(t_t, t_s), mode


def time_to_failure(tensile_strength, cohesion, normal_stress, shear_stress, tan_friction, beta1, beta2):
    """Closed-form creep time to failure under frozen stresses (paper Eq. 5 and 7).

    See :func:`channel_times`; a bond at zero stress fails when its strength reaches 0 (criteria use
    >=), consistent with :func:`failed_now`.

    Returns
    -------
    t_fail : ndarray
        [s]; finite times are in [0, TIME_CAP]; inf only for 'never'.
    mode : ndarray of int
        MODE_TENSION (1, also on ties), MODE_SHEAR (2) or MODE_NEVER (0).
    """
    return earliest(*channel_times(tensile_strength, cohesion, normal_stress, shear_stress, tan_friction,
                                   beta1, beta2))


def active_channels(tensile_strength, cohesion, normal_stress, shear_stress, tan_friction, threshold_ratio,
                    threshold_stress):
    """(tension, shear) masks of the channels above the activation threshold (Potyondy 2007).

    A channel corrodes while its driving stress is >= ``threshold_ratio`` x its strength (tension:
    J^T; shear: the Mohr-Coulomb strength J^C + s_n tan(phi)) and >= ``threshold_stress`` [Pa]; a
    condition whose value is 0 is off.
    """
    sigma, tau = np.asarray(normal_stress, float), np.asarray(shear_stress, float)
    ten = np.ones(np.broadcast(sigma, tau).shape, bool)
    sh = ten.copy()
    if threshold_ratio > 0:
        ten = ten & (sigma >= threshold_ratio * np.asarray(tensile_strength, float))
        sh = sh & (tau >= threshold_ratio * shear_strength(cohesion, sigma, tan_friction))
    if threshold_stress > 0:
        ten, sh = ten & (sigma >= threshold_stress), sh & (tau >= threshold_stress)
    return ten, sh


def at_failure_point(new_t, new_c, jt, jc, sigma, tau, tphi, positions, modes):
    """Set failing bonds (``positions``, ``modes``) exactly on their failure point: J^T = sigma, or
    J^C = tau + sigma tan(phi) to the last bit, so that :func:`failed_now` holds; bonds already past
    it keep their degraded strengths."""
    fi = np.asarray(positions, dtype=int).ravel()
    fmode = np.asarray(modes).ravel()
    ten, sh = fi[fmode == MODE_TENSION], fi[fmode == MODE_SHEAR]
    new_t[ten] = np.where(jt[ten] > sigma[ten], sigma[ten], new_t[ten])  # already failed: keep
    target = np.maximum(tau[sh] + sigma[sh] * tphi[sh], 0.0)
    for _ in range(4):  # undo rounding of J^C - sigma tan(phi): a few ulps at most
        short = tau[sh] < shear_strength(target, sigma[sh], tphi[sh])
        target = np.where(short & (target > 0), np.nextafter(target, -np.inf), target)
    not_yet = tau[sh] < shear_strength(jc[sh], sigma[sh], tphi[sh])
    new_c[sh] = np.where(not_yet, target, new_c[sh])
    return new_t, new_c


class StrengthLaw(DegradationLaw):
    """Common part of the laws that lower J^T and J^C (stiffness unchanged): state, failure point,
    criteria and threshold.  Subclasses give the channel times and the degradation."""
    state_names = ("tensile_strength", "cohesion")
    exact_jump = True
    time_scales_with_beta1 = True

    def __init__(self, threshold_ratio=0.0, threshold_stress=0.0):
        r, s = float(threshold_ratio), float(threshold_stress)
        if not (0 <= r < 1):
            raise ValueError(f"threshold_ratio must be in [0, 1) (got {threshold_ratio!r}); 0 = off")
        if not (0 <= s < np.inf):
            raise ValueError(f"threshold_stress must be finite and >= 0 Pa (got {threshold_stress!r}); 0 = off")
        self.threshold_ratio, self.threshold_stress = r, s

    @property
    def has_threshold(self) -> bool:
        return self.threshold_ratio > 0 or self.threshold_stress > 0

    def _threshold_text(self):
        parts = ([f"ratio {self.threshold_ratio:g}"] if self.threshold_ratio else []) + \
                ([f"stress {self.threshold_stress:g} Pa"] if self.threshold_stress else [])
        return f"; activation threshold {' and '.join(parts)}" if parts else ""

    def initial_state(self, tensile_strength0, cohesion0, tan_friction):
        jt0, jc0 = np.asarray(tensile_strength0, float), np.asarray(cohesion0, float)
        return BondState(jt0, jc0, np.asarray(tan_friction, float),
                         {"tensile_strength": jt0.copy(), "cohesion": jc0.copy()})

    def strengths(self, state):
        return state["tensile_strength"], state["cohesion"], None

    def failed_now(self, state, stresses):
        return failed_now(state["tensile_strength"], state["cohesion"], stresses.normal, stresses.shear,
                          state.tan_friction)

    def active(self, state, stresses):
        """(tension, shear) channels that corrode now (all, without a threshold)."""
        return active_channels(state["tensile_strength"], state["cohesion"], stresses.rate_normal, stresses.rate_shear,
                               state.tan_friction, self.threshold_ratio, self.threshold_stress)

    def channel_times(self, state, stresses):
        raise NotImplementedError

    def time_to_failure(self, state, stresses):
        t_t, t_s = self.channel_times(state, stresses)
        if self.has_threshold:   # an inactive channel never fails, unless it has failed already
            ten, sh = self.active(state, stresses)
            t_t, t_s = np.where(ten | (t_t == 0), t_t, np.inf), np.where(sh | (t_s == 0), t_s, np.inf)
        return earliest(t_t, t_s)

    def at_failure(self, new, state, stresses, positions, modes):
        new_t, new_c = at_failure_point(new["tensile_strength"], new["cohesion"], state["tensile_strength"],
                                        state["cohesion"], stresses.normal, stresses.shear, state.tan_friction,
                                        positions, modes)
        return {"tensile_strength": new_t, "cohesion": new_c}


class HilligCharles(StrengthLaw):
    """Paper Eq. 7 on strength (the default), with an optional activation threshold."""
    name = NAME

    def __init__(self, beta1, beta2, threshold_ratio=0.0, threshold_stress=0.0):
        super().__init__(threshold_ratio, threshold_stress)
        b1, b2 = check_rate_constants(beta1, beta2)
        self.beta1, self.beta2 = float(b1), float(b2)

    def describe(self):
        return (f"Hillig-Charles on strength (paper Eq. 7): beta1 {self.beta1:g} Pa/s, beta2 {self.beta2:g} 1/Pa"
                + self._threshold_text())

    def rate(self, state, stresses):
        r_t = degradation_rate(stresses.rate_normal, self.beta1, self.beta2)
        r_s = degradation_rate(stresses.rate_shear, self.beta1, self.beta2)
        if self.has_threshold:
            ten, sh = self.active(state, stresses)
            r_t, r_s = np.where(ten, r_t, 0.0), np.where(sh, r_s, 0.0)
        return r_t, r_s

    def degrade(self, state, stresses, dt):
        active = self.active(state, stresses) if self.has_threshold else None
        jt, jc = degrade(state["tensile_strength"], state["cohesion"], stresses.rate_normal, stresses.rate_shear, dt,
                         self.beta1, self.beta2, active)
        return {"tensile_strength": jt, "cohesion": jc}

    def channel_times(self, state, stresses):
        return channel_times(state["tensile_strength"], state["cohesion"], stresses.normal, stresses.shear,
                             state.tan_friction, self.beta1, self.beta2, stresses.rate_normal, stresses.rate_shear)


#: The law this module builds (its class attributes, e.g. ``time_scales_with_beta1``, are the law's own).
LAW = HilligCharles


def build(sc) -> HilligCharles:
    """Paper Eq. 7 from ``[stress_corrosion]`` parameters (beta1, beta2, threshold_ratio, threshold_stress)."""
    return HilligCharles(sc.beta1, sc.beta2, sc.threshold_ratio, sc.threshold_stress)
