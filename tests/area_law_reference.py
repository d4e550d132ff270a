"""The area law as it was before grainfrac_yade/law (commit 7e91240, grainfrac_yade/corrosion.py and the area
branch of clocks.EventClock), kept verbatim as a reference for tests/test_law_area.py: the new law must agree
with it and be at least 10 times faster.  Not used by the package."""
import numpy as np
from scipy import special

from grainfrac_yade.errors import NumericalFailure

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
MODE_CORRODED = 3   # area mode only: a reaches 0 before either criterion is met

# --- area-mode quadrature of t = int da/|da/dt| = int du / (u^2 rate(u)), u = 1/a ---
# |d ln(integrand)/du| <= K = max|beta2 p|, |beta2 q| + 2 (u >= 1). Panels grow geometrically
# from u_from, so each panel's log-variation is ~(ratio-1) times the decay from the peak:
# negligible where the integrand matters, large only where it is exponentially small.
GL_NODES = 10       # Gauss-Legendre nodes per panel: machine precision for log-variation < ~10
N_PANELS = 64       # geometric panels per bond: 25 decades of u at ratio <= 2.5 per panel
FIRST_PANEL = 0.1   # first panel width in units of 1/K: log-variation <= 0.1 across it
K_GRID_MAX = 1e40   # cap on K for the grid: beyond it every exponent k*u (u >= 1) is clipped
                    # at +-LOG_LIMIT, so the integrand is flat and needs no finer panel
AREA_MIN = 1e-250   # a below this counts as 0: keeps u = 1/a, TAIL_RATIO*u and grid ratios finite
TAIL_RATIO = 1e16   # a below a_from/1e16 counts as 0: as |da/dt| >= beta1/J^C0, the dropped
                    # tail lasts <= 1e-16 a_from J^C0/beta1 (1e-3 s for the paper's constants)
BISECTION_STEPS = 60  # halvings inside one panel in degrade_area: 2^-60 < float64 resolution
CHUNK = 2048        # bonds per quadrature batch: <= CHUNK*N_PANELS*GL_NODES*8 B = 10 MB/array
ASYMPTOTIC_X = 50.0  # x above which x e^x E1(x) uses its asymptotic series (e^x E1 overflows)
ASYMPTOTIC_TERMS = 40  # series terms: 40!/50^40 ~ 1e-20, far below float64 resolution


def _arr(x):
    return np.asarray(x, dtype=float)


def _check_law(beta1, beta2):
    b1, b2 = _arr(beta1), _arr(beta2)
    if not (np.all(np.isfinite(b1)) and np.all(b1 > 0)):
        raise ValueError(f"beta1 must be finite and > 0 Pa/s (got {beta1!r}); paper: 1e-3")
    if not (np.all(np.isfinite(b2)) and np.all(b2 >= 0)):
        raise ValueError(f"beta2 must be finite and >= 0 1/Pa (got {beta2!r}); paper: 1e-7")
    return b1, b2


def _check_shear(tau, name="shear_stress"):
    if np.any(_arr(tau) < 0):
        raise ValueError(f"{name} must be |F_s|/A >= 0 Pa; pass the magnitude")


def check_finite(name, values, labels=None, item="bond"):
    """Raise NumericalFailure if ``values`` (one per ``item``) hold NaN or inf; name how many and the first.

    ``labels``: the items' numbers, to name the first bad one (default: its position).
    """
    v = np.ravel(_arr(values))
    bad = np.flatnonzero(~np.isfinite(v))
    if bad.size:
        first = bad[0] if labels is None else np.ravel(labels)[bad[0]]
        raise NumericalFailure(f"{name} is NaN or infinite at {bad.size} of {v.size} {item}(s) (first: {item} "
                               f"{first}, {v[bad[0]]})")


def _finite(**named):
    """The arrays of ``named`` (name=value, in order), each checked by :func:`check_finite`."""
    for name, value in named.items():
        check_finite(name, value)
    return [_arr(v) for v in named.values()]


def _log_rate(stress, beta1, beta2):
    """ln(beta1 exp(beta2 stress)) clipped to +-LOG_LIMIT (beta2*stress may overflow to inf)."""
    with np.errstate(over="ignore", under="ignore"):
        exponent = np.multiply(beta2, stress)
    return np.clip(np.log(beta1) + exponent, -LOG_LIMIT, LOG_LIMIT)


