"""Numerics shared by the degradation laws: clipped exponentials, input checks, failure criteria.

Sign conventions (all stresses in Pa): ``normal_stress`` sigma = F_n/A0 is TENSION POSITIVE, the
compressive normal stress is s_n = -sigma; ``shear_stress`` tau = |F_s|/A0 >= 0, both per intact
bond area A0.  Strengths: tensile J^T, cohesion J^C [Pa]; ``tan_friction`` = tan(phi) [-].

Every exponent is clipped to [-LOG_LIMIT, LOG_LIMIT], so no function overflows or returns NaN for
finite input; ``inf`` appears only as the documented answer 'never fails'.  A NaN or infinite
stress, force or strength (a DEM that blew up) is refused with
:class:`~grainfrac_yade.errors.NumericalFailure`: it never yields a time, a verdict or a strength.
"""
import numpy as np

from ..errors import NumericalFailure

# float64 exp() overflows above ln(1.8e308) ~ 709.8 and leaves the normal range below
# ln(2.2e-308) ~ -708.4; clipping every exponent to +-700 keeps exp() finite and normal with
# a margin of e^9 ~ 8e3 for one further product.
LOG_LIMIT = 700.0
# Largest degradation rate [Pa/s or 1/s] and largest finite time [s] returned: exp(LOG_LIMIT)
# ~ 1.01e304. A finite lifetime beyond it is reported as TIME_CAP, never as inf.
RATE_CAP = float(np.exp(LOG_LIMIT))
TIME_CAP = RATE_CAP

MODE_NEVER = 0      # does not fail under frozen stresses (time is inf)
MODE_TENSION = 1    # same code as YADE JCFpm's crack file
MODE_SHEAR = 2      # same code as YADE JCFpm's crack file
MODE_CORRODED = 3   # area law only: the area reaches 0 before either criterion is met


def arr(x):
    return np.asarray(x, dtype=float)


def check_rate_constants(beta1, beta2, beta2_unit="1/Pa", beta2_paper="1e-7"):
    """beta1 > 0 [Pa/s] and beta2 >= 0 as float arrays; ValueError naming the bad one."""
    b1, b2 = arr(beta1), arr(beta2)
    if not (np.all(np.isfinite(b1)) and np.all(b1 > 0)):
        raise ValueError(f"beta1 must be finite and > 0 Pa/s (got {beta1!r}); paper: 1e-3")
    if not (np.all(np.isfinite(b2)) and np.all(b2 >= 0)):
        raise ValueError(f"beta2 must be finite and >= 0 {beta2_unit} (got {beta2!r}); paper: {beta2_paper}")
    return b1, b2


def check_shear(tau, name="shear_stress"):
    if np.any(arr(tau) < 0):
        raise ValueError(f"{name} must be |F_s|/A >= 0 Pa; pass the magnitude")


def check_finite(name, values, labels=None, item="bond"):
    """Raise NumericalFailure if ``values`` (one per ``item``) hold NaN or inf; name how many and the first.

    ``labels``: the items' numbers, to name the first bad one (default: its position).
    """
    v = np.ravel(arr(values))
    bad = np.flatnonzero(~np.isfinite(v))
    if bad.size:
        first = bad[0] if labels is None else np.ravel(labels)[bad[0]]
        raise NumericalFailure(f"{name} is NaN or infinite at {bad.size} of {v.size} {item}(s) (first: {item} "
                               f"{first}, {v[bad[0]]})")


def finite(**named):
    """The arrays of ``named`` (name=value, in order), each checked by :func:`check_finite`."""
    for name, value in named.items():
        check_finite(name, value)
    return [arr(v) for v in named.values()]


def check_dt(dt):
    d = arr(dt)
    if not np.all(d >= 0):
        raise ValueError(f"dt must be >= 0 s (got {dt!r})")
    return d


