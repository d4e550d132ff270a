"""The saw-tooth of a linear softening envelope (grainfrac_yade/softening.py) against closed forms, and its parameters."""
import math

import numpy as np
import pytest

from grainfrac_yade.params import load_parameters
from grainfrac_yade.softening import (envelope_energy, sawtooth_energy, sawtooth_energy_deficit, sawtooth_teeth,
                                      softening_of)

#: Closed forms hold to round-off: sums of N terms of order 1 (1e-12 relative leaves room for N = 1000).
EXACT = 1e-12
CASES = [(n, mu) for n in (1, 2, 3, 4, 7, 20) for mu in (1.0, 1.5, 4.0, 10.0)]


def _envelope(delta, mu, f0=1.0, d0=1.0):
    """The linear softening envelope f(delta) beyond the peak (module doc of grainfrac_yade.softening)."""
    return f0 * (mu * d0 - delta) / ((mu - 1.0) * d0)


@pytest.mark.parametrize("n,mu", CASES)
def test_teeth_have_equal_strength_steps_and_their_peaks_on_the_envelope(n, mu):
    k, f = sawtooth_teeth(n, mu)
    assert len(k) == len(f) == n and k[0] == 1.0 and f[0] == 1.0
    assert np.allclose(np.diff(f), -1.0 / n, rtol=0, atol=EXACT)
    assert np.all(np.diff(k) < 0) and np.all(k > 0)
    delta = f / k
    if mu > 1:
        assert np.allclose(_envelope(delta, mu), f, rtol=EXACT, atol=0)
    else:           # a vertical envelope: every peak at delta_0
        assert np.allclose(delta, 1.0, rtol=EXACT, atol=0)


def _area_under_the_sawtooth(n, mu, f0, d0):
    """The energy a monotonic opening puts in, as the area under the piecewise linear force-separation path (rise on
    each tooth's secant to its peak, drop at fixed separation to the next tooth, the last drop to 0), by the
    trapezoid rule, exact on a piecewise linear path: with nothing stored at the end, the energy dissipated."""
    k, f = sawtooth_teeth(n, mu)
    k, f = k * f0 / d0, f * f0
    delta = f / k
    xs, ys = [0.0], [0.0]
    for i in range(n):
        xs.append(delta[i]), ys.append(f[i])
        xs.append(delta[i]), ys.append(k[i + 1] * delta[i] if i + 1 < n else 0.0)
    return float(np.trapz(ys, xs))


@pytest.mark.parametrize("n,mu", CASES)
def test_energy_of_a_monotonic_opening_against_its_closed_forms(n, mu):
    """The sum of the triangles between successive secants equals the area under the saw-tooth path and the envelope's
    area less the closed-form deficit (module doc), for a bond of f_0 = 12 MPa x 1e-8 m2 and delta_0 = 2e-8 m."""
    f0, d0 = 0.12, 2e-8
    w = sawtooth_energy(n, mu, f0, d0)
    g = envelope_energy(mu, f0, d0)
    assert g == pytest.approx(0.5 * f0 * d0 * mu, rel=EXACT)
    assert w == pytest.approx(_area_under_the_sawtooth(n, mu, f0, d0), rel=EXACT)
    assert w == pytest.approx(g - sawtooth_energy_deficit(n, mu, f0, d0), rel=EXACT)
    assert w <= g * (1 + EXACT)
    if n == 1 or mu == 1:       # brittle: the elastic energy at strength, all of it
        assert w == pytest.approx(0.5 * f0 * d0, rel=EXACT)


@pytest.mark.parametrize("mu", [1.5, 4.0, 10.0])
def test_energy_approaches_the_envelope_as_the_teeth_multiply(mu):
    """G - W_N falls with every tooth added, and (G - W_N) / G follows its expansion in 1/N, the Euler-Maclaurin sum
    of the closed form: ln(mu) / N - (mu - 1)^2 / (2 mu N^2) + (mu - 1)^2 (mu^2 - 1) / (12 mu^2 N^3), whose remainder
    is O(1/N^5), relative to the third term ~ c / N^2 (c = 6.3 at mu = 10, the largest here, measured at N = 10):
    at N >= 100 below 1 % of the third term (the tolerance is that truncation, not round-off)."""
    g = envelope_energy(mu)
    gaps = [(g - sawtooth_energy(n, mu)) / g for n in range(1, 60)]
    assert np.all(np.diff(gaps) < 0) and gaps[-1] > 0
    a = mu - 1.0
    for n in (100, 1000):
        gap = sawtooth_energy_deficit(n, mu) / g
        third = a ** 2 * (mu ** 2 - 1) / (12 * mu ** 2 * n ** 3)
        two_terms = math.log(mu) / n - a ** 2 / (2 * mu * n ** 2)
        assert abs(gap - two_terms - third) <= 0.01 * third
    # N = 4, mu = 4 (the shipped sawtooth): the teeth take 71.3 % of the envelope's energy
    assert sawtooth_energy(4, 4.0) / envelope_energy(4.0) == pytest.approx(1.4265796703296703 / 2.0, rel=EXACT)


@pytest.mark.parametrize("teeth,mu", [(0, 2.0), (2, 0.5), (2, math.nan), (1.5, 2.0)])
def test_bad_teeth_are_refused(teeth, mu):
    with pytest.raises(ValueError):
        sawtooth_teeth(teeth, mu)


def test_shipped_default_is_the_brittle_law_and_brittle_settings_are_none():
    p = load_parameters()
    assert p.numerics.static_softening == "none" and softening_of(p.numerics) is None
    for extra in (["numerics.static_softening_teeth=1"], ["numerics.static_softening_ductility=1"]):
        q = load_parameters(overrides=["numerics.static_softening=sawtooth", *extra])
        assert softening_of(q.numerics) is None
    q = load_parameters(overrides=["numerics.static_softening=sawtooth", "numerics.static_softening_teeth=3",
                                   "numerics.static_softening_ductility=2.5"])
    k, f = softening_of(q.numerics)
    assert np.array_equal(k, sawtooth_teeth(3, 2.5)[0]) and np.array_equal(f, sawtooth_teeth(3, 2.5)[1])
