"""The static engine: what :func:`grainfrac_yade.engines.engine` returns for ``numerics.engine = "static"``.

Quasi-static: the same specimen, bonds and laws as the YADE scene, solved by static equilibrium between bond
failures (:mod:`grainfrac_yade.static`: no inertia, no loading rate, deterministic).  A scene
(:class:`.scene.StaticScene`, which implements :class:`grainfrac_yade.engines.Scene`) advances load increments,
each followed along the sequentially linear path with bonds broken one at a time.  Pure numpy and scipy: never
imports YADE.

What the protocols reach through an engine module: ``build_scene``, ``scene_from_state``, ``consolidate`` (the
isotropic stage of a confined test).  Not in the static engine yet, each refused with one line naming the fix
(:data:`UNSUPPORTED`, checked by the command line before a run folder is made): the creep hold (a held platen
stress in the static scene), the Brazilian jaws and levers, VTK series.

Settings that only a dynamic engine reads (:data:`DYNAMIC_ONLY`: damping, mass scaling, the servo, wave
crossings, relaxation budgets) do not stop a static run: one given on the command line with ``--set`` gets a
one-line warning (:func:`.settings.warn_dynamic_only`), and every run's summary records them as not used
(:func:`.settings.summary_keys`).
"""
from __future__ import annotations

import importlib.metadata

from ..errors import GrainfracError
from .scene import VTK_REFUSED, StaticScene, build_scene, consolidate, scene_from_state  # noqa: F401
from .settings import DYNAMIC_ONLY, NAME, summary_keys, warn_dynamic_only  # noqa: F401

#: No time integration: no inertia and no unbalanced force (the paper clock's Eq. 8 needs one).
DYNAMIC = False
#: Names of the strain a VTK series is timed by (as the YADE engine's; VTK output is refused here).
AXIAL_STRAIN, DIAMETRAL_STRAIN = "axial", "diametral"

#: Commands the static engine cannot run yet -> the one line that says so and the fix.
UNSUPPORTED = {
    "creep": ("the static engine's creep hold needs a held platen stress in the static scene (the creep protocol "
              "drives a stress servo; not built yet); fix: --engine yade (numerics.engine = \"yade\")"),
    "bench": ("the static engine has no DEM steps to time (bench measures YADE's stepping and creep runs); fix: "
              "bench with numerics.engine = \"yade\""),
    "brazilian": ("the static engine's Brazilian test needs the disc's jaws in the static core (not built yet); "
                  "fix: --engine yade (numerics.engine = \"yade\")"),
}


def version() -> str:
    """The versions of the libraries the static engine computes with (numpy, scipy)."""
    return "numpy " + importlib.metadata.version("numpy") + ", scipy " + importlib.metadata.version("scipy")


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
        raise GrainfracError(VTK_REFUSED)