def _quotient(numerator, log_denominator):
    """numerator / exp(log_denominator) for numerator > 0 (else 1 is used), in [e^-700, e^700]."""
    num = np.where(numerator > 0, numerator, 1.0)
    log_q = np.log(num) - log_denominator
    with np.errstate(all="ignore"):  # discarded where |log_q| >= LOG_LIMIT
        direct = num / np.exp(log_denominator)
    clipped = np.exp(np.clip(log_q, -LOG_LIMIT, LOG_LIMIT))
    return np.where(np.abs(log_q) < LOG_LIMIT, direct, clipped)


def degradation_rate(stress, beta1, beta2):
    """Strength-loss rate beta1 exp(beta2 stress) of paper Eq. 7 [Pa/s].

    Parameters
    ----------
    stress : array_like
        Driving stress [Pa]: sigma (tension positive) or tau.
    beta1 : array_like
        Rate constant [Pa/s], > 0.
    beta2 : array_like
        Stress sensitivity [1/Pa], >= 0.

    Returns
    -------
    ndarray
        Rate [Pa/s] in [exp(-LOG_LIMIT), RATE_CAP]: the exponent is clipped to +-LOG_LIMIT.
    """
    b1, b2 = _check_law(beta1, beta2)
    stress, = _finite(stress=stress)
    return np.exp(_log_rate(stress, b1, b2))


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
        return _arr(cohesion) - _arr(normal_stress) * _arr(tan_friction)


def failed_now(tensile_strength, cohesion, normal_stress, shear_stress, tan_friction):
    """Failure criteria of paper Eq. 4-5: sigma >= J^T (tension), tau >= J^C + s_n tan(phi) (shear).

    Parameters
    ----------
    tensile_strength, cohesion : array_like
        J^T, J^C [Pa].
    normal_stress, shear_stress : array_like
        sigma (tension positive), tau >= 0 [Pa].
    tan_friction : array_like
        tan(phi) [-].

    Returns
    -------
    tensile_failed, shear_failed : ndarray of bool
    """
    jt, jc, sigma, tau, tphi = _finite(tensile_strength=tensile_strength, cohesion=cohesion,
                                       normal_stress=normal_stress, shear_stress=shear_stress,
                                       tan_friction=tan_friction)
    return sigma >= jt, tau >= shear_strength(jc, sigma, tphi)


def _loss(log_rate, dt):
    """rate*dt [Pa] for rate = exp(log_rate) without overflow; 0 for dt == 0."""
    positive = dt > 0
    log_dt = np.log(np.where(positive, dt, 1.0))
    log_loss = log_rate + log_dt
    with np.errstate(all="ignore"):  # discarded where |log_loss| >= LOG_LIMIT
        direct = np.exp(log_rate) * dt
    loss = np.where(np.abs(log_loss) < LOG_LIMIT, direct,
                    np.exp(np.clip(log_loss, -LOG_LIMIT, LOG_LIMIT)))
    return np.where(positive & (log_loss > -LOG_LIMIT), loss, 0.0)


def _check_dt(dt):
    d = _arr(dt)
    if not np.all(d >= 0):
        raise ValueError(f"dt must be >= 0 s (got {dt!r})")
    return d


def degrade(tensile_strength, cohesion, normal_stress, shear_stress, dt, beta1, beta2):
    """Strengths after creep time dt under frozen stresses (paper Eq. 7, exact for constant rate).

    J^T <- max(J^T - beta1 exp(beta2 sigma) dt, 0), J^C <- max(J^C - beta1 exp(beta2 tau) dt, 0).
    Failure is not checked here (see :func:`failed_now`).

    Parameters
    ----------
    tensile_strength, cohesion : array_like
        J^T, J^C [Pa].
    normal_stress, shear_stress : array_like
        sigma (tension positive), tau >= 0 [Pa].
    dt : array_like
        Creep time step [s], >= 0.
    beta1, beta2 : array_like
        Law constants [Pa/s], [1/Pa].

    Returns
    -------
    new_tensile_strength, new_cohesion : ndarray
        [Pa], never below 0.
    """
    b1, b2 = _check_law(beta1, beta2)
    jt, jc, sigma, tau = _finite(tensile_strength=tensile_strength, cohesion=cohesion,
                                 normal_stress=normal_stress, shear_stress=shear_stress)
    _check_shear(tau)
    d = _check_dt(dt)
    with np.errstate(over="ignore"):  # only for strengths near -1.8e308, clipped to 0 below
        jt = jt - _loss(_log_rate(sigma, b1, b2), d)
        jc = jc - _loss(_log_rate(tau, b1, b2), d)
    return np.maximum(jt, 0.0), np.maximum(jc, 0.0)


