"""Mechanical engines: what computes a scene's motion and bond forces (pure; the engines load lazily).

Three engines, selected by ``numerics.engine`` (``--engine`` on ``ucs``, ``creep``, ``brazilian``; docs/engines.md):

* ``"yade"`` (the default): YADE's explicit DEM with dynamic relaxation
  (:mod:`grainfrac_yade.engines.yade.engine`, which alone imports YADE);
* ``"static"``: static equilibrium between bond failures, bonds broken one at a time, relaxing where no static
  equilibrium settles (:mod:`grainfrac_yade.engines.static.engine`, pure numpy and scipy; UCS, confined, Brazilian and
  creep tests);
* ``"hybrid"``: the static engine with the relaxation strategy of YADE's dynamic stints where the statics give
  out (:mod:`grainfrac_yade.engines.hybrid.engine`; UCS, confined and creep tests).

Every engine module declares ``ENGINE``, an :class:`EngineModule` (``_interface.py``): its ``name``, whether it is
``dynamic``, its checkpoint ``scene_file``, ``build_scene(specimen, params, layout=None)`` and
``scene_from_state(specimen, params, state, layout=None)`` returning a scene that implements :class:`Scene`, and the
hooks the test protocols (:mod:`grainfrac_yade.protocols`) and the commands call on it (``consolidate``,
``apply_levers``, ``stress_corrosion``, what it refuses, the timings of ``bench``).  :func:`.registry.engine_for` finds the engine of a run's
parameters; a command never imports an engine's package itself.  Adding an engine: a module
declaring its ``ENGINE``, its name in :data:`.registry.ENGINE_MODULES` and among the choices of
``numerics.engine`` (docs/maintainers.md).  Each engine is a sub-package beside the interface and the registry
(``yade/``, ``static/``, ``hybrid/``) and imports only the pure core and ``_interface`` (the hybrid also the
static engine, whose scene it runs with its own relaxation strategy through the scene's public hooks, and, in its
``engine.py`` alone, YADE's by name through :mod:`.dynamic`, the registry's dynamic engines).  This ``__init__`` imports no engine (the registry does, by name), so that an engine may import the
interface.
"""
from __future__ import annotations

from importlib import import_module

__all__ = ["EngineModule", "PlatenDrive", "Scene", "SceneState"]


def __getattr__(name):
    """The interface's names, loaded on first use: importing an engine's sub-package (``engines.yade``, whose
    ``use_default_threads`` must run before numpy loads OpenBLAS) loads no numpy through this package."""
    if name in __all__:
        return getattr(import_module(f"{__name__}._interface"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + __all__)
