"""The static engine: what :func:`grainfrac_yade.engines.registry.engine` returns for ``numerics.engine = "static"``.

Quasi-static: the same specimen, bonds and laws as the YADE scene, solved by static equilibrium between bond
failures (:mod:`grainfrac_yade.engines.static`: no inertia, no loading rate, deterministic).  A scene
(:class:`.scene.StaticScene`, which implements :class:`grainfrac_yade.engines.Scene`) advances load increments,
each followed along the sequentially linear path with bonds broken one at a time.  Pure numpy and scipy: never
imports YADE.

What the protocols reach through an engine module: ``build_scene``, ``scene_from_state``, ``consolidate`` (the
isotropic stage of a confined test) and ``stress_corrosion`` (the creep test's bond writer, :class:`StaticCorrosion`:
the creep test of :mod:`grainfrac_yade.protocols.creep` runs on the static scene's held platen stress with the event
clock; the paper clock needs dynamics and is refused).  Every command runs on it: :data:`UNSUPPORTED` (what the
command line refuses before a run folder is made) is empty; what it refuses within a command (the paper clock, a
stiffness-changing law, rough platens, blocked rotation of fem cells) is refused in one line naming the fix.  The
Brazilian test runs on the disc's jaws of :mod:`.jaws` (``attach_jaws``) with the levers of ``apply_levers``.
What ``bench --static`` and the static study scripts read of a scene beside the protocols (:mod:`.bench_timing`:
the solver's counters, the path's breaks, the path alone timed for a number of breaks, in CPU time) is reached
here (:data:`ENGINE`'s ``timings``), as YADE's timings are in its engine module.  VTK series are written as on any engine
(:mod:`grainfrac_yade.protocols.snapshots` reads the scene's ``cell_motion`` and ``bond_shift``; :data:`VTK_REFUSED`
is empty).

Settings that only a dynamic engine reads (:data:`DYNAMIC_ONLY`: damping, mass scaling, the servo, wave
crossings, relaxation budgets) do not stop a static run: one given on the command line with ``--set`` gets a
one-line warning (:func:`.settings.warn_dynamic_only`), and every run's summary records them as not used
(:func:`.settings.summary_keys`).
"""
from __future__ import annotations

import importlib.metadata

import numpy as np

from ...errors import GrainfracError
from ...failure_criterion import reading_refusal
from ...law import MODE_CORRODED, Stresses, check_finite
from ...kernel.corrosion import BondCorrosion
from ...geometry.disc import DiscTessellation
from .._interface import EngineModule
from . import bench_timing
from .jaws import DiscScene
from .jaws import apply_levers as _apply_levers
from .scene import STIFFNESS_LAW_REFUSED, VTK_REFUSED, StaticScene, consolidate, scene_from_state
from .settings import NAME, warn_dynamic_only

#: No time integration: no inertia and no unbalanced force (the paper clock's Eq. 8 needs one).
DYNAMIC = False
#: A checkpoint's scene: numpy's npz of the core's state (:meth:`.scene.StaticScene.save`).
SCENE_FILE = "scene.npz"

#: Commands the static engine cannot run -> the one line that says so and the fix: none (the hybrid engine adds its own).
UNSUPPORTED: dict = {}


def version() -> str:
    """The versions of the libraries the static engine computes with (numpy, scipy)."""
    return "numpy " + importlib.metadata.version("numpy") + ", scipy " + importlib.metadata.version("scipy")


