"""The YADE engine: what :func:`grainfrac_yade.engines.registry.engine` returns for ``numerics.engine = "yade"``.

Explicit DEM (YADE's JCFpm bonds, Cundall's non-viscous damping) with dynamic relaxation: a scene
(:class:`.scene.GrainScene`, which implements :class:`grainfrac_yade.engines.Scene`) advances DEM
steps, and equilibrium is reached by relaxing until the project's criterion holds.  Importing this
module does not import YADE: :func:`.load_yade` does, when the first scene is built.

The isotropic stage of a confined test (``consolidate``: a stress servo and dynamic relaxation), the
Brazilian levers applied to a scene (``apply_levers``), the stress-corrosion bond writer of a creep test
(``stress_corrosion(scene, sc_params, saved=None)``: reads the bond forces, writes what the degradation law
says they can carry; the law's state is :class:`grainfrac_yade.kernel.corrosion.BondCorrosion`), yade-batch rows and the timings of ``bench`` are this engine's, listed here so that the test
protocols (:mod:`grainfrac_yade.protocols`) and the commands reach them through the engine registry and
never import this package.
"""
from __future__ import annotations

from . import load_yade, use_default_threads  # noqa: F401
from .batch import read_table, row_errors, row_plan, run_folder_name  # noqa: F401
from .bench_timing import loading_step_cost, time_bond_io, time_stepping  # noqa: F401
from .confinement import consolidate  # noqa: F401
from .corrosion_engine import stress_corrosion  # noqa: F401
from .levers import Levers, apply_levers, new_breaks  # noqa: F401
from .scene import GrainScene, build_scene, scene_from_state  # noqa: F401

#: The value of ``numerics.engine`` that selects this engine.
NAME = "yade"
#: Time-stepping dynamics (inertia, waves): the paper clock's unbalanced-force criterion needs it.
DYNAMIC = True


def version() -> str:
    """YADE's version (imports YADE)."""
    return load_yade().config.version
