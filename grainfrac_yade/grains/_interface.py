"""What every grain model offers (pure numpy; no YADE).

A grain model decides how a Voronoi cell becomes DEM bodies: its sphere layout (a
:class:`~grainfrac_yade.layout.ClumpLayout`, or a subclass of it that carries what the model adds),
its bonds (:func:`~grainfrac_yade.layout.bond_properties` on that layout), its bodies' masses and
its critical DEM step.  The YADE side of each model (bodies, elements, kinematics) is the module
of the same name in :mod:`grainfrac_yade.engines.yade` (``rigid_cells``, ``fem_cells``), which sets
the masses and the step that :meth:`GrainModel.masses_and_step` computes, so that
:func:`grainfrac_yade.grains.critical_dem_step` (``specimen.json``) equals the scene's
``dt_critical`` by construction.
"""
from __future__ import annotations

import numpy as np

from ..layout import BondProperties, ClumpLayout
from ..params import Parameters
from ..geometry.specimen import Specimen


class GrainModel:
    """One way of making Voronoi cells into DEM bodies.

    Attributes
    ----------
    name : str
        The value of ``resolution.grain_model`` that selects it (and ``ClumpLayout.model`` of its layouts).
    rotating : bool
        Its bodies rotate in the plane (sqrt(I/K_rot) bounds the step too).
    resume_note : str
        "" if a resumed run of this model is bit-identical to the uninterrupted one (one thread),
        else why not.
    bonds_on_faces : bool
        Its bonds act on their face's plane (a sphere on each side of the face): a bond's reference gap is the
        spheres' distance along the face normal, and a state carries the plane's normal.  False: bonds between
        spheres (the gap is their overlap).
    """
    name = ""
    rotating = True
    resume_note = ""
    bonds_on_faces = False

    def build_layout(self, specimen: Specimen, params: Parameters) -> ClumpLayout:
        """The spheres and bonds of ``specimen`` under ``params.resolution``."""
        raise NotImplementedError

    def masses_and_step(self, specimen: Specimen, params: Parameters, layout: ClumpLayout, props: BondProperties,
                        body_pos: np.ndarray | None = None) -> tuple:
        """(mass [kg], inertia [kg m^2], critical DEM step [s]) of the scene's bodies, with the step floor
        ``numerics.step_floor_quantile`` applied.  ``body_pos`` (n, 3): where YADE put the bodies, for
        models whose bodies' reference points YADE chooses (rigid clumps); None: where the model says."""
        raise NotImplementedError
