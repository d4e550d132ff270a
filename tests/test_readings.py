"""The readings of the driving stress (grainfrac_yade/law/readings.py): the face's F / L against hand sums, the
closed-form lifetime under a face's stress, the parameters' refusals, and the wiring on the static engine."""
import math

import numpy as np
import pytest

from grainfrac_yade.errors import ParameterError
from grainfrac_yade.law import Stresses
from grainfrac_yade.law.hillig_charles import HilligCharles, channel_times
from grainfrac_yade.law.readings import READING_NAMES, FaceReading, NodeReading, build_reading, face_stresses
from grainfrac_yade.params import load_parameters

BETA1, BETA2 = 1e-3, 1e-7


def test_face_stresses_are_the_face_sums_over_the_face_area():
    # face 0: bonds 0, 2 (areas 1, 3 mm^2); face 1: bond 1 alone; face 2: bonds 3, 4
    face = np.array([0, 1, 0, 2, 2])
    area = np.array([1e-6, 2e-6, 3e-6, 0.5e-6, 0.5e-6])
    fn = np.array([4.0, -6.0, -8.0, 1.0, 3.0])
    fs = np.array([1.0, 2.0, 3.0, 0.0, 5.0])
    sigma, tau = face_stresses(face, area, fn, fs)
    assert sigma == pytest.approx([-1e6, -3e6, -1e6, 4e6, 4e6], rel=1e-15)   # (4 - 8) / 4 mm^2, -6 / 2, (1 + 3) / 1
    assert tau == pytest.approx([1e6, 1e6, 1e6, 5e6, 5e6], rel=1e-15)


def test_a_face_of_one_bond_reads_its_own_stress_to_the_bit():
    area = np.array([1e-6, 3e-6])
    fn, fs = np.array([2.5, -7.0]), np.array([0.3, 1.1])
    sigma, tau = face_stresses([0, 1], area, fn, fs)
    assert np.array_equal(sigma, fn / area) and np.array_equal(tau, fs / area)


class _Scene:
    def __init__(self, fn, fs):
        self.fn, self.fs = np.asarray(fn, float), np.asarray(fs, float)

    def bond_forces(self, indices=None):
        return (self.fn, self.fs) if indices is None else (self.fn[indices], self.fs[indices])


class _Layout:
    bond_face = np.array([0, 0, 1])
    bond_area = np.array([1e-6, 1e-6, 2e-6])


def test_the_readings_give_the_own_or_the_face_stresses_of_the_bonds_asked():
    scene = _Scene([10.0, -2.0, 4.0], [1.0, 3.0, 2.0])
    own_n, own_s = np.array([-2e6, 2e6]), np.array([3e6, 1e6])
    node = build_reading("node", _Layout())
    assert isinstance(node, NodeReading)
    n, s = node.driving(np.array([1, 2]), own_n, own_s, scene)
    assert n is own_n and s is own_s
    face = build_reading("face", _Layout())
    assert isinstance(face, FaceReading)
    n, s = face.driving(np.array([1, 2]), own_n, own_s, scene)
    assert n == pytest.approx([4e6, 2e6], rel=1e-15) and s == pytest.approx([2e6, 1e6], rel=1e-15)
    with pytest.raises(ValueError, match="choose one of node, face"):
        build_reading("edge", _Layout())
    assert READING_NAMES == ("node", "face")


def test_stresses_drive_with_their_own_unless_told():
    st = Stresses.of([0, 1], [1e6, 2e6], [3e6, 4e6])
    assert st.rate_normal is st.normal and st.rate_shear is st.shear
    face = Stresses.of([0, 1], [1e6, 2e6], [3e6, 4e6], [5e6, 6e6], [7e6, 8e6]).take([1])
    assert face.normal.tolist() == [2e6] and face.rate_normal.tolist() == [6e6] and face.rate_shear.tolist() == [8e6]


def test_the_lifetime_under_a_face_stress_is_the_closed_form():
    """Paper Eq. 7 at the face's rate, Eq. 4-5 at the bond's own stress: t_T = (J^T - sigma) / (beta1
    exp(beta2 sigma_face)), t_S = (J^C - (tau - s_n tan phi)) / (beta1 exp(beta2 tau_face))."""
    jt, jc, tphi = 10e6, 30e6, math.tan(math.radians(40.0))
    sigma, tau = np.array([4e6, -20e6]), np.array([0.0, 35e6])
    sigma_f, tau_f = np.array([2e6, -15e6]), np.array([0.0, 25e6])
    t_t, t_s = channel_times(jt, jc, sigma, tau, tphi, BETA1, BETA2, sigma_f, tau_f)
    # tolerance 4 ulps: exp and one division (math vs numpy may round the exponential differently)
    assert t_t[0] == pytest.approx((jt - 4e6) / (BETA1 * math.exp(BETA2 * 2e6)), rel=1e-15, abs=0)
    assert t_s[1] == pytest.approx((jc - (35e6 - 20e6 * tphi)) / (BETA1 * math.exp(BETA2 * 25e6)), rel=1e-15, abs=0)
    assert math.isinf(t_t[1])   # compressed in its own stress: never in tension, whatever the face reads
    own_t, own_s = channel_times(jt, jc, sigma, tau, tphi, BETA1, BETA2)
    assert own_t[0] / t_t[0] == pytest.approx(math.exp(BETA2 * (2e6 - 4e6)), rel=1e-14)
    assert own_s[1] / t_s[1] == pytest.approx(math.exp(BETA2 * (25e6 - 35e6)), rel=1e-14)


