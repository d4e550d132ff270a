"""Mechanical engines: what computes a scene's motion and bond forces (pure; the engines load lazily).

One engine today, selected by ``numerics.engine``:

* ``"yade"`` (the default): YADE's explicit DEM with dynamic relaxation
  (:mod:`grainfrac_yade.yade_adapter.engine`, which alone imports YADE).

Every engine module offers ``NAME``, ``build_scene(specimen, params, layout=None)`` and
``scene_from_state(specimen, params, state, layout=None)`` returning a scene that implements
:class:`Scene` (``_interface.py``), and the test runners and their writers' helpers that the commands
call (see :data:`ENGINE_MODULES`).  :func:`engine_for` finds the engine of a run's parameters; a
command never imports an engine's package itself.  Adding an engine: a module implementing the
interface, its name in :data:`ENGINE_MODULES` and among the choices of ``numerics.engine``
(docs/maintainers.md).
"""
from __future__ import annotations

import importlib

from ..errors import ParameterError
from ._interface import PlatenDrive, Scene, SceneState

#: Values of ``numerics.engine``, each with the module that implements it (imported on first use:
#: YADE loads only when a scene is built).
ENGINE_MODULES = {"yade": "grainfrac_yade.yade_adapter.engine"}
#: The names of :data:`ENGINE_MODULES` (the choices of ``numerics.engine``).
ENGINE_NAMES = tuple(ENGINE_MODULES)


def engine(name: str, source: str = "parameters"):
    """The engine module ``name``; ParameterError naming the key and the choices if there is none
    (``source``: where the name came from)."""
    if name not in ENGINE_MODULES:
        raise ParameterError(source, "numerics.engine", f"{name!r} is not one of {list(ENGINE_NAMES)}",
                             f"use one of {list(ENGINE_NAMES)}")
    return importlib.import_module(ENGINE_MODULES[name])


def engine_for(params):
    """The engine module of ``params`` (``numerics.engine``)."""
    return engine(params.numerics.engine)


__all__ = ["ENGINE_MODULES", "ENGINE_NAMES", "PlatenDrive", "Scene", "SceneState", "engine",
           "engine_for"]
