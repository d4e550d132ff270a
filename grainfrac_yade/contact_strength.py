"""Heterogeneous contact strength: a seeded Weibull multiplier per grain face (pure numpy).

Grain boundaries of one mineral pair are not equally strong (flaws, partial healing, orientation): the
weakest-link statistics of brittle solids describe such scatter by a Weibull distribution (Weibull
1951).  Every Voronoi face f gets one multiplier w_f drawn from a Weibull distribution of modulus
(shape) m and scale lambda = 1 / Gamma(1 + 1/m), so that its mean is exactly 1 and the mean strength of
each pair stays Table 2's:

    P(w <= x) = 1 - exp(-(x / lambda)^m),    E[w] = lambda Gamma(1 + 1/m) = 1,
    CV[w] = sqrt(Gamma(1 + 2/m) / Gamma(1 + 1/m)^2 - 1)

(m = 3: CV 0.363; m = 5: 0.229; m = 10: 0.121).  The same w_f multiplies the tensile strength J^T and
the cohesion J^C of every bond on face f: a grain boundary with a larger flaw is weaker in tension
and in shear alike, so the ratio J^T / J^C of each pair stays as given.  One draw per face, not per
bond, makes the draw independent of the grain model (a face of rigid cells has one bond, a face of fem
cells one per face node): rigid and fem specimens of one seed have the same weak faces.

The draw has its own random stream, seeded by the specimen's seed and :data:`CONTACT_STRENGTH_STREAM`:
the tessellation's and the minerals' draws (``numpy.random.default_rng(seed)``) are untouched, and the
same seed gives the same multipliers, bit for bit.  Modulus 0 is "no scatter": every multiplier is 1.0
exactly, so strengths are bit-identical to a model without the draw.
"""
from __future__ import annotations

import math

import numpy as np

#: Second word of the seed of the contact-strength stream (the first is the specimen's seed); any fixed
#: number distinct from the other streams' (engines.yade.levers.LEVER_STREAM) would do.
CONTACT_STRENGTH_STREAM = 20261202
#: Weibull modulus meaning "no scatter" (every multiplier 1).
NO_SCATTER = 0.0
#: Smallest Weibull modulus a parameter set may give [1]: m = 1 is the exponential distribution (CV 1).
#: Below it the density's mode is at 0 (most faces all but unbonded) and the CV exceeds 1 (2.2 at m = 0.5;
#: Gamma overflows below m = 0.006); Weibull moduli of rock strengths lie above it.
MIN_WEIBULL_MODULUS = 1.0


def weibull_unit_mean_scale(modulus: float) -> float:
    """Scale lambda = 1 / Gamma(1 + 1/m) [1] of the Weibull distribution of modulus m whose mean is 1."""
    _require_positive(modulus)
    return 1.0 / math.gamma(1.0 + 1.0 / modulus)


def weibull_cv(modulus: float) -> float:
    """Coefficient of variation sqrt(Gamma(1 + 2/m) / Gamma(1 + 1/m)^2 - 1) [1] of a Weibull distribution
    of modulus m (it does not depend on the scale)."""
    _require_positive(modulus)
    g1, g2 = math.gamma(1.0 + 1.0 / modulus), math.gamma(1.0 + 2.0 / modulus)
    return math.sqrt(g2 / (g1 * g1) - 1.0)


def weibull_multipliers(n: int, modulus: float, rng: np.random.Generator) -> np.ndarray:
    """(n,) strength multipliers [1] drawn from the unit-mean Weibull distribution of modulus ``modulus``
    (module doc); ``modulus`` 0 (:data:`NO_SCATTER`): ones, and ``rng`` is not used."""
    if modulus == NO_SCATTER:
        return np.ones(int(n))
    return weibull_unit_mean_scale(modulus) * rng.weibull(modulus, int(n))


def face_strength_multipliers(n_faces: int, modulus: float, seed: int) -> np.ndarray:
    """(n_faces,) multiplier [1] of J^T and J^C of each Voronoi face of the specimen of ``seed``, from the
    contact-strength stream (module doc)."""
    return weibull_multipliers(n_faces, modulus, contact_strength_rng(seed))


def contact_strength_rng(seed: int) -> np.random.Generator:
    """The contact-strength stream of specimen seed ``seed`` (independent of the specimen's own stream)."""
    return np.random.default_rng([int(seed), CONTACT_STRENGTH_STREAM])


def _require_positive(modulus: float):
    if not (math.isfinite(modulus) and modulus > 0):
        raise ValueError(f"Weibull modulus must be finite and > 0, got {modulus!r}")


__all__ = ["CONTACT_STRENGTH_STREAM", "NO_SCATTER", "MIN_WEIBULL_MODULUS", "weibull_unit_mean_scale", "weibull_cv", "weibull_multipliers",
           "face_strength_multipliers", "contact_strength_rng"]
