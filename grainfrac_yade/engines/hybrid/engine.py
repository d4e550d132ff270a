"""The hybrid engine: what :func:`grainfrac_yade.engines.registry.engine` returns for ``numerics.engine = "hybrid"``.

The static engine's scene, tests and bond writer (:mod:`grainfrac_yade.engines.static.engine`), with dynamic stints on
YADE where statics give out (:class:`.scene.HybridScene`).  Between stints nothing moves in time: the paper clock
(Eq. 8 measures an unbalanced force at every creep step) is refused as on the static engine.  The dynamic settings
(damping, mass scaling, the servo and the relaxation budgets) are used by the stints, so none is reported unused;
the static engine's relaxation settings are not (:mod:`.settings`).
Importing this module does not import YADE: the first stint does.
"""
from __future__ import annotations

from ..static.engine import (VTK_REFUSED,  # noqa: F401
                             apply_levers, consolidate, stress_corrosion)
from ..static.engine import UNSUPPORTED as STATIC_UNSUPPORTED
from ..static.engine import version as static_version
from .scene import HybridScene, build_scene, scene_from_state  # noqa: F401
from .settings import warn_not_used

#: The value of ``numerics.engine`` that selects this engine.
NAME = "hybrid"
#: No time integration between stints: no unbalanced force for the paper clock.
DYNAMIC = False
#: Commands the hybrid engine cannot run -> the one line that says so and the fix: the static engine's, and the
#: Brazilian test (its stints would need YADE's jaws handed the static state).
UNSUPPORTED = {**STATIC_UNSUPPORTED,
               "brazilian": ("the hybrid engine has no Brazilian test (its dynamic stints would need YADE's jaws); fix: "
                             "--engine yade or --engine static")}


def version() -> str:
    """The static engine's libraries (the stints' YADE version is recorded with the stints' engine)."""
    return static_version()


def warn_dynamic_only(overrides, params) -> list:
    """The dynamic stints read every dynamic setting; the static relaxation's settings are not read
    (:mod:`.settings`)."""
    return warn_not_used(overrides)
