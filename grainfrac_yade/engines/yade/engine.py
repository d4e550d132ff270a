"""The YADE engine: what :func:`grainfrac_yade.engines.registry.engine` returns for ``numerics.engine = "yade"``.

Explicit DEM (YADE's JCFpm bonds, Cundall's non-viscous damping) with dynamic relaxation: a scene
(:class:`.scene.GrainScene`, which implements :class:`grainfrac_yade.engines.Scene`) advances DEM
steps, and equilibrium is reached by relaxing until the project's criterion holds.  Importing this
module does not import YADE: :func:`.load_yade` does, when the first scene is built.

The isotropic stage of a confined test (``consolidate``: a stress servo and dynamic relaxation), the
Brazilian levers applied to a scene (``apply_levers``), the stress-corrosion bond writer of a creep test
(``stress_corrosion(scene, sc_params, saved=None)``: reads the bond forces, writes what the degradation law
says they can carry; the law's state is :class:`grainfrac_yade.kernel.corrosion.BondCorrosion`), yade-batch
rows (:mod:`.batch`) and the timings of ``bench`` (:mod:`.bench_timing`) are this engine's, gathered in
:data:`ENGINE` (a :class:`grainfrac_yade.engines.EngineModule`) so that the test protocols
(:mod:`grainfrac_yade.protocols`) and the commands reach them through the engine registry and never import this
package.
"""
from __future__ import annotations

from .._interface import EngineModule
from ...failure_criterion import refuse_static_path_settings, static_path_refusal
from . import batch, bench_timing, load_yade
from .confinement import consolidate
from .corrosion_engine import stress_corrosion
from .levers import apply_levers
from . import scene as _scene

#: The value of ``numerics.engine`` that selects this engine.
NAME = "yade"
#: Time-stepping dynamics (inertia, waves): the paper clock's unbalanced-force criterion needs it.
DYNAMIC = True
#: A checkpoint's scene: ``O.save``'s binary archive, gzip'd (the extension selects it).
SCENE_FILE = "scene.yade.gz"


def version() -> str:
    """YADE's version (imports YADE)."""
    return load_yade().config.version


def refused_settings(params) -> str:
    """The one line refusing what only the static engine's path models: the saw-tooth softening
    (``numerics.static_softening``; YADE's JCFpm bonds break at their strength) and face failure
    (``numerics.static_failure``; YADE breaks bonds one by one) ("" where the run asks for neither)."""
    return static_path_refusal(params, NAME)


def build_scene(specimen, params, layout=None):
    """:func:`.scene.build_scene`, a setting this engine has no model of refused in one line first."""
    refuse_static_path_settings(params, NAME)
    return _scene.build_scene(specimen, params, layout)


scene_from_state = _scene.scene_from_state


#: What the registry returns for ``numerics.engine = "yade"``.
ENGINE = EngineModule(name=NAME, dynamic=DYNAMIC, scene_file=SCENE_FILE, version=version, build_scene=build_scene,
                      scene_from_state=scene_from_state, consolidate=consolidate, apply_levers=apply_levers,
                      stress_corrosion=stress_corrosion, timings=bench_timing, batch_rows=batch,
                      refused_settings=refused_settings)
