"""Voronoi tessellation of a disc (Brazilian test specimen), clipped exactly to the circle.

Pure numpy/scipy.  Seeds are drawn uniformly in the disc; each seed is mirrored
radially across the circle (p' = c + (2R - |p - c|) (p - c)/|p - c|): the bisector
of p and p' is the tangent at the rim point nearest p, so the mirrored seeds'
cells lie outside the disc and the real seeds' cells cover it exactly (the box
tessellation's mirroring, :mod:`grainfrac_yade.geometry.tessellation`, with the circle's
tangents as walls).  A ring of far points keeps every cell finite.  Each cell, a
convex polygon, is then intersected with the disc: its boundary is straight
pieces (Voronoi faces) and circular arcs (the rim).  Lloyd iterations move the
seeds to the exact centroids of the clipped cells.

Exact and sampled geometry:

* ``cell_measure`` and ``cell_centroid`` are exact: the polygon of the cell's
  corners (straight pieces' end points) plus, for each arc of angle d, the
  circular segment R^2/2 (d - sin d) with its centroid 4 R sin^3(d/2) / (3 (d - sin d))
  from the centre.  The cell areas sum to pi R^2 to rounding (tested: 1e-12 relative).
* ``cell_vertices`` is the polygon with each arc sampled every
  :data:`ARC_SAMPLE_DEG` degrees or less (for pictures, sphere radii and inertia;
  a chord of 2 degrees lies within R (1 - cos 1 deg) = 1.5e-4 R of the arc).
* Interior faces (Voronoi ridges between two cells, clipped to the disc) are
  straight and exact, as in the box.  Rim arcs are the boundary faces:
  ``boundary_measure`` is the arc length, ``boundary_midpoint`` the arc's
  midpoint on the circle, ``boundary_arc`` its start and end angles, and
  ``boundary_side`` the quadrant of the midpoint in the box's wall codes
  (right: -45..45 deg, top: 45..135, left, bottom), so ``cells_on_side`` still
  answers for a quarter of the rim.  Loading arcs: :meth:`DiscTessellation.cells_in_arc`.

The disc of diameter D sits in the box [0, D]^2, centred at (D/2, D/2).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import Voronoi

from ..errors import GrainfracError
from .tessellation import MIN_FACE_FRACTION, SIDES, Tessellation, _ccw, _check_one_region_per_seed

#: Largest angle between two samples of a rim arc in ``cell_vertices`` [deg].
ARC_SAMPLE_DEG = 2.0
#: Points closer than this fraction of the radius are the same point (piece ends, arc ends).
SAME_POINT_FRACTION = 1e-9
#: A line closer to the circle's tangent than this fraction of the radius misses the disc: each cell's
#: own mirror bisector is a tangent, which rounding would otherwise turn into a chord about 1e-8 R long
#: (dropped genuine chords are below 3e-5 R, their circular segments below 1e-14 R^2).
TANGENT_FRACTION = 1e-10
#: Far points bounding every Voronoi cell: this many, at this many radii from the centre.
FAR_POINTS, FAR_RADII = 16, 8.0
TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class DiscTessellation(Tessellation):
    """A :class:`~grainfrac_yade.geometry.tessellation.Tessellation` of a disc (see module doc).

    Extra attributes: ``centre`` (2,) [m], ``radius`` [m], ``boundary_arc`` (nb, 2) start and
    end angle [rad] of each rim arc, counter-clockwise (start in [-pi, pi), end > start).
    """
    centre: np.ndarray = None
    radius: float = 0.0
    boundary_arc: np.ndarray = None

    @property
    def diameter(self) -> float:
        return 2.0 * self.radius

    def cells_in_arc(self, angle: float, half_width: float) -> np.ndarray:
        """Cells with a rim arc overlapping the arc [angle - half_width, angle + half_width] [rad].

        Always holds the cell whose rim arc contains ``angle`` (``half_width`` 0 gives that one).
        """
        lo = self.boundary_arc[:, 0]
        span = self.boundary_arc[:, 1] - lo
        # distance (counter-clockwise) from each arc's start to the window's start, in [0, 2 pi)
        start = (angle - half_width - lo) % TWO_PI
        hit = (start <= span) | (start + 2.0 * half_width >= TWO_PI)
        return np.unique(self.boundary_cell[hit])

    def polar_angle(self, points) -> np.ndarray:
        """Angle [rad] of points (n, 2) about the disc's centre, in [-pi, pi)."""
        d = np.asarray(points, float)[..., :2] - self.centre
        return np.arctan2(d[..., 1], d[..., 0])


