"""Intact bonds on face planes kept against YADE's smooth-joint sliding rule.

YADE's JCFpm law with ``smoothJoint`` (the bonds of finite-element cells act on their face's plane)
zeroes a joint interaction, cohesion and tension included, once its ``jointCumulativeSliding`` (the
sum over every DEM step of the sliding increment's length, not the net slip) exceeds twice the
smaller radius of its two spheres; it counts no crack then.  The rule stands for a broken face whose
two sides slid past each other.  It hits intact bonds too: their path grows with every elastic
oscillation, slowly for ordinary spheres, at once for tiny ones (a regularised tessellation's
four-cell vertices give spheres of 3e-7 m: measured on 10 x 20 mm, seed 1, 2 % threshold, 13 bonds
erased before the peak and the UCS 197 MPa, against 261 MPa with this guard;
docs/studies/regularisation.md).

:class:`IntactJointGuard` (``numerics.keep_intact_joints``) resets the path of every intact bond
every :data:`SWEEP_STEPS` DEM steps, and before every step for the bonds whose path grew by more
than :data:`RISK_FRACTION` of their limit within one sweep.  The path does not enter the forces
(the law's dilation term is zero: JCFpm's joint dilation angle is 0 here), so the guard changes
nothing but the erasure.  A broken bond keeps the law's rule, counted from about its break on.
Bonds erased all the same (their path crossed the limit within one sweep), and every erasure
when the guard is off, are counted by the scene (``GrainScene.erased_by_sliding``): the guard never
fails silently.
"""
from __future__ import annotations

import numpy as np

#: DEM steps between two resets of every intact bond's sliding path. At 10 x 20 mm (seed 1, 2 %
#: threshold, 0.5 /s) the tiniest spheres' bonds took about 10,000 steps to slide their limit of
#: 5e-7 m, so 100 steps leave a margin of about 100.
SWEEP_STEPS = 100
#: A bond whose path grew by more than this fraction of its limit within one sweep is reset before
#: every DEM step from then on (a margin of 4 against a path that grows faster in the next sweep).
RISK_FRACTION = 0.25


class IntactJointGuard:
    """Driver (before every DEM step) that keeps intact smooth-joint bonds from being erased by their
    cumulative sliding path (module doc)."""
    name = "IntactJointGuard"

    def __init__(self, scene):
        lay = scene.layout
        radius = lay.sphere_radius[lay.bond_spheres]
        #: (b,) the law's limit on each bond's sliding path [m]: 2 min(r1, r2)
        self.limit = 2.0 * radius.min(axis=1)
        self.at_risk = np.empty(0, dtype=np.int64)
        self._step = 0

    def before_step(self, scene):
        self._step += 1
        inter, broken = scene.interactions, scene.broken
        if self._step % SWEEP_STEPS:
            for k in self.at_risk:
                if not broken[k]:
                    inter[k].phys.jointCumulativeSliding = 0.0
            return
        risky = []
        for k in np.flatnonzero(~broken):
            phys = inter[k].phys
            if phys.jointCumulativeSliding > RISK_FRACTION * self.limit[k]:
                risky.append(k)
            phys.jointCumulativeSliding = 0.0
        if risky:
            self.at_risk = np.union1d(self.at_risk, risky).astype(np.int64)
