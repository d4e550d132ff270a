"""The dynamic engines by name: the engines that integrate motion in time (``dynamic``), each imported on first use.

The part of the engine registry (:data:`.registry.ENGINE_MODULES` names the same modules) that an engine may
use itself: the hybrid engine hands a collapse to a dynamic engine by name (:func:`dynamic_engine`), and cannot
import the registry, which imports the hybrid engine.  Importing this module imports no engine (YADE's loads when a stint
or a scene needs it).
"""
from __future__ import annotations

import importlib

from ..errors import ParameterError
from ._interface import EngineModule

#: The dynamic engines among the values of ``numerics.engine``, each with the module that implements it.
DYNAMIC_ENGINE_MODULES = {"yade": "grainfrac_yade.engines.yade.engine"}


def engine_of_module(module_name: str) -> EngineModule:
    """The :class:`EngineModule` that the engine module ``module_name`` declares (its ``ENGINE``), imported on first
    use; TypeError if it declares none (an engine module must)."""
    declared = getattr(importlib.import_module(module_name), "ENGINE", None)
    if not isinstance(declared, EngineModule):
        raise TypeError(f"{module_name}.ENGINE is {type(declared).__name__}, not an EngineModule "
                        "(grainfrac_yade.engines._interface): every engine module declares one")
    return declared


def dynamic_engine(name: str) -> EngineModule:
    """The dynamic engine ``name``; ParameterError naming the choices if ``name`` is not one."""
    if name not in DYNAMIC_ENGINE_MODULES:
        raise ParameterError("parameters", "numerics.engine", f"{name!r} is not a dynamic engine",
                             f"use one of {list(DYNAMIC_ENGINE_MODULES)}")
    return engine_of_module(DYNAMIC_ENGINE_MODULES[name])
