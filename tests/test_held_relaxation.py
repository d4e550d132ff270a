"""The kernel's held-load relaxation loop (grainfrac_yade/kernel/held_relaxation.py) on a scripted relaxation: the
order of its checks, its budget, its chunks, its safe points and its take-back back-off; and the servo law."""
from types import SimpleNamespace

import pytest

from grainfrac_yade.kernel.held_relaxation import (BUDGET, COLLAPSE, EQUILIBRIUM, FAILED, LOST_LOAD, CollapseWatch,
                                                   HeldRelaxing, collapse_watch, relax_held)
from grainfrac_yade.kernel.servo import ServoLaw


class Scripted(HeldRelaxing):
    """A relaxation whose checks answer from per-check scripts (check k reads entry k; past the end, the last)."""

    def __init__(self, failure=("",), lost=(False,), balanced=(False,), settle=(True,), strain=(0.0,), servo=None):
        self.scripts = dict(failure=failure, lost=lost, balanced=balanced, settle=settle, strain=strain)
        self.servo = servo
        self.chunks, self.calls, self.check = [], [], -1

    def _next(self, name):
        self.calls.append((self.check, name))
        seq = self.scripts[name]
        return seq[min(self.check, len(seq) - 1)]

    def advance(self, steps):
        self.chunks.append(steps)

    def checked(self, done):
        self.check += 1
        self.calls.append((self.check, "checked"))

    def failure(self):
        return self._next("failure")

    def lost(self):
        return self._next("lost")

    def balanced(self):
        return self._next("balanced")

    def settle(self):
        return self._next("settle")

    def axial_strain(self):
        return self._next("strain")


def test_rest_ends_it_at_the_first_check_that_passes():
    r = Scripted(balanced=(False, False, True))
    end = relax_held(r, 1000, 50)
    assert (end.outcome, end.steps, end.gave_out) == (EQUILIBRIUM, 150, 0) and r.chunks == [50, 50, 50]
    assert [c for c in r.calls if c[0] == 0] == [(0, "checked"), (0, "failure"), (0, "lost"), (0, "balanced")]


def test_the_checks_run_in_order_failure_collapse_lost_rest():
    servo = SimpleNamespace(closing_clipped_steps=10 ** 6, stress=0.0, target=1.0)
    watch = CollapseWatch(1e-3, 0.0)
    r = Scripted(failure=("", "", "strain cap"), lost=(False,), strain=(0.0, 0.0, 1.0), servo=servo)
    end = relax_held(r, 1000, 10, watch=watch, collapse_stress_ratio=0.5)
    assert (end.outcome, end.reason, end.steps) == (FAILED, "strain cap", 30)   # the failure before the collapse
    r = Scripted(strain=(0.0, 1.0), servo=servo, lost=(False, True))
    end = relax_held(r, 1000, 10, watch=CollapseWatch(1e-3, 0.0), collapse_stress_ratio=0.5)
    assert end.outcome == COLLAPSE and end.steps == 20 and end.reason.startswith("collapse: servo at its closing")
    assert (1, "lost") not in r.calls                                            # the collapse before the lost load
    r = Scripted(lost=(False, True), balanced=(True,), settle=(False,))
    end = relax_held(r, 1000, 10)
    assert end.outcome == LOST_LOAD and end.steps == 20


def test_the_budget_runs_whole_chunks_or_ends_at_the_budget_unchecked():
    r = Scripted()
    end = relax_held(r, 125, 50)
    assert (end.outcome, end.steps, r.chunks) == (BUDGET, 150, [50, 50, 50])
    r = Scripted(balanced=(False, False, True))
    end = relax_held(r, 125, 50, clip_to_budget=True)
    assert (end.outcome, end.steps, r.chunks) == (BUDGET, 125, [50, 50, 25])
    assert r.check == 1                                                         # the clipped chunk is not checked
    assert relax_held(Scripted(), 1000, 50, done=1000).steps == 1000             # a resumed relaxation at its budget


def test_rest_waits_for_min_steps_and_a_take_back_that_gives_out_backs_off():
    r = Scripted(balanced=(True,))
    assert relax_held(r, 1000, 10, min_steps=35).steps == 40
    r = Scripted(balanced=(True,), settle=(False,) * 6 + (True,))
    end = relax_held(r, 1000, 10)
    # gave out at the first check (10 steps): the next look 2 checks on (30); gave out there: 4 checks on (70)
    assert (end.outcome, end.steps, end.gave_out) == (EQUILIBRIUM, 70, 2)
    assert [n for n, name in r.calls if name == "balanced"] == [0, 2, 6]


def test_safe_points_come_between_chunks_with_the_counters_to_resume_from():
    points = []
    watch = CollapseWatch(1e-3, 0.25)
    r = Scripted(balanced=(False, False, True), servo=SimpleNamespace(closing_clipped_steps=0, stress=1.0, target=1.0))
    relax_held(r, 1000, 10, watch=watch, done=20, safe_point=points.append)
    assert [p["done"] for p in points] == [20, 30, 40]
    assert points[0]["collapse"] == {"previous": 0.25, "start": None, "checks": 0}


def test_collapse_watch_is_off_at_a_zero_increment_and_comes_back_from_its_state():
    off = SimpleNamespace(collapse_strain_increment=0.0)
    on = SimpleNamespace(collapse_strain_increment=1e-3)
    assert collapse_watch(off, 0.1) is None
    watch = collapse_watch(on, 0.1, {"previous": 0.2, "start": 0.15, "checks": 3})
    assert (watch.previous, watch.start, watch.checks) == (0.2, 0.15, 3)
    assert collapse_watch(on, 0.1).previous == 0.1


@pytest.mark.parametrize("stress, speed, clipped", [(90.0, 0.5, 1), (99.99, 0.01 * 0.01 / 1e-3, 0), (120.0, -0.5, -1)])
def test_servo_law_commands_the_clipped_speed_and_counts_saturated_steps(stress, speed, clipped):
    law = ServoLaw(100.0, 0.01, 0.5)
    assert law.command(stress, 1e-3) == pytest.approx(speed) and law.clipped == clipped
    law.command(stress, 1e-3)
    assert law.closing_clipped_steps == (2 if clipped == 1 else 0) and law.stress == stress