def time_to_failure(tensile_strength, cohesion, normal_stress, shear_stress, tan_friction,
                    beta1, beta2):
    """Closed-form creep time to failure under frozen stresses (paper Eq. 5 and 7).

    Tension: t_T = (J^T - sigma) / (beta1 exp(beta2 sigma)); 0 if sigma >= J^T; inf ('never')
    if sigma < 0, because J^T cannot fall below 0. Shear: the cohesion must fall to
    J^C* = tau - s_n tan(phi), so t_S = (J^C - J^C*) / (beta1 exp(beta2 tau)); 0 if already
    failed; inf ('never') if J^C* < 0 (friction alone carries tau). A bond at zero stress fails
    when its strength reaches 0 (criteria use >=), consistent with :func:`failed_now`.

    Parameters
    ----------
    tensile_strength, cohesion : array_like
        J^T, J^C [Pa].
    normal_stress, shear_stress : array_like
        sigma (tension positive), tau >= 0 [Pa].
    tan_friction : array_like
        tan(phi) [-].
    beta1, beta2 : array_like
        Law constants [Pa/s], [1/Pa].

    Returns
    -------
    t_fail : ndarray
        [s]; finite times are in [0, TIME_CAP] (log-space, clipped); inf only for 'never'.
    mode : ndarray of int
        MODE_TENSION (1, also on ties), MODE_SHEAR (2) or MODE_NEVER (0).
    """
    b1, b2 = _check_law(beta1, beta2)
    jt, jc, sigma, tau, tphi = np.broadcast_arrays(*_finite(
        tensile_strength=tensile_strength, cohesion=cohesion, normal_stress=normal_stress,
        shear_stress=shear_stress, tan_friction=tan_friction))
    _check_shear(tau)
    with np.errstate(over="ignore"):  # inf only where sigma < 0 ('never' anyway)
        gap_t = jt - sigma
        gap_s = shear_strength(jc, sigma, tphi) - tau  # cohesion still to lose; +inf: never
    t_t = np.where(gap_t <= 0, 0.0, np.where(
        sigma >= 0, _quotient(gap_t, _log_rate(sigma, b1, b2)), np.inf))
    t_s = np.where(gap_s <= 0, 0.0, np.where(
        gap_s > jc, np.inf, _quotient(gap_s, _log_rate(tau, b1, b2))))
    mode = np.where(t_t <= t_s, MODE_TENSION, MODE_SHEAR)
    mode = np.where(np.isinf(t_t) & np.isinf(t_s), MODE_NEVER, mode)
    return np.minimum(t_t, t_s), mode


# ----------------------------------------------------------------------------- area mode
def _area_args(area_fraction, p, q, jt0, jc0, beta1, beta2):
    a = _arr(area_fraction)
    if not np.all((a > 0) & (a <= 1)):
        raise ValueError("area_fraction must be in (0, 1]; drop bonds whose area reached 0")
    a = np.maximum(a, AREA_MIN)
    for name, v in (("tensile_strength0", jt0), ("cohesion0", jc0)):
        if not np.all((_arr(v) > 0) & np.isfinite(_arr(v))):
            raise ValueError(f"{name} must be finite and > 0 Pa (got {v!r})")
    p, q = _finite(normal_force_per_area0=p, shear_force_per_area0=q)
    _check_shear(q, "shear_force_per_area0")
    b1, b2 = _check_law(beta1, beta2)
    with np.errstate(over="ignore", under="ignore"):  # inf is clipped downstream
        k_t, k_s = b2 * p, b2 * q
    l_t = np.log(b1) - np.log(_arr(jt0))
    l_s = np.log(b1) - np.log(_arr(jc0))
    return a, k_t, k_s, l_t, l_s


