"""Grain models: how a Voronoi cell becomes DEM bodies (pure numpy; no YADE).

One module per model, selected by ``resolution.grain_model``:

* :mod:`.rigid` (``"rigid"``, the default): each cell one rigid body, a sphere or a face-lined clump
  of ``resolution.spheres_per_cell`` spheres, its elasticity in series with the bonds;
* :mod:`.fem` (``"fem"``): each cell a cluster of spheres at the nodes of its triangle mesh, each
  triangle a constant-strain finite element with its mineral's Table 1 moduli.

Every model implements :class:`GrainModel` (``_interface.py``: layout, masses and critical step,
kinematics) as the object ``MODEL`` of its module; :func:`grain_model` finds it by name and
:func:`model_of` by the layout it built.  The YADE side of each model is the module of the same
name in :mod:`grainfrac_yade.engines.yade` (``rigid_cells``, ``fem_cells``).  Adding a model: a new
module here with a ``MODEL``, its name in :data:`GRAIN_MODEL_NAMES` and among the choices of
``resolution.grain_model``, and its YADE module (docs/maintainers.md).
"""
from __future__ import annotations

import importlib

from ..layout import ClumpLayout, bond_properties
from ..params import Parameters
from ..geometry.specimen import Specimen
from ._interface import GrainModel

#: Values of ``resolution.grain_model``: each is the name of a module of this package.
GRAIN_MODEL_NAMES = ("rigid", "fem")


def grain_model(name: str) -> GrainModel:
    """The grain model ``name`` (ValueError naming the choices if there is none)."""
    if name not in GRAIN_MODEL_NAMES:
        raise ValueError(f"no grain model {name!r}; choose one of {', '.join(GRAIN_MODEL_NAMES)}")
    return importlib.import_module(f"{__name__}.{name}").MODEL


def rotating_grain_models() -> list:
    """The names of the grain models whose bodies rotate in the plane (``GrainModel.rotating``)."""
    return [name for name in GRAIN_MODEL_NAMES if grain_model(name).rotating]


def model_of(layout: ClumpLayout) -> GrainModel:
    """The grain model that built ``layout``."""
    return grain_model(layout.model)


def layout_for(specimen: Specimen, params: Parameters) -> ClumpLayout:
    """The layout of ``specimen`` under the grain model ``params.resolution.grain_model``."""
    return grain_model(params.resolution.grain_model).build_layout(specimen, params)


def critical_dem_step(specimen: Specimen, params: Parameters, layout: ClumpLayout | None = None) -> float:
    """Critical DEM step [s] of the scene ``build_scene(specimen, params)`` would build (its ``dt_critical``),
    for the grain model ``params.resolution.grain_model``; no YADE needed."""
    layout = layout or layout_for(specimen, params)
    props = bond_properties(specimen, layout, params)
    return model_of(layout).masses_and_step(specimen, params, layout, props)[2]


__all__ = ["GRAIN_MODEL_NAMES", "GrainModel", "critical_dem_step", "grain_model", "layout_for", "model_of",
           "rotating_grain_models"]