def log_rate(stress, beta1, beta2):
    """ln(beta1 exp(beta2 stress)) clipped to +-LOG_LIMIT (beta2*stress may overflow to inf)."""
    with np.errstate(over="ignore", under="ignore"):
        exponent = np.multiply(beta2, stress)
    return np.clip(np.log(beta1) + exponent, -LOG_LIMIT, LOG_LIMIT)


def quotient(numerator, log_denominator):
    """numerator / exp(log_denominator) for numerator > 0 (else 1 is used), in [e^-700, e^700]."""
    num = np.where(numerator > 0, numerator, 1.0)
    log_q = np.log(num) - log_denominator
    with np.errstate(all="ignore"):  # discarded where |log_q| >= LOG_LIMIT
        direct = num / np.exp(log_denominator)
    clipped = np.exp(np.clip(log_q, -LOG_LIMIT, LOG_LIMIT))
    return np.where(np.abs(log_q) < LOG_LIMIT, direct, clipped)


def loss(log_rate_, dt):
    """rate*dt [Pa] for rate = exp(log_rate) without overflow; 0 for dt == 0."""
    positive = dt > 0
    log_dt = np.log(np.where(positive, dt, 1.0))
    log_loss = log_rate_ + log_dt
    with np.errstate(all="ignore"):  # discarded where |log_loss| >= LOG_LIMIT
        direct = np.exp(log_rate_) * dt
    out = np.where(np.abs(log_loss) < LOG_LIMIT, direct, np.exp(np.clip(log_loss, -LOG_LIMIT, LOG_LIMIT)))
    return np.where(positive & (log_loss > -LOG_LIMIT), out, 0.0)


def time_from_log(log_t):
    """exp(log_t) clipped to [0, TIME_CAP]; -inf gives 0, +inf stays inf ('never')."""
    with np.errstate(under="ignore"):
        out = np.exp(np.clip(log_t, -LOG_LIMIT, LOG_LIMIT))
    return np.where(np.isneginf(log_t), 0.0, np.where(np.isposinf(log_t), np.inf, out))


def logaddexp(x, y):
    """ln(e^x + e^y) without underflow flags (terms below e^-LOG_LIMIT relative are dropped)."""
    m = np.maximum(x, y)
    with np.errstate(invalid="ignore"):  # -inf - -inf: both terms empty
        gap = np.abs(x - y)
    small = np.where(gap < LOG_LIMIT, np.exp(-np.where(gap < LOG_LIMIT, gap, 0.0)), 0.0)
    with np.errstate(invalid="ignore"):
        return np.where(np.isneginf(m), -np.inf, m + np.log1p(small))


def shear_strength(cohesion, normal_stress, tan_friction):
    """Mohr-Coulomb shear strength J^C + s_n tan(phi), s_n = -sigma (paper Eq. 5) [Pa].

    Parameters
    ----------
    cohesion : array_like
        J^C [Pa].
    normal_stress : array_like
        sigma [Pa], tension positive; in tension the strength falls below J^C.
    tan_friction : array_like
        tan(phi) [-].

    Returns
    -------
    ndarray
        Shear strength [Pa]; saturates to +-inf only beyond the float range (|sigma| > ~1e308).
    """
    with np.errstate(over="ignore", under="ignore"):
        return arr(cohesion) - arr(normal_stress) * arr(tan_friction)


def failed_now(tensile_strength, cohesion, normal_stress, shear_stress, tan_friction):
    """Failure criteria of paper Eq. 4-5: sigma >= J^T (tension), tau >= J^C + s_n tan(phi) (shear).

    Returns
    -------
    tensile_failed, shear_failed : ndarray of bool
    """
    jt, jc, sigma, tau, tphi = finite(tensile_strength=tensile_strength, cohesion=cohesion,
                                      normal_stress=normal_stress, shear_stress=shear_stress,
                                      tan_friction=tan_friction)
    return sigma >= jt, tau >= shear_strength(jc, sigma, tphi)
