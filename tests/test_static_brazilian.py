"""The Brazilian test on the static engine: the disc's jaws of grainfrac_yade.engines.static.jaws, driven by the unchanged
protocol (pure, tiny discs, seconds each; no YADE)."""
import json
import math

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from grainfrac_yade.elastic import ROLLING_REGULARISATION, build_network, stiffness_matrix
from grainfrac_yade.engines.registry import engine_for
from grainfrac_yade.errors import GrainfracError
from grainfrac_yade.geometry.specimen import build_disc_specimen, build_specimen
from grainfrac_yade.params import load_parameters
from grainfrac_yade.kernel.levers import PRE_EXISTING, Levers

#: A 4 mm disc of 0.5 mm grains (about 64 cells), rows every 2e-5 diametral strain: rigid cells split it in about
#: 200 rows (0.3 CPU s, seed 1).
TINY = ["brazilian.diameter=4e-3", "specimen.grain_size=0.5e-3", "brazilian.record_strain_increment=2e-5",
        "numerics.engine=static"]
#: summary.json keys that name the code or measure the machine, not the run.
NOT_THE_RUN = ("code_version", "wall_s", "cpu_s")
#: The resumed tests: a checkpoint before every row, to 0.3 % diametral strain (150 rows, bonds broken by then).
RESUMED = ("numerics.checkpoint_interval=1e-9", "brazilian.max_strain=3e-3")
#: Round-off between the static core's solve (SuperLU, its own assembly order) and the reference's spsolve:
#: measured 1e-13 relative on the UCS specimens (tests/test_static_elastic.py); 1e-9 still catches any change of
#: the jaws' boundary (a jaw node's lateral dof left free moves the load by more than 1e-3).
ROUND_OFF = 1e-9


def _params(*extra, fem=False):
    return load_parameters(extra_files=["params/presets/fem_coarse.toml"] if fem else [], overrides=[*TINY, *extra])


def _jawed(p, seed=1, lateral=None):
    bz = p.brazilian
    scene = engine_for(p).build_scene(build_disc_specimen(p, seed), p)
    jaws = scene.attach_jaws(math.radians(bz.loading_arc_deg), lateral or bz.platen_lateral)
    jaws.set_closing_speed(bz.strain_rate * jaws.diameter)
    return scene, jaws


def _reference_load(scene, jaws, closure, lateral):
    """The jaw load [N] of the same disc solved directly (elastic.py's network and stiffness, nothing of the static
    core): jaw cells' nodes at -+closure/2 in y, rotations 0, x 0 (fixed jaws) or one x pinned (free)."""
    s, p, lay = scene.specimen, scene.params, scene.layout
    net = build_network(s, p, lay.model, lay)
    k, dofs = stiffness_matrix(net)
    rot = dofs[:, 2][dofs[:, 2] >= 0]
    if len(rot):
        k = k + sp.csr_matrix((np.full(len(rot), ROLLING_REGULARISATION * np.abs(k.diagonal()[rot]).max()),
                               (rot, rot)), shape=k.shape)
    top, bottom = np.isin(net.node_cell, jaws.top), np.isin(net.node_cell, jaws.bottom)
    u, fixed = np.zeros(k.shape[0]), np.zeros(k.shape[0], bool)
    u[dofs[top, 1]], u[dofs[bottom, 1]] = -0.5 * closure, 0.5 * closure
    fixed[dofs[top | bottom, 1]] = True
    r = dofs[top | bottom, 2]
    fixed[r[r >= 0]] = True
    if lateral == "fixed":
        fixed[dofs[top | bottom, 0]] = True
    else:
        fixed[dofs[np.flatnonzero(bottom)[0], 0]] = True
    free = ~fixed
    u[free] = spla.spsolve(k[free][:, free].tocsc(), -k[free][:, fixed] @ u[fixed])
    reaction = k @ u
    return 0.5 * (reaction[dofs[bottom, 1]].sum() - reaction[dofs[top, 1]].sum())


