"""Face failure on the static engine (``numerics.static_failure = "face"``): paper Eq. 4-5 on each face's resultant,
the face breaking as a whole; closed forms on tiny networks, the same results to the bit as the bond criterion with
one bond per face, the one-line refusals (no YADE)."""
import json

import numpy as np
import pytest

from grainfrac_yade.engines.registry import engine_for
from grainfrac_yade.engines.static import contacts as cl
from grainfrac_yade.engines.static.cascade import Path
from grainfrac_yade.engines.static.face_failure import BondFailure, FaceFailure
from grainfrac_yade.engines.static.network import build_static_network
from grainfrac_yade.engines.static.solver import Equilibrium
from grainfrac_yade.errors import GrainfracError, ParameterError
from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.grains import layout_for
from grainfrac_yade.params import load_parameters
from static_tiny import JC, JT, KS, PHI, network

#: Two bonds on one vertical face (normal +x) between a node on the bottom platen and one on the top platen: closing
#: the platens shears both by the closure; their shear stiffnesses differ.
STIFFER = 3.0


def _sheared_face(face):
    return network([[0.0, 0.0], [1e-3, 0.0]], [[0, 1], [0, 1]], [[1.0, 0.0], [1.0, 0.0]], top=[1], bottom=[0],
                   ks=[KS, STIFFER * KS], face=face)


def _path(net, criterion):
    eq = Equilibrium(net)
    path = Path(eq)
    path.failure = criterion(net)
    return path, path.run_closure(eq.initial(0.0), 1e-6, stop=lambda st, rec: len(rec) >= 1)


def test_a_face_fails_on_its_resultant_not_on_its_more_loaded_bond():
    """Two bonds of area A on one face sheared by the closure d (no normal force): the bond criterion breaks the
    stiffer one alone at d = J^C A / (3 k_s); the face criterion breaks both at once at d = J^C 2A / (k_s + 3 k_s),
    where the resultant tau = (k_s + 3 k_s) d / 2A meets J^C (the bracketing tolerance: 1e-9 relative)."""
    area = 1e-6
    bond_path, bond_state = _path(_sheared_face([0, 1]), BondFailure)
    (rec,) = bond_path.records
    assert rec.closure == pytest.approx(JC * area / (STIFFER * KS), rel=1e-9)
    assert len(rec.bonds) == 1 and rec.modes == [cl.SHEAR] and bond_state.broken.sum() == 1
    face_path, face_state = _path(_sheared_face([0, 0]), FaceFailure)
    (rec,) = face_path.records
    assert rec.closure == pytest.approx(JC * 2 * area / ((1 + STIFFER) * KS), rel=1e-9)
    assert sorted(rec.bonds) == [0, 1] and rec.modes == [cl.SHEAR, cl.SHEAR] and face_state.broken.all()


def test_face_crossing_increment_is_the_resultants():
    """Three bonds, two on face 0 with opposite shear forces (a turning face: their signed sum cancels) and one alone
    on face 1: the face's increment to its strength along F = F0 + x F1 is the closed form of the resultants
    (tension: (J^T 2A - sum F_n0) / sum F_n1; shear: (J^C 2A - s sum F_s0 - sum F_n0 tan(phi)) / (s sum F_s1 +
    sum F_n1 tan(phi))), the same on both bonds of the face; the lone bond's is its own to the bit."""
    area = 1e-6
    net = network([[0.0, 0.0], [0.0, 1e-3], [1e-3, 0.0]], [[0, 1], [0, 1], [0, 2]],
                  [[0.0, 1.0], [0.0, 1.0], [1.0, 0.0]], top=[1], bottom=[0], face=[0, 0, 1])
    face = FaceFailure(net)
    fn0, fs0 = np.array([1.0, 2.0, -3.0]), np.array([5.0, -5.0, 4.0])
    fn1, fs1 = np.array([100.0, 300.0, 50.0]), np.array([200.0, -150.0, 80.0])
    broken = np.zeros(3, bool)
    jt, jc = net.tensile_strength, net.cohesion
    x = face.crossing_increment(fn0, fs0, fn1, fs1, jt, jc, broken)
    t = np.tan(PHI)
    fn0f, fs0f, fn1f, fs1f = 3.0, 0.0, 400.0, 50.0
    cand = [(JT * 2 * area - fn0f) / fn1f] + [(JC * 2 * area - s * fs0f - fn0f * t) / (s * fs1f + fn1f * t)
                                             for s in (1.0, -1.0) if s * fs1f + fn1f * t > 0]
    assert x[0] == x[1] == pytest.approx(min(cand), rel=1e-14)      # the sums in another order: round-off
    own = cl.crossing_increment(fn0[2:], fs0[2:], fn1[2:], fs1[2:], net.area[2:], jt[2:], jc[2:], net.tan_friction[2:])
    assert x[2] == own[0]
    # the face's stresses: resultant over its area, shear by the signed sum (here 0: the bonds' shears cancel)
    sigma, tau = face.stresses(fn0, fs0, broken)
    assert sigma[0] == sigma[1] == pytest.approx(3.0 / (2 * area), rel=1e-15) and tau[0] == tau[1] == 0.0
    assert (sigma[2], tau[2]) == (fn0[2] / area, abs(fs0[2]) / area)


