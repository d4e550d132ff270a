"""Levers of a grain-based model on its tensile strength, applied to a built scene (study options).

Each lever changes the bonds or the cells of a scene built by :func:`.scene.build_scene` before
the first DEM step; with every lever off (:class:`Levers` defaults) nothing is touched, so results
are bit-identical to a scene without levers.  They are options of the ``brazilian`` command and of
the lever study (``studies/brazilian_levers.py``, which applies them to UCS tests too), recorded in
each summary.json under ``levers``; they are not model parameters (``params/``), so the other
commands (ucs, creep) do not know them.  The levers on the contacts that are parameters of every
command and both grain models live in ``[calibration]`` (k_s/k_n, J^T/J^C, inter-mineral strength, a
per-face Weibull scatter of strength: :func:`grainfrac_yade.params.calibrated_contact`,
:mod:`grainfrac_yade.contact_strength`); ``brazilian --tensile-scale`` sets the contact rows' J^T.

* ``slit_fraction`` f: a random share f of the bonds (faces, with one sphere per cell) start broken
  ("slits", as the flat-joint model's unbonded faces, Potyondy 2012, or a granite's pre-existing
  grain-boundary cracks): no tension and no cohesion, friction phi_r, in contact, so they carry
  compression and friction but no tension.  Recorded with break mode :data:`PRE_EXISTING` and left
  out of the crack counts of the test (``new_breaks``).
* ``strength_cv`` c: each bond's J^T and J^C multiplied by one factor drawn from a lognormal of mean 1
  and coefficient of variation c (weak and strong grain boundaries; the mean strength stays).
* ``block_rotation``: no cell rotates (rigid cells; an upper bound of the rotational resistance that
  grain interlocking, or several bonds per face as ``resolution.spheres_per_cell = 8`` give, adds to
  the one centre-to-centre bond per face that leaves rotation free).

Random draws use their own stream, seeded by the specimen's seed: the specimen is unchanged.
"""
from __future__ import annotations

import numpy as np

from ...errors import GrainfracError
from ...grains import rotating_grain_models
from ...kernel.levers import LEVER_STREAM, PRE_EXISTING, Levers, lever_draws, new_breaks  # noqa: F401

def apply_levers(scene, levers: Levers, seed: int) -> dict:
    """Apply ``levers`` to ``scene`` (before its first step); return what was done (counts)."""
    done = {"levers": levers.to_dict()}
    if not levers.active:
        return done
    if scene.O.iter != 0:
        raise GrainfracError("levers: the scene has already run; fix: apply levers right after build_scene")
    if not scene.model.rotating:   # the levers act on each cell's one body, which rotates
        rotating = rotating_grain_models()
        raise GrainfracError(f"levers: built for cells that are one rotating body each (grain models {rotating}), "
                             f"not {scene.model.name!r} cells; fix: use resolution.grain_model = \"{rotating[0]}\"")
    factor, slits = lever_draws(levers, seed, scene.n_bonds)
    if factor is not None:
        for k, inter in enumerate(scene.interactions):
            ph = inter.phys
            ph.FnMax = float(ph.FnMax * factor[k])
            ph.FsMax = float(ph.FsMax * factor[k])
        done["strength_factor_mean"] = float(factor.mean())
    if slits is not None:
        scene.break_bonds(slits, PRE_EXISTING)
        done["n_slits"] = int(len(slits))
    if levers.block_rotation:
        for body in scene.cell_body:
            st = scene.O.bodies[int(body)].state
            if "Z" not in st.blockedDOFs:
                st.blockedDOFs = st.blockedDOFs + "Z"
    return done