def test_the_law_steps_at_the_face_rate_and_fails_on_the_own_stress():
    law = HilligCharles(BETA1, BETA2)
    jt0, jc0 = np.array([10e6]), np.array([30e6])
    state = law.initial_state(jt0, jc0, np.array([0.8]))
    st = Stresses.of([0], [4e6], [0.0], [2e6], [0.0])
    r_t, _ = law.rate(state, st)
    assert r_t[0] == pytest.approx(BETA1 * math.exp(BETA2 * 2e6), rel=1e-15)
    dt, failing, modes = law.interval(state, st, math.inf, 0.1)
    new = law.step(state, st, dt, failing, modes)
    assert failing.tolist() == [0] and new["tensile_strength"][0] == 4e6   # on its own failure point
    assert law.failed_now(state.replaced([0], new), st)[0][0]


def test_with_their_own_as_driving_stresses_the_law_is_unchanged_to_the_bit():
    rng = np.random.default_rng(3)
    law = HilligCharles(BETA1, BETA2)
    n = 50
    state = law.initial_state(rng.uniform(5e6, 15e6, n), rng.uniform(20e6, 40e6, n), np.full(n, 0.8))
    sigma, tau = rng.uniform(-30e6, 12e6, n), rng.uniform(0, 40e6, n)
    implicit, explicit = Stresses.of(np.arange(n), sigma, tau), Stresses.of(np.arange(n), sigma, tau, sigma.copy(),
                                                                            tau.copy())
    for a, b in zip(law.time_to_failure(state, implicit), law.time_to_failure(state, explicit)):
        assert np.array_equal(a, b)
    da, db = law.degrade(state, implicit, 1e5), law.degrade(state, explicit, 1e5)
    assert all(np.array_equal(da[k], db[k]) for k in da)


@pytest.mark.parametrize("law", ["normalised", "area"])
def test_a_face_reading_with_a_law_that_ties_the_stresses_is_refused_in_one_line(law):
    with pytest.raises(ParameterError) as e:
        load_parameters(overrides=["stress_corrosion.reading=face", f"stress_corrosion.law={law}"])
    text = str(e.value)
    assert "\n" not in text and "stress_corrosion.reading" in text and "hillig_charles" in text


def test_an_unknown_reading_names_the_choices():
    with pytest.raises(ParameterError, match=r"\['node', 'face'\]"):
        load_parameters(overrides=["stress_corrosion.reading=edge"])


def _creep_4x8(files, seed, load, reading):
    from grainfrac_yade.geometry.specimen import build_specimen
    from grainfrac_yade.protocols.creep import run_creep
    p = load_parameters(extra_files=files, overrides=["numerics.engine=static", "specimen.width=4e-3",
                                                      "specimen.height=8e-3", f"stress_corrosion.reading={reading}"])
    return run_creep(build_specimen(p, seed), p, load)


def test_rigid_cells_have_a_bond_per_face_so_the_face_reading_is_the_node_reading_to_the_bit():
    """One run against another on the same machine (same arithmetic): a face's sum of one bond over its own area is
    that bond's stress exactly, so every event matches."""
    node, face = (_creep_4x8([], 1, 180e6, r) for r in ("node", "face"))
    assert node.n_events == face.n_events > 0
    assert node.clock.creep_time == face.clock.creep_time
    assert np.array_equal(node.break_time, face.break_time, equal_nan=True)


def test_fem_cells_corrode_by_the_face_in_the_face_reading():
    """Two bonds per face (fem_coarse): the face reading moves the events (the earliest break here is later: the
    first bond to fail in the node reading carries more than its face's mean), and the two bonds of a face
    corrode at one rate."""
    node, face = (_creep_4x8(["params/presets/fem_coarse.toml"], 4, 200e6, r) for r in ("node", "face"))
    first = lambda run: np.min(run.break_time[run.break_time > 0])  # noqa: E731
    assert first(face) > first(node)
    assert not np.array_equal(node.break_time, face.break_time, equal_nan=True)
    st = face.corr.stresses(np.arange(face.scene.n_bonds))   # at the end: both bonds of a face read one stress
    pairs = np.argsort(face.scene.layout.bond_face, kind="stable").reshape(-1, 2)
    assert np.array_equal(st.rate_normal[pairs[:, 0]], st.rate_normal[pairs[:, 1]])
    assert not np.array_equal(st.normal[pairs[:, 0]], st.normal[pairs[:, 1]])