def _log_area_rate(u, l_t, k_t, l_s, k_s):
    """ln|da/dt| at u = 1/a; each channel's exponent clipped to +-LOG_LIMIT."""
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        e_t = l_t + k_t * u
        e_s = l_s + k_s * u
    return _logaddexp(np.clip(e_t, -LOG_LIMIT, LOG_LIMIT), np.clip(e_s, -LOG_LIMIT, LOG_LIMIT))


def _logaddexp(x, y):
    """ln(e^x + e^y) without underflow flags (terms below e^-LOG_LIMIT relative are dropped)."""
    m = np.maximum(x, y)
    with np.errstate(invalid="ignore"):  # -inf - -inf: both terms empty
        gap = np.abs(x - y)
    small = np.where(gap < LOG_LIMIT, np.exp(-np.where(gap < LOG_LIMIT, gap, 0.0)), 0.0)
    return m + np.log1p(small)


def area_rate(area_fraction, normal_force_per_area0, shear_force_per_area0, tensile_strength0,
              cohesion0, beta1, beta2):
    """Area-fraction loss rate -da/dt = (beta1/J^T0) e^(beta2 p/a) + (beta1/J^C0) e^(beta2 q/a).

    Area-mode analogue of paper Eq. 7 (at a = 1 each term is the paper's rate / strength).

    Parameters
    ----------
    area_fraction : array_like
        a in (0, 1] [-].
    normal_force_per_area0, shear_force_per_area0 : array_like
        p = F_n/A0 (tension positive), q = |F_s|/A0 >= 0 [Pa].
    tensile_strength0, cohesion0 : array_like
        Intrinsic J^T0, J^C0 [Pa], > 0.
    beta1, beta2 : array_like
        Law constants [Pa/s], [1/Pa].

    Returns
    -------
    ndarray
        -da/dt [1/s], > 0; each channel capped at RATE_CAP.
    """
    a, k_t, k_s, l_t, l_s = _area_args(area_fraction, normal_force_per_area0,
                                       shear_force_per_area0, tensile_strength0, cohesion0,
                                       beta1, beta2)
    return np.exp(_log_area_rate(1.0 / a, l_t, k_t, l_s, k_s))


def _area_limits(p, q, jt0, jc0, tan_friction):
    """Per-channel failure area fractions (-inf: channel never met for a > 0)."""
    p, q, jt0, jc0, tphi = np.broadcast_arrays(*_finite(
        normal_force_per_area0=p, shear_force_per_area0=q, tensile_strength0=jt0, cohesion0=jc0,
        tan_friction=tan_friction))
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        a_t = np.where(p > 0, p / jt0, -np.inf)       # p/a >= J^T0
        need = q + p * tphi                           # = tau0 - s_n0 tan(phi)
        a_s = np.where(need > 0, need / jc0, -np.inf)  # q/a >= J^C0 - (p/a) tan(phi)
    return a_t, a_s


def area_failure_point(normal_force_per_area0, shear_force_per_area0, tensile_strength0,
                       cohesion0, tan_friction):
    """Largest area fraction at which a failure criterion is met under frozen forces.

    Tension: sigma_eff = p/a >= J^T0 gives a_T = p/J^T0 (p > 0). Shear: q/a >= J^C0 - (p/a)
    tan(phi) gives a_S = (q + p tan(phi))/J^C0 = (tau0 - s_n0 tan(phi))/J^C0 (if > 0).

    Parameters
    ----------
    normal_force_per_area0, shear_force_per_area0 : array_like
        p, q [Pa] (see :func:`area_rate`).
    tensile_strength0, cohesion0 : array_like
        J^T0, J^C0 [Pa].
    tan_friction : array_like
        tan(phi) [-].

    Returns
    -------
    a_fail : ndarray
        [-]; 0 where neither criterion can be met: the bond corrodes away (MODE_CORRODED).
    mode : ndarray of int
        MODE_TENSION (also on ties), MODE_SHEAR or MODE_CORRODED.
    """
    a_t, a_s = _area_limits(normal_force_per_area0, shear_force_per_area0, tensile_strength0,
                            cohesion0, tan_friction)
    a_fail = np.maximum(a_t, a_s)
    mode = np.where(a_t >= a_s, MODE_TENSION, MODE_SHEAR)
    corroded = np.isneginf(a_fail)
    return np.where(corroded, 0.0, a_fail), np.where(corroded, MODE_CORRODED, mode)


