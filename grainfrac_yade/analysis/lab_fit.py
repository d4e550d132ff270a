"""Joint calibration to the laboratory's bands: a response-surface least-squares fit (pure numpy/scipy).

Five properties of Lac du Bonnet granite are targets at once: the UCS, Young's modulus E, the
Brazilian tensile strength sigma_t, and the crack-initiation and crack-damage ratios CI/UCS and
CD/UCS (``params/reference/ldb_lab_properties.csv``).  Five contact parameters are fitted
(:data:`FIT_VARIABLES`, each a ``[calibration]`` key).  A DEM test is costly and, on small fem
specimens, chaotic (a tiny change of input moves a peak by a few per cent), so the fit does not
differentiate the model itself.  It is a documented search in three steps:

1. a Latin-hypercube design of the variables in the unit cube (:func:`design`), each point run as a UCS
   test and a Brazilian test on a few seeds;
2. a linear response surface of each observable in the unit-cube coordinates, fitted by ordinary least
   squares to the points' seed means (:func:`fit_surrogate`):

       y_k(u) = a_k + sum_j b_kj u_j,
       y = (ln UCS, ln E, ln sigma_t, CI/UCS, CD/UCS);

3. the weighted least-squares problem on that surface, solved by ``scipy.optimize.least_squares``
   within the design's bounds (:func:`solve`):

       min_u sum_k ((y_k(u) - y_k*) / s_k)^2,

   with y* the lab's values and s the lab's spreads, in log for the three strengths and moduli
   (s = ln(1 + spread / value)).

The candidate is then run on more seeds (the verification); its measured residuals, not the
surface's, are the fit's result.
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..contact_strength import NO_SCATTER

#: The lab properties of LdB granite with their sources (a copy of shared/reference/).
LAB_PROPERTIES_CSV = Path(__file__).resolve().parents[2] / "params" / "reference" / "ldb_lab_properties.csv"


@dataclass(frozen=True)
class FitVariable:
    """One fitted ``[calibration]`` key, mapped from a unit-cube coordinate u in [0, 1].

    ``log``: value = low (high / low)^u (factors: equal steps in ratio); else value = low + (high - low) u.
    """
    name: str
    key: str
    low: float
    high: float
    log: bool
    unit: str
    doc: str

    def value(self, u: float) -> float:
        u = float(np.clip(u, 0.0, 1.0))
        if self.log:
            return self.low * (self.high / self.low) ** u
        return self.low + (self.high - self.low) * u


#: Weibull scatter is fitted as 1/m (0 = none, continuous in the CV); below this 1/m the draw is off
#: (m > 50: CV < 0.025, within the chaos of a peak).
MIN_INVERSE_WEIBULL_MODULUS = 0.02

#: The fitted variables and their design bounds.  Why these bounds: strength x 0.5-1.0 spans the fem
#: UCS as printed (286 MPa on 10 x 20 mm) down past the lab's 200 MPa; k_s/k_n x 1-4 spans the
#: published 2.51 of a UDEC LdB model; J^T/J^C x 0.3-1 and inter/intra 0.5-1 are the levers' measured
#: ranges (docs/studies/lab_bands.md); 1/m 0-0.6 is none to m = 1.67 (CV 0.62).
FIT_VARIABLES = (
    FitVariable("strength", "calibration.strength_scale", 0.5, 1.0, True, "1",
                "multiplies J^T and J^C of every pair"),
    FitVariable("ks_over_kn", "calibration.shear_stiffness_ratio_scale", 1.0, 4.0, True, "1",
                "multiplies every pair's k_s/k_n"),
    FitVariable("tensile_over_cohesion", "calibration.tensile_cohesion_ratio_scale", 0.3, 1.0, True, "1",
                "multiplies J^T of every pair, J^C kept"),
    FitVariable("inter_over_intra", "calibration.inter_mineral_strength_ratio", 0.5, 1.0, True, "1",
                "multiplies J^T and J^C of mixed-mineral pairs"),
    FitVariable("inverse_weibull_modulus", "calibration.strength_weibull_modulus", 0.0, 0.6, False, "1",
                "1/m of the per-face Weibull strength multiplier (the key takes m)"),
)

#: Observables of the fit: name, the lab property (row of the lab CSV) it is compared with, log or not.
OBSERVABLES = (
    ("ucs", "uniaxial_compressive_strength", True),
    ("young", "young_modulus", True),
    ("tensile_strength", "brazilian_tensile_strength", True),
    ("ci_over_ucs", "crack_initiation_stress_ratio", False),
    ("cd_over_ucs", "crack_damage_stress_ratio", False),
)


def key_value(variable: FitVariable, u: float) -> float:
    """The ``[calibration]`` value of ``variable`` at coordinate ``u`` (1/m turned into m; 0 = no scatter)."""
    v = variable.value(u)
    if variable.name == "inverse_weibull_modulus":
        return NO_SCATTER if v < MIN_INVERSE_WEIBULL_MODULUS else 1.0 / v
    return v


def overrides(u) -> list:
    """``key=value`` overrides of the point ``u`` (one coordinate per :data:`FIT_VARIABLES`)."""
    u = np.asarray(u, dtype=float)
    if u.shape != (len(FIT_VARIABLES),):
        raise ValueError(f"a point has {len(FIT_VARIABLES)} coordinates, got shape {u.shape}")
    return [f"{v.key}={key_value(v, x):.6g}" for v, x in zip(FIT_VARIABLES, u)]


#: The point of Tables 1 and 2 as printed (every factor 1, no scatter): the design's first point, so
#: that the surface is anchored where the model has been measured most.
AS_PRINTED = np.array([1.0, 0.0, 1.0, 1.0, 0.0])


def design(n: int, seed: int) -> np.ndarray:
    """(n + 1, 5) design points in the unit cube: :data:`AS_PRINTED`, then n Latin-hypercube points
    (scipy.stats.qmc, seeded: the same n and seed give the same points)."""
    from scipy.stats import qmc
    if n < len(FIT_VARIABLES) + 1:
        raise ValueError(f"a linear surface in {len(FIT_VARIABLES)} variables needs at least "
                         f"{len(FIT_VARIABLES) + 2} points, got {n} + 1")
    return np.vstack([AS_PRINTED, qmc.LatinHypercube(d=len(FIT_VARIABLES), seed=seed).random(n)])


@dataclass(frozen=True)
class LabTargets:
    """The lab's values y* and spreads s of :data:`OBSERVABLES`, in the fit's scale (log for log ones)."""
    names: tuple
    value: np.ndarray      # as in the lab CSV (Pa, 1)
    spread: np.ndarray     # as in the lab CSV
    scaled_value: np.ndarray
    scaled_spread: np.ndarray
    sources: tuple


def lab_targets(path: Path = LAB_PROPERTIES_CSV, ucs_value: float | None = None) -> LabTargets:
    """Targets from the lab CSV; ``ucs_value`` [Pa] replaces the UCS value (its spread kept)."""
    rows = {r["property"]: r for r in csv.DictReader(Path(path).open())}
    value, spread, sources = [], [], []
    for name, prop, _ in OBSERVABLES:
        if prop not in rows or not rows[prop]["spread"]:
            raise ValueError(f"{path}: no row '{prop}' with a spread (needed by the lab fit)")
        value.append(float(rows[prop]["value"]))
        spread.append(float(rows[prop]["spread"]))
        sources.append(rows[prop]["source"])
    value, spread = np.array(value), np.array(spread)
    if ucs_value is not None:
        value[0] = ucs_value
    logs = np.array([lg for _, _, lg in OBSERVABLES])
    scaled_value = np.where(logs, np.log(value), value)
    scaled_spread = np.where(logs, np.log1p(spread / value), spread)
    return LabTargets(tuple(n for n, _, _ in OBSERVABLES), value, spread, scaled_value, scaled_spread, tuple(sources))


def scaled(measured) -> np.ndarray:
    """(m, 5) observables in the fit's scale from (m, 5) measured values (Pa and 1; NaN stays NaN)."""
    y = np.array(measured, dtype=float)
    logs = np.array([lg for _, _, lg in OBSERVABLES])
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(logs, np.log(y), y)