def n_cells_for_disc(diameter: float, grain_size: float) -> int:
    """Number of cells whose mean equivalent diameter is ``grain_size``: (D / grain size)^2."""
    return max(1, int(round((diameter / grain_size) ** 2)))


def check_disc_size(diameter: float, grain_size: float, where: str = "brazilian.diameter"):
    """GrainfracError unless the disc is larger than a grain and holds at least two cells."""
    if not (math.isfinite(diameter) and diameter > 0):
        raise GrainfracError(f"{where}: {diameter!r} is not a positive diameter; fix: give the disc's diameter in m "
                             "(e.g. 31.7e-3)")
    ratio = diameter / grain_size
    if not math.isfinite(ratio * ratio):   # (D / d)^2 cells: the count would overflow a float
        raise GrainfracError(f"{where}: a disc of {diameter:g} m holds more cells of specimen.grain_size = "
                             f"{grain_size:g} m than a float counts; fix: give the disc's diameter in m (e.g. 31.7e-3)")
    if grain_size >= diameter or n_cells_for_disc(diameter, grain_size) < 2:
        raise GrainfracError(f"{where}: a disc of {diameter:g} m holds no more than one grain of "
                             f"specimen.grain_size = {grain_size:g} m (a lone cell has no face to bond); fix: make "
                             "the diameter larger than the grain size (paper: 1 mm grains, 31.7 mm wide)")


def voronoi_disc(diameter: float, grain_size: float, rng: np.random.Generator,
                 lloyd_iterations: int = 2) -> DiscTessellation:
    """Random Voronoi tessellation of a disc of ``diameter`` [m] with cells of about ``grain_size`` [m].

    Seeds uniform in the disc (radius R sqrt(u), angle 2 pi v; ``rng`` seeded by the caller),
    then ``lloyd_iterations`` moves to the exact centroids of the clipped cells.
    """
    check_disc_size(diameter, grain_size)
    radius = 0.5 * diameter
    centre = np.array([radius, radius])
    u = rng.random((n_cells_for_disc(diameter, grain_size), 2))
    r = radius * np.sqrt(u[:, 0])
    seeds = centre + np.column_stack([r * np.cos(TWO_PI * u[:, 1]), r * np.sin(TWO_PI * u[:, 1])])
    tess = tessellate_disc(seeds, diameter, grain_size)
    for _ in range(lloyd_iterations):
        tess = tessellate_disc(tess.cell_centroid.copy(), diameter, grain_size)
    return tess


