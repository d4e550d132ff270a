"""Elastic wave crossings of a specimen, and the DEM step budget of a load-controlled hold measured in them.

A stress change at a platen reaches the other platen after one crossing time H / c, with c the bar wave
speed sqrt(E / rho) (one-dimensional longitudinal wave; rho the mass density the scene integrates, i.e.
the grains' density times ``numerics.density_scale``).  In DEM steps a crossing is H / (c dt): mass
scaling stretches c and dt alike, so it does not change the count, but the specimen's height and its
smallest cells do.  A servo that corrects the stress faster than a crossing, or a relaxation budget of a
few crossings, behaves differently on a specimen three times taller: :func:`hold_budget` lets both be
given in crossings, never below their fixed step counts.
"""
from __future__ import annotations

import math
from dataclasses import dataclass


def bar_wave_speed(young, density):
    """c = sqrt(E / rho) [m/s], E [Pa], rho [kg/m3] (arrays or scalars)."""
    return (young / density) ** 0.5


def crossing_steps(height: float, young: float, density: float, dem_step: float) -> float:
    """DEM steps for a wave to cross ``height`` [m]: H / (c dt)."""
    return height / (bar_wave_speed(young, density) * dem_step)


def steps_for(fixed_steps: int, crossings: float, steps_per_crossing: float) -> int:
    """The larger of ``fixed_steps`` and ``crossings`` wave crossings in DEM steps (rounded up); with
    ``crossings`` = 0, ``fixed_steps`` exactly."""
    return max(int(fixed_steps), math.ceil(crossings * steps_per_crossing))


@dataclass(frozen=True)
class HoldBudget:
    """DEM steps of a load-controlled hold: one wave crossing, the servo's response (it removes a stress
    error in about this many steps) and the relaxation budget (no equilibrium within it = failure)."""
    crossing_steps: float | None
    servo_response_steps: int
    max_relaxation_steps: int

    def as_dict(self) -> dict:
        return {"wave_crossing_steps": self.crossing_steps, "servo_response_steps_used": self.servo_response_steps,
                "max_relaxation_steps_used": self.max_relaxation_steps}

    @classmethod
    def from_dict(cls, data: dict) -> "HoldBudget":
        return cls(data["wave_crossing_steps"], int(data["servo_response_steps_used"]),
                   int(data["max_relaxation_steps_used"]))

    @classmethod
    def fixed(cls, creep) -> "HoldBudget":
        """The step counts of ``creep`` alone (crossing unknown): a hold saved before budgets had crossings."""
        return cls(None, int(creep.servo_response_steps), int(creep.max_relaxation_steps))


def hold_budget(creep, height: float, young: float, density: float, dem_step: float) -> HoldBudget:
    """:class:`HoldBudget` of ``creep`` (:class:`~grainfrac_yade.params.schema.CreepParams`) on a specimen
    of ``height`` [m], modulus ``young`` [Pa] and scene density ``density`` [kg/m3], stepped at ``dem_step``
    [s]: ``servo_response_steps`` and ``max_relaxation_steps``, each raised to
    ``servo_response_crossings`` and ``max_relaxation_crossings`` crossings where those are larger."""
    n = crossing_steps(height, young, density, dem_step)
    return HoldBudget(crossing_steps=n,
                      servo_response_steps=steps_for(creep.servo_response_steps, creep.servo_response_crossings, n),
                      max_relaxation_steps=steps_for(creep.max_relaxation_steps, creep.max_relaxation_crossings, n))


def scene_density(params) -> float:
    """Area-weighted grain density of the composition times ``numerics.density_scale`` [kg/m3]."""
    return sum(fraction * params.grains[m].density for m, fraction in params.composition.items()) \
        * params.numerics.density_scale


def budget_fields(budget: HoldBudget | None) -> dict:
    """Summary fields of a hold's budget; None values for a run that never held its load (failed on loading)."""
    if budget is None:
        return {"wave_crossing_steps": None, "servo_response_steps_used": None, "max_relaxation_steps_used": None}
    return budget.as_dict()