def failed_now_area(area_fraction, normal_force_per_area0, shear_force_per_area0,
                    tensile_strength0, cohesion0, tan_friction):
    """Area-mode criteria sigma_eff >= J^T0, tau_eff >= J^C0 + s_n_eff tan(phi), as a <= a_T, a_S.

    Parameters are those of :func:`area_failure_point` plus ``area_fraction`` a [-].

    Returns
    -------
    tensile_failed, shear_failed : ndarray of bool
    """
    a_t, a_s = _area_limits(normal_force_per_area0, shear_force_per_area0, tensile_strength0,
                            cohesion0, tan_friction)
    a = _arr(area_fraction)
    return a <= a_t, a <= a_s


def _logsumexp(x, axis):
    m = np.max(x, axis=axis, keepdims=True)
    m = np.where(np.isfinite(m), m, 0.0)
    d = x - m
    s = np.sum(np.where(d > -LOG_LIMIT, np.exp(np.maximum(d, -LOG_LIMIT)), 0.0), axis=axis)
    with np.errstate(divide="ignore"):  # log(0) = -inf: an empty panel
        return np.log(s) + np.squeeze(m, axis=axis)


def _log_integral(lo, hi, rate_args):
    """ln of int_lo^hi du/(u^2 |da/dt|) with one Gauss-Legendre panel per row of lo, hi."""
    xi, w = np.polynomial.legendre.leggauss(GL_NODES)
    half = (hi - lo) / 2.0
    u = (lo + half)[..., None] + half[..., None] * xi
    log_w = np.log(np.where(half > 0, half, 1.0))[..., None] + np.log(w)
    log_w = np.where((half > 0)[..., None], log_w, -np.inf)
    psi = -_log_area_rate(u, *(r[..., None] for r in rate_args)) - 2.0 * np.log(u)
    return _logsumexp(psi + log_w, axis=-1)


def _cumulative(u_lo, u_hi, rate_args):
    """Geometric panel edges (n, N_PANELS+1) from u_lo to u_hi and ln of the integral up to each."""
    _, k_t, _, k_s = rate_args
    k = np.minimum(np.maximum(np.abs(k_t), np.abs(k_s)), K_GRID_MAX) + 2.0
    span = u_hi - u_lo
    first = np.minimum(span, FIRST_PANEL / k)
    ratio = np.where(first > 0, span / np.where(first > 0, first, 1.0), 1.0)
    d = first[:, None] * ratio[:, None] ** (np.arange(N_PANELS) / (N_PANELS - 1.0))
    d[:, -1] = span
    edges = u_lo[:, None] + np.concatenate([np.zeros((len(u_lo), 1)), d], axis=1)
    panel = _log_integral(edges[:, :-1], edges[:, 1:], tuple(r[:, None] for r in rate_args))
    cum = panel.copy()
    for j in range(1, N_PANELS):
        cum[:, j] = _logaddexp(cum[:, j - 1], panel[:, j])
    return edges, np.concatenate([np.full((len(u_lo), 1), -np.inf), cum], axis=1)


def _chunks(n):
    return (slice(i, min(i + CHUNK, n)) for i in range(0, n, CHUNK))


def _time_from_log(log_t):
    with np.errstate(under="ignore"):
        return np.where(np.isneginf(log_t), 0.0, np.exp(np.clip(log_t, -LOG_LIMIT, LOG_LIMIT)))


