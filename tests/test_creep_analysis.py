"""Creep stage detection and damage index on synthetic histories (no YADE)."""
import numpy as np
import pytest

from grainfrac_yade.creep_analysis import creep_stages, damage_index


def _three_stage_strain(t, t_f, t1, t2):
    """Decelerating (primary) up to t1, linear (secondary) to t2, accelerating (tertiary) to t_f."""
    eps = np.where(t < t1, 1e-4 * (1 - (1 - t / t1) ** 3), 1e-4)
    eps = eps + 2e-5 * t / t_f
    tert = np.clip(t - t2, 0, None) / (t_f - t2)
    return eps + 3e-4 * tert**3


@pytest.mark.parametrize("steps", [False, True])
def test_stages_of_a_three_stage_curve(steps):
    t_f, t1, t2 = 1.6e4, 0.2 * 1.6e4, 0.8 * 1.6e4
    t = np.linspace(0, t_f, 400 if not steps else 60)
    eps = _three_stage_strain(t, t_f, t1, t2)
    if steps:  # step-like history as the event clock writes it: strain held between events
        t = np.repeat(t, 2)[1:]
        eps = np.repeat(eps, 2)[:-1]
    primary_end, tertiary_start = creep_stages(t, eps)
    assert 0.05 * t_f < primary_end < 0.45 * t_f
    assert 0.6 * t_f < tertiary_start < 0.95 * t_f
    assert primary_end < tertiary_start


def test_damage_index_runs_from_zero_to_one():
    n = np.array([0, 3, 5, 20, 50])
    d = damage_index(n, n[-1])
    assert d[0] == 0 and d[-1] == 1 and np.all(np.diff(d) >= 0)