@pytest.mark.parametrize("fem, lateral", [(False, "fixed"), (False, "free"), (True, "fixed"), (True, "free")])
def test_jaw_load_before_any_break_is_the_elastic_solve(fem, lateral):
    """Before the first break the load is linear in the closure (two history rows: twice the load) and equals the
    direct elastic solve of the disc under the same jaw boundary."""
    p = _params(fem=fem)
    scene, jaws = _jawed(p, lateral=lateral)
    scene.run(1)
    p1, c1 = jaws.load(), jaws.diametral_strain() * jaws.diameter
    scene.run(1)
    p2, c2 = jaws.load(), jaws.diametral_strain() * jaws.diameter
    assert not scene.broken.any() and p1 > 0
    assert c1 == pytest.approx(p.brazilian.record_strain_increment * jaws.diameter, rel=1e-12)
    assert p2 / c2 == pytest.approx(p1 / c1, rel=ROUND_OFF)
    assert p1 == pytest.approx(_reference_load(scene, jaws, c1, lateral), rel=ROUND_OFF)


def test_load_is_carried_across_the_horizontal_diameter():
    """Equilibrium of the upper half: the y-forces that the bonds between cells above and below the centre carry
    sum to the jaw load (the load read at the jaws is the one through the disc)."""
    p = _params()
    scene, jaws = _jawed(p)
    above = scene.cell_positions()[:, 1] > scene.specimen.tessellation.centre[1]
    scene.run(3)
    net, st = scene.net, scene.state
    assert above[jaws.top].all() and not above[jaws.bottom].any()
    side = above[net.node_cell]
    a, b = side[net.bond_nodes[:, 0]], side[net.bond_nodes[:, 1]]
    cross = (a != b).astype(float)
    gn, gt = net.force_rows(st.broken)
    f = gn.T @ (cross * st.fn) + gt.T @ (cross * st.fs)       # generalised force of the crossing bonds
    ydofs = net.dofs[side, 1]
    assert abs(f[ydofs].sum()) == pytest.approx(jaws.load(), rel=1e-9)


def _folder(tmp_path, name, *extra, levers=None):
    from grainfrac_yade.protocols.brazilian_output import run_brazilian_to_folder
    out = tmp_path / name
    return run_brazilian_to_folder(_params(*extra), 1, out, levers=levers), out


def test_run_folder_has_finite_values_and_a_peak(tmp_path):
    """protocols/brazilian.py on the static engine: the usual run folder, finite values, a peak past which the load
    fell (the split), sigma_t = 2 P / (pi D t) of the largest load, the engine recorded."""
    s, out = _folder(tmp_path, "a")
    for name in ("summary.json", "history.csv", "cracks.csv", "params.json", "load_strain.png", "crack_map_peak.png",
                 "crack_map_end.png"):
        assert (out / name).exists(), name
    assert s["numerical_failure"] is False and s["peak_reached"] is True and s["end_reason"].startswith("post-peak")
    assert s["engine"] == "static" and s["broken_total"] > 0 and s["jaw_cells"][0] >= 1
    text = (out / "history.csv").read_text() + (out / "summary.json").read_text() + (out / "cracks.csv").read_text()
    assert "nan" not in text.lower() and "infinity" not in text.lower()
    hist = np.genfromtxt(out / "history.csv", delimiter=",", names=True)
    assert np.all(np.isfinite(hist["load_n"])) and len(hist) > 10
    peak = hist["load_n"].max()
    assert s["peak_load_n"] == pytest.approx(peak)
    assert s["tensile_strength_pa"] == pytest.approx(2 * peak / (math.pi * s["diameter_m"] * s["thickness_m"]))
    assert hist["load_n"][-1] < 0.5 * peak
    assert np.allclose(np.diff(hist["diametral_strain"]), 2e-5, rtol=1e-6)


