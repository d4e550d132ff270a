"""Stress corrosion of the scene's cohesive bonds: the YADE side of a degradation law.

The law and its per-bond state are pure numpy (:class:`grainfrac_yade.kernel.corrosion.BondCorrosion`,
which :class:`StressCorrosion` extends).  This adapter only reads bond forces
(:meth:`StressCorrosion.stresses`) and writes what the law says a bond can carry: ``FnMax`` and
``FsMax``, and ``kn``/``ks`` for a law that changes stiffness (the area law).

A bond the law says has failed is handed to YADE's JCFpm law with its strength a hair
(``BREAK_MARGIN``) below its current load, so the law breaks it on the next step, in its true mode,
and records it (a strength of exactly 0 would never break in tension: shared/yade_notes.md).

Broken bonds of a law that changes stiffness get their contact stiffness back
(:class:`ContactStiffnessRestorer`): a broken bond stays a frictional contact that carries
compression (``neverErase``), and a corroded bond's stiffness (down to 1e-9 of k_n0) would let the
grains pass through each other.  The stiffness returns to k_n0, k_s0 with the contact's reference gap
moved so that the normal force is continuous; further closing is resisted with k_n0.

NaN or infinite bond forces (a DEM that blew up) are refused where they are read, and nothing
non-finite is ever written to YADE: both raise :class:`~grainfrac_yade.errors.NumericalFailure`.
"""
from __future__ import annotations

import numpy as np

from ...law import MODE_CORRODED, MODE_TENSION, Stresses, check_finite
from ...kernel.corrosion import STATE_KEYS, BondCorrosion  # noqa: F401
from .scene import SHEAR

#: Relative margin below the current load given to a bond that has reached its strength,
#: so that YADE's strict ">" test breaks it on the next step.
BREAK_MARGIN = 1e-6
#: Smallest strength written to YADE, relative to the bond's initial strength: JCFpm never
#: breaks a bond with FnMax = 0 in tension.
MIN_STRENGTH_FRACTION = 1e-9


