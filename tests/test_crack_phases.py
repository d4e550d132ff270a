"""Cracks by phase of a creep life (analysis.crack_phases): counts and shares on hand-made crack tables."""
import math

import numpy as np
import pandas as pd
import pytest

from grainfrac_yade.analysis.crack_phases import (AXIAL_WITHIN_DEG, axial, crack_phases, early_creep_cracks)


def cracks(rows):
    return pd.DataFrame(rows, columns=["creep_time_s", "mode", "kind", "face_normal_angle_deg"])


def test_axial_means_face_plane_near_the_load_axis():
    # normal along x (0 or 180 deg) = face along y, the load axis; normal along y = face across the load
    got = axial([0.0, AXIAL_WITHIN_DEG, AXIAL_WITHIN_DEG + 1, 90.0, 180.0 - AXIAL_WITHIN_DEG, 179.9, 360.0])
    assert got.tolist() == [True, True, False, False, True, True, True]
    # random orientations: a third of the faces are axial
    angles = np.linspace(0.0, 180.0, 180_000, endpoint=False)
    assert axial(angles).mean() == pytest.approx(1 / 3, abs=1e-4)


def test_phases_count_each_crack_once_and_shares_are_exact():
    life = 100.0
    table = cracks([
        (-1.0, "tensile", "inter", 0.0),      # ramp
        (0.0, "tensile", "intra", 10.0),      # first relaxation after the ramp: first creep phase
        (50.0, "shear", "inter", 90.0),       # exactly 0.5 t_f: first phase
        (60.0, "tensile", "inter", 170.0),    # 0.5-0.9
        (90.0, "shear", "intra", 45.0),       # exactly 0.9 t_f: 0.5-0.9
        (99.0, "tensile", "inter", 5.0),      # 0.9 t_f to before t_f
        (100.0, "shear", "inter", 60.0),      # final relaxation
        (100.0, "shear", "intra", 120.0),     # final relaxation
    ])
    got = crack_phases(table, life, bond_inter=[True, True, False, False])
    by = got.set_index("phase")
    assert by["cracks"].tolist() == [1, 2, 2, 1, 2, 1, 4]
    assert by["cracks"].iloc[:5].sum() == len(table)
    first = by.loc["0-0.5 t_f"]
    assert (first["tensile_share"], first["axial_share"], first["inter_share"]) == (0.5, 0.5, 0.5)
    mid = by.loc["0.5-0.9 t_f"]
    assert (mid["tensile_share"], mid["axial_share"], mid["inter_share"]) == (0.5, 0.5, 0.5)
    final = by.loc["final relaxation (t = t_f)"]
    assert (final["tensile_share"], final["axial_share"], final["inter_share"]) == (0.0, 0.0, 0.5)
    assert by.loc["bonds intact at the start of creep", "inter_share"] == 0.5
    assert math.isnan(by.loc["bonds intact at the start of creep", "tensile_share"])


def test_empty_phase_gives_nan_shares_and_no_bond_row_without_bonds():
    got = crack_phases(cracks([(-1.0, "tensile", "inter", 0.0), (10.0, "shear", "intra", 90.0)]), 10.0)
    by = got.set_index("phase")
    assert by.loc["0.5-0.9 t_f", "cracks"] == 0 and math.isnan(by.loc["0.5-0.9 t_f", "tensile_share"])
    assert by.loc["final relaxation (t = t_f)", "cracks"] == 1
    assert "bonds intact at the start of creep" not in by.index


def test_early_cracks_are_the_first_in_creep_time_without_the_ramp():
    table = cracks([(-1.0, "tensile", "inter", 0.0)] * 5
                   + [(float(t), "shear", "intra" if t < 3 else "inter", 0.0) for t in range(30, 0, -1)])
    early = early_creep_cracks(table, 0.1)
    assert sorted(early["creep_time_s"]) == [1.0, 2.0, 3.0]
    assert early_creep_cracks(cracks([(-1.0, "tensile", "inter", 0.0)])).empty


@pytest.mark.parametrize("life", [0.0, -1.0, float("nan"), float("inf")])
def test_lifetime_must_be_a_positive_time(life):
    with pytest.raises(ValueError, match="positive creep time"):
        crack_phases(cracks([(1.0, "shear", "intra", 0.0)]), life)
