"""The hybrid engine: what :func:`grainfrac_yade.engines.registry.engine` returns for ``numerics.engine = "hybrid"``.

The static engine's scene, tests and bond writer (:mod:`grainfrac_yade.engines.static.engine`), the scene with the
relaxation strategy of dynamic stints on YADE where statics give out (:class:`.stints.DynamicStints`): the static
engine with that strategy.  This module composes the two engines: the stints get YADE's engine module by name
from the registry's dynamic engines (:func:`grainfrac_yade.engines.dynamic.dynamic_engine`, at the first stint),
never by importing ``engines/yade/``.  Between stints nothing moves in time: the paper clock
(Eq. 8 measures an unbalanced force at every creep step) is refused as on the static engine.  The dynamic settings
(damping, mass scaling, the servo and the relaxation budgets) are used by the stints, so none is reported unused;
the static engine's relaxation settings are not (:mod:`.settings`).
Importing this module does not import YADE: the first stint does.
"""
from __future__ import annotations

from .._interface import EngineModule
from ...failure_criterion import refuse_static_path_settings, static_path_refusal
from ..dynamic import dynamic_engine
from ..static.engine import ENGINE as STATIC
from ..static.scene import StaticScene
from .stints import DynamicStints
from .settings import warn_not_used

#: The value of ``numerics.engine`` that selects this engine.
NAME = "hybrid"
#: The engine of the dynamic stints (a name of :data:`grainfrac_yade.engines.dynamic.DYNAMIC_ENGINE_MODULES`),
#: imported at the first stint.
DYNAMIC_ENGINE = "yade"
#: No time integration between stints: no unbalanced force for the paper clock.
DYNAMIC = False
#: Commands the hybrid engine cannot run -> the one line that says so and the fix: the static engine's, and the
#: Brazilian test (its stints would need YADE's jaws handed the static state).
UNSUPPORTED = {**STATIC.unsupported,
               "brazilian": ("the hybrid engine has no Brazilian test (its dynamic stints would need YADE's jaws); fix: "
                             "--engine yade or --engine static")}


def version() -> str:
    """The static engine's libraries (the stints' YADE version is recorded with the stints' engine)."""
    return STATIC.version()


def warn_dynamic_only(overrides, params) -> list:
    """The dynamic stints read every dynamic setting; the static relaxation's settings are not read
    (:mod:`.settings`)."""
    return warn_not_used(overrides)


def refused_settings(params) -> str:
    """The one line refusing the saw-tooth softening (``numerics.static_softening``) and face failure
    (``numerics.static_failure``): both are events of the static path, which the dynamic stints do not have ("" where
    the run asks for neither)."""
    return static_path_refusal(params, NAME)


def build_scene(specimen, params, layout=None) -> StaticScene:
    """The hybrid scene of ``specimen`` (rigid or fem cells): a static scene with the strategy of dynamic stints on
    :data:`DYNAMIC_ENGINE` (a setting it has no model of refused in one line first)."""
    refuse_static_path_settings(params, NAME)
    return StaticScene(specimen, params, layout, DynamicStints(lambda: dynamic_engine(DYNAMIC_ENGINE)))


def scene_from_state(specimen, params, state, layout=None) -> StaticScene:
    """A hybrid scene of ``specimen`` in ``state`` (a :class:`grainfrac_yade.engines.SceneState` of any engine), the
    static equilibrium solved there."""
    scene = build_scene(specimen, params, layout)
    scene.apply_state(state)
    return scene


#: What the registry returns for ``numerics.engine = "hybrid"``: the static engine's tests, bond writer and
#: checkpoint scene file (a static scene's npz, stints and all) with the static scene run by the stints' strategy.
ENGINE = EngineModule(name=NAME, dynamic=DYNAMIC, scene_file=STATIC.scene_file, version=version,
                      build_scene=build_scene, scene_from_state=scene_from_state, consolidate=STATIC.consolidate,
                      apply_levers=STATIC.apply_levers, stress_corrosion=STATIC.stress_corrosion,
                      unsupported=UNSUPPORTED, vtk_refused=STATIC.vtk_refused, warn_dynamic_only=warn_dynamic_only,
                      refused_settings=refused_settings)
