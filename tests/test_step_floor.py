"""Per-cell mass scaling (``numerics.step_floor_quantile``): the few stiffest, lightest cells get the mass
that brings their own DEM step up to a quantile of all cells' steps; statics stay those of the model."""
import numpy as np
import pytest

from conftest import needs_yade
from grainfrac_yade.layout import step_floor_factors
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen

SMALL = ["specimen.width=4e-3", "specimen.height=8e-3"]


def test_factors_raise_exactly_the_cells_below_the_quantile():
    steps = np.array([1.0, 0.25, 2.0, 0.5, 4.0])
    f = step_floor_factors(steps, 0.5)          # the median step is 1.0
    assert f.tolist() == [1.0, 16.0, 1.0, 4.0, 1.0]
    assert np.all(steps * np.sqrt(f) >= 1.0)    # a step grows as sqrt(mass factor)
    assert (steps * np.sqrt(f)).min() == pytest.approx(1.0, rel=1e-15)


def test_quantile_zero_is_off_and_one_is_the_largest_step():
    steps = np.array([3.0, 1.0, 2.0])
    assert step_floor_factors(steps, 0.0).tolist() == [1.0, 1.0, 1.0]
    assert np.allclose(steps * np.sqrt(step_floor_factors(steps, 1.0)), 3.0, rtol=1e-15)


@pytest.mark.parametrize("steps, q, match", [
    ([1.0, 2.0], -0.1, "quantile"), ([1.0, 2.0], 1.5, "quantile"), ([1.0, 0.0], 0.5, "finite and positive"),
    ([1.0, np.nan], 0.5, "finite and positive"), ([], 0.5, "finite and positive")])
def test_bad_input_is_refused(steps, q, match):
    with pytest.raises(ValueError, match=match):
        step_floor_factors(steps, q)


def test_parameter_is_validated_with_one_line():
    from grainfrac_yade.errors import GrainfracError
    with pytest.raises(GrainfracError, match="numerics.step_floor_quantile"):
        load_parameters(overrides=["numerics.step_floor_quantile=1.5"])


def _cell_masses(scene):
    O = scene.O
    return np.array([sum(O.bodies[int(b)].state.mass for b in scene.bodies_of([c]))
                     for c in range(scene.specimen.n_cells)])


@needs_yade
@pytest.mark.yade
@pytest.mark.parametrize("model", ["rigid", "fem"])
def test_scene_step_rises_to_the_quantile_and_only_cells_below_get_heavier(model):
    from grainfrac_yade.dem_step import cell_steps
    from grainfrac_yade.elastic import cluster_network, node_stiffness
    from grainfrac_yade.grains.fem import sphere_mass_inertia
    from grainfrac_yade.grains.rigid import body_steps
    from grainfrac_yade.layout import cell_mass_inertia
    from grainfrac_yade.engines.yade.scene import build_scene
    q = 0.3
    base = load_parameters(overrides=SMALL + [f"resolution.grain_model={model}"])
    floored = load_parameters(overrides=SMALL + [f"resolution.grain_model={model}",
                                                 f"numerics.step_floor_quantile={q}"])
    s = build_specimen(base, 3)
    plain = build_scene(s, base)
    m0 = _cell_masses(plain)
    # each cell's own step in the plain scene, as the scene computes it
    mass, inertia = cell_mass_inertia(s, base, base.numerics.density_scale)
    if model == "rigid":
        pos = np.array([tuple(plain.O.bodies[int(b)].state.pos) for b in plain.cell_body])
        inertia = np.array([plain.O.bodies[int(b)].state.inertia[0] for b in plain.cell_body])
        own = body_steps(plain.layout, plain.props, s, mass, inertia, pos)
    else:
        mass, _ = sphere_mass_inertia(s, plain.layout, mass)
        k = node_stiffness(cluster_network(s, base, plain.layout))   # the assembly again, independently
        own = cell_steps(np.sqrt(mass / k), plain.layout.sphere_cell,
                         s.n_cells)
    assert plain.dt_critical == pytest.approx(own.min(), rel=1e-12)
    scene = build_scene(s, floored)
    floor = np.quantile(own, q)
    assert scene.dt_critical == pytest.approx(floor, rel=1e-9) and scene.dt_critical > plain.dt_critical
    assert scene.O.dt == pytest.approx(floored.numerics.timestep_safety * floor, rel=1e-9)
    m1 = _cell_masses(scene)
    below = own < floor
    assert below.any() and not below.all()
    assert np.array_equal(m1[~below], m0[~below])
    assert m1[below] == pytest.approx(m0[below] * (floor / own[below]) ** 2, rel=1e-9)


@needs_yade
@pytest.mark.yade
@pytest.mark.parametrize("model", ["rigid", "fem"])
def test_heavier_cells_leave_the_statics_unchanged(model):
    """The slow elastic ramp of test_elastic / test_fem_scene, with half the cells made heavier: platen
    stress and every bond force still equal the static solve of the same model (masses do not enter it)."""
    from grainfrac_yade.elastic import cluster_network, rigid_network
    from test_elastic import _assert_yade_ramp_matches_static_solve
    p = load_parameters(overrides=SMALL + [f"resolution.grain_model={model}", "numerics.damping=0.7",
                                           "numerics.step_floor_quantile=0.5"])
    _assert_yade_ramp_matches_static_solve(p, rigid_network if model == "rigid" else cluster_network,
                                           relax_steps=20000)
