"""Collapse under the held load: the stress servo saturated closing while the axial strain grows by more
than ``creep.collapse_strain_increment`` ends a creep run as soon as the specimen gives way, instead of
after ``creep.max_relaxation_steps`` DEM steps without equilibrium.

The bookkeeping (:class:`CollapseWatch`), the servo's clip flag and the paper clock loop are tested on
hand-made sequences and stand-ins; one YADE run on a tiny specimen shows the criterion ending a real
collapse early with the lifetime of the criterion switched off.
"""
import itertools
from types import SimpleNamespace

import pytest

from conftest import needs_yade
from grainfrac_yade.clocks import PaperClock
from grainfrac_yade.errors import ParameterError
from grainfrac_yade.params import load_parameters
from grainfrac_yade.kernel.held_relaxation import CollapseWatch, collapsing
from grainfrac_yade.engines.yade.platens import StressServo
from test_reliability import JC, JT, StandInBonds, StandInHolder, loop_params


def _feed(watch, checks):
    """Feed (saturated, strain) checks; the index of the first that reaches collapse, else None."""
    for i, (saturated, strain) in enumerate(checks):
        if watch.update(saturated, strain):
            return i
    return None


# ------------------------------------------------------------------ the bookkeeping
def test_collapse_is_reached_once_the_saturated_strain_gain_exceeds_the_increment():
    watch = CollapseWatch(1e-3, 0.002)
    # the first saturated check counts from the strain of the check before it (0.002)
    assert _feed(watch, [(True, 0.0024), (True, 0.0028), (True, 0.00301), (True, 0.0034)]) == 2
    assert watch.growth == pytest.approx(1.01e-3) and watch.checks == 3


def test_a_gain_equal_to_the_increment_is_not_collapse():
    watch = CollapseWatch(0.5, 0.0)
    assert _feed(watch, [(True, 0.25), (True, 0.5)]) is None and watch.growth == 0.5
    assert watch.update(True, 0.75)


def test_any_interruption_of_the_saturation_starts_the_count_again():
    watch = CollapseWatch(1e-3, 0.0)
    checks = [(True, 0.0006), (True, 0.0009),   # 0.9e-3 gained
              (False, 0.00095),                # servo back within its limits: reset
              (True, 0.0012), (True, 0.0018),  # 0.85e-3 since 0.00095
              (True, 0.00196)]                 # 1.01e-3 since 0.00095
    assert _feed(watch, checks) == 5
    assert watch.start == 0.00095 and watch.checks == 3


def test_unsaturated_checks_never_reach_collapse_however_far_the_strain_runs():
    watch = CollapseWatch(1e-4, 0.0)
    assert _feed(watch, [(False, 0.001 * k) for k in range(1, 50)]) is None
    assert watch.start is None and watch.growth == 0.0 and watch.checks == 0


def test_alternating_saturation_never_accumulates():
    watch = CollapseWatch(1e-3, 0.0)
    assert _feed(watch, [(k % 2 == 0, 4e-4 * k) for k in range(1, 100)]) is None


def test_increment_zero_switches_the_criterion_off():
    watch = CollapseWatch(0.0, 0.0)
    assert _feed(watch, [(True, 0.001 * k) for k in range(1, 50)]) is None
    assert watch.growth == pytest.approx(0.049)   # still measured, never a collapse


def test_the_state_round_trips_and_the_count_goes_on():
    """A checkpoint of the paper clock stores the watch's state; the restored watch decides as the original."""
    a = CollapseWatch(1e-3, 0.0)
    _feed(a, [(False, 0.0001), (True, 0.0005), (True, 0.0009)])
    b = CollapseWatch.from_state(1e-3, a.state_dict())
    assert b.state_dict() == a.state_dict()
    assert a.update(True, 0.00111) and b.update(True, 0.00111)


