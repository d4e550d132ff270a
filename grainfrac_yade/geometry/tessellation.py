"""Voronoi tessellation of a rectangular specimen (2D) or a box (3D), clipped exactly.

Pure numpy/scipy.  The seeds are mirrored across every side of the box before
the Voronoi diagram is built, so each seed's cell is bounded by the box walls
exactly (the mirrored seed's bisector *is* the wall).  Lloyd iterations move the
seeds to their cell centroids to even out the grain size.

All lengths in m; "measure" means area (2D, m^2) or volume (3D, m^3) of a cell,
and "face measure" the length (2D, m) or area (3D, m^2) of a face.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull, Voronoi

from ..errors import GrainfracError
from ..params.cells import cell_count

#: Faces shorter than this fraction of the grain size are dropped as degenerate
#: (they come from four nearly co-circular seeds; their bonds would carry nothing).
MIN_FACE_FRACTION = 1e-6
#: Vertices within this fraction of the box size from a wall are snapped onto it.
SNAP_FRACTION = 1e-12
#: Names of the box walls, in the order of ``boundary_side`` codes.
SIDES = ("left", "right", "bottom", "top", "back", "front")


@dataclass(frozen=True)
class Tessellation:
    """Cells and faces of a clipped Voronoi tessellation.

    Attributes
    ----------
    box : (dim,) box size [m]; the box spans [0, box].
    seeds : (n, dim) generator points [m].
    cell_vertices : list of (k, dim) arrays; in 2D the polygon, counter-clockwise.
    cell_measure : (n,) area (2D) or volume (3D) [m^2 or m^3].
    cell_centroid : (n, dim) [m].
    face_cells : (m, 2) int, the two cells of each interior face, a < b.
    face_measure : (m,) length (2D) or area (3D) [m or m^2].
    face_normal : (m, dim) unit normal pointing from cell a to cell b.
    face_midpoint : (m, dim) centroid of the face [m].
    face_vertices : list of (k, dim) arrays (2D: the two end points).
    boundary_cell, boundary_side, boundary_measure, boundary_midpoint :
        faces on the box walls: cell index, wall code (index into ``SIDES``),
        measure and centroid.
    """
    box: np.ndarray
    seeds: np.ndarray
    cell_vertices: list
    cell_measure: np.ndarray
    cell_centroid: np.ndarray
    face_cells: np.ndarray
    face_measure: np.ndarray
    face_normal: np.ndarray
    face_midpoint: np.ndarray
    face_vertices: list
    boundary_cell: np.ndarray
    boundary_side: np.ndarray
    boundary_measure: np.ndarray
    boundary_midpoint: np.ndarray

    @property
    def dim(self) -> int:
        return len(self.box)

    @property
    def n_cells(self) -> int:
        return len(self.seeds)

    @property
    def n_faces(self) -> int:
        return len(self.face_cells)

    def equivalent_diameter(self) -> np.ndarray:
        """Diameter of the circle (2D) or sphere (3D) of each cell's measure [m]."""
        if self.dim == 2:
            return np.sqrt(4.0 * self.cell_measure / math.pi)
        return np.cbrt(6.0 * self.cell_measure / math.pi)

    def cells_on_side(self, side: str) -> np.ndarray:
        """Indices of cells with a face on wall ``side`` (e.g. "top")."""
        return np.unique(self.boundary_cell[self.boundary_side == SIDES.index(side)])


def n_cells_for(box, grain_size: float) -> int:
    """Number of cells whose mean equivalent diameter is ``grain_size`` (:func:`cell_count`, rounded, at least 1)."""
    return max(1, int(round(cell_count(box, grain_size))))


def voronoi_box(box, grain_size: float, rng: np.random.Generator, lloyd_iterations: int = 2) -> Tessellation:
    """Random Voronoi tessellation of the box [0, box] with cells of about ``grain_size``.

    Parameters
    ----------
    box : (dim,) sequence, dim 2 or 3 [m]
    grain_size : equivalent diameter of a cell [m]
    rng : numpy Generator (seeded by the caller; same seed gives the same cells, bit for bit)
    lloyd_iterations : seeds moved to their cell centroids this many times
    """
    box = np.asarray(box, dtype=float)
    if len(box) not in (2, 3):
        raise ValueError("box must have 2 or 3 sizes")
    seeds = rng.random((n_cells_for(box, grain_size), len(box))) * box
    tess = _tessellate(seeds, box, grain_size)
    for _ in range(lloyd_iterations):
        tess = _tessellate(tess.cell_centroid.copy(), box, grain_size)
    return tess


def tessellate_seeds(seeds, box, grain_size: float) -> Tessellation:
    """Clipped Voronoi tessellation of given seeds (e.g. two cells for a one-bond test)."""
    return _tessellate(np.asarray(seeds, float), np.asarray(box, float), grain_size)


def _mirrored(seeds: np.ndarray, box: np.ndarray) -> np.ndarray:
    copies = [seeds]
    for axis in range(len(box)):
        for wall in (0.0, box[axis]):
            m = seeds.copy()
            m[:, axis] = 2.0 * wall - m[:, axis]
            copies.append(m)
    return np.vstack(copies)


