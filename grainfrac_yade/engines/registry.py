"""The engine registry: ``numerics.engine`` -> the module that implements it (imported on first use, so that
YADE loads only when a scene is built) and the :class:`~grainfrac_yade.engines.EngineModule` it declares (``ENGINE``).  Its names are the choices of ``numerics.engine`` in the schema
(``tests/test_engines.py`` holds the two equal)."""
from __future__ import annotations

from ..errors import ParameterError
from ._interface import EngineModule
from .dynamic import engine_of_module

#: Values of ``numerics.engine``, each with the module that implements it (the dynamic ones as in
#: :data:`.dynamic.DYNAMIC_ENGINE_MODULES`, which an engine may look up itself; ``tests/test_engines.py`` holds
#: the two alike).
ENGINE_MODULES = {"yade": "grainfrac_yade.engines.yade.engine", "static": "grainfrac_yade.engines.static.engine",
                  "hybrid": "grainfrac_yade.engines.hybrid.engine"}
#: The names of :data:`ENGINE_MODULES` (the choices of ``numerics.engine``).
ENGINE_NAMES = tuple(ENGINE_MODULES)


def engine(name: str, source: str = "parameters") -> EngineModule:
    """The engine ``name`` (the :class:`EngineModule` its module holds as ``ENGINE``); ParameterError naming the key
    and the choices if there is none (``source``: where the name came from)."""
    if name not in ENGINE_MODULES:
        raise ParameterError(source, "numerics.engine", f"{name!r} is not one of {list(ENGINE_NAMES)}",
                             f"use one of {list(ENGINE_NAMES)}")
    return engine_of_module(ENGINE_MODULES[name])


def engine_for(params) -> EngineModule:
    """The engine of ``params`` (``numerics.engine``)."""
    return engine(params.numerics.engine)


def require_dynamic(params, what: str) -> EngineModule:
    """The engine of ``params`` if it integrates motion in time (:attr:`EngineModule.dynamic`: inertia, an
    unbalanced force); ParameterError naming ``what`` needs it otherwise (the paper clock's Eq. 8 measures the
    unbalanced force)."""
    module = engine_for(params)
    if not module.dynamic:
        raise ParameterError("parameters", "numerics.engine", f"{params.numerics.engine!r} has no dynamics, and {what} "
                             "needs them", "use a dynamic engine (e.g. 'yade') or stress_corrosion.clock = \"event\"")
    return module