def test_a_broken_bond_leaves_its_face_and_the_group_is_the_intact_rest():
    """A face of three bonds, one broken: the resultant sums the two intact ones; a bond that fails takes the
    face's other intact bond with it (canonical order), never the broken one."""
    net = network([[0.0, 0.0], [0.0, 1e-3]], [[0, 1], [0, 1], [0, 1]], [[0.0, 1.0]] * 3, top=[1], bottom=[0],
                  face=[0, 0, 0])
    face = FaceFailure(net)
    broken = np.array([False, True, False])
    fn = np.array([4.0, 100.0, 6.0])
    sigma, _ = face.stresses(fn, np.zeros(3), broken)
    assert sigma[0] == sigma[2] == pytest.approx(10.0 / (2 * net.area[0]), rel=1e-15)
    assert face.group(2, broken).tolist() == [0, 2]
    assert BondFailure(net).group(2, broken).tolist() == [2]


def test_unequal_strengths_on_a_face_read_their_area_weighted_mean():
    """A face whose bonds' strengths differ (a scatter per bond): its strength is their area-weighted mean."""
    net = network([[0.0, 0.0], [0.0, 1e-3]], [[0, 1], [0, 1]], [[0.0, 1.0]] * 2, top=[1], bottom=[0],
                  face=[0, 0], area=[1e-6, 3e-6], jt=[JT, 2 * JT])
    face = FaceFailure(net)
    fn = np.array([1.0, 1.0]) * 1.75 * JT * 4e-6 / 2       # sigma_face = 1.75 J^T, the weighted mean
    ratio, mode = face.overstress(fn, np.zeros(2), net.tensile_strength, net.cohesion, np.zeros(2, bool))
    assert ratio[0] == ratio[1] == pytest.approx(1.0, rel=1e-15) and mode.tolist() == [cl.TENSION] * 2


@pytest.mark.parametrize("model", ["rigid", "fem"])
def test_the_bonds_of_a_face_share_its_tangent(model):
    """What makes the signed shear forces of one face's bonds add: every bond of a face has the face's normal (to
    round-off: rigid cells' face-lined layouts take it from their spheres' centres) and joins the face's first cell to
    its second; checked on the layouts with several bonds per face (fem K = 4; rigid cells lined with 8 spheres)."""
    from grainfrac_yade.elastic import build_network
    extra = ["params/presets/fem_coarse.toml"] if model == "fem" else []
    over = ["resolution.nodes_per_face=4"] if model == "fem" else ["resolution.spheres_per_cell=8"]
    p = load_parameters(extra_files=extra, overrides=["specimen.width=3e-3", "specimen.height=6e-3", *over])
    s = build_specimen(p, 1)
    lay = layout_for(s, p)
    net = build_network(s, p, lay.model, lay)
    t = s.tessellation
    assert np.bincount(net.spring_face).max() > 1
    assert np.allclose(net.spring_normal, t.face_normal[net.spring_face][:, :2], rtol=0, atol=1e-12)
    cells = net.node_cell[net.spring_nodes]
    assert np.array_equal(cells, t.face_cells[net.spring_face])


# ---------------------------------------------------------------------- one bond per face: the same to the bit
RIGID = ["numerics.engine=static", "specimen.width=4e-3", "specimen.height=8e-3", "numerics.checkpoint_interval=0"]
MACHINE = ("wall_s", "cpu_s", "code_version", "static_relaxation_cpu_s")


def _cli(capsys, *argv):
    from grainfrac_yade.cli import main
    rc = main(list(argv))
    return rc, capsys.readouterr()


def _without_criterion(tree):
    """``tree`` (a summary) without the machine's keys and without the criterion's name where it records the
    parameters (and the note that it differs from the calibration's)."""
    if isinstance(tree, dict):
        return {k: _without_criterion(v) for k, v in tree.items() if k not in MACHINE and k != "static_failure"}
    if isinstance(tree, list):      # the notes on settings that differ from the calibration's
        return [_without_criterion(v) for v in tree if not (isinstance(v, str) and "static_failure" in v)]
    return tree


def _same_run(a, b):
    sa, sb = (_without_criterion(json.loads((f / "summary.json").read_text())) for f in (a, b))
    assert json.dumps(sa, sort_keys=True, default=str) == json.dumps(sb, sort_keys=True, default=str)
    assert (a / "cracks.csv").read_bytes() == (b / "cracks.csv").read_bytes()
    assert _history_text(a) == _history_text(b)


def _history_text(folder):
    """history.csv's text without its machine's column (wall_s, a creep history's)."""
    rows = [line.split(",") for line in (folder / "history.csv").read_text().splitlines()]
    keep = [i for i, name in enumerate(rows[0]) if name not in MACHINE]
    return [[r[i] for i in keep] for r in rows]