def unscaled(y) -> np.ndarray:
    """Inverse of :func:`scaled`."""
    y = np.asarray(y, dtype=float)
    logs = np.array([lg for _, _, lg in OBSERVABLES])
    return np.where(logs, np.exp(y), y)


@dataclass(frozen=True)
class Surrogate:
    """Response surface y = intercept + slope u + curvature u_q^2 of each observable (OLS on the points
    where it was measured; ``squared``: the indices q of the variables with a square term, none for a
    linear surface), with its coefficient of determination r2 and residual sd (fit scale)."""
    intercept: np.ndarray   # (5,)
    slope: np.ndarray       # (5, 5): slope[k, j] = d y_k / d u_j at u_j = 0
    r2: np.ndarray          # (5,)
    residual_sd: np.ndarray  # (5,)
    n_points: np.ndarray    # (5,)
    squared: tuple = ()     # indices of the variables with a square term
    #: (5, len(squared)): coefficient of u_q^2 (no columns for a linear surface)
    curvature: np.ndarray = field(default_factory=lambda: np.zeros((len(OBSERVABLES), 0)))

    def predict(self, u) -> np.ndarray:
        u = np.asarray(u, dtype=float)
        return self.intercept + self.slope @ u + self.curvature @ (u[list(self.squared)] ** 2)


