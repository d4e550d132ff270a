"""The equilibrium criterion of a held load and the finite-value check of a measure (pure numpy; any engine's scene).

A scene (:class:`grainfrac_yade.engines.Scene`) is *relaxed* when its unbalanced force (:meth:`~grainfrac_yade.
engines.Scene.unbalanced`: the mean resultant force on the bodies the platens do not drive) over the mean force of
its bonds is below ``creep.equilibrium_tolerance``; a stress servo *holds its target at equilibrium* when the scene
is relaxed and the held stress is within ``creep.stress_tolerance`` x the target.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import NumericalFailure
from ..law import check_finite

#: Bonds sampled for the mean bond force (every k-th of the given ones, k = len // this).
BOND_FORCE_SAMPLE = 500


def check_value(name, value, step):
    """NumericalFailure if a measured value is NaN or infinite."""
    if not math.isfinite(value):
        raise NumericalFailure(f"{name} is {value} at DEM step {step}")


def mean_bond_force(scene, bonds) -> float:
    """Mean magnitude of the bond force [N] over a sample of ``bonds`` (about BOND_FORCE_SAMPLE of
    them), the scale that unbalanced forces are measured against; 0 if there are none."""
    sample = bonds[:: max(1, len(bonds) // BOND_FORCE_SAMPLE)]
    fn, fs = scene.bond_forces(sample)
    check_finite("bond force", np.hypot(fn, fs), sample)
    return float(np.mean(np.hypot(fn, fs))) if len(sample) else 0.0


def relaxed(scene, bonds, creep_params) -> bool:
    """The scene's unbalanced force (:meth:`~grainfrac_yade.engines.Scene.unbalanced`: mean resultant force on the
    bodies the platens do not drive) over the mean force of ``bonds`` is below ``creep.equilibrium_tolerance``."""
    _, rel = scene.unbalanced(mean_bond_force(scene, bonds))
    return rel < creep_params.equilibrium_tolerance


def held_at_equilibrium(scene, servo, bonds, creep_params) -> bool:
    """A stress servo (the platens' ``hold_stress``) holds its target at equilibrium: the scene :func:`relaxed`,
    and the held stress within ``creep.stress_tolerance`` x the target.  NumericalFailure if a force or the stress
    is not finite."""
    balanced = relaxed(scene, bonds, creep_params)
    check_value("held axial stress", servo.stress, scene.steps)
    return balanced and abs(servo.stress - servo.target) < creep_params.stress_tolerance * servo.target
