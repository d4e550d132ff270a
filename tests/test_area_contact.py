"""Area law in YADE: a broken or corroded-away bond becomes a contact of the full stiffness k_n0, k_s0 that
carries its compression, instead of keeping the corroded stiffness (down to 1e-9 k_n0), through which the
grains would pass.  One bond between two cells under a constant force (tests/single_bond.py);
about 1 s per case.  (A bond the area law breaks in shear cannot be checked this way: under a constant shear
force that beat full friction, residual friction cannot hold it and the cell slides away.)"""
import pytest

from conftest import needs_yade
from grainfrac_yade.params import load_parameters

pytestmark = [needs_yade, pytest.mark.yade]

AREA = ["stress_corrosion.law=area", "stress_corrosion.clock=event", "stress_corrosion.creep_time_limit=1e30"]
#: DEM steps run after the break to see whether the contact holds the load.
AFTER_STEPS = 3000


def _corrode(normal_stress, shear_stress, restore=True, monkeypatch=None):
    """Corrode one bond under a constant force to its break; then AFTER_STEPS more DEM steps.
    Returns (holder, penetration at a = 1, at the break, after the steps, normal force after [N])."""
    from grainfrac_yade.clocks import EventClock
    from grainfrac_yade.protocols.creep_loops import event_clock_loop
    from single_bond import BondUnderForce
    p = load_parameters(overrides=AREA)
    holder = BondUnderForce(p, normal_stress, shear_stress)
    if not restore:
        monkeypatch.setattr(type(holder.corr), "restore_contact_stiffness", lambda self, idx: None)
    inter = holder.scene.interactions[0]
    pen_intact = inter.geom.penetrationDepth
    sc = p.stress_corrosion
    event_clock_loop(holder, holder.corr, EventClock(sc.max_strength_loss_fraction, sc.creep_time_limit))
    assert holder.failed and holder.scene.broken[0]
    pen_break = inter.geom.penetrationDepth
    holder.scene.run(AFTER_STEPS)
    fn = float(inter.phys.normalForce.dot(inter.geom.normal))   # compression positive
    return holder, pen_intact, pen_break, inter.geom.penetrationDepth, fn


def test_a_corroded_away_bond_is_a_full_stiffness_contact_that_holds_its_compression():
    """Compressed at 50 MPa without shear no criterion is met: the bond corrodes away (the adapter breaks it).
    It gets k_n0 and k_s0 back, carries the applied compression (to 1e-3), and the grains stay where the
    corroded bond had let them go (no further closing)."""
    holder, pen_intact, pen_break, pen_after, fn = _corrode(-50e6, 0.0)
    ph = holder.scene.interactions[0].phys
    assert holder.scene.break_mode[0] == 2 and holder.corr.restored[0]       # broken by the adapter (mode 3)
    assert ph.kn == holder.corr.kn0[0] and ph.ks == holder.corr.ks0[0]
    applied = -holder.force[0]
    assert fn == pytest.approx(applied, rel=1e-3)
    assert pen_break > pen_intact                      # the corroding bond softened: the grains closed in
    assert abs(pen_after - pen_break) < 1e-3 * (pen_break - pen_intact)


def test_without_the_restored_stiffness_the_grains_pass_through_each_other(monkeypatch):
    """The behaviour before the fix: the corroded-away contact keeps 1e-9 k_n0 and cannot hold the load:
    the loaded cell runs through the fixed one (the penetration depth passes through its maximum and turns
    negative on the far side)."""
    holder, pen_intact, pen_break, pen_after, fn = _corrode(-50e6, 0.0, restore=False, monkeypatch=monkeypatch)
    ph = holder.scene.interactions[0].phys
    assert ph.kn < 1e-6 * holder.corr.kn0[0]
    assert abs(pen_after - pen_break) > 100 * (pen_break - pen_intact)


def test_a_bond_broken_in_tension_closes_again_as_a_full_stiffness_contact():
    """Pulled at 40 MPa the bond corrodes to a = sigma/J^T0 and JCFpm breaks it in tension; the driver
    (ContactStiffnessRestorer) gives it k_n0, k_s0 before the next step.  Pushed back with the same force,
    the crack closes at the bond's initial gap and the contact carries the compression with k_n0:
    D = F/k_n0, not F/(a k_n0)."""
    holder, *_ = _corrode(40e6, 0.0)
    ph = holder.scene.interactions[0].phys
    assert holder.scene.break_mode[0] == 1 and holder.corr.restored[0]
    assert ph.kn == holder.corr.kn0[0] and ph.ks == holder.corr.ks0[0]
    O, body = holder.scene.O, holder._body
    push = -holder.force[0]
    O.forces.setPermF(body.id, (push, 0.0, 0.0))
    holder.scene.run(20 * AFTER_STEPS)
    inter = holder.scene.interactions[0]
    fn = float(inter.phys.normalForce.dot(inter.geom.normal))
    assert fn == pytest.approx(-push, rel=1e-3)
    assert inter.geom.penetrationDepth - inter.phys.initD == pytest.approx(-push / holder.corr.kn0[0], rel=1e-3)
