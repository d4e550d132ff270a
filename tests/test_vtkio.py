"""Legacy VTK writer: counts, data arrays, rigid motion of cell polygons; read back by VTK when installed."""
import numpy as np
import pytest

from grainfrac_yade.errors import GrainfracError
from grainfrac_yade.vtkio import cluster_rigid_motion, read_counts, rigid_motion, write_polygons, write_segments

SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
TRIANGLE = np.array([[2.0, 0.0], [3.0, 0.0], [2.0, 1.0]])


def test_polygons_and_segments_round_trip(tmp_path):
    cells = write_polygons(tmp_path / "c.vtk", [SQUARE, TRIANGLE], {"mineral": np.array([0, 3]),
                                                                     "area_m2": np.array([1.0, 0.5])})
    bonds = write_segments(tmp_path / "b.vtk", np.array([[[0, 0], [1, 1]], [[1, 0], [2, 0]], [[0, 1], [3, 0]]]),
                           {"state": np.array([0, 1, 2]), "strength_pa": np.array([1e6, 0.0, np.nan])})
    assert read_counts(cells) == {"points": 7, "items": 2, "arrays": ["mineral", "area_m2"]}
    assert read_counts(bonds) == {"points": 6, "items": 3, "arrays": ["state", "strength_pa"]}
    try:
        import vtk
    except ImportError:
        return
    reader = vtk.vtkPolyDataReader()
    reader.SetFileName(str(cells))
    reader.ReadAllScalarsOn()
    reader.Update()
    data = reader.GetOutput()
    assert data.GetNumberOfCells() == 2 and data.GetCell(1).GetNumberOfPoints() == 3
    assert data.GetCellData().GetArray("area_m2").GetValue(1) == 0.5


def test_a_wrong_array_length_is_refused(tmp_path):
    with pytest.raises(GrainfracError, match="one value per item"):
        write_polygons(tmp_path / "c.vtk", [SQUARE], {"mineral": np.array([0, 1])})
    assert not (tmp_path / "c.vtk").exists()


def test_rigid_motion_rotates_about_the_centroid_then_translates():
    centroid = SQUARE.mean(axis=0)
    moved = rigid_motion([SQUARE], [centroid], np.array([[5.0, 5.0, 0.0]]), np.array([np.pi / 2]))[0]
    assert np.allclose(moved.mean(axis=0), [5.0, 5.0])
    assert np.allclose(moved[0], [5.5, 4.5])   # corner (0,0) -> (-0.5,-0.5) rotated 90 deg -> (0.5,-0.5)


def test_cluster_rigid_motion_recovers_a_rotation_and_translation():
    """Points of two groups moved rigidly: the motion of each group, and of its polygon."""
    rng = np.random.default_rng(3)
    ref = rng.uniform(0, 1, (9, 2))
    group = np.array([0] * 5 + [1] * 4)
    weights = rng.uniform(0.5, 2, 9)
    centroids = np.array([[0.5, 0.5], [0.2, 0.8]])
    angle, shift = np.array([0.3, -1.2]), np.array([[1.0, 2.0], [-3.0, 0.5]])
    cur = np.empty_like(ref)
    for g in (0, 1):
        c, s = np.cos(angle[g]), np.sin(angle[g])
        cur[group == g] = ref[group == g] @ np.array([[c, -s], [s, c]]).T + shift[g]
    pos, ang = cluster_rigid_motion(ref, cur, group, weights, centroids)
    np.testing.assert_allclose(ang, angle, atol=1e-12)
    moved = rigid_motion([SQUARE, TRIANGLE], centroids, pos, ang)
    for g, poly in enumerate((SQUARE, TRIANGLE)):   # the polygon moves as its points do
        c, s = np.cos(angle[g]), np.sin(angle[g])
        np.testing.assert_allclose(moved[g], poly @ np.array([[c, -s], [s, c]]).T + shift[g], atol=1e-12)
    # one point: translation only
    pos, ang = cluster_rigid_motion(ref[:1], ref[:1] + 1.0, np.array([0]), np.ones(1), ref[:1] + 0.1)
    assert ang[0] == 0.0 and np.allclose(pos, ref[:1] + 1.1)