class StaticCorrosion(BondCorrosion):
    """A degradation law's state on a static scene's bonds (:class:`BondCorrosion`): reads the solved bond forces,
    writes the law's strengths into the path's (J^T, J^C per intact area) and hands the bonds at their failure point to the scene's next solve."""

    name = "StressCorrosion"

    def __init__(self, scene: StaticScene, sc_params):
        super().__init__(scene, sc_params)
        if not self.law.exact_jump:
            raise GrainfracError(STIFFNESS_LAW_REFUSED)
        refused = reading_refusal(scene.params)
        if refused:
            raise GrainfracError(refused)
        if scene.path.teeth is not None:        # a saw-tooth lowers the law's strengths as the path's
            scene.path.teeth.strength_listeners.append(self.follow_tooth)

    def follow_tooth(self, bonds, ratio):
        """Bonds ``bonds`` (canonical numbers) took their next saw-tooth (:mod:`.teeth`): the law's current,
        corroded strengths x ``ratio`` (f_{i+1} / f_i), as the path's, so that corrosion goes on from them."""
        lay = self.scene.net.order[np.atleast_1d(bonds)]
        self.state = self.state.replaced(lay, {k: self.state[k][lay] * ratio for k in ("tensile_strength",
                                                                                      "cohesion")})

    def stresses(self, idx) -> Stresses:
        """:meth:`BondCorrosion.stresses` as the path's failure criterion reads them
        (:meth:`.face_failure.BondFailure.law_stresses`: the bonds' own, or with face failure their faces' resultant
        ones, the driving stresses kept)."""
        return self.scene.path.failure.law_stresses(super().stresses(idx), self.scene.state, self.scene.canon)

    def write(self, idx):
        """The law's strengths of bonds ``idx`` into the scene (no solve: the next one follows them)."""
        idx = np.asarray(idx, dtype=np.int64)
        jt, jc, _ = self.law.strengths(self.state.subset(idx))
        check_finite("strength written to a static bond", jt, idx)
        check_finite("strength written to a static bond", jc, idx)
        self.scene.write_bond_strengths(idx, jt, jc)

    def hand_over_failures(self, idx, sigma, tau, modes):
        """Bonds ``idx`` at their failure point (written strengths at their stresses, :data:`MODE_CORRODED`: none
        left): broken at the scene's next solve (:meth:`.scene.StaticScene.hand_over`)."""
        idx = np.asarray(idx, dtype=np.int64)
        corroded = idx[np.asarray(modes) == MODE_CORRODED]
        if len(corroded):
            self.scene.write_bond_strengths(corroded, 0.0, 0.0)
        self.scene.hand_over(idx)

    def degrade(self, dt, stresses: Stresses):
        """The law for creep time ``dt`` under frozen ``stresses``, written (the paper clock's step)."""
        self.advance(dt, stresses)
        self.write(stresses.index)

    def load_state(self, state: dict, write: bool = True):
        """Restore :meth:`state_dict` output; ``write``: into the scene's bonds (False after a checkpoint's restore,
        whose scene file holds the strengths)."""
        self.load_arrays(state)
        if write:
            self.write(self.intact())


def stress_corrosion(scene: StaticScene, sc_params, saved: dict | None = None) -> StaticCorrosion:
    """The creep test's bond writer of a static ``scene`` (``[stress_corrosion]`` parameters), listed among its
    drivers; ``saved``: the law's state from a checkpoint (the strengths came back with the scene)."""
    corr = StaticCorrosion(scene, sc_params)
    if saved is not None:
        corr.load_state(saved, write=False)
    scene.drivers.append(corr)
    return corr


def build_scene(specimen, params, layout=None) -> StaticScene:
    """The static scene of ``specimen`` (rigid or fem cells, as ``resolution.grain_model`` builds its layout): a
    :class:`.jaws.DiscScene` (with the Brazilian jaws) for a disc, a :class:`.scene.StaticScene` otherwise."""
    cls = DiscScene if isinstance(specimen.tessellation, DiscTessellation) else StaticScene
    return cls(specimen, params, layout)


def apply_levers(scene: StaticScene, levers, seed: int) -> dict:
    """The Brazilian levers on a static scene before its loading (:func:`.jaws.apply_levers`: strength scatter and
    slits on both grain models, blocked rotation on rigid cells); what was done, as YADE's counts."""
    return _apply_levers(scene, levers, seed)


#: What the registry returns for ``numerics.engine = "static"``.
ENGINE = EngineModule(name=NAME, dynamic=DYNAMIC, scene_file=SCENE_FILE, version=version, build_scene=build_scene,
                      scene_from_state=scene_from_state, consolidate=consolidate, apply_levers=apply_levers,
                      stress_corrosion=stress_corrosion, unsupported=UNSUPPORTED, vtk_refused=VTK_REFUSED,
                      warn_dynamic_only=warn_dynamic_only, timings=bench_timing)