def test_same_row_twice_is_identical(tmp_path):
    """Determinism: the same row twice gives the same summary.json (but code version and machine times), history
    and cracks.csv."""
    s1, o1 = _folder(tmp_path, "one")
    s2, o2 = _folder(tmp_path, "two")
    for s in (s1, s2):
        for k in NOT_THE_RUN:
            s.pop(k, None)
    assert json.dumps(s1, sort_keys=True, default=str) == json.dumps(s2, sort_keys=True, default=str)
    assert (o1 / "cracks.csv").read_bytes() == (o2 / "cracks.csv").read_bytes()
    assert (o1 / "history.csv").read_bytes() == (o2 / "history.csv").read_bytes()


def test_cli_runs_brazilian_on_the_static_engine(capsys, tmp_path):
    """``brazilian --engine static`` is no longer refused: rc 0 and a summary."""
    from grainfrac_yade.cli import main
    out = tmp_path / "cli"
    rc = main(["brazilian", "--engine", "static", "--seed", "1", "--diameter", "4e-3", "--grain-size", "0.5e-3",
               "--set", "brazilian.record_strain_increment=2e-5", "--out", str(out)])
    capsys.readouterr()
    assert rc == 0 and json.loads((out / "summary.json").read_text())["engine"] == "static"


def test_levers_on_the_static_disc():
    """Strength scatter: J^T and J^C x one lognormal factor per bond (mean near 1); slits: broken before loading
    with the pre-existing mode and left out of the counts; blocked rotation: no rotation anywhere."""
    p = _params()
    module = engine_for(p)
    specimen = build_disc_specimen(p, 1)
    plain = module.build_scene(specimen, p)
    jt0, jc0 = plain.bond_strengths()
    scene = module.build_scene(specimen, p)
    done = module.apply_levers(scene, Levers(slit_fraction=0.2, strength_cv=0.3, block_rotation=True), 1)
    assert done["n_slits"] == round(0.2 * scene.n_bonds) == int(scene.broken.sum())
    assert np.all(scene.break_mode[scene.broken] == PRE_EXISTING)
    jt, jc = scene.bond_strengths()
    intact = ~scene.broken
    factor = jt[intact] / jt0[intact]
    assert np.allclose(jc[intact] / jc0[intact], factor, rtol=1e-12) and factor.std() > 0.1
    assert 0.8 < done["strength_factor_mean"] < 1.2
    jaws = scene.attach_jaws(math.radians(p.brazilian.loading_arc_deg), "fixed")
    jaws.set_closing_speed(p.brazilian.strain_rate * jaws.diameter)
    scene.run(5)
    rot = scene.net.dofs[:, 2]
    assert jaws.load() > 0 and np.all(scene.state.u[rot[rot >= 0]] == 0.0)


def test_no_lever_touches_nothing():
    p = _params()
    scene = engine_for(p).build_scene(build_disc_specimen(p, 1), p)
    assert engine_for(p).apply_levers(scene, Levers(), 1) == {"levers": Levers().to_dict()}
    assert not scene.broken.any()


def test_block_rotation_on_fem_cells_is_one_line():
    p = _params(fem=True)
    scene = engine_for(p).build_scene(build_disc_specimen(p, 1), p)
    with pytest.raises(GrainfracError, match="fix:") as exc:
        engine_for(p).apply_levers(scene, Levers(block_rotation=True), 1)
    assert "\n" not in str(exc.value)


def test_jaws_on_a_box_or_a_loaded_disc_are_one_line():
    """The jaws need a disc, and go on before loading; a lateral condition other than fixed/free is refused."""
    p = _params("specimen.width=3e-3", "specimen.height=6e-3")
    box = engine_for(p).build_scene(build_specimen(p, 1), p)
    scene, jaws = _jawed(_params())
    scene.run(1)
    for call in (lambda: box.attach_jaws(0.2, "fixed"), lambda: scene.attach_jaws(0.2, "fixed"),
                 lambda: engine_for(p).build_scene(build_disc_specimen(_params(), 1), p).attach_jaws(0.2, "rough")):
        with pytest.raises(GrainfracError, match="fix:") as exc:
            call()
        assert "\n" not in str(exc.value)


