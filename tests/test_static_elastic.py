"""Static engine before anything breaks: the same forces, E and nu as the elastic reference (no YADE)."""
import numpy as np
import pytest

from grainfrac_yade.elastic import DEFAULT_STRAIN, build_network, solve_uniaxial
from grainfrac_yade.grains import layout_for
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.engines.static.network import build_static_network
from grainfrac_yade.engines.static.solver import Equilibrium

TINY = ["specimen.width=4e-3", "specimen.height=8e-3"]
#: Round-off: the same matrices summed in another order and factorised by SuperLU instead of spsolve; measured
#: 1e-13 (rigid) and 3e-14 (fem) relative to the largest bond force on 4 x 8 mm.  1e-9 leaves room for other
#: BLAS builds and still catches any change of the model (a lever arm or a series stiffness moves forces by >1e-4).
ROUND_OFF = 1e-9


@pytest.fixture(scope="module", params=["rigid", "fem"])
def pair(request):
    extra = ["params/presets/fem_coarse.toml"] if request.param == "fem" else []
    p = load_parameters(extra_files=extra, overrides=TINY)
    s = build_specimen(p, 1)
    lay = layout_for(s, p)
    return s, p, lay


def test_intact_forces_equal_the_elastic_reference(pair):
    """Every bond's normal and shear force and the platen stress equal elastic.solve_uniaxial's."""
    s, p, lay = pair
    ref = solve_uniaxial(build_network(s, p, lay.model, lay), s)
    net = build_static_network(s, p, lay)
    st = Equilibrium(net).initial(DEFAULT_STRAIN * net.height)
    scale = np.abs(ref.normal_force).max()
    assert np.abs(st.fn - ref.normal_force[net.order]).max() <= ROUND_OFF * scale
    assert np.abs(st.fs - ref.shear_force[net.order]).max() <= ROUND_OFF * scale
    assert st.stress == pytest.approx(ref.applied_stress, rel=ROUND_OFF)


def test_young_and_poisson_equal_the_elastic_reference(pair):
    """E = stress / strain from the tangent response, nu from the side cells' lateral displacement."""
    s, p, lay = pair
    ref = solve_uniaxial(build_network(s, p, lay.model, lay), s)
    net = build_static_network(s, p, lay)
    eq = Equilibrium(net)
    st = eq.initial(0.0)
    v, _, _, dstress = eq.response(st)
    assert dstress * net.height == pytest.approx(ref.young, rel=ROUND_OFF)
    lateral = (v[net.dofs[net.right, 0]].mean() - v[net.dofs[net.left, 0]].mean()) / net.width * net.height
    assert lateral == pytest.approx(ref.poisson, rel=ROUND_OFF)


def test_canonical_order_does_not_depend_on_the_input_numbering(pair):
    """The same bonds numbered otherwise give the same canonical network (order maps back to the input)."""
    s, p, lay = pair
    perm = np.random.default_rng(7).permutation(lay.n_bonds)
    a, b = build_static_network(s, p, lay), build_static_network(s, p, lay, bond_permutation=perm)
    assert np.array_equal(a.bond_nodes, b.bond_nodes)
    assert np.array_equal(perm[b.order], a.order)
    assert (a.cn != b.cn).nnz == 0 and (a.gt != b.gt).nnz == 0
