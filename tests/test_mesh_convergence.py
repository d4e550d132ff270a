"""The convergence arithmetic of the discretisation study against closed forms (pure core, no YADE)."""
import math

import numpy as np
import pytest

from grainfrac_yade.analysis.mesh_convergence import extrapolate, finest_within, log_changes, paired_changes


def test_extrapolation_recovers_a_power_law_at_unequal_refinement_ratios():
    # U = 120 + 900 h^1.5 at h = 1/8, 1/12, 1/16 (ratios 1.5 and 1.33): the exact order and limit come back
    k = np.array([8.0, 12.0, 16.0])
    u = 120.0 + 900.0 * (1.0 / k) ** 1.5
    fit, why = extrapolate(1.0 / k, u)
    assert fit is not None, why
    # bisection to the interval's round-off: the order to 1e-9, the limit to 1e-9 relative
    assert fit.order == pytest.approx(1.5, abs=1e-9)
    assert fit.limit == pytest.approx(120.0, rel=1e-9)
    assert fit.coefficient == pytest.approx(900.0, rel=1e-8)
    np.testing.assert_allclose(fit.value(1.0 / k), u, rtol=1e-12)
    # |U - limit| = 0.05 x 120 at h = (6 / 900)^(1 / 1.5)
    assert fit.spacing_within(0.05) == pytest.approx((6.0 / 900.0) ** (1.0 / 1.5), rel=1e-8)


def test_extrapolation_uses_the_three_finest_and_falls_from_above_too():
    h = np.array([1 / 4, 1 / 8, 1 / 12, 1 / 24])
    u = 200.0 - 50.0 * h ** 2.0
    u[0] = 999.0   # a coarse result outside the asymptotic range is not used
    fit, _ = extrapolate(h, u)
    assert fit.order == pytest.approx(2.0, abs=1e-9) and fit.limit == pytest.approx(200.0, rel=1e-9)


def test_no_extrapolation_where_the_changes_change_sign_or_do_not_shrink():
    h = [1 / 8, 1 / 12, 1 / 16]
    fit, why = extrapolate(h, [200.0, 160.0, 170.0])
    assert fit is None and "not monotone" in why
    # changes growing (-40 then -60): no order in the searched range gives a ratio below 1
    fit, why = extrapolate(h, [200.0, 160.0, 100.0])
    assert fit is None and "asymptotic range" in why
    fit, why = extrapolate(h[:2], [200.0, 160.0])
    assert fit is None and "fewer than three" in why
    with pytest.raises(ValueError):
        extrapolate([1 / 8, 1 / 8, 1 / 16], [1.0, 2.0, 3.0])


def test_paired_changes_and_the_studys_criterion():
    c = paired_changes([200.0, 160.0, 156.0])
    assert math.isnan(c[0])
    np.testing.assert_allclose(c[1:], [-0.2, -0.025], rtol=1e-12)
    assert finest_within([200.0, 160.0, 156.0], 0.05)
    assert not finest_within([200.0, 160.0], 0.05)
    assert not finest_within([200.0], 0.05)


def test_the_studys_k_series_table_groups_by_specimen_and_interior():
    from studies.model_convergence import k_series

    def r(k, u, seed=1, rings=4):
        return {"width_mm": "5.0", "height_mm": "10.0", "seed": str(seed), "cell_rings_1": str(rings),
                "cell_ring_growth_1": "2.0", "bonds_per_face_1": str(k), "ucs_mpa": str(u)}
    law = {k: 120.0 + 900.0 * (1.0 / k) ** 1.5 for k in (8, 12, 16)}
    stiff = [dict(r(8, 300.0), stiffness_scale_1="4.0")]     # another bond stiffness: a series of its own
    stiff.append(dict(r(6, 900.0), peak_reached="False"))     # no peak: shown, not a point of the series
    stiff.append(dict(r(4, 600.0), peak_axial_strain_percent="1.2", poisson_1="3.4"))   # split: shown, not a point
    rows = [r(k, u) for k, u in law.items()] + [r(8, 200.0, seed=2), r(12, 160.0, seed=2)] + stiff
    text = k_series(rows).splitlines()
    assert len(text) == 5 and "| 5 x 10 | 1 | 4 (2) | 4 | 8: 300.0 |" in text[3]
    del text[3]
    seed1, seed2 = text[2], text[3]
    # within 5 % of 120 MPa: 900 h^1.5 <= 6, h <= (1/150)^(2/3), K >= 150^(2/3) = 28.2
    assert "| 5 x 10 | 1 | 4 (2) | 1 | 4: split (600.0 at 1.2 %, nu 3.40), 6: no peak (900.0 at the end), 8: 159.8, 12: 141.7 (-11.3 %)" in seed1 and "limit 120.0 MPa, order 1.50" in seed1 and "from K = 29" in seed1
    assert "12: 160.0 (-20.0 %)" in seed2 and "fewer than three results" in seed2


