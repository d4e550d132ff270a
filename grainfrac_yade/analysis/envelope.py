"""Peak-strength envelopes of confined compression tests (pure numpy; least squares).

Two criteria for the peak axial stress sigma_1 against the confining stress sigma_3:

- Mohr-Coulomb, linear in the principal stresses: sigma_1 = C_0 + q sigma_3 with
  q = (1 + sin phi) / (1 - sin phi) and cohesion c = C_0 (1 - sin phi) / (2 cos phi) = C_0 / (2 sqrt q)
  (Jaeger, Cook & Zimmerman 2007, ch. 4).
- Hoek-Brown for intact rock (Hoek & Brown 1980; s = 1, a = 0.5):
  sigma_1 = sigma_3 + sigma_ci sqrt(m_i sigma_3 / sigma_ci + 1), fitted as Hoek & Brown did, by the
  straight line (sigma_1 - sigma_3)^2 = sigma_ci^2 + m_i sigma_ci sigma_3 (Eberhardt 2012, ISRM
  suggested method: intercept sigma_ci^2, slope m_i sigma_ci).

Both fits take every test (not the means per confinement), so scatter between seeds weighs in.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import GrainfracError
from .fits import LineFit, fit_line


@dataclass(frozen=True)
class MohrCoulombFit:
    """sigma_1 = unconfined_strength + passive_coefficient x sigma_3 [Pa]."""
    line: LineFit

    @property
    def unconfined_strength(self) -> float:
        """C_0, the line's sigma_1 at sigma_3 = 0 [Pa]."""
        return float(self.line.intercept)

    @property
    def passive_coefficient(self) -> float:
        """q = d sigma_1 / d sigma_3 [1]."""
        return float(self.line.slope)

    @property
    def friction_angle_deg(self) -> float:
        """phi from q = (1 + sin phi) / (1 - sin phi) [deg]; NaN if q <= 1 (no friction)."""
        q = self.passive_coefficient
        return math.degrees(math.asin((q - 1) / (q + 1))) if q > 1 else float("nan")

    @property
    def cohesion(self) -> float:
        """c = C_0 / (2 sqrt q) [Pa]."""
        return self.unconfined_strength / (2 * math.sqrt(self.passive_coefficient))

    def peak(self, sigma3):
        return self.line.predict(sigma3)


@dataclass(frozen=True)
class HoekBrownFit:
    """Intact-rock Hoek-Brown envelope (s = 1, a = 0.5)."""
    sigma_ci: float      # Pa, the envelope's uniaxial compressive strength
    m_i: float           # 1
    r2: float            # coefficient of determination of sigma_1 (not of the linearised fit)

    def peak(self, sigma3):
        s3 = np.asarray(sigma3, float)
        return s3 + self.sigma_ci * np.sqrt(np.maximum(self.m_i * s3 / self.sigma_ci + 1.0, 0.0))


def _checked(sigma3, sigma1, source: str):
    s3, s1 = np.asarray(sigma3, float), np.asarray(sigma1, float)
    if s3.shape != s1.shape or s3.ndim != 1:
        raise GrainfracError(f"{source}: sigma_3 and sigma_1 must be two 1-D arrays of one length; fix: one "
                             "(confining stress, peak stress) pair per test")
    if not (np.all(np.isfinite(s3)) and np.all(np.isfinite(s1))):
        raise GrainfracError(f"{source}: a stress is NaN or infinite; fix: leave out tests without a peak "
                             "(numerical failure)")
    if np.any(s3 < 0) or np.any(s1 <= s3):
        raise GrainfracError(f"{source}: every test needs sigma_3 >= 0 and a peak sigma_1 above it; fix: check "
                             "the confining stresses and the peaks")
    if len(np.unique(s3)) < 2:
        raise GrainfracError(f"{source}: an envelope needs tests at two confining stresses at least (found "
                             f"{len(np.unique(s3))}); fix: add tests at another confinement.stress")
    return s3, s1


def fit_mohr_coulomb(sigma3, sigma1, source: str = "envelope") -> MohrCoulombFit:
    """Least-squares Mohr-Coulomb line through all tests (sigma_3, sigma_1) [Pa]."""
    s3, s1 = _checked(sigma3, sigma1, source)
    return MohrCoulombFit(fit_line(s3, s1))


def fit_hoek_brown(sigma3, sigma1, source: str = "envelope") -> HoekBrownFit:
    """Hoek-Brown (s = 1, a = 0.5) by the straight line (sigma_1 - sigma_3)^2 against sigma_3.

    GrainfracError if the line's intercept (sigma_ci^2) is not positive: the data are no Hoek-Brown
    envelope (e.g. the deviator falls with confinement).
    """
    s3, s1 = _checked(sigma3, sigma1, source)
    line = fit_line(s3, (s1 - s3) ** 2)
    if not line.intercept > 0:
        raise GrainfracError(f"{source}: the Hoek-Brown line has a non-positive intercept sigma_ci^2 = "
                             f"{line.intercept:.4g} Pa^2: the peaks do not follow the criterion; fix: check the runs "
                             "(or use the Mohr-Coulomb fit)")
    sigma_ci = math.sqrt(line.intercept)
    fit = HoekBrownFit(sigma_ci=sigma_ci, m_i=float(line.slope / sigma_ci), r2=float("nan"))
    ss_tot = float(np.sum((s1 - s1.mean()) ** 2))
    r2 = 1.0 - float(np.sum((s1 - fit.peak(s3)) ** 2)) / ss_tot if ss_tot > 0 else float("nan")
    return HoekBrownFit(sigma_ci=sigma_ci, m_i=fit.m_i, r2=r2)
