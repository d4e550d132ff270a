"""The creep phase's speed knobs in YADE: ``creep.relaxation_damping`` (damping of the relaxations only)
and the paper clock's ``stress_corrosion.unbalanced_engine_period``. Each leaves the ramp, and so the load,
exactly as it was; what they do to lifetimes and cost is measured by the accuracy-cost study
(params/accuracy_cost.toml), not asserted here."""
import math

import pytest

from conftest import needs_yade
from grainfrac_yade.errors import ParameterError
from grainfrac_yade.params import load_parameters

TINY = ["specimen.width=3e-3", "specimen.height=6e-3", "stress_corrosion.creep_time_limit=1e13",
        "numerics.checkpoint_interval=0"]
LOAD = 0.8 * 300e6   # Pa, as test_collapse's tiny run


@pytest.mark.parametrize("value", [-0.1, 1.0, float("nan")])
def test_relaxation_damping_outside_0_1_is_one_line(value):
    with pytest.raises(ParameterError, match="creep.relaxation_damping"):
        load_parameters(overrides=[("creep.relaxation_damping", value)])


def test_unbalanced_engine_period_must_be_a_positive_whole_number():
    with pytest.raises(ParameterError, match="unbalanced_engine_period"):
        load_parameters(overrides=[("stress_corrosion.unbalanced_engine_period", 0)])


def _run(extra):
    from grainfrac_yade.geometry.specimen import build_specimen
    from grainfrac_yade.protocols.creep import run_creep
    p = load_parameters(overrides=TINY + extra)
    return run_creep(build_specimen(p, 1), p, LOAD)


@needs_yade
@pytest.mark.yade
def test_relaxation_damping_acts_after_the_ramp_only():
    base, damped = _run([]), _run(["creep.relaxation_damping=0.6"])
    assert base.rows[0] == {**damped.rows[0], "wall_s": base.rows[0]["wall_s"]}   # the ramp, bit for bit
    assert base.scene.newton.damping == pytest.approx(load_parameters().numerics.damping)
    assert damped.scene.newton.damping == pytest.approx(0.6)
    assert damped.failed and math.isfinite(damped.rows[-1]["creep_time_s"])


@needs_yade
@pytest.mark.yade
def test_the_paper_clock_with_a_lazy_unbalanced_period_runs_to_failure_from_the_same_ramp():
    paper = ["stress_corrosion.clock='paper'"]
    every, lazy = _run(paper), _run(paper + ["stress_corrosion.unbalanced_engine_period=20"])
    assert every.rows[0] == {**lazy.rows[0], "wall_s": every.rows[0]["wall_s"]}
    assert every.failed and lazy.failed and not lazy.numerical_failure
    assert lazy.rows[-1]["creep_time_s"] > 0
