"""Measures of a YADE scene that its drivers share: finite values, resultant forces on bodies (the mean
bond force that unbalanced forces are measured against is engine-neutral:
:func:`grainfrac_yade.kernel.equilibrium.mean_bond_force`)."""
from __future__ import annotations

import numpy as np

from ...law import check_finite
from ...kernel.equilibrium import BOND_FORCE_SAMPLE, check_value, mean_bond_force  # noqa: F401


def resultant_forces(scene, body_ids) -> tuple:
    """(largest, mean) resultant force on ``body_ids`` from the last DEM step [N]; NumericalFailure
    if one is NaN or infinite."""
    f = scene.O.forces.f
    res = np.array([f(b).norm() for b in body_ids])
    check_finite("resultant force", res, body_ids, item="body")
    return res.max(), res.mean()