def _tessellate(seeds: np.ndarray, box: np.ndarray, grain_size: float) -> Tessellation:
    n, dim = seeds.shape
    vor = Voronoi(_mirrored(seeds, box))
    _check_one_region_per_seed(vor, seeds)
    verts = vor.vertices.copy()
    snap = SNAP_FRACTION * box.max()
    for axis in range(dim):
        for wall in (0.0, box[axis]):
            verts[np.abs(verts[:, axis] - wall) < snap, axis] = wall
    cell_vertices, measure, centroid = [], np.empty(n), np.empty((n, dim))
    for i in range(n):
        region = vor.regions[vor.point_region[i]]
        pts = verts[region]
        if dim == 2:
            pts = _ccw(pts)
            measure[i], centroid[i] = _polygon_area_centroid(pts)
        else:
            measure[i], centroid[i] = _polyhedron_volume_centroid(pts)
        cell_vertices.append(pts)

    min_face = MIN_FACE_FRACTION * grain_size ** (dim - 1)
    f_cells, f_meas, f_norm, f_mid, f_verts = [], [], [], [], []
    b_cell, b_side, b_meas, b_mid = [], [], [], []
    for (p, q), rv in zip(vor.ridge_points, vor.ridge_vertices):
        if p >= n and q >= n:
            continue
        if p >= n:
            p, q = q, p
        pts = verts[rv]
        if dim == 3:
            pts = _order_in_plane(pts, vor.points[q] - vor.points[p])
        meas, mid = _face_measure_midpoint(pts)
        if meas < min_face:
            continue
        if q < n:
            a, b = min(p, q), max(p, q)
            normal = seeds[b] - seeds[a]
            f_cells.append((a, b))
            f_meas.append(meas)
            f_norm.append(normal / np.linalg.norm(normal))
            f_mid.append(mid)
            f_verts.append(pts)
        else:
            b_cell.append(p)
            b_side.append((q - n) // n)
            b_meas.append(meas)
            b_mid.append(mid)
    order = np.lexsort(np.array(f_cells).T[::-1])  # sort faces by (a, b) for determinism
    return Tessellation(
        box=box, seeds=seeds, cell_vertices=cell_vertices, cell_measure=measure, cell_centroid=centroid,
        face_cells=np.array(f_cells, dtype=np.int64)[order], face_measure=np.array(f_meas)[order],
        face_normal=np.array(f_norm)[order], face_midpoint=np.array(f_mid)[order],
        face_vertices=[f_verts[k] for k in order],
        boundary_cell=np.array(b_cell, dtype=np.int64), boundary_side=np.array(b_side, dtype=np.int64),
        boundary_measure=np.array(b_meas), boundary_midpoint=np.array(b_mid).reshape(-1, dim))


def _check_one_region_per_seed(vor: Voronoi, seeds: np.ndarray):
    """GrainfracError if two seeds share a Voronoi region.

    Qhull (option Qc) merges a seed lying within its precision of another (measured: 1e-9 m apart in a
    4 x 8 mm box, 3e-9 m still separate) and gives both the same region: two overlapping cells, one of
    them without faces, which the scene would load as an unbonded body inside another.
    """
    regions = vor.point_region[:len(seeds)]
    shared, first = np.unique(regions, return_index=True)
    if len(shared) == len(seeds):
        return
    j = int(np.setdiff1d(np.arange(len(seeds)), first)[0])
    i = int(np.flatnonzero(regions == regions[j])[0])
    raise GrainfracError(f"tessellation: seeds {i} and {j} lie {np.linalg.norm(seeds[i] - seeds[j]):.3g} m apart, "
                         "too close for the Voronoi construction to tell apart (their cells would overlap); fix: "
                         "merge them or move them apart")


def _ccw(pts: np.ndarray) -> np.ndarray:
    c = pts.mean(axis=0)
    return pts[np.argsort(np.arctan2(pts[:, 1] - c[1], pts[:, 0] - c[0]))]


def _polygon_area_centroid(pts: np.ndarray):
    """Shoelace area [m^2] and centroid [m] of a counter-clockwise polygon."""
    x, y = pts[:, 0], pts[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = 0.5 * cross.sum()
    cx = ((x + xn) * cross).sum() / (6.0 * area)
    cy = ((y + yn) * cross).sum() / (6.0 * area)
    return area, np.array([cx, cy])


def _polyhedron_volume_centroid(pts: np.ndarray):
    """Volume [m^3] and centroid [m] of a convex polyhedron given by its vertices."""
    hull = ConvexHull(pts)
    c0 = pts.mean(axis=0)
    tri = pts[hull.simplices]
    vols = np.abs(np.einsum("ij,ij->i", tri[:, 0] - c0, np.cross(tri[:, 1] - c0, tri[:, 2] - c0))) / 6.0
    cents = (tri.sum(axis=1) + c0) / 4.0
    return vols.sum(), (cents * vols[:, None]).sum(axis=0) / vols.sum()


def _order_in_plane(pts: np.ndarray, normal: np.ndarray) -> np.ndarray:
    n = normal / np.linalg.norm(normal)
    u = np.cross(n, [1.0, 0.0, 0.0])
    if np.linalg.norm(u) < 0.1:
        u = np.cross(n, [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(n, u)
    d = pts - pts.mean(axis=0)
    return pts[np.argsort(np.arctan2(d @ v, d @ u))]


def _face_measure_midpoint(pts: np.ndarray):
    if pts.shape[1] == 2:
        return float(np.linalg.norm(pts[1] - pts[0])), pts.mean(axis=0)
    c0 = pts.mean(axis=0)
    a, b = pts - c0, np.roll(pts, -1, axis=0) - c0
    tri_area = 0.5 * np.linalg.norm(np.cross(a, b), axis=1)
    tri_cent = (c0 + pts + np.roll(pts, -1, axis=0)) / 3.0
    area = tri_area.sum()
    return float(area), (tri_cent * tri_area[:, None]).sum(axis=0) / area