def test_bond_numbering_does_not_change_the_path():
    """The same disc with its bonds numbered otherwise (the network's input permuted): the same broken bonds, in the
    same order, at the same closures, the same loads."""
    from grainfrac_yade.engines.static.jaws import jaw_network, JawEquilibrium, jaw_cells
    from grainfrac_yade.engines.static.network import build_static_network
    from grainfrac_yade.engines.static.cascade import Path
    p = _params()
    scene, jaws = _jawed(p)
    perm = np.random.default_rng(3).permutation(scene.n_bonds)
    net = jaw_network(build_static_network(scene.specimen, p, scene.layout, bond_permutation=perm),
                      scene.specimen.tessellation, jaw_cells(scene.specimen.tessellation,
                                                             math.radians(p.brazilian.loading_arc_deg)))
    eq = JawEquilibrium(net, True)
    path = Path(eq)
    closure = 150 * p.brazilian.record_strain_increment * jaws.diameter
    other = path.run_closure(eq.initial(0.0), closure)
    scene.move_to(closure)
    assert scene.broken.sum() > 0
    assert np.array_equal(perm[net.order], scene.net.order)
    assert np.array_equal(other.broken, scene.state.broken)
    assert [r.bonds for r in path.records] == [r.bonds for r in scene.path.records]
    assert other.stress == pytest.approx(scene.state.stress, rel=1e-9)


def test_resumed_from_a_checkpoint_is_identical(tmp_path):
    """A checkpoint before every history row (the static scene saved as an .npz, the jaws' speed in the state):
    resuming from the last one gives the uninterrupted test's history and result."""
    from grainfrac_yade.protocols.brazilian import resume_brazilian, run_brazilian
    p = _params(*RESUMED)
    specimen = build_disc_specimen(p, 1)
    cols, result, _, _ = run_brazilian(specimen, p, checkpoint_folder=tmp_path, run_values={"seed": 1})
    assert (tmp_path / "checkpoint").is_dir()
    cols2, result2, _, _ = resume_brazilian(specimen, p, tmp_path)
    assert cols2 == cols
    assert result["broken_total"] > 0
    for k in ("steps", "broken_total", "end_reason", "peak_reached", "loaded_arc_deg", "static_path_max_load_n"):
        assert result2[k] == result[k], k


def test_path_max_load_is_the_largest_load_on_the_path():
    """The summary's static_path_max_load_n: the largest load at a crossing (before its cascade) or a row, at least the
    rows' largest, and its 2 P / (pi D t)."""
    from grainfrac_yade.protocols.brazilian import run_brazilian
    p = _params()
    specimen = build_disc_specimen(p, 1)
    cols, result, scene, _ = run_brazilian(specimen, p)
    rows_max = max(cols["load_n"])
    path_max = result["static_path_max_load_n"]
    crossings = max(r.stress_before for r in scene.path.records) * scene.net.width * scene.net.thickness
    assert path_max == max(rows_max, crossings) and path_max >= rows_max
    assert result["static_path_max_tensile_stress_pa"] == pytest.approx(
        2 * path_max / (math.pi * specimen.tessellation.diameter * specimen.thickness), rel=1e-12)


def test_resumed_with_blocked_rotation_is_identical(tmp_path):
    """The blocked rotation (a lever, applied before loading) comes back with the checkpoint's jaws: the resumed test
    equals the uninterrupted one."""
    from grainfrac_yade.protocols.brazilian import resume_brazilian, run_brazilian
    p = _params(*RESUMED)
    specimen = build_disc_specimen(p, 1)
    levers = Levers(block_rotation=True)
    cols, result, scene, _ = run_brazilian(specimen, p, levers=levers, checkpoint_folder=tmp_path,
                                           run_values={"seed": 1})
    cols2, result2, scene2, _ = resume_brazilian(specimen, p, tmp_path)
    assert scene2.rotation_blocked and cols2 == cols
    rot = scene2.net.dofs[:, 2]
    assert np.all(scene2.state.u[rot[rot >= 0]] == 0.0)
    assert result["broken_total"] > 0
    for k in ("steps", "broken_total", "end_reason", "static_path_max_load_n"):
        assert result2[k] == result[k], k
