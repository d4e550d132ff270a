"""Legacy ASCII VTK files of cells (polygons) and bonds (lines) for ParaView; pure numpy.

ParaView opens ``.vtk`` POLYDATA files directly; a series ``cells_0000.vtk``,
``cells_0001.vtk``... is read as a time series. Data arrays are attached per
polygon or per line (CELL_DATA); integer arrays are written as ``int``, the rest
as ``double``.  No VTK library is needed.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .errors import GrainfracError


def rigid_motion(vertices: list, centroids: np.ndarray, positions: np.ndarray, angles: np.ndarray) -> list:
    """Polygons moved as rigid bodies: rotated by ``angles`` [rad] about their centroid, then
    translated so the centroid sits at ``positions`` (2D; extra columns ignored)."""
    out = []
    for v, c, p, a in zip(vertices, centroids, positions, angles):
        rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
        out.append((np.asarray(v)[:, :2] - c[:2]) @ rot.T + p[:2])
    return out


def _data_block(data: dict, n: int) -> list:
    lines = [f"CELL_DATA {n}"] if data else []
    for name, values in data.items():
        arr = np.asarray(values)
        if arr.shape != (n,):
            raise GrainfracError(f"VTK array {name!r} has shape {arr.shape}, expected ({n},); fix: one value per item")
        if arr.dtype == bool or np.issubdtype(arr.dtype, np.integer):
            kind, text = "int", " ".join(str(int(x)) for x in arr)
        else:
            kind, text = "double", " ".join(repr(float(x)) if np.isfinite(x) else "-1" for x in arr)
        lines += [f"SCALARS {name} {kind} 1", "LOOKUP_TABLE default", text]
    return lines


def _write(path, title: str, points: np.ndarray, topology: str, items: list, data: dict) -> Path:
    path = Path(path)
    pts = np.zeros((len(points), 3))
    pts[:, :points.shape[1]] = points
    size = sum(len(i) + 1 for i in items)
    lines = ["# vtk DataFile Version 3.0", title, "ASCII", "DATASET POLYDATA", f"POINTS {len(pts)} double"]
    lines += [" ".join(repr(float(x)) for x in row) for row in pts]
    lines += [f"{topology} {len(items)} {size}"] + [" ".join(map(str, [len(i), *i])) for i in items]
    lines += _data_block(data, len(items))
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text("\n".join(lines) + "\n")
    tmp.replace(path)
    return path


def write_polygons(path, polygons: list, data: dict, title: str = "cells") -> Path:
    """POLYDATA file of ``polygons`` (list of (k, 2) vertex arrays [m]) with per-polygon ``data``."""
    points = np.vstack(polygons) if polygons else np.zeros((0, 2))
    items, start = [], 0
    for poly in polygons:
        items.append(list(range(start, start + len(poly))))
        start += len(poly)
    return _write(path, title, points, "POLYGONS", items, data)


def write_segments(path, segments: np.ndarray, data: dict, title: str = "bonds") -> Path:
    """POLYDATA file of line ``segments`` ((c, 2, 2) [m]) with per-segment ``data``."""
    seg = np.asarray(segments, float).reshape(-1, 2, 2)
    points = seg.reshape(-1, 2)
    items = [[2 * i, 2 * i + 1] for i in range(len(seg))]
    return _write(path, title, points, "LINES", items, data)


def read_counts(path) -> dict:
    """Number of points, items and data arrays of a file this module wrote (for tests and checks)."""
    words = Path(path).read_text().split("\n")
    out = {"arrays": []}
    for line in words:
        if line.startswith("POINTS"):
            out["points"] = int(line.split()[1])
        elif line.startswith(("POLYGONS", "LINES")):
            out["items"] = int(line.split()[1])
        elif line.startswith("SCALARS"):
            out["arrays"].append(line.split()[1])
    return out
