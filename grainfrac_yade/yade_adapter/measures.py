"""Measures of a YADE scene that its drivers share: finite values, resultant forces on bodies, the mean
bond force that unbalanced forces are measured against."""
from __future__ import annotations

import math

import numpy as np

from ..law import check_finite
from ..protocols.loading import check_value  # noqa: F401


def resultant_forces(scene, body_ids) -> tuple:
    """(largest, mean) resultant force on ``body_ids`` from the last DEM step [N]; NumericalFailure
    if one is NaN or infinite."""
    f = scene.O.forces.f
    res = np.array([f(b).norm() for b in body_ids])
    check_finite("resultant force", res, body_ids, item="body")
    return res.max(), res.mean()


#: Bonds sampled for the mean bond force (every k-th of the given ones, k = len // this).
BOND_FORCE_SAMPLE = 500


def mean_bond_force(scene, bonds) -> float:
    """Mean magnitude of the bond force [N] over a sample of ``bonds`` (about BOND_FORCE_SAMPLE of
    them), the scale that unbalanced forces are measured against; 0 if there are none."""
    sample = bonds[:: max(1, len(bonds) // BOND_FORCE_SAMPLE)]
    fn, fs = scene.bond_forces(sample)
    check_finite("bond force", np.hypot(fn, fs), sample)
    return float(np.mean(np.hypot(fn, fs))) if len(sample) else 0.0
