"""Legacy VTK writer: counts, data arrays, rigid motion of cell polygons; read back by VTK when installed."""
import numpy as np
import pytest

from grainfrac_yade.errors import GrainfracError
from grainfrac_yade.vtkio import read_counts, rigid_motion, write_polygons, write_segments

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