def test_the_k_series_refuses_a_foreign_csv_in_one_line(tmp_path, capsys):
    from studies.model_convergence import main
    bad = tmp_path / "other.csv"
    bad.write_text("run,ucs_mpa\nx,100\n")
    assert main(["--k-series", str(bad), "--out", str(tmp_path / "k.md")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "other.csv" in err[0] and "fix:" in err[0]
    assert not (tmp_path / "k.md").exists()


def test_log_changes_are_the_logarithms_of_the_ratios():
    out = log_changes([2.5e5, 2.5e6, 1.25e7])
    assert math.isnan(out[0])
    assert out[1:] == pytest.approx([math.log(10.0), math.log(5.0)], rel=1e-15)


def test_the_lifetime_series_lays_rows_out_at_a_ratio_of_the_own_ucs_and_at_one_stress():
    from studies.model_convergence_lifetimes import series

    def r(k, reading, ucs, lifetime, ratio=0.8, events=10, failed="True", law="hillig_charles"):
        return {"width_mm": "10.0", "height_mm": "20.0", "seed": "1", "cell_rings_1": "4", "cell_ring_growth_1": "2.0",
                "bonds_per_face_1": str(k), "law": law, "reading": reading, "driving_stress_ratio_1": str(ratio),
                "given_ucs_mpa": str(ucs), "held_mpa": str(ratio * ucs), "failed": failed,
                "lifetime_s": "" if failed != "True" else str(lifetime), "n_events_1": str(events)}
    own = [{"width_mm": "10.0", "height_mm": "20.0", "seed": "1", "cell_rings_1": "4", "cell_ring_growth_1": "2.0",
            "bonds_per_face_1": str(k), "ucs_mpa": str(u)} for k, u in ((8, 200.0), (12, 160.0), (16, 150.0))]
    rows = [r(8, "node", 200.0, 1e5), r(12, "node", 160.0, 1e6), r(16, "node", 150.0, 1.5e6),
            r(8, "face", 150.0, 4e5), r(12, "face", 150.0, 6e5),          # one stress (120 MPa), not own ratios
            r(16, "face", 150.0, 8e5),                                    # K = 16's own ratio and 120 MPa alike
            r(12, "face", 160.0, 1e9, failed="False"),                    # unfailed: not a point
            r(8, "node", 200.0, 3e3, law="normalised")]                  # another law: a series of its own
    text = series(rows, own)
    ratio_part, stress_part = text.split("At one held stress:")
    node = [line for line in ratio_part.splitlines() if ", hillig_charles, node, 0.8 |" in line]
    assert len(node) == 1 and "[+2.30]" in node[0] and "16: 1.5e+06 s (10 events) [+0.41] | within 0.5 |" in node[0]
    face_ratio = [line for line in ratio_part.splitlines() if ", face, 0.8 |" in line]
    assert len(face_ratio) == 1 and "16: 8e+05 s" in face_ratio[0] and "| one K |" in face_ratio[0]
    face_stress = [line for line in stress_part.splitlines() if ", face, 120.00 |" in line]
    assert len(face_stress) == 1 and "8: 4e+05 s" in face_stress[0] and "[+0.29] | within 0.5 |" in face_stress[0]
    assert not any(", node, " in line for line in stress_part.splitlines())   # node rows: one K per held stress
    assert "| 10 x 20, 1, 4 (2), normalised, node, 0.8 | 8: 3000 s (10 events) | one K |" in ratio_part


def test_the_lifetime_series_refuses_a_foreign_csv_in_one_line(tmp_path, capsys):
    from studies.model_convergence_lifetimes import main
    bad = tmp_path / "other.csv"
    bad.write_text("run,ucs_mpa\nx,100\n")
    assert main(["--series", str(bad), "--ucs", str(bad), "--out", str(tmp_path / "t.md")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "other.csv" in err[0] and "fix:" in err[0]
    assert main(["--series", str(tmp_path / "missing.csv"), "--out", str(tmp_path / "t.md")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "missing.csv: cannot read" in err[0]
    assert not (tmp_path / "t.md").exists()
