"""Hillig-Charles stress corrosion of the scene's cohesive bonds (paper Eq. 7), driven by a creep clock.

The bond state lives in numpy arrays (strengths, area fractions); YADE is touched
only to read bond forces and to write ``FnMax``/``FsMax`` (and ``kn``/``ks`` in
the area mode).  Two degradation modes (``stress_corrosion.mode``):

* ``strength`` (paper): J^T and J^C fall at beta1*exp(beta2*stress); stiffness stays.
* ``area`` (Potyondy 2007 idea): the bond's effective area fraction a falls, so
  stiffness k = a k0 and capacity J a A0 fall together and the stress on what
  remains rises (see :mod:`grainfrac_yade.corrosion`).

A bond the law says has failed is handed to YADE's JCFpm law with its strength a
hair (``BREAK_MARGIN``) below its current load, so the law breaks it on the next
step, in its true mode, and records it (a strength of exactly 0 would never break
in tension: shared/yade_notes.md).

NaN or infinite bond forces (a DEM that blew up) are refused where they are read
(:meth:`StressCorrosion.stresses`), and nothing non-finite is ever written to YADE:
both raise :class:`~grainfrac_yade.errors.NumericalFailure`.
"""
from __future__ import annotations

import numpy as np

from .. import corrosion
from .scene import SHEAR

#: Relative margin below the current load given to a bond that has reached its strength,
#: so that YADE's strict ">" test breaks it on the next step.
BREAK_MARGIN = 1e-6
#: Smallest strength written to YADE, relative to the bond's initial strength: JCFpm never
#: breaks a bond with FnMax = 0 in tension.
MIN_STRENGTH_FRACTION = 1e-9