def test_rigid_cells_one_bond_per_face_ucs_is_the_bond_criterion_to_the_bit(tmp_path):
    """Rigid 4 x 8 mm UCS, seed 1 (one bond per face): face failure gives the bond criterion's summary, cracks and
    history byte for byte."""
    from grainfrac_yade.commands.ucs import run_ucs_to_folder
    p = load_parameters(overrides=RIGID)
    lay = layout_for(build_specimen(p, 1), p)
    assert np.bincount(lay.bond_face).max() == 1
    summaries = {}
    for crit in ("bond", "face"):
        q = load_parameters(overrides=[*RIGID, f"numerics.static_failure={crit}"])
        summaries[crit] = run_ucs_to_folder(q, 1, tmp_path / crit)
    assert summaries["bond"]["peak_reached"] and summaries["bond"]["broken_total"] > 10
    _same_run(tmp_path / "bond", tmp_path / "face")


def test_rigid_cells_one_bond_per_face_creep_is_the_bond_criterion_to_the_bit(capsys, tmp_path):
    """Rigid 4 x 8 mm creep at 160 MPa, seed 1, the face reading: face failure gives the bond criterion's run byte
    for byte (summary, cracks, history)."""
    row = ["--engine", "static", "--width", "4e-3", "--height", "8e-3", "--stress", "160", "--seed", "1", "--set",
           "stress_corrosion.reading=face", "--set", "numerics.checkpoint_interval=0"]
    for crit in ("bond", "face"):
        rc, _ = _cli(capsys, "creep", *row, "--set", f"numerics.static_failure={crit}", "--out", str(tmp_path / crit))
        assert rc == 0
    assert json.loads((tmp_path / "bond" / "summary.json").read_text())["n_events"] >= 1
    _same_run(tmp_path / "bond", tmp_path / "face")


def test_fem_face_failure_breaks_whole_faces():
    """fem cells 3 x 6 mm, K = 4: along the UCS path every face is intact or broken as a whole, and a face's bonds
    break in one record."""
    p = load_parameters(extra_files=["params/presets/fem_coarse.toml"],
                        overrides=["specimen.width=3e-3", "specimen.height=6e-3", "resolution.nodes_per_face=4",
                                   "numerics.static_failure=face"])
    s = build_specimen(p, 1)
    net = build_static_network(s, p, layout_for(s, p))
    eq = Equilibrium(net)
    path = Path(eq)
    path.failure = FaceFailure(net)
    state = path.run_closure(eq.initial(0.0), 0.02 * net.height, stop=lambda st, rec: len(rec) >= 6)
    assert len(path.records) >= 6
    per_face = np.bincount(net.bond_face, weights=state.broken)
    size = np.bincount(net.bond_face)
    assert np.all((per_face == 0) | (per_face == size))
    for rec in path.records:
        faces = net.bond_face[rec.bonds]
        assert np.all(np.bincount(faces, minlength=len(size))[np.unique(faces)] == size[np.unique(faces)])


# ---------------------------------------------------------------------- refusals
@pytest.mark.parametrize("engine", ["yade", "hybrid"])
def test_face_failure_refused_on_the_dynamic_engines_in_one_line(capsys, tmp_path, engine):
    rc, out = _cli(capsys, "ucs", "--engine", engine, "--width", "3e-3", "--height", "6e-3", "--set",
                   "numerics.static_failure=face", "--out", str(tmp_path / "x"))
    assert rc == 2 and out.err.count("\n") == 1 and "numerics.static_failure" in out.err and "fix:" in out.err
    assert not (tmp_path / "x").exists()
    p = load_parameters(overrides=[f"numerics.engine={engine}", "numerics.static_failure=face"])
    with pytest.raises(GrainfracError, match="static_failure"):
        engine_for(p).build_scene(None, p)


def test_face_failure_with_sawtooth_refused_in_one_line(capsys, tmp_path):
    with pytest.raises(ParameterError, match="static_softening"):
        load_parameters(overrides=["numerics.static_failure=face", "numerics.static_softening=sawtooth"])
    rc, out = _cli(capsys, "ucs", "--engine", "static", "--width", "3e-3", "--height", "6e-3", "--set",
                   "numerics.static_failure=face", "--set", "numerics.static_softening=sawtooth",
                   "--out", str(tmp_path / "x"))
    assert rc == 2 and out.err.count("\n") == 1 and "fix:" in out.err and not (tmp_path / "x").exists()


def test_face_failure_creep_without_the_face_reading_refused_in_one_line(capsys, tmp_path):
    rc, out = _cli(capsys, "creep", "--engine", "static", "--width", "3e-3", "--height", "6e-3", "--stress", "100",
                   "--set", "numerics.static_failure=face", "--out", str(tmp_path / "x"))
    assert rc == 2 and out.err.count("\n") == 1 and "stress_corrosion.reading" in out.err and "fix:" in out.err
    assert not (tmp_path / "x").exists()
