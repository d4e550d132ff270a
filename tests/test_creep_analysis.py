"""Creep stage detection and damage index on synthetic histories (no YADE)."""
import numpy as np
import pytest

from grainfrac_yade.analysis.creep_analysis import (STAGE_MIN_EVENTS, STAGE_WINDOW, creep_stages, damage_index, local_rates,
                                            resolve_creep_stages)


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


def _stored_histories():
    import sys
    from pathlib import Path

    import pandas as pd
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from platform_fingerprint import stored_sets
    for folder in stored_sets():
        for f in sorted(folder.glob("reference_creep_*_history.csv")):
            yield f"{folder.name}/{f.name}", pd.read_csv(f, float_precision="round_trip")


def _stages_in_life_fractions(t, eps):
    s = resolve_creep_stages(t[:-1], eps[:-1], t[-1])
    return s.unresolved, tuple(None if v is None else v / t[-1] for v in s[:2])


def test_stages_do_not_move_under_a_last_bit_perturbation_of_the_stored_histories():
    """Every stored reference history (every machine's set), and a step-like synthetic curve, perturbed
    by 1e-12 relative in time and strain (a rounding difference, far above one ulp): the stages,
    in fractions of the life, stay where they were, or stay unresolved for the same reason."""
    t_f = 1.6e4
    t = np.linspace(0, t_f, 40)
    eps = np.repeat(_three_stage_strain(t, t_f, 0.2 * t_f, 0.8 * t_f), 2)[:-1]
    cases = [("synthetic", np.repeat(t, 2)[1:], eps)]
    cases += [(name, h["creep_time_s"].to_numpy(), h["axial_strain"].to_numpy()) for name, h in _stored_histories()]
    assert len(cases) >= 4
    rng = np.random.default_rng(7)
    for name, t, eps in cases:
        reason, fractions = _stages_in_life_fractions(t, eps)
        for _ in range(50):
            tp = t * (1 + 1e-12 * rng.uniform(-1, 1, len(t)))
            ep = eps * (1 + 1e-12 * rng.uniform(-1, 1, len(eps)))
            reason_p, fractions_p = _stages_in_life_fractions(tp, ep)
            assert reason_p == reason, name
            assert fractions_p == pytest.approx(fractions, abs=1e-9), name


def test_a_history_with_too_few_events_has_no_stages():
    t = np.arange(9.0)   # 8 creep times after the start, before the end at 12
    stages = resolve_creep_stages(t, np.linspace(1e-3, 2e-3, len(t)), 12.0)
    assert stages[:2] == (None, None)
    assert stages.unresolved == f"8 creep times before the collapse, at least {STAGE_MIN_EVENTS} needed for three stages"
    assert creep_stages(t, np.linspace(1e-3, 2e-3, len(t)), 12.0) == (None, None)


def test_a_curve_without_creep_strain_has_no_stages():
    t = np.linspace(0, 100.0, 30)
    assert resolve_creep_stages(t, np.full_like(t, 1e-3)).unresolved == "no creep strain"


def test_the_rate_of_a_window_without_events_is_exactly_zero():
    t = np.array([0.0, 10.0, 90.0, 100.0])
    eps = np.array([1e-3, 1.3e-3, 1.3e-3, 2e-3])      # flat from 0.1 to 0.9 of the life
    tau, rate = local_rates(t, eps)
    flat = (tau >= 0.1 + STAGE_WINDOW / 2) & (tau <= 0.9 - STAGE_WINDOW / 2)
    assert np.all(rate[flat] == 0.0)


def test_a_linear_curve_has_its_slope_as_local_rate():
    t = np.linspace(0, 50.0, 11)
    tau, rate = local_rates(t, 1e-3 + 2e-6 * t)
    assert rate == pytest.approx(np.full_like(tau, 2e-6), rel=1e-9)