def tessellate_disc(seeds, diameter: float, grain_size: float) -> DiscTessellation:
    """Voronoi cells of ``seeds`` (n, 2), all strictly inside the disc [0, D]^2-centred, clipped to it."""
    seeds = np.asarray(seeds, float)
    radius = 0.5 * diameter
    centre = np.array([radius, radius])
    n = len(seeds)
    d = seeds - centre
    dist = np.linalg.norm(d, axis=1)
    if n < 2 or np.any(dist >= radius):
        raise GrainfracError(f"disc tessellation: {n} seeds, {int(np.sum(dist >= radius))} of them on or outside the "
                             "circle; fix: give at least two seeds strictly inside the disc")
    direction = np.where(dist[:, None] > 0, d / np.where(dist > 0, dist, 1.0)[:, None], np.array([1.0, 0.0]))
    mirrored = centre + (2.0 * radius - dist)[:, None] * direction
    far_angle = TWO_PI * np.arange(FAR_POINTS) / FAR_POINTS
    far = centre + FAR_RADII * radius * np.column_stack([np.cos(far_angle), np.sin(far_angle)])
    vor = Voronoi(np.vstack([seeds, mirrored, far]))
    _check_one_region_per_seed(vor, seeds)
    verts = vor.vertices
    tol = SAME_POINT_FRACTION * radius

    cell_vertices, measure, centroid = [], np.empty(n), np.empty((n, 2))
    b_cell, b_arc = [], []
    for i in range(n):
        region = vor.regions[vor.point_region[i]]
        if -1 in region or not region:
            raise GrainfracError(f"disc tessellation: cell {i} is unbounded; fix: report this seed set (the far "
                                 "points should bound every cell)")
        clip = clip_polygon_to_disc(_ccw(verts[region]), centre, radius, tol)
        measure[i], centroid[i] = clip.area, clip.centroid
        cell_vertices.append(clip.sampled)
        for arc in clip.arcs:
            b_cell.append(i)
            b_arc.append(arc)

    min_face = MIN_FACE_FRACTION * grain_size
    f_cells, f_meas, f_norm, f_mid, f_verts = [], [], [], [], []
    for (p, q), rv in zip(vor.ridge_points, vor.ridge_vertices):
        if p >= n or q >= n:
            continue
        if -1 in rv:
            raise GrainfracError(f"disc tessellation: the face of cells {p} and {q} is unbounded; fix: report this "
                                 "seed set")
        piece = _clip_segment(verts[rv[0]], verts[rv[1]], centre, radius)
        if piece is None:
            continue
        a_pt, b_pt = piece
        length = float(np.linalg.norm(b_pt - a_pt))
        if length < min_face:
            continue
        a, b = min(p, q), max(p, q)
        normal = seeds[b] - seeds[a]
        f_cells.append((a, b))
        f_meas.append(length)
        f_norm.append(normal / np.linalg.norm(normal))
        f_mid.append(0.5 * (a_pt + b_pt))
        f_verts.append(np.array([a_pt, b_pt]))
    if not f_cells:
        raise GrainfracError("disc tessellation: no interior face; fix: use more than one grain across the disc")
    order = np.lexsort(np.array(f_cells).T[::-1])
    arcs = np.array(b_arc, float).reshape(-1, 2)
    mid_angle = arcs.mean(axis=1)
    return DiscTessellation(
        box=np.array([diameter, diameter]), seeds=seeds, cell_vertices=cell_vertices, cell_measure=measure,
        cell_centroid=centroid, face_cells=np.array(f_cells, dtype=np.int64)[order],
        face_measure=np.array(f_meas)[order], face_normal=np.array(f_norm)[order],
        face_midpoint=np.array(f_mid)[order], face_vertices=[f_verts[k] for k in order],
        boundary_cell=np.array(b_cell, dtype=np.int64), boundary_side=_quadrant_side(mid_angle),
        boundary_measure=radius * (arcs[:, 1] - arcs[:, 0]),
        boundary_midpoint=centre + radius * np.column_stack([np.cos(mid_angle), np.sin(mid_angle)]),
        centre=centre, radius=radius, boundary_arc=arcs)


def _quadrant_side(angle: np.ndarray) -> np.ndarray:
    """Wall code (index into ``SIDES``) of rim points at ``angle`` [rad]: the quadrant they face."""
    a = np.degrees(angle) % 360.0
    side = np.full(len(a), SIDES.index("right"), dtype=np.int64)
    side[(a >= 45) & (a < 135)] = SIDES.index("top")
    side[(a >= 135) & (a < 225)] = SIDES.index("left")
    side[(a >= 225) & (a < 315)] = SIDES.index("bottom")
    return side


@dataclass(frozen=True)
class ClippedCell:
    """A convex polygon intersected with a disc."""
    area: float             # m^2, exact
    centroid: np.ndarray    # (2,) m, exact
    sampled: np.ndarray     # (k, 2) polygon with rim arcs sampled, counter-clockwise
    arcs: list              # [(start, end)] rim arcs [rad], start in [-pi, pi), end > start


