"""Regularised tessellation (``specimen.min_edge_fraction``, grainfrac_yade/geometry/regularise.py): exact invariants.

Pure numpy, no YADE.  Tolerances: areas and wall lengths sum to the domain's to 1e-12 relative (a few
thousand float64 additions of terms of the domain's size: rounding ~1e-15; the collapse itself is exact
because neighbouring cells share their corners); points on the rim to 1e-12 R (one sqrt and division).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from grainfrac_yade.geometry.disc import voronoi_disc
from grainfrac_yade.errors import GrainfracError
from grainfrac_yade.grains import layout_for
from grainfrac_yade.geometry.minerals import allocate_minerals
from grainfrac_yade.params import PARAMS_DIR, load_parameters, migrate_tree
from grainfrac_yade.geometry.regularise import regularise
from grainfrac_yade.geometry.specimen import build_disc_specimen, build_specimen
from grainfrac_yade.geometry.tessellation import voronoi_box

GRAIN = 1e-3
SUM_REL = 1e-12      # see module doc
RIM_REL = 1e-12
#: fractions tried: the study's range and one far beyond it (half the faces go; refusals happen)
FRACTIONS = (0.02, 0.1, 0.45)


def _params(fraction, width=10e-3, height=20e-3, fem=False):
    extra = [PARAMS_DIR / "presets" / "fem_coarse.toml"] if fem else []
    return load_parameters(extra_files=extra, overrides=[f"specimen.width={width}", f"specimen.height={height}",
                                                         f"specimen.min_edge_fraction={fraction}"])


def _box(seed, fraction):
    return build_specimen(_params(fraction), seed)


def _disc(seed, fraction, diameter=10e-3):
    return build_disc_specimen(_params(fraction), seed, diameter=diameter)


def _polygon_edges(t, c):
    v = t.cell_vertices[c]
    return [(v[k], v[(k + 1) % len(v)]) for k in range(len(v))]


def _check_faces(t, min_edge, kept):
    n = t.n_cells
    a, b = t.face_cells.T
    assert np.all((0 <= a) & (a < b) & (b < n))                               # two distinct cells
    assert len({(int(x), int(y)) for x, y in t.face_cells}) == t.n_faces       # one face per pair
    assert np.array_equal(np.lexsort(t.face_cells.T[::-1]), np.arange(t.n_faces))
    # no interior face shorter than the threshold except the counted refusals
    assert int(np.sum(t.face_measure < min_edge)) <= kept
    for f in range(t.n_faces):
        p, q = t.face_vertices[f]
        d = q - p
        assert t.face_measure[f] == pytest.approx(np.linalg.norm(d), rel=1e-12)
        assert np.allclose(t.face_midpoint[f], 0.5 * (p + q), rtol=0, atol=1e-12 * GRAIN)
        nrm = t.face_normal[f]
        assert abs(np.linalg.norm(nrm) - 1) < 1e-12
        # perpendicular to the face (Voronoi faces: seeds' bisector, to rounding ~1e-16 relative; use 1e-9)
        assert abs(nrm @ d) <= 1e-9 * np.linalg.norm(d)
        # from cell a to cell b: each centroid on its own side of the face line
        assert nrm @ (t.face_midpoint[f] - t.cell_centroid[a[f]]) > 0
        assert nrm @ (t.cell_centroid[b[f]] - t.face_midpoint[f]) > 0
    # every cell survives: positive area, at least one face
    assert np.all(t.cell_measure > 0)
    assert set(np.unique(t.face_cells)) == set(range(n))


def _convex(poly):
    e = np.roll(poly, -1, axis=0) - poly
    e2 = np.roll(e, -1, axis=0)
    return np.all(e[:, 0] * e2[:, 1] - e[:, 1] * e2[:, 0] > 0)


@pytest.mark.parametrize("fraction", FRACTIONS)
@pytest.mark.parametrize("seed", (1, 2))
def test_box_invariants(seed, fraction):
    sp = _box(seed, fraction)
    t = sp.tessellation
    w, h = t.box
    base = _box(seed, 0.0).tessellation
    assert t.n_cells == base.n_cells                                           # collapsing deletes no cell
    # each collapse removes one face or wall side (faces below the smallest kept one, 1e-6 grain, were never
    # counted: hence <=)
    total, base_total = t.n_faces + len(t.boundary_cell), base.n_faces + len(base.boundary_cell)
    assert sp.edges_collapsed > 0 and base_total - sp.edges_collapsed <= total < base_total
    assert abs(t.cell_measure.sum() / (w * h) - 1) < SUM_REL
    _check_faces(t, fraction * GRAIN, sp.edges_kept_short)
    # wall faces: each wall's pieces sum to its length; vertices stay in the box
    side = np.bincount(t.boundary_side, weights=t.boundary_measure, minlength=4)
    assert np.allclose(side, [h, h, w, w], rtol=SUM_REL, atol=0)
    from grainfrac_yade.geometry.tessellation import _polygon_area_centroid
    for c in range(t.n_cells):
        v = t.cell_vertices[c]
        assert np.all((v >= 0) & (v <= t.box))
        assert _convex(v)
        area, cen = _polygon_area_centroid(v)
        assert area == t.cell_measure[c] and np.array_equal(cen, t.cell_centroid[c])
    # every face is a side of both its cells' polygons (the same two points, exactly)
    for f, (a, b) in enumerate(t.face_cells):
        p, q = t.face_vertices[f]
        for c in (a, b):
            assert any((np.array_equal(p, x) and np.array_equal(q, y)) or (np.array_equal(p, y) and np.array_equal(q, x))
                       for x, y in _polygon_edges(t, c))
    # no polygon side (interior face or wall side) shorter than the threshold but the counted refusals
    sides = {tuple(sorted([tuple(x), tuple(y)])) for c in range(t.n_cells) for x, y in _polygon_edges(t, c)}
    assert len([k for k in sides if math.dist(*k) < fraction * GRAIN]) == sp.edges_kept_short
    assert np.sum(t.boundary_measure < fraction * GRAIN) <= sp.edges_kept_short


@pytest.mark.parametrize("fraction", FRACTIONS)
def test_disc_invariants(fraction):
    sp = _disc(1, fraction)
    t = sp.tessellation
    base = _disc(1, 0.0).tessellation
    assert t.n_cells == base.n_cells and sp.edges_collapsed > 0
    assert abs(t.cell_measure.sum() / (math.pi * t.radius**2) - 1) < SUM_REL
    assert abs(t.boundary_measure.sum() / (2 * math.pi * t.radius) - 1) < SUM_REL
    # rim arcs: none shorter than the threshold (arc length >= chord) but the counted refusals
    assert np.sum(t.boundary_measure < fraction * GRAIN) <= sp.edges_kept_short
    _check_faces(t, fraction * GRAIN, sp.edges_kept_short)
    # rim arcs: each cell's arcs end on the circle; every vertex inside the closed disc
    for v in t.cell_vertices:
        assert np.all(np.linalg.norm(v - t.centre, axis=1) <= t.radius * (1 + RIM_REL))
    ends = t.centre + t.radius * np.stack([np.cos(t.boundary_arc), np.sin(t.boundary_arc)], axis=-1)
    assert np.all(t.boundary_arc[:, 1] > t.boundary_arc[:, 0])
    assert len(ends) == len(t.boundary_cell)
    # each cell's centroid lies inside its own polygon (convex cells: on the inner side of every face)
    for f, (a, b) in enumerate(t.face_cells):
        assert t.face_normal[f] @ (t.face_midpoint[f] - t.cell_centroid[a]) > 0


def test_refusals_are_counted_and_keep_every_cell():
    """At 0.45 of the grain size some collapses would flatten a cell: they are refused and counted."""
    sp = _box(2, 0.45)
    assert sp.edges_kept_short > 0
    assert sp.tessellation.n_cells == _box(2, 0.0).n_cells


def test_same_seed_same_specimen():
    for make in (_box, _disc):
        one, two = make(3, 0.05), make(3, 0.05)
        t1, t2 = one.tessellation, two.tessellation
        for name in ("cell_measure", "cell_centroid", "face_cells", "face_measure", "face_normal", "face_midpoint",
                     "boundary_cell", "boundary_side", "boundary_measure", "boundary_midpoint"):
            assert np.array_equal(getattr(t1, name), getattr(t2, name)), name
        assert all(np.array_equal(x, y) for x, y in zip(t1.cell_vertices, t2.cell_vertices))
        assert np.array_equal(one.mineral, two.mineral) and one.edges_collapsed == two.edges_collapsed


def test_threshold_zero_is_todays_tessellation():
    """0 = off: the tessellation object itself comes back, and the specimen is built as before the knob."""
    rng = np.random.default_rng(4)
    t = voronoi_box([10e-3, 20e-3], GRAIN, rng, 2)
    assert regularise(t, 0.0, GRAIN)[0] is t
    d = voronoi_disc(10e-3, GRAIN, np.random.default_rng(4), 2)
    assert regularise(d, 0.0, GRAIN)[0] is d
    # the specimen of the default parameters (threshold 0) equals the one built by hand without the step
    p = _params(0.0)
    sp = build_specimen(p, 4)
    mineral = allocate_minerals(t.cell_measure, [p.composition[m] for m in p.minerals], rng)
    assert np.array_equal(sp.mineral, mineral) and sp.edges_collapsed == 0
    for name in ("cell_measure", "cell_centroid", "face_cells", "face_measure", "face_normal", "face_midpoint",
                 "boundary_measure", "boundary_midpoint"):
        assert np.array_equal(getattr(sp.tessellation, name), getattr(t, name)), name
    assert load_parameters().specimen.min_edge_fraction == 0.0


def test_fem_layout_of_a_regularised_specimen():
    """Finite-element cells mesh a regularised specimen: the elements cover each cell's area."""
    p = _params(0.05, fem=True)
    sp = build_specimen(p, 1)
    lay = layout_for(sp, p)
    assert lay.n_elements > 0
    pts = lay.sphere_center[:, :2]
    tri = lay.element_spheres
    a = 0.5 * np.abs(np.cross(pts[tri[:, 1]] - pts[tri[:, 0]], pts[tri[:, 2]] - pts[tri[:, 0]]))
    # elements join spheres inset towards the centroid by contact_inset: they cover slightly less
    assert 0.9 < a.sum() / sp.tessellation.cell_measure.sum() <= 1.0 + SUM_REL


def test_bad_thresholds_are_refused():
    with pytest.raises(GrainfracError, match="specimen.min_edge_fraction"):
        load_parameters(overrides=["specimen.min_edge_fraction=0.5"])
    with pytest.raises(GrainfracError, match="specimen.min_edge_fraction"):
        load_parameters(overrides=["specimen.min_edge_fraction=-0.01"])
    with pytest.raises(GrainfracError, match="specimen.min_edge_fraction.*2D|plane"):
        load_parameters(overrides=["specimen.dimension=3", "specimen.thickness=5e-3", "specimen.width=5e-3",
                                   "specimen.height=5e-3", "specimen.min_edge_fraction=0.02"])


def test_older_params_read_the_threshold_as_off():
    tree = {"specimen": {"width": 1.0}}
    notes = migrate_tree(tree)
    assert tree["specimen"]["min_edge_fraction"] == 0.0 and notes
    tree = {"specimen": {"min_edge_fraction": 0.05}}
    migrate_tree(tree)
    assert tree["specimen"]["min_edge_fraction"] == 0.05