def test_the_reason_names_the_criterion_and_its_numbers():
    watch = CollapseWatch(6e-4, 0.0)
    _feed(watch, [(True, 3e-4), (True, 6.5e-4)])
    assert watch.reason(50) == ("collapse: servo at its closing speed limit for 100 DEM steps while the axial "
                                "strain grew by 0.00065 > collapse_strain_increment 0.0006")


# ------------------------------------------------------------------ the servo's clip flag
class StandInPlatens:
    height = 0.02

    def __init__(self, stresses):
        self.stresses, self.velocity = iter(stresses), None

    def axial_stress(self):
        return next(self.stresses)

    def set_axial_velocity(self, v):
        self.velocity = v


def test_servo_reports_its_clip_and_counts_steps_clipped_closing_in_a_row():
    target = 100e6
    platens = StandInPlatens([99.99e6, 50e6, 0.0, 150e6, 0.0, 0.0, 100e6])
    servo = StressServo(platens, target, 50e9, 200, max_speed=0.04)
    scene = SimpleNamespace(O=SimpleNamespace(dt=1e-7))
    seen = []
    for _ in range(7):
        servo.before_step(scene)
        seen.append((servo.clipped, servo.closing_clipped_steps, platens.velocity))
    assert [s[:2] for s in seen] == [(0, 0), (1, 1), (1, 2), (-1, 0), (1, 1), (1, 2), (0, 0)]
    assert seen[1][2] == 0.04 and seen[3][2] == -0.04 and seen[6][2] == 0.0


# ------------------------------------------------------------------ the paper clock loop
class CollapsingHolder(StandInHolder):
    """Stand-in creep run whose servo is clipped closing on the steps listed in ``clipped`` (by pass) while
    the platens close 1e-4 of strain per pass; unbalanced all along (F_u = 1, above the threshold)."""

    def __init__(self, clipped):
        super().__init__(itertools.repeat(1.0))
        self.clipped = clipped
        self.passes = 0
        self.servo = SimpleNamespace(closing_clipped_steps=0, stress=0.0, target=1.0)   # carrying nothing
        self.platens = SimpleNamespace(axial_strain=lambda: 1e-4 * self.passes)

    def mark_breaks(self, creep_time):   # called once per pass, after its DEM steps
        self.passes += 1
        self.servo.closing_clipped_steps = self.servo.closing_clipped_steps + 1 if self.clipped(self.passes) else 0

    def safe_point(self, phase, loop):
        self.last_loop = loop


def _paper(holder, increment, max_relaxation_steps=1000):
    from grainfrac_yade.protocols.creep_loops import paper_clock_loop
    clock = PaperClock(1e-5, 1e4, 1e-2)
    sc, cp = loop_params({"creep_time_limit": 1e9, "engine_period": 1, "unbalanced_engine_period": 1,
                          "unbalanced_force_reference": "relative"},
                         {"record_period": 10**9, "max_relaxation_steps": max_relaxation_steps,
                          "collapse_strain_increment": increment, "collapse_stress_ratio": 0.25})
    paper_clock_loop(holder, StandInBonds([1e6], [5e6], JT, JC), clock, sc, cp)
    return holder, clock


def test_paper_clock_ends_at_collapse_long_before_the_no_equilibrium_backstop():
    holder, clock = _paper(CollapsingHolder(lambda k: k > 10), 1.05e-3)
    # saturated from pass 11 on, counted from the strain of pass 10 (1e-3): collapse when the gain
    # passes 1.05e-3, at pass 21 (2.1e-3), not after 1000 unbalanced DEM steps
    assert holder.failed and holder.failure_reason.startswith("collapse: servo at its closing speed limit for 11 "
                                                              "DEM steps while the axial strain grew by 0.0011")
    assert clock.n_steps == 21
    assert holder.last_loop["collapse"]["checks"] == 10   # the watch's state goes with the checkpoint


def test_paper_clock_interrupted_saturation_falls_back_on_the_backstop():
    holder, clock = _paper(CollapsingHolder(lambda k: k % 5 != 0), 1e-3, max_relaxation_steps=100)
    assert holder.failed and holder.failure_reason.startswith("no equilibrium at the held load")
    assert clock.n_steps == 101


