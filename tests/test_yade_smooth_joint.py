"""YADE's smooth joint (the bonds of fem cells) against the linear contact of Table 2, in compression.

The law reads a smooth joint's normal displacement as D = initD - |(x1 - x2) . n|, initD the sphere centres'
initial distance along the joint normal n: a pair pressed past initD has crossed the joint and unloads (D falls
again, tension beyond 2 initD).  Fem cells put the two spheres of a contact about 1 um apart at the presets'
``resolution.contact_inset = 0.001``, which sets YADE's fem UCS (docs/studies/static_engine.md, "YADE's fem peak is
its smooth joint's pass-through").  This pins the rule: a YADE release that changes it changes every YADE fem row.
"""
import pytest

from conftest import needs_yade

GAP = 1e-6           # m, initD: the sphere centres' distance along the joint normal
RADIUS = 1e-4        # m
KN = 1e8             # N/m, the bond's normal stiffness (written per bond, as the scene does)


def _normal_force_at(compressions):
    """The smooth joint's normal force [N] (compression positive) at each of ``compressions`` [m] of closing."""
    from grainfrac_yade.engines.yade import load_yade
    load_yade()
    from yade import O, utils, Vector3
    from yade import wrapper as w
    O.reset()
    mat = O.materials.append(w.JCFpmMat(young=1e10, poisson=0.25, density=2600, tensileStrength=1.0, cohesion=1.0,
                                        frictionAngle=0.5))
    ids = [O.bodies.append(utils.sphere((x, 0, 0), RADIUS, material=mat)) for x in (0.0, GAP)]
    for i in ids:
        O.bodies[i].state.blockedDOFs = "xyzXYZ"
    O.engines = [w.ForceResetter(), w.InsertionSortCollider([w.Bo1_Sphere_Aabb()]),
                 w.InteractionLoop([w.Ig2_Sphere_Sphere_ScGeom()], [w.Ip2_JCFpmMat_JCFpmMat_JCFpmPhys()],
                                   [w.Law2_ScGeom_JCFpmPhys_JointedCohesiveFrictionalPM(neverErase=True,
                                                                                       smoothJoint=True)]),
                 w.NewtonIntegrator(damping=0.0)]
    O.dt = 1e-9
    inter = utils.createInteraction(*ids)
    ph = inter.phys
    ph.kn, ph.ks, ph.FnMax, ph.FsMax = KN, KN, 1e9, 1e9      # strong: no break in these steps
    ph.isOnJoint, ph.jointNormal = True, Vector3(1, 0, 0)
    O.step()                                                  # the bond's first step: initD, stress-free
    out = []
    for c in compressions:
        O.bodies[ids[1]].state.pos = Vector3(GAP - c, 0, 0)
        O.step()
        out.append(ph.normalForce.norm())
    return out


@needs_yade
def test_a_smooth_joint_pressed_past_its_gap_unloads():
    forces = _normal_force_at([0.5 * GAP, 1.0 * GAP, 1.5 * GAP])
    linear = [KN * c for c in (0.5 * GAP, 1.0 * GAP, 1.5 * GAP)]
    # up to the gap, Table 2's linear contact (relative round-off of positions near 1e-6 m: 1e-9)
    assert forces[0] == pytest.approx(linear[0], rel=1e-6)
    assert forces[1] == pytest.approx(linear[1], rel=1e-6)
    # past it the pair has crossed the joint: YADE's force falls back to k_n (2 initD - c), not k_n c
    assert forces[2] == pytest.approx(KN * (2 * GAP - 1.5 * GAP), rel=1e-6)
    assert forces[2] < 0.5 * linear[2]
