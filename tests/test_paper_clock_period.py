"""The paper clock's law period while unbalanced (``stress_corrosion.unbalanced_engine_period``): while F_u is
at or above the threshold the creep step sits at dt_min (paper Eq. 8), so k DEM steps advance creep time by
k x dt_min whether the law is applied after each or once for all k; only the cost changes. Tested on the
creep loop's stand-ins (test_reliability): the same creep time per DEM step, k times fewer applications, the
period back to every step once balanced, and the same no-equilibrium failure."""
import itertools

import pytest

from grainfrac_yade.clocks import PaperClock
from grainfrac_yade.protocols.creep_loops import paper_clock_loop
from test_reliability import JC, JT, StandInBonds, StandInHolder, loop_params


class CountingBonds(StandInBonds):
    def __init__(self, *a, **k):
        super().__init__(*a, **k)
        self.applications = []

    def degrade(self, dt, stresses):
        super().degrade(dt, stresses)
        self.applications.append((self.scene.steps, dt))


def _run(forces, unbalanced_period, max_relaxation_steps=10**9, time_limit=1e5):
    holder = StandInHolder(forces)
    bonds = CountingBonds([1e6, 2e6], [5e6, 5e6], JT, JC)
    clock = PaperClock(1e-5, 1e4, 1e-2)
    sc, cp = loop_params({"creep_time_limit": time_limit, "engine_period": 1,
                          "unbalanced_engine_period": unbalanced_period, "unbalanced_force_reference": "relative"},
                         {"record_period": 10**9, "max_relaxation_steps": max_relaxation_steps})
    paper_clock_loop(holder, bonds, clock, sc, cp)
    return holder, bonds, clock


def test_unbalanced_steps_give_the_same_creep_time_with_k_times_fewer_applications():
    # 101 unbalanced DEM steps, then balanced until the creep-time limit; the first application after a
    # balanced one (and the first of all) comes after engine_period steps, the next ones after k
    _, every, clock1 = _run(itertools.chain([2e-2] * 101, itertools.repeat(0.0)), 1)
    _, lazy, clock10 = _run(itertools.chain([2e-2] * 11, itertools.repeat(0.0)), 10)
    assert every.applications[101][0] == 102            # every step: balance seen on the DEM step it comes
    # lazy: balance seen at step 111 (up to k - 1 steps late), where the 10 steps it covers take the F_u
    # of the last one and double the step as steps 102-111 did one by one: the same creep time
    assert [s for s, _ in lazy.applications[:12]] == [1] + list(range(11, 102, 10)) + [111]
    assert sum(dt for _, dt in lazy.applications[:11]) == pytest.approx(101 * 1e-5, rel=1e-12)
    assert sum(dt for _, dt in every.applications[:101]) == pytest.approx(101 * 1e-5, rel=1e-12)
    assert sum(dt for _, dt in lazy.applications[:12]) == pytest.approx(sum(dt for _, dt in every.applications[:111]),
                                                                        rel=1e-12)
    assert clock10.creep_time == pytest.approx(clock1.creep_time, rel=1e-12)
    assert len(every.applications) - len(lazy.applications) == 100 - 10 + 9


def test_the_no_equilibrium_failure_counts_dem_steps_not_applications():
    holder, bonds, clock = _run(itertools.repeat(2e-2), 10, max_relaxation_steps=95)
    assert holder.failed and "for 101 DEM steps" in holder.failure_reason      # 1 + 10 x 10 > 95
    assert bonds.scene.steps == 101 and clock.creep_time == pytest.approx(101 * 1e-5, rel=1e-12)


def test_a_period_of_one_is_the_paper_clock_as_before():
    holder, bonds, _ = _run(itertools.repeat(2e-2), 1, max_relaxation_steps=20)
    assert len(bonds.applications) == 21 and "for 21 DEM steps" in holder.failure_reason
