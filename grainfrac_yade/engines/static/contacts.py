"""The bond and contact law of the YADE scene as array functions (pure numpy).

Sign conventions as :mod:`grainfrac_yade.law`: normal displacement du_n and force F_n opening / tension
positive; F_s signed along the bond's tangent; sigma = F_n / A0, tau = |F_s| / A0.

Intact bond (YADE's JCFpm, cohesive): linear, F_n = k_n du_n, F_s = k_s du_s, in tension and compression.
It fails (paper Eq. 4-5, :func:`grainfrac_yade.law.failed_now`) when sigma >= J^T (tension cut-off) or
tau >= J^C + s_n tan(phi), s_n = -sigma (Mohr-Coulomb shear), both per intact area A0.

Broken contact (JCFpm after a break, ``neverErase``): compression only, F_n = k_n min(du_n, 0); shear elastic
from the contact's shear reference s_p (the plastic slip), F_s = k_s (du_s - s_p), limited by the residual
friction |F_s| <= -F_n tan(phi_r): where the trial force exceeds it the contact slips, F_s = sign x
(-F_n tan(phi_r)) (return mapping from the last converged s_p, which is what makes friction path
dependent).  An open contact carries nothing and forgets its shear (s_p = du_s, as YADE zeroes it).

Given each contact's status (intact, open, stick, slip with its sign) the law is affine in (du_n, du_s):
F = A du + b (:func:`affine_law`), so the equilibrium at fixed statuses is one linear solve.
"""
from __future__ import annotations

import numpy as np

from ...law import failed_now
from .ties import DECISION_REL_TOL

#: Status of a contact: intact bond, broken and open, broken and sticking, broken and slipping.
INTACT, OPEN, STICK, SLIP = 0, 1, 2, 3
#: Names of the contact statuses, by code (what a message says).
STATUS_NAMES = ("intact", "open", "stick", "slip")
#: Relative force band [1] within which a contact keeps its status: at the friction limit (stick or slip), relative to
#: its own forces; at the open/close point, relative to the largest normal force of the state.  The round-off of a
#: solve (~1e-12 of the contact forces, and another on another CPU) would otherwise flip it back and forth, or one way
#: on one machine and the other way on another (:mod:`.ties`).
STATUS_HYSTERESIS = DECISION_REL_TOL
#: Failure modes, the codes of YADE's JCFpm crack file (as :mod:`grainfrac_yade.law`).
TENSION, SHEAR = 1, 2


def affine_law(status, sign, s_p, kn, ks, tan_r):
    """Per contact (a_nn, a_ns, a_sn, a_ss, b_n, b_s): F_n = a_nn du_n + a_ns du_s + b_n, F_s = a_sn du_n +
    a_ss du_s + b_s under fixed statuses (module doc).  Slip: F_s = -sign tan(phi_r) k_n du_n, the consistent
    tangent of the friction limit (non-symmetric)."""
    z = np.zeros(len(kn))
    closed = (status == INTACT) | (status == STICK) | (status == SLIP)
    a_nn = np.where(closed, kn, 0.0)
    stick = (status == INTACT) | (status == STICK)
    a_ss = np.where(stick, ks, 0.0)
    a_sn = np.where(status == SLIP, -sign * tan_r * kn, 0.0)
    b_s = np.where(status == STICK, -ks * s_p, 0.0)
    return a_nn, z, a_sn, a_ss, z.copy(), b_s


def forces(du_n, du_s, status, sign, s_p, kn, ks, tan_r):
    """(F_n, F_s) [N] of every contact at relative displacements (du_n, du_s) [m] under fixed statuses."""
    a_nn, a_ns, a_sn, a_ss, b_n, b_s = affine_law(status, sign, s_p, kn, ks, tan_r)
    return a_nn * du_n + a_ns * du_s + b_n, a_sn * du_n + a_ss * du_s + b_s