class StressCorrosion:
    """Bond degradation state of a scene plus the operations both creep clocks need."""

    name = "StressCorrosion"

    def __init__(self, scene, sc_params):
        self.scene, self.p = scene, sc_params
        props = scene.props
        self.area0 = scene.layout.bond_area.copy()
        self.tensile0 = props.tensile_strength.copy()
        self.cohesion0 = props.cohesion.copy()
        self.tensile = self.tensile0.copy()          # J^T [Pa] (strength mode)
        self.cohesion = self.cohesion0.copy()        # J^C [Pa] (strength mode)
        self.area_fraction = np.ones(scene.n_bonds)  # a [1] (area mode)
        self.kn0 = props.normal_stiffness.copy()
        self.ks0 = props.shear_stiffness.copy()
        self.tan_phi = np.tan(props.friction_angle)
        self.creep_time = 0.0

    # ------------------------------------------------------------------ reading
    def stresses(self, idx):
        """sigma (tension positive) and tau [Pa] of bonds ``idx``; per intact area A0 in area mode.

        NumericalFailure if a force is NaN or infinite."""
        fn, fs = self.scene.bond_forces(idx)
        corrosion.check_finite("bond normal force", fn, idx)
        corrosion.check_finite("bond shear force", fs, idx)
        return fn / self.area0[idx], fs / self.area0[idx]

    def intact(self) -> np.ndarray:
        return np.flatnonzero(~self.scene.broken)

    def law_arrays(self, idx):
        """(J^T, J^C) in strength mode, (J^T0, J^C0) in area mode, for bonds ``idx``."""
        if self.p.mode == "area":
            return self.tensile0[idx], self.cohesion0[idx]
        return self.tensile[idx], self.cohesion[idx]

    # ------------------------------------------------------------------ writing
    def write(self, idx):
        """Push the numpy state of bonds ``idx`` into YADE (strengths; stiffness in area mode)."""
        inter = self.scene.interactions
        if self.p.mode == "area":
            a = self.area_fraction[idx]
            cap_t = np.maximum(self.tensile0[idx] * a, MIN_STRENGTH_FRACTION * self.tensile0[idx]) * self.area0[idx]
            cap_c = np.maximum(self.cohesion0[idx] * a, MIN_STRENGTH_FRACTION * self.cohesion0[idx]) * self.area0[idx]
            kn, ks = self.kn0[idx] * np.maximum(a, MIN_STRENGTH_FRACTION), self.ks0[idx] * np.maximum(a, MIN_STRENGTH_FRACTION)
            _check_written(idx, cap_t, cap_c, kn)
            for n, k in enumerate(idx):
                ph = inter[k].phys
                if ph.isCohesive:
                    ratio = float(kn[n]) / ph.kn
                    ph.kn, ph.ks = float(kn[n]), float(ks[n])
                    ph.shearForce = ph.shearForce * ratio   # the law's shear force is incremental
                    ph.FnMax, ph.FsMax = float(cap_t[n]), float(cap_c[n])
            return
        ft = np.maximum(self.tensile[idx], MIN_STRENGTH_FRACTION * self.tensile0[idx]) * self.area0[idx]
        fc = np.maximum(self.cohesion[idx], MIN_STRENGTH_FRACTION * self.cohesion0[idx]) * self.area0[idx]
        _check_written(idx, ft, fc)
        for n, k in enumerate(idx):
            ph = inter[k].phys
            if ph.isCohesive:
                ph.FnMax, ph.FsMax = float(ft[n]), float(fc[n])

    def hand_over_failures(self, idx, sigma, tau, modes):
        """Set bonds ``idx`` (at their failure point) a hair below their load so the law breaks them."""
        inter = self.scene.interactions
        _check_written(idx, sigma, tau)   # Python's max(nan, 0) is nan: refuse before any max() below
        for k, s, t, m in zip(idx, sigma, tau, modes):
            ph = inter[k].phys
            if m == corrosion.MODE_CORRODED:  # nothing left; friction alone carries it: break it ourselves
                self.scene.break_bonds([k], SHEAR)
            elif m == corrosion.MODE_TENSION:
                ph.FnMax = max(float(s * self.area0[k]) * (1 - BREAK_MARGIN), MIN_STRENGTH_FRACTION * ph.FnMax)
            else:  # shear (or corroded away): Mohr-Coulomb limit just below the shear force
                fn = -s * self.area0[k]  # compression positive
                ph.FsMax = max(float(t * self.area0[k] - fn * ph.tanFrictionAngle) * (1 - BREAK_MARGIN)
                               - BREAK_MARGIN * abs(t * self.area0[k]), 0.0)
                if ph.FsMax <= 0.0:
                    ph.FsMax = MIN_STRENGTH_FRACTION * self.cohesion0[k] * self.area0[k]
                    ph.FnMax = MIN_STRENGTH_FRACTION * self.tensile0[k] * self.area0[k]

    # ------------------------------------------------------------------ law steps
    def degrade_for(self, dt, idx, sigma, tau):
        """Apply Eq. 7 (or the area law) for creep time ``dt`` under frozen stresses; write to YADE."""
        if self.p.mode == "area":
            self.area_fraction[idx] = corrosion.degrade_area(self.area_fraction[idx], sigma, tau,
                                                             self.tensile0[idx], self.cohesion0[idx], dt,
                                                             self.p.beta1, self.p.beta2)
        else:
            self.tensile[idx], self.cohesion[idx] = corrosion.degrade(self.tensile[idx], self.cohesion[idx],
                                                                      sigma, tau, dt, self.p.beta1, self.p.beta2)
        self.creep_time += dt
        self.write(idx)

    def state_dict(self) -> dict:
        """Whole engine state (for checkpoints): arrays as lists, creep time."""
        return {"creep_time": self.creep_time, "tensile_strength_pa": self.tensile.tolist(),
                "cohesion_pa": self.cohesion.tolist(), "area_fraction": self.area_fraction.tolist(),
                "mode": self.p.mode}

    def load_state(self, state: dict, write: bool = True):
        """Restore :meth:`state_dict` output; ``write``: push the strengths into YADE's bonds (False when
        the bonds come back with the scene, as after ``O.load`` of a checkpoint: a bond handed over
        at its failure point holds a strength the arrays do not, and must keep it)."""
        self.creep_time = float(state["creep_time"])
        self.tensile = np.array(state["tensile_strength_pa"], float)
        self.cohesion = np.array(state["cohesion_pa"], float)
        self.area_fraction = np.array(state["area_fraction"], float)
        if write:
            self.write(self.intact())


def _check_written(idx, *values):
    """NumericalFailure unless every value meant for YADE's bonds ``idx`` is finite."""
    for v in values:
        corrosion.check_finite("value written to a YADE bond", v, idx)
