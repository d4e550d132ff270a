"""The static engine's name and the settings it does not read (pure: parameters only).

A static equilibrium has no time integration: damping, the DEM step, mass scaling, the collider and the creep
servo's and relaxation's budgets (steps, elastic wave crossings) mean nothing to it.  A run on the static engine
records them as not used; one given with ``--set`` gets a one-line warning.  The inertial relaxation
(``numerics.static_relaxation = "inertial"``, :mod:`.inertial`) moves with inertia where the static statuses do
not settle and reads the integration's and the creep servo's settings (:data:`USED_BY_RELAXATION`).
"""
from __future__ import annotations

#: The value of ``numerics.engine`` that selects this engine.
NAME = "static"

#: Parameters that only a dynamic engine reads: explicit integration (damping, time step, mass scaling), the
#: collider, the creep servo and the dynamic relaxation budgets (steps and elastic wave crossings).
DYNAMIC_ONLY = ("numerics.damping", "numerics.timestep_safety", "numerics.density_scale",
                "numerics.step_floor_quantile", "numerics.verlet_fraction", "numerics.verlet_radius_quantile",
                "creep.servo_response_steps", "creep.servo_max_strain_rate", "creep.servo_response_crossings",
                "creep.check_period", "creep.max_relaxation_steps", "creep.max_relaxation_crossings",
                "creep.relaxation_damping", "numerics.handover_cascade_bonds", "numerics.stint_min_crossings")


#: Dynamic-only settings that a static path's relaxation reads, per ``numerics.static_relaxation``.
USED_BY_RELAXATION = {
    "none": (),
    "overdamped": (),
    "inertial": ("numerics.damping", "numerics.timestep_safety", "numerics.density_scale",
                 "numerics.step_floor_quantile", "creep.servo_response_steps", "creep.servo_max_strain_rate",
                 "creep.servo_response_crossings", "creep.check_period", "creep.max_relaxation_steps",
                 "creep.max_relaxation_crossings", "creep.relaxation_damping"),
}


def not_used(params) -> tuple:
    """The dynamic-only settings that a static run with ``params`` does not read."""
    used = USED_BY_RELAXATION[params.numerics.static_relaxation]
    return tuple(k for k in DYNAMIC_ONLY if k not in used)


def _value(params, key: str):
    section, name = key.split(".")
    return getattr(getattr(params, section), name)


def summary_keys(params) -> dict:
    """What a run's summary.json records of the engine: its name, and the dynamic-only settings (with their
    values) that it did not use."""
    return {"engine": NAME, "settings_not_used": {k: _value(params, k) for k in not_used(params)}}


def override_key(item) -> str:
    """The parameter key of an override: a ``(key, value)`` pair or a ``section.key=value`` string as ``--set`` gives
    it."""
    return item.split("=", 1)[0].strip() if isinstance(item, str) else item[0]


def warn_dynamic_only(overrides, params) -> list:
    """One warning line per dynamic-only setting among ``overrides`` (``(key, value)`` pairs or
    ``section.key=value`` strings as ``--set`` gives them) that a run with ``params`` does not read."""
    out, unused = [], not_used(params)
    for item in overrides:
        key = override_key(item)
        if key in unused:
            out.append(f"warning: --set {key}: the static engine has no dynamics and does not use it")
    return out