class StressCorrosion(BondCorrosion):
    """A degradation law's state on a scene's bonds (:class:`BondCorrosion`), and the reads and writes of
    YADE's bonds the creep clocks need."""

    name = "StressCorrosion"

    def __init__(self, scene, sc_params):
        super().__init__(scene, sc_params)

    # ------------------------------------------------------------------ writing
    def write(self, idx):
        """Push the state of bonds ``idx`` into YADE: strengths, and stiffness for a law that changes it."""
        idx = np.asarray(idx, dtype=np.int64)
        inter = self.scene.interactions
        jt, jc, stiffness = self.law.strengths(self.state.subset(idx))
        ft = np.maximum(jt, MIN_STRENGTH_FRACTION * self.tensile0[idx]) * self.area0[idx]
        fc = np.maximum(jc, MIN_STRENGTH_FRACTION * self.cohesion0[idx]) * self.area0[idx]
        if stiffness is None:
            _check_written(idx, ft, fc)
            for n, k in enumerate(idx):
                ph = inter[k].phys
                if ph.isCohesive:
                    ph.FnMax, ph.FsMax = float(ft[n]), float(fc[n])
            return
        kn = self.kn0[idx] * np.maximum(stiffness, MIN_STRENGTH_FRACTION)
        ks = self.ks0[idx] * np.maximum(stiffness, MIN_STRENGTH_FRACTION)
        _check_written(idx, ft, fc, kn)
        for n, k in enumerate(idx):
            ph = inter[k].phys
            if ph.isCohesive:
                ratio = float(kn[n]) / ph.kn
                ph.kn, ph.ks = float(kn[n]), float(ks[n])
                ph.shearForce = ph.shearForce * ratio   # the law's shear force is incremental
                ph.FnMax, ph.FsMax = float(ft[n]), float(fc[n])

    def hand_over_failures(self, idx, sigma, tau, modes):
        """Set bonds ``idx`` (at their failure point) a hair below their load so the law breaks them."""
        inter = self.scene.interactions
        _check_written(idx, sigma, tau)   # Python's max(nan, 0) is nan: refuse before any max() below
        for k, s, t, m in zip(idx, sigma, tau, modes):
            ph = inter[k].phys
            if m == MODE_CORRODED:  # nothing left; friction alone carries it: break it ourselves
                self.scene.break_bonds([k], SHEAR)
                self.restore_contact_stiffness([k])
            elif m == MODE_TENSION:
                ph.FnMax = max(float(s * self.area0[k]) * (1 - BREAK_MARGIN), MIN_STRENGTH_FRACTION * ph.FnMax)
            else:  # shear: Mohr-Coulomb limit just below the shear force
                fn = -s * self.area0[k]  # compression positive
                ph.FsMax = max(float(t * self.area0[k] - fn * ph.tanFrictionAngle) * (1 - BREAK_MARGIN)
                               - BREAK_MARGIN * abs(t * self.area0[k]), 0.0)
                if ph.FsMax <= 0.0:
                    ph.FsMax = MIN_STRENGTH_FRACTION * self.cohesion0[k] * self.area0[k]
                    ph.FnMax = MIN_STRENGTH_FRACTION * self.tensile0[k] * self.area0[k]

    def restore_contact_stiffness(self, idx):
        """Broken bonds ``idx`` become contacts of stiffness k_n0, k_s0 with the normal force they carry now
        (the reference gap moves by the extra closure a softened bond allowed); once per bond."""
        inter, bodies = self.scene.interactions, self.scene.O.bodies
        for k in np.atleast_1d(idx):
            k = int(k)
            if self.restored[k]:
                continue
            i = inter[k]
            ph = i.phys
            fn = float(ph.normalForce.dot(ph.jointNormal if ph.isOnJoint else i.geom.normal))  # compression +
            if fn > 0:   # in compression: the same force with the full stiffness
                if ph.isOnJoint:
                    gap = abs((bodies[i.id2].state.pos - bodies[i.id1].state.pos).dot(ph.jointNormal))
                    ph.initD = gap + fn / float(self.kn0[k])        # D = initD - gap
                else:
                    ph.initD = i.geom.penetrationDepth - fn / float(self.kn0[k])   # D = pen - initD
            ph.kn, ph.ks = float(self.kn0[k]), float(self.ks0[k])
            self.restored[k] = True

    # ------------------------------------------------------------------ law steps
    def degrade(self, dt, stresses: Stresses):
        """Apply the law for creep time ``dt`` under frozen ``stresses`` (the paper clock's step); write to YADE."""
        self.advance(dt, stresses)
        self.write(stresses.index)

    def load_state(self, state: dict, write: bool = True):
        """Restore :meth:`state_dict` output; ``write``: push the strengths into YADE's bonds (False when
        the bonds come back with the scene, as after ``O.load`` of a checkpoint: a bond handed over
        at its failure point holds a strength the arrays do not, and must keep it)."""
        self.load_arrays(state)
        if write:
            self.write(self.intact())


class ContactStiffnessRestorer:
    """Scene driver (before every DEM step): broken bonds of a law that changes stiffness get their
    contact stiffness back as soon as the contact law has broken them (a cheap check of the crack count)."""

    name = "ContactStiffnessRestorer"

    def __init__(self, corr: StressCorrosion):
        self.corr = corr
        self._seen = -1

    def before_step(self, scene):
        if scene._cracks_seen != self._seen:
            new = np.flatnonzero(scene.broken & ~self.corr.restored)
            if new.size:
                self.corr.restore_contact_stiffness(new)
            self._seen = scene._cracks_seen


def _check_written(idx, *values):
    """NumericalFailure unless every value meant for YADE's bonds ``idx`` is finite."""
    for v in values:
        check_finite("value written to a YADE bond", v, idx)


def add_stiffness_restorer(scene, corr):
    """For a law that changes stiffness: broken bonds get their contact stiffness back before the next step."""
    if not corr.law.exact_jump:
        scene.drivers.append(ContactStiffnessRestorer(corr))


def stress_corrosion(scene, sc_params, saved: dict | None = None) -> StressCorrosion:
    """The stress-corrosion bond writer of ``scene`` (``[stress_corrosion]`` parameters ``sc_params``), listed among
    its engines, with the contact-stiffness restorer of a law that changes stiffness.  ``saved``: the law's state
    from a checkpoint (:meth:`StressCorrosion.state_dict`), loaded without writing to the bonds, which came back
    with the scene."""
    corr = StressCorrosion(scene, sc_params)
    if saved is not None:
        corr.load_state(saved, write=False)
    scene.extras.append(corr)
    add_stiffness_restorer(scene, corr)
    return corr
