"""The static engine: what :func:`grainfrac_yade.engines.engine` returns for ``numerics.engine = "static"``.

Quasi-static: the same specimen, bonds and laws as the YADE scene, solved by static equilibrium between bond
failures (:mod:`grainfrac_yade.static`: no inertia, no loading rate, deterministic).  A scene
(:class:`.scene.StaticScene`, which implements :class:`grainfrac_yade.engines.Scene`) advances load increments,
each followed along the sequentially linear path with bonds broken one at a time.  Pure numpy and scipy: never
imports YADE.

What the protocols reach through an engine module: ``build_scene``, ``scene_from_state``, ``consolidate`` (the
isotropic stage of a confined test).  Not in the static engine yet, each refused with one line naming the fix
(:data:`UNSUPPORTED`, checked by the command line before a run folder is made): the creep runner (still YADE's
own, not written against the scene interface), the Brazilian jaws and levers, VTK series.

Settings that only a dynamic engine reads (:data:`DYNAMIC_ONLY`: damping, mass scaling, the servo, wave
crossings, relaxation budgets) do not stop a static run: one given on the command line with ``--set`` gets a
one-line warning (:func:`warn_dynamic_only`), and every run's summary records them as not used
(:func:`summary_keys`).
"""
from __future__ import annotations

import importlib.metadata

from ..errors import GrainfracError
from .scene import StaticScene, build_scene, consolidate, scene_from_state  # noqa: F401

#: The value of ``numerics.engine`` that selects this engine.
NAME = "static"
#: No time integration: no inertia and no unbalanced force (the paper clock's Eq. 8 needs one).
DYNAMIC = False
#: Names of the strain a VTK series is timed by (as the YADE engine's; VTK output is refused here).
AXIAL_STRAIN, DIAMETRAL_STRAIN = "axial", "diametral"

#: Parameters that only a dynamic engine reads: explicit integration (damping, time step, mass scaling), the
#: collider, the creep servo and the dynamic relaxation budgets (steps and elastic wave crossings).
DYNAMIC_ONLY = ("numerics.damping", "numerics.timestep_safety", "numerics.density_scale",
                "numerics.step_floor_quantile", "numerics.verlet_fraction", "numerics.verlet_radius_quantile",
                "creep.servo_response_steps", "creep.servo_max_strain_rate", "creep.servo_response_crossings",
                "creep.check_period", "creep.max_relaxation_steps", "creep.max_relaxation_crossings",
                "creep.relaxation_damping")

#: Commands the static engine cannot run yet -> the one line that says so and the fix.
UNSUPPORTED = {
    "creep": ("the static engine's creep hold needs the creep protocol written against the scene interface (the "
              "creep runner is still YADE's own); fix: --engine yade (numerics.engine = \"yade\")"),
    "brazilian": ("the static engine's Brazilian test needs the disc's jaws in the static core (not built yet); "
                  "fix: --engine yade (numerics.engine = \"yade\")"),
}


def version() -> str:
    """The versions of the libraries the static engine computes with (numpy, scipy)."""
    return "numpy " + importlib.metadata.version("numpy") + ", scipy " + importlib.metadata.version("scipy")


def _value(params, key: str):
    section, name = key.split(".")
    return getattr(getattr(params, section), name)


def summary_keys(params) -> dict:
    """What a run's summary.json records of the engine: its name, and the dynamic-only settings (with their
    values) that it did not use."""
    return {"engine": NAME, "settings_not_used": {k: _value(params, k) for k in DYNAMIC_ONLY}}


def warn_dynamic_only(overrides) -> list:
    """One warning line per dynamic-only setting among ``overrides`` (``(key, value)`` pairs or
    ``section.key=value`` strings as ``--set`` gives them)."""
    out = []
    for item in overrides:
        key = item.split("=", 1)[0].strip() if isinstance(item, str) else item[0]
        if key in DYNAMIC_ONLY:
            out.append(f"warning: --set {key}: the static engine has no dynamics and does not use it")
    return out


def _refuse(what: str):
    raise GrainfracError(UNSUPPORTED[what])


def run_creep(*args, **kwargs):
    """Refused (:data:`UNSUPPORTED`)."""
    _refuse("creep")


def resume_creep(*args, **kwargs):
    """Refused (:data:`UNSUPPORTED`)."""
    _refuse("creep")


def apply_levers(*args, **kwargs):
    """Refused: the Brazilian levers act on a YADE disc (:data:`UNSUPPORTED`)."""
    _refuse("brazilian")


class StrainSeries:
    """VTK series: not written by the static engine yet (refused with one line)."""

    def __init__(self, *args, **kwargs):
        raise GrainfracError("static engine: VTK series (--vtk-every) are not written yet; fix: leave out --vtk-every, "
                             "or --engine yade")