def trial_status(du_n, du_s, broken, s_p, kn, ks, tan_r, status=None, sign=None):
    """Statuses the broken contacts take at (du_n, du_s) by the return mapping from their last converged shear
    reference ``s_p``: (status, sign, violation [N]).  Open where du_n > 0; else the trial shear force
    k_s (du_s - s_p) against the friction limit -F_n tan(phi_r) = -k_n du_n tan(phi_r): stick inside, slip
    (its sign) beyond.  Given the statuses the solution was made with (``status``, ``sign``), a contact keeps open or
    closed, and a closed one stick or slip, within :data:`STATUS_HYSTERESIS` of its switching point; a contact now
    slipping stays slipping only while its slip goes its way (sign x trial force beyond the limit); else it sticks
    first.
    ``violation``: how far the contact is from its other status, in force (what orders the status changes of one
    iteration)."""
    fn = kn * np.minimum(du_n, 0.0)
    f_trial = ks * (du_s - s_p)
    cap = -fn * tan_r
    opening = du_n > 0
    if status is not None:   # at the open/close point within round-off a contact keeps open or closed
        band_n = STATUS_HYSTERESIS * float(np.abs(kn * du_n).max(initial=0.0))
        was_closed = (status == STICK) | (status == SLIP)
        opening = np.where(was_closed, kn * du_n > band_n, np.where(status == OPEN, kn * du_n > -band_n, opening))
    new = np.where(opening, OPEN, np.where(np.abs(f_trial) > cap, SLIP, STICK))
    new_sign = np.where(f_trial >= 0, 1.0, -1.0)
    if status is not None:
        reversed_slip = (status == SLIP) & (new == SLIP) & (new_sign != sign)
        new = np.where(reversed_slip, STICK, new)
        new_sign = np.where(reversed_slip, sign, new_sign)
    if status is not None:   # at the friction limit within round-off a closed contact keeps stick or slip
        band = STATUS_HYSTERESIS * (np.abs(fn) + np.abs(f_trial))
        both_closed = ((status == STICK) | (status == SLIP)) & ((new == STICK) | (new == SLIP))
        keep = both_closed & (np.abs(np.abs(f_trial) - cap) <= band)
        new = np.where(keep, status, new)
        new_sign = np.where(keep, sign, new_sign)
    new = np.where(broken, new, INTACT)
    violation = np.where(du_n > 0, kn * du_n, np.minimum(-fn, np.abs(np.abs(f_trial) - cap)))
    return new, new_sign, violation


def converged_slip(du_s, status, fs, ks):
    """Shear reference after a converged state: s_p = du_s - F_s / k_s (slip moves it; open resets it)."""
    return np.where(status == OPEN, du_s, du_s - np.divide(fs, ks, out=np.zeros_like(fs), where=ks > 0))


def overstress(fn, fs, area, jt, jc, tan_phi):
    """(ratio, mode) per bond: the larger of sigma / J^T and tau / (J^C + s_n tan(phi)) (paper Eq. 4-5), inf
    where a strength is not positive and its stress not below it; mode TENSION where the tensile ratio is the
    larger (also on ties, as :func:`grainfrac_yade.law.hillig_charles.earliest`), else SHEAR."""
    sigma, tau = fn / area, np.abs(fs) / area
    strength_s = jc - sigma * tan_phi
    with np.errstate(divide="ignore", invalid="ignore"):
        r_t = np.where(jt > 0, sigma / np.where(jt > 0, jt, 1.0), np.where(sigma >= jt, np.inf, -np.inf))
        r_s = np.where(strength_s > 0, tau / np.where(strength_s > 0, strength_s, 1.0), np.inf)
    return np.maximum(r_t, r_s), np.where(r_t >= r_s, TENSION, SHEAR)


def failing(fn, fs, area, jt, jc, tan_phi):
    """Bonds that have reached their strength: paper Eq. 4-5 exactly as the law package tests it."""
    ten, sh = failed_now(jt, jc, fn / area, np.abs(fs) / area, tan_phi)
    return ten | sh


def crossing_increment(fn0, fs0, fn1, fs1, area, jt, jc, tan_phi):
    """Per bond, the smallest increment x > 0 of the control at which F = F0 + x F1 reaches the strength
    (paper Eq. 4-5 along a straight path): tension k: F_n = J^T A0; shear: s F_s + F_n tan(phi) = J^C A0 for
    s = +-1.  inf where the path never reaches it.  Bonds already at or beyond it give 0."""
    big = np.full(len(fn0), np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        cand = [np.where(fn1 > 0, (jt * area - fn0) / fn1, big)]
        for s in (1.0, -1.0):
            den = s * fs1 + fn1 * tan_phi
            cand.append(np.where(den > 0, (jc * area - s * fs0 - fn0 * tan_phi) / den, big))
    x = np.min(np.stack(cand), axis=0)
    return np.where(np.isnan(x), np.inf, np.maximum(x, 0.0))


def break_state(du_n, du_s, fs, kn, ks, tan_r):
    """(status, sign, s_p) of bonds that break now: JCFpm keeps the shear force, capped by the residual
    friction, on a closed face; an opening face carries nothing (module doc)."""
    fn = kn * np.minimum(du_n, 0.0)
    cap = -fn * tan_r
    fs_c = np.clip(fs, -cap, cap)
    status = np.where(du_n > 0, OPEN, np.where(np.abs(fs) > cap, SLIP, STICK))
    sign = np.where(fs >= 0, 1.0, -1.0)
    return status, sign, np.where(du_n > 0, du_s, du_s - np.divide(fs_c, ks, out=np.zeros_like(fs_c), where=ks > 0))