def _clip_segment(a, b, centre, radius):
    """The part of segment a-b inside the closed disc as (start, end), or None."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    t = _inside_interval(a, b, centre, radius)
    if t is None:
        return None
    d = b - a
    return a + t[0] * d, a + t[1] * d


def _inside_interval(a, b, centre, radius):
    """Parameter interval [t0, t1] within [0, 1] of a + t (b - a) inside the disc, or None."""
    d = b - a
    f = a - centre
    qa = float(d @ d)
    if qa == 0.0:
        return None
    if abs(f[0] * d[1] - f[1] * d[0]) >= (1.0 - TANGENT_FRACTION) * radius * math.sqrt(qa):
        return None   # the line misses the circle or touches it (a cell's own tangent: its mirror's bisector)
    qb = 2.0 * float(f @ d)
    qc = float(f @ f) - radius * radius
    disc = qb * qb - 4.0 * qa * qc
    if disc <= 0.0:
        return None
    root = math.sqrt(disc)
    # numerically stable roots of qa t^2 + qb t + qc
    q = -0.5 * (qb + math.copysign(root, qb))
    t1, t2 = (q / qa, qc / q) if q != 0.0 else (-root / (2 * qa), root / (2 * qa))
    lo, hi = max(0.0, min(t1, t2)), min(1.0, max(t1, t2))
    if hi <= lo:
        return None
    return lo, hi


def clip_polygon_to_disc(poly: np.ndarray, centre, radius: float, tol: float) -> ClippedCell:
    """Intersection of a convex counter-clockwise polygon (k, 2) with the disc (``centre``, ``radius``).

    The boundary of the intersection follows the polygon's edges inside the disc and, between an
    edge piece ending on the circle and the next one starting elsewhere on it, the circle
    counter-clockwise.  Area and centroid: the polygon of the pieces' end points plus the circular
    segment of each arc (module doc).  A polygon containing the whole disc gives the disc.
    """
    centre = np.asarray(centre, float)
    pieces = []
    k = len(poly)
    for j in range(k):
        a, b = poly[j], poly[(j + 1) % k]
        seg = _clip_segment(a, b, centre, radius)
        if seg is not None and np.linalg.norm(seg[1] - seg[0]) > tol:
            pieces.append(seg)
    if not pieces:
        # a convex polygon with no edge inside the disc either contains the disc or misses it
        if _inside_convex(poly, centre):
            sampled = _arc_points(-math.pi, math.pi, centre, radius)[:-1]
            return ClippedCell(math.pi * radius**2, centre.copy(), sampled, [(-math.pi, math.pi)])
        return ClippedCell(0.0, centre.copy(), np.empty((0, 2)), [])
    corners, sampled, arcs = [], [], []
    for j, (start, end) in enumerate(pieces):
        nxt = pieces[(j + 1) % len(pieces)][0]
        if not corners or np.linalg.norm(start - corners[-1]) > tol:
            corners.append(start)
            sampled.append(start)
        corners.append(end)
        sampled.append(end)
        if np.linalg.norm(nxt - end) > tol:            # leave the polygon's edge, follow the rim
            a0 = math.atan2(end[1] - centre[1], end[0] - centre[0])
            a1 = math.atan2(nxt[1] - centre[1], nxt[0] - centre[0])
            span = (a1 - a0) % TWO_PI
            start_angle = (a0 + math.pi) % TWO_PI - math.pi
            arcs.append((start_angle, start_angle + span))
            sampled.extend(_arc_points(a0, a0 + span, centre, radius)[1:-1])
    if len(corners) > 1 and np.linalg.norm(corners[0] - corners[-1]) <= tol:
        corners.pop()
        sampled.pop()
    corners = np.array(corners)
    area, moment = _shoelace(corners)
    for a0, a1 in arcs:
        seg_area, seg_moment = _segment_area_moment(a0, a1 - a0, centre, radius)
        area += seg_area
        moment = moment + seg_moment
    return ClippedCell(float(area), moment / area, np.array(sampled), arcs)


def _shoelace(pts: np.ndarray):
    """Area and first moment (area x centroid) of a counter-clockwise polygon."""
    if len(pts) < 3:
        return 0.0, np.zeros(2)
    origin = pts[0]                      # local coordinates: no cancellation against the box offset
    x, y = pts[:, 0] - origin[0], pts[:, 1] - origin[1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = 0.5 * cross.sum()
    return area, area * origin + np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / 6.0


def _segment_area_moment(a0: float, span: float, centre, radius: float):
    """Area and first moment of the circular segment cut by the chord of the arc [a0, a0 + span]."""
    area = 0.5 * radius**2 * (span - math.sin(span))
    if area <= 0.0:
        return 0.0, np.zeros(2)
    dist = 4.0 * radius * math.sin(0.5 * span) ** 3 / (3.0 * (span - math.sin(span)))
    mid = a0 + 0.5 * span
    return area, area * (centre + dist * np.array([math.cos(mid), math.sin(mid)]))


def _arc_points(a0: float, a1: float, centre, radius: float) -> np.ndarray:
    """Points on the circle from angle a0 to a1 (both included), at most ARC_SAMPLE_DEG apart."""
    n = max(1, int(math.ceil(math.degrees(a1 - a0) / ARC_SAMPLE_DEG)))
    ang = np.linspace(a0, a1, n + 1)
    return centre + radius * np.column_stack([np.cos(ang), np.sin(ang)])


def _inside_convex(poly: np.ndarray, point) -> bool:
    """True if ``point`` lies inside the convex counter-clockwise polygon."""
    d = np.roll(poly, -1, axis=0) - poly
    rel = np.asarray(point) - poly
    return bool(np.all(d[:, 0] * rel[:, 1] - d[:, 1] * rel[:, 0] >= 0.0))