def test_paper_clock_with_the_criterion_off_keeps_its_counters_as_before():
    holder, clock = _paper(CollapsingHolder(lambda k: True), 0.0, max_relaxation_steps=100)
    assert holder.failure_reason.startswith("no equilibrium at the held load") and clock.n_steps == 101
    assert "collapse" not in holder.last_loop


def test_a_check_collapses_only_clipped_on_every_step_and_carrying_a_fraction_of_the_load():
    servo = SimpleNamespace(closing_clipped_steps=50, stress=10e6, target=100e6)
    assert collapsing(servo, 50, 0.25)
    assert not collapsing(SimpleNamespace(closing_clipped_steps=49, stress=10e6, target=100e6), 50, 0.25)
    # an arrested cascade: the servo at its limit, the specimen still carrying half the load
    assert not collapsing(SimpleNamespace(closing_clipped_steps=500, stress=49e6, target=100e6), 50, 0.25)
    assert not collapsing(SimpleNamespace(closing_clipped_steps=500, stress=25e6, target=100e6), 50, 0.25)


def test_paper_clock_ignores_saturation_while_the_specimen_carries_the_load():
    holder = CollapsingHolder(lambda k: k > 10)
    holder.servo.stress = 0.6   # of the target 1.0: arrested, not collapsed
    holder, clock = _paper(holder, 1.05e-3, max_relaxation_steps=100)
    assert holder.failure_reason.startswith("no equilibrium at the held load") and clock.n_steps == 101


# ------------------------------------------------------------------ the parameter
def test_the_increment_is_a_nonnegative_strain():
    assert load_parameters(overrides=["creep.collapse_strain_increment=0"]).creep.collapse_strain_increment == 0
    with pytest.raises(ParameterError, match="collapse_strain_increment"):
        load_parameters(overrides=["creep.collapse_strain_increment=-1e-3"])
    for bad in ("0", "1.5"):
        with pytest.raises(ParameterError, match="collapse_stress_ratio"):
            load_parameters(overrides=[f"creep.collapse_stress_ratio={bad}"])


# ------------------------------------------------------------------ a real collapse
@needs_yade
@pytest.mark.yade
def test_a_tiny_specimen_ends_by_collapse_early_with_the_lifetime_of_the_criterion_off():
    """3 x 6 mm, seed 1, 0.8 x 300 MPa, event clock: the final relaxation is a collapse (the servo closes
    at its limit from its start); the criterion (default increment) stops it after a fraction of
    ``max_relaxation_steps``; with the criterion off the same run waits for the backstop.  Everything
    before the final relaxation is the same, so the lifetime is the same to the last bit."""
    from grainfrac_yade.geometry.specimen import build_specimen
    from grainfrac_yade.protocols.creep import run_creep
    base = ["specimen.width=3e-3", "specimen.height=6e-3", "stress_corrosion.creep_time_limit=1e13",
            "numerics.checkpoint_interval=0"]
    runs = {}
    for name, extra in (("on", []), ("off", ["creep.collapse_strain_increment=0"])):
        p = load_parameters(overrides=base + extra)
        runs[name] = run_creep(build_specimen(p, 1), p, 0.8 * 300e6)
    on, off = runs["on"], runs["off"]
    cp = load_parameters().creep
    assert cp.collapse_strain_increment > 0
    assert on.failed and on.failure_reason.startswith("collapse: servo at its closing speed limit")
    assert off.failed and off.failure_reason == "no equilibrium at the held load (strain runs away)"
    assert off.last_relaxation_steps == cp.max_relaxation_steps
    assert on.last_relaxation_steps < 0.6 * cp.max_relaxation_steps
    assert on.rows[-1]["creep_time_s"] == off.rows[-1]["creep_time_s"] > 0
    assert on.n_events == off.n_events
    assert [r["creep_time_s"] for r in on.rows] == [r["creep_time_s"] for r in off.rows]
    assert on.rows[-1]["step"] < off.rows[-1]["step"]