def area_time(area_from, area_to, normal_force_per_area0, shear_force_per_area0,
              tensile_strength0, cohesion0, beta1, beta2):
    """Creep time for the area fraction to fall from a_from to a_to under frozen forces.

    t = int_{a_to}^{a_from} da / |da/dt| = int du / (u^2 |da/dt|), u = 1/a, by composite
    Gauss-Legendre on N_PANELS geometric panels per bond (module constants). a_to below
    a_from/TAIL_RATIO counts as a = 0; the dropped tail lasts <= a_from J^C0/(beta1 TAIL_RATIO).

    Parameters
    ----------
    area_from, area_to : array_like
        a_from in (0, 1], a_to in [0, a_from] [-]; a_to >= a_from gives 0.
    normal_force_per_area0, shear_force_per_area0, tensile_strength0, cohesion0 : array_like
        p, q, J^T0, J^C0 [Pa] (see :func:`area_rate`).
    beta1, beta2 : array_like
        Law constants [Pa/s], [1/Pa].

    Returns
    -------
    ndarray
        Time [s] in [0, TIME_CAP] (always finite: |da/dt| >= beta1/J^C0 > 0).
    """
    a, *rates = _area_args(area_from, normal_force_per_area0, shear_force_per_area0,
                           tensile_strength0, cohesion0, beta1, beta2)
    shape = np.broadcast_shapes(a.shape, _arr(area_to).shape, *(r.shape for r in rates))
    a = np.broadcast_to(a, shape).ravel()
    a_to = np.clip(np.broadcast_to(_arr(area_to), shape).ravel(), 0.0, a)
    k_t, k_s, l_t, l_s = (np.broadcast_to(r, shape).ravel() for r in rates)
    u_lo = 1.0 / a
    a_cut = np.maximum(a / TAIL_RATIO, AREA_MIN)
    u_hi = 1.0 / np.maximum(a_to, a_cut)
    log_t = np.empty(a.size)
    for s in _chunks(a.size):
        _, cum = _cumulative(u_lo[s], u_hi[s], (l_t[s], k_t[s], l_s[s], k_s[s]))
        log_t[s] = cum[:, -1]
    return _time_from_log(log_t).reshape(shape)


def time_to_failure_area(area_fraction, normal_force_per_area0, shear_force_per_area0,
                         tensile_strength0, cohesion0, tan_friction, beta1, beta2):
    """Area-mode creep time to failure under frozen forces: :func:`area_time` to a_fail.

    a_fail from :func:`area_failure_point`; 0 if a <= a_fail already. Parameters as there plus
    ``area_fraction`` a [-] and beta1 [Pa/s], beta2 [1/Pa].

    Returns
    -------
    t_fail : ndarray
        [s], finite (area mode has no 'never': the bond corrodes away at worst).
    mode : ndarray of int
        MODE_TENSION, MODE_SHEAR or MODE_CORRODED.
    """
    a_fail, mode = area_failure_point(normal_force_per_area0, shear_force_per_area0,
                                      tensile_strength0, cohesion0, tan_friction)
    a = _arr(area_fraction)
    t = area_time(a, np.minimum(a_fail, a), normal_force_per_area0, shear_force_per_area0,
                  tensile_strength0, cohesion0, beta1, beta2)
    t = np.where(a <= a_fail, 0.0, t)
    return t, np.broadcast_to(mode, t.shape).copy()


