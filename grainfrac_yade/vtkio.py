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
