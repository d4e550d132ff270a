"""Wave crossings and the hold's step budget (grainfrac_yade.wave): closed forms, and the defaults keep the
fixed step counts exactly."""
import math
from types import SimpleNamespace

import pytest

from grainfrac_yade.wave import HoldBudget, bar_wave_speed, budget_fields, crossing_steps, hold_budget, scene_density, steps_for


def test_bar_wave_speed_and_crossing_steps_closed_form():
    """c = sqrt(E / rho); H / (c dt): 70 GPa over 2640 kg/m3 x 1e4 gives c = 51.49 m/s; 63.4 mm at 2.7e-7 s is
    63.4e-3 / (51.49 x 2.7e-7) = 4,560 steps."""
    c = bar_wave_speed(70e9, 2640.0 * 1e4)
    assert c == math.sqrt(70e9 / 2.64e7)
    assert crossing_steps(63.4e-3, 70e9, 2.64e7, 2.7e-7) == pytest.approx(63.4e-3 / (c * 2.7e-7), rel=1e-15)
    assert 4550 < crossing_steps(63.4e-3, 70e9, 2.64e7, 2.7e-7) < 4570


def test_mass_scaling_leaves_the_crossing_steps_alone():
    """The DEM step scales as sqrt(m) and so does the crossing time: x 100 in density, x 10 in dt, same count."""
    assert crossing_steps(0.02, 70e9, 2.64e5, 1e-7) == pytest.approx(crossing_steps(0.02, 70e9, 2.64e7, 1e-6), rel=1e-12)


def test_zero_crossings_keep_the_fixed_steps_exactly():
    creep = SimpleNamespace(servo_response_steps=200, servo_response_crossings=0.0, max_relaxation_steps=30000,
                            max_relaxation_crossings=0.0)
    b = hold_budget(creep, 63.4e-3, 70e9, 2.64e7, 2.7e-7)
    assert (b.servo_response_steps, b.max_relaxation_steps) == (200, 30000)
    assert HoldBudget.fixed(creep) == HoldBudget(None, 200, 30000)


def test_crossings_raise_the_budget_only_where_longer():
    creep = SimpleNamespace(servo_response_steps=200, servo_response_crossings=0.5, max_relaxation_steps=30000,
                            max_relaxation_crossings=20.0)
    n = crossing_steps(63.4e-3, 70e9, 2.64e7, 2.7e-7)
    b = hold_budget(creep, 63.4e-3, 70e9, 2.64e7, 2.7e-7)
    assert b.servo_response_steps == math.ceil(0.5 * n) and b.max_relaxation_steps == math.ceil(20.0 * n)
    assert steps_for(30000, 1.0, n) == 30000   # one crossing is shorter than the fixed budget
    assert HoldBudget.from_dict(b.as_dict()) == b
    assert budget_fields(None) == {k: None for k in b.as_dict()}


def test_scene_density_is_the_area_weighted_grain_density_times_the_mass_scaling(params):
    expected = sum(f * params.grains[m].density for m, f in params.composition.items()) * params.numerics.density_scale
    assert scene_density(params) == expected
    assert scene_density(params) == pytest.approx(2640.0 * params.numerics.density_scale, rel=1e-12)