def degrade_area(area_fraction, normal_force_per_area0, shear_force_per_area0,
                 tensile_strength0, cohesion0, dt, beta1, beta2):
    """Area fraction after creep time dt under frozen forces (area-mode Eq. 7, exact inverse).

    Solves area_time(a, a_new) = dt: cumulative composite quadrature over the geometric panels
    of :func:`area_time`, then BISECTION_STEPS bisections inside the panel holding dt.
    Failure is not checked (see :func:`failed_now_area`).

    Parameters
    ----------
    area_fraction : array_like
        a in (0, 1] [-].
    normal_force_per_area0, shear_force_per_area0, tensile_strength0, cohesion0 : array_like
        p, q, J^T0, J^C0 [Pa].
    dt : array_like
        Creep time step [s], >= 0.
    beta1, beta2 : array_like
        Law constants [Pa/s], [1/Pa].

    Returns
    -------
    ndarray
        New a [-] in [0, a]; 0 if dt reaches full corrosion.
    """
    a, *rates = _area_args(area_fraction, normal_force_per_area0, shear_force_per_area0,
                           tensile_strength0, cohesion0, beta1, beta2)
    d = _check_dt(dt)
    shape = np.broadcast_shapes(a.shape, d.shape, *(r.shape for r in rates))
    a, d, a_in = (np.broadcast_to(x, shape).ravel() for x in (a, d, _arr(area_fraction)))
    k_t, k_s, l_t, l_s = (np.broadcast_to(r, shape).ravel() for r in rates)
    log_dt = np.log(np.where(d > 0, d, 1.0))
    out = a_in.astype(float)
    for s in _chunks(a.size):
        ra = (l_t[s], k_t[s], l_s[s], k_s[s])
        u_lo = 1.0 / a[s]
        edges, cum = _cumulative(u_lo, 1.0 / np.maximum(a[s] / TAIL_RATIO, AREA_MIN), ra)
        j = np.argmax(cum >= log_dt[s, None], axis=1)  # first edge past dt (j >= 1)
        gone = cum[:, -1] < log_dt[s]
        j = np.where(gone, 1, j)
        rows = np.arange(len(j))
        lo, hi = edges[rows, j - 1], edges[rows, j]
        with np.errstate(divide="ignore"):  # exp(...) < 1 strictly; -inf only if equal
            log_rest = log_dt[s] + np.log1p(-np.exp(np.minimum(cum[rows, j - 1] - log_dt[s], 0.0)))
        left, right = lo.copy(), hi.copy()
        for _ in range(BISECTION_STEPS):
            mid = 0.5 * (left + right)
            below = _log_integral(lo, mid, ra) < log_rest
            left, right = np.where(below, mid, left), np.where(below, right, mid)
        new = 1.0 / (0.5 * (left + right))
        out[s] = np.where(d[s] > 0, np.where(gone, 0.0, np.minimum(new, a_in[s])), a_in[s])
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
    integral E1, scipy.special.exp1). A reference for tests: accurate while k/a_to < ~LOG_LIMIT.

    Parameters
    ----------
    area_from, area_to : array_like
        a_from in (0, 1], a_to in [0, a_from] [-].
    force_per_area0 : array_like
        p = F/A0 of the channel [Pa], >= 0.
    strength0 : array_like
        That channel's intrinsic strength J0 [Pa], > 0.
    beta1, beta2 : array_like
        Law constants [Pa/s], [1/Pa].

    Returns
    -------
    ndarray
        Time [s].
    """
    b1, b2 = _check_law(beta1, beta2)
    force, = _finite(force_per_area0=force_per_area0)
    with np.errstate(over="ignore"):  # beta2 p beyond the float range: inf, clipped below
        k = b2 * force
    if np.any(k < 0):
        raise ValueError("force_per_area0 must be >= 0 Pa for the single-channel closed form")

    def antiderivative(a):
        x = k / np.where(a > 0, a, 1.0)
        with np.errstate(under="ignore"):  # e^-x G(x) below 1e-308: the time is 0 to float precision
            return np.where(a > 0, a * np.exp(-np.minimum(x, LOG_LIMIT)) * _one_minus_x_ex_e1(x), 0.0)

    a0, a1 = _arr(area_from), _arr(area_to)
    return _arr(strength0) / b1 * (antiderivative(a0) - antiderivative(a1))


# ----------------------------------------------------------------------------- the old event clock's area interval
def old_event_interval(area, p, q, jt0, jc0, tphi, beta1, beta2, fraction, time_left=np.inf):
    """(dt, failing, new area) of one event-clock interval as EventClock.next_interval + apply did in area mode
    (loss cap: ``fraction`` of the CURRENT area)."""
    area, p, q, jt0, jc0, tphi = (np.asarray(x, float) for x in (area, p, q, jt0, jc0, tphi))
    t_fail, _ = time_to_failure_area(area, p, q, jt0, jc0, tphi, beta1, beta2)
    t_first = float(np.min(t_fail))
    cap = float(np.min(area_time(area, (1.0 - fraction) * area, p, q, jt0, jc0, beta1, beta2)))
    dt = min(t_first, cap, time_left)
    failing = np.flatnonzero(t_fail <= dt * (1.0 + 1e-12))
    new = degrade_area(area, p, q, jt0, jc0, dt, beta1, beta2)
    a_fail, _ = area_failure_point(p, q, jt0, jc0, tphi)
    new[failing] = np.where(area[failing] > a_fail[failing], a_fail[failing], new[failing])
    return dt, failing, new
