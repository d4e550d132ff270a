"""XML VTK files of cells (polygons) and bonds (line segments) and their ParaView time series; no YADE.

Each output time is one ``.vtp`` (VTK XML PolyData) file of cells and one of bonds, written with
VTK's own XML writer (Debian's ``python3-vtk9``); the series are tied together by ``.pvd``
collections whose ``timestep`` is the run's own time (creep time [s] for creep runs, the axial or
diametral strain for UCS and Brazilian tests), so ParaView's time axis is that time, not the file
index.

Data: per polygon or per segment (cell data), integer arrays as Int32, the rest as Float64 (NaN
kept: "not yet", e.g. the break time of an intact bond), text arrays as strings.  Field data (per
file) hold the time (``TimeValue``, which ParaView also reads for a plain file series), its name
and unit, and tables that name the integer codes (e.g. ``bond_state_names``: entry k names state
k).  The module imports VTK only when it writes or reads.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from .errors import GrainfracError

#: Bond states written as ``state`` (the scene's break mode): entry k names code k.
BOND_STATE_NAMES = ("intact", "tensile crack", "shear crack")
#: Bond kinds written as ``inter``: entry k names code k.
BOND_KIND_NAMES = ("intra-granular", "inter-granular")
#: How the cell and bond series are named: ``<name>_NNNN.vtp`` files and ``<name>.pvd``.
SERIES_DIGITS = 4


def _vtk():
    """VTK's data, IO and numpy modules (one clear line when Debian's python3-vtk9 is missing)."""
    try:
        from vtkmodules import vtkCommonCore, vtkCommonDataModel, vtkIOXML
        from vtkmodules.util import numpy_support
    except ImportError:
        raise GrainfracError("VTK output needs VTK's Python modules (import vtkmodules failed); fix: run setup.sh "
                             "or apt-get install python3-vtk9, and use Debian's /usr/bin/python3") from None
    return vtkCommonCore, vtkCommonDataModel, vtkIOXML, numpy_support


# ---------------------------------------------------------------------------------------------- geometry
def rigid_motion(vertices: list, centroids: np.ndarray, positions: np.ndarray, angles: np.ndarray) -> list:
    """Polygons moved as rigid bodies: rotated by ``angles`` [rad] about their centroid, then
    translated so the centroid sits at ``positions`` (2D; extra columns ignored)."""
    out = []
    for v, c, p, a in zip(vertices, centroids, positions, angles):
        rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
        out.append((np.asarray(v)[:, :2] - c[:2]) @ rot.T + p[:2])
    return out


def cluster_rigid_motion(reference: np.ndarray, current: np.ndarray, group: np.ndarray, weights: np.ndarray,
                         centroids: np.ndarray):
    """Least-squares rigid motion (translation + rotation about z) of groups of points (2D).

    ``reference`` and ``current`` (p, >=2) point positions, ``group`` (p,) the group of each point
    (0..n-1, every group non-empty), ``weights`` (p,) positive; ``centroids`` (n, >=2) a reference
    point per group (e.g. a polygon's centroid).  Returns the current position of each group's
    reference point (n, 2) and the rotation angle [rad] (n,) that minimise
    sum w |R (x0 - c0) + c - x|^2 (c0, c: weighted mean points), i.e. what :func:`rigid_motion`
    takes.  A group of one point (or of points on one spot) only translates.
    """
    n = len(centroids)
    w_sum = np.bincount(group, weights=weights, minlength=n)

    def mean(x):
        return np.column_stack([np.bincount(group, weights=weights * x[:, i], minlength=n) / w_sum for i in (0, 1)])

    c0, c1 = mean(reference), mean(current)
    a, b = reference[:, :2] - c0[group], current[:, :2] - c1[group]
    sin = np.bincount(group, weights=weights * (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]), minlength=n)
    cos = np.bincount(group, weights=weights * (a * b).sum(1), minlength=n)
    angle = np.arctan2(sin, cos)
    d = centroids[:, :2] - c0
    ca, sa = np.cos(angle), np.sin(angle)
    return c1 + np.column_stack([ca * d[:, 0] - sa * d[:, 1], sa * d[:, 0] + ca * d[:, 1]]), angle


# ---------------------------------------------------------------------------------------------- writing
def _array(name: str, values, n: int | None):
    """A VTK array named ``name`` of ``values`` (numbers or strings); ``n``: required length."""
    core, _, _, nps = _vtk()
    if isinstance(values, str):
        values = [values]
    arr = np.asarray(values)
    if arr.ndim == 0:
        arr = arr.reshape(1)
    if n is not None and arr.shape != (n,):
        raise GrainfracError(f"VTK array {name!r} has shape {arr.shape}, expected ({n},); fix: one value per item")
    if arr.dtype.kind in "USO":
        out = core.vtkStringArray()
        out.SetNumberOfValues(len(arr))
        for k, v in enumerate(arr):
            out.SetValue(k, str(v))
    elif arr.dtype == bool or np.issubdtype(arr.dtype, np.integer):
        out = nps.numpy_to_vtk(np.ascontiguousarray(arr, dtype=np.int32), deep=True, array_type=core.VTK_INT)
    else:
        out = nps.numpy_to_vtk(np.ascontiguousarray(arr, dtype=np.float64), deep=True, array_type=core.VTK_DOUBLE)
    out.SetName(name)
    return out


def _polydata(points: np.ndarray, items: list, kind: str, data: dict, field: dict):
    core, model, _, nps = _vtk()
    n = len(items)
    arrays = [_array(name, values, n) for name, values in data.items()]   # all checked before anything is built
    fields = [_array(name, values, None) for name, values in field.items()]
    pts3 = np.zeros((len(points), 3))
    pts3[:, :points.shape[1]] = points
    pts = core.vtkPoints()
    pts.SetData(nps.numpy_to_vtk(pts3, deep=True, array_type=core.VTK_DOUBLE))
    cells = model.vtkCellArray()
    for item in items:
        cells.InsertNextCell(len(item))
        for p in item:
            cells.InsertCellPoint(int(p))
    poly = model.vtkPolyData()
    poly.SetPoints(pts)
    (poly.SetPolys if kind == "polygons" else poly.SetLines)(cells)
    for a in arrays:
        poly.GetCellData().AddArray(a)
    for a in fields:
        poly.GetFieldData().AddArray(a)
    return poly


def _write(path, poly) -> Path:
    _, _, io, _ = _vtk()
    path = Path(path)
    if path.suffix != ".vtp":
        raise GrainfracError(f"{path}: VTK XML PolyData files end in .vtp; fix: name it {path.stem}.vtp")
    tmp = path.with_name(path.stem + ".tmp.vtp")
    writer = io.vtkXMLPolyDataWriter()
    writer.SetFileName(str(tmp))
    writer.SetInputData(poly)
    writer.SetDataModeToAppended()   # binary, zlib-compressed: a paper-size snapshot is ~1 MB
    writer.SetCompressorTypeToZLib()
    if writer.Write() != 1:
        raise GrainfracError(f"{path}: VTK could not write the file; fix: check the folder is writable")
    tmp.replace(path)
    return path


def write_polygons(path, polygons: list, data: dict, field: dict | None = None) -> Path:
    """``.vtp`` of ``polygons`` (list of (k, 2) vertex arrays [m]) with per-polygon ``data`` and ``field`` data."""
    points = np.vstack(polygons) if len(polygons) else np.zeros((0, 2))
    items, start = [], 0
    for poly in polygons:
        items.append(range(start, start + len(poly)))
        start += len(poly)
    return _write(path, _polydata(points, items, "polygons", data, field or {}))


def write_segments(path, segments: np.ndarray, data: dict, field: dict | None = None) -> Path:
    """``.vtp`` of line ``segments`` ((c, 2, 2) [m]) with per-segment ``data`` and ``field`` data."""
    seg = np.asarray(segments, float).reshape(-1, 2, 2)
    items = [(2 * i, 2 * i + 1) for i in range(len(seg))]
    return _write(path, _polydata(seg.reshape(-1, 2), items, "lines", data, field or {}))


def time_field(time: float, name: str, unit: str) -> dict:
    """Field data of one output time: ``TimeValue`` (read by ParaView), the time's name and unit."""
    return {"TimeValue": np.array([float(time)]), "time_name": name, "time_unit": unit}


def write_pvd(path, times, files) -> Path:
    """``.pvd`` collection of ``files`` (relative to the .pvd's folder) at ``times``.

    Times must not decrease; of several files at one time only the last is listed (the later state
    at that time: ParaView shows one dataset per timestep).
    """
    path = Path(path)
    times = [float(t) for t in times]
    if len(times) != len(files):
        raise GrainfracError(f"{path}: {len(times)} times for {len(files)} files; fix: one time per file")
    if any(b < a for a, b in zip(times, times[1:])):
        raise GrainfracError(f"{path}: output times decrease ({times}); fix: write the series in time order")
    keep = [k for k in range(len(times)) if k + 1 == len(times) or times[k + 1] != times[k]]
    root = ET.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
    coll = ET.SubElement(root, "Collection")
    for k in keep:
        ET.SubElement(coll, "DataSet", timestep=repr(times[k]), group="", part="0", file=str(files[k]))
    ET.indent(root)
    tmp = path.with_name(path.name + ".tmp")
    ET.ElementTree(root).write(tmp, encoding="utf-8", xml_declaration=True)
    tmp.replace(path)
    return path


def series_file(name: str, index: int) -> str:
    """File name of output ``index`` of series ``name`` (e.g. ``cells_0003.vtp``)."""
    return f"{name}_{index:0{SERIES_DIGITS}d}.vtp"


# ---------------------------------------------------------------------------------------------- reading
def read_pvd(path) -> list:
    """[(timestep, file path)] of a ``.pvd`` collection, in its order."""
    path = Path(path)
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise GrainfracError(f"{path}: not a readable .pvd collection ({exc}); fix: give a .pvd this code "
                             "wrote") from None
    return [(float(d.get("timestep")), path.parent / d.get("file")) for d in root.iter("DataSet")]


def read_vtp(path) -> dict:
    """Contents of a ``.vtp`` file as numpy: ``points`` (p, 3), ``cells`` (list of point-id lists),
    ``cell_data`` and ``field_data`` {name: array (numbers) or list (strings)}."""
    _, _, io, nps = _vtk()
    path = Path(path)
    if not path.is_file():
        raise GrainfracError(f"{path}: no such VTK file; fix: give a .vtp of a run's vtk/ folder")
    reader = io.vtkXMLPolyDataReader()
    reader.SetFileName(str(path))
    reader.Update()
    poly = reader.GetOutput()

    def arrays(data):
        out = {}
        for k in range(data.GetNumberOfArrays()):
            a = data.GetAbstractArray(k)
            if a.IsA("vtkStringArray"):
                out[a.GetName()] = [a.GetValue(i) for i in range(a.GetNumberOfValues())]
            else:
                out[a.GetName()] = nps.vtk_to_numpy(a).copy()
        return out

    cells = []
    for c in range(poly.GetNumberOfCells()):
        ids = poly.GetCell(c).GetPointIds()
        cells.append([ids.GetId(i) for i in range(ids.GetNumberOfIds())])
    pts = poly.GetPoints()
    return {"points": nps.vtk_to_numpy(pts.GetData()).copy() if pts is not None else np.zeros((0, 3)),
            "cells": cells, "cell_data": arrays(poly.GetCellData()), "field_data": arrays(poly.GetFieldData())}


def due_times(pending: list, now: float) -> tuple:
    """(due, still pending) of the requested snapshot times ``pending`` (sorted, [s]) at time ``now``: those at or
    before ``now`` are written now, as one frame of the state at ``now`` (the first recorded state at or after each)."""
    k = 0
    while k < len(pending) and pending[k] <= now:
        k += 1
    return list(pending[:k]), list(pending[k:])


def merged_frame_note(requested, frame_time: float, clock: str = "creep") -> str:
    """One progress line saying that the requested times ``requested`` [s] fell into one frame at ``frame_time``
    (the clock stepped over them: no state between two recorded rows exists to write)."""
    times = ", ".join(f"{t:g}" for t in requested)
    return (f"VTK: requested {clock} times {times} s fell into one frame at {frame_time:.6g} s (the clock stepped "
            "over them: there is no state in between to write)")