def fit_surrogate(points, y, squared=()) -> Surrogate:
    """OLS fit of :class:`Surrogate` to (m, 5) points and (m, 5) observables in the fit's scale; a NaN
    observable (not measured at that point) drops that point for that observable only.  ``squared``:
    indices of the variables that get a square term too (the Weibull axis: sigma_t falls steeply with
    1/m); () is the linear surface."""
    points, y = np.asarray(points, dtype=float), np.asarray(y, dtype=float)
    squared = tuple(int(q) for q in squared)
    n_var = points.shape[1]
    n_terms = n_var + len(squared)
    features = np.column_stack([points, points[:, list(squared)] ** 2]) if squared else points
    intercept, slope = np.zeros(y.shape[1]), np.zeros((y.shape[1], n_var))
    curvature = np.zeros((y.shape[1], len(squared)))
    r2, sd, count = np.zeros(y.shape[1]), np.zeros(y.shape[1]), np.zeros(y.shape[1], dtype=int)
    for k in range(y.shape[1]):
        ok = np.isfinite(y[:, k])
        if ok.sum() < n_terms + 2:
            raise ValueError(f"observable {OBSERVABLES[k][0]}: {ok.sum()} measured points, the surface "
                             f"needs at least {n_terms + 2}")
        a = np.column_stack([np.ones(ok.sum()), features[ok]])
        coef, *_ = np.linalg.lstsq(a, y[ok, k], rcond=None)
        fitted = a @ coef
        ss_res = float(((y[ok, k] - fitted) ** 2).sum())
        ss_tot = float(((y[ok, k] - y[ok, k].mean()) ** 2).sum())
        intercept[k], slope[k], curvature[k] = coef[0], coef[1:n_var + 1], coef[n_var + 1:]
        r2[k] = 1.0 - ss_res / ss_tot if ss_tot > 0 else 1.0
        sd[k] = math.sqrt(ss_res / (ok.sum() - n_terms - 1)) if ok.sum() > n_terms + 1 else 0.0
        count[k] = ok.sum()
    return Surrogate(intercept, slope, r2, sd, count, squared, curvature)


def weighted_residuals(y, targets: LabTargets) -> np.ndarray:
    """(y - y*) / s in the fit's scale: the number of lab spreads each observable is off."""
    return (np.asarray(y, dtype=float) - targets.scaled_value) / targets.scaled_spread


def solve(surrogate: Surrogate, targets: LabTargets, starts: int = 8, seed: int = 0):
    """The point u in the unit cube minimising the surface's weighted residuals (scipy least_squares,
    trust-region reflective within the bounds; the best of ``starts`` seeded starts, the cube's centre
    first).  Returns (u, predicted weighted residuals)."""
    from scipy.optimize import least_squares
    n = surrogate.slope.shape[1]
    rng = np.random.default_rng(seed)
    best = None
    for start in [np.full(n, 0.5), *rng.random((max(starts - 1, 0), n))]:
        res = least_squares(lambda u: weighted_residuals(surrogate.predict(u), targets), start,
                            bounds=(np.zeros(n), np.ones(n)), method="trf")
        if best is None or res.cost < best.cost - 1e-12:
            best = res
    return best.x, weighted_residuals(surrogate.predict(best.x), targets)
