"""Regularised plane tessellations: short Voronoi edges collapsed (``specimen.min_edge_fraction``).

Pure numpy.  Four nearly co-circular seeds give a Voronoi edge far shorter than the grain size; the
finite-element cells mesh such an edge into a fan triangle that is very stiff between its two close
nodes, and that triangle sets the critical DEM step of the whole specimen.  The practice of the field
is to remove such edges: 3DEC's block edge tolerance, UDEC's minimum edge length (twice the rounding
length) and Neper's regularisation of Voronoi tessellations (Quey, Dawson & Barbe 2011, Comput.
Methods Appl. Mech. Eng. 200: small edges removed so that the cells mesh into good elements).

The collapse of an edge (a face shared by two cells, a cell's side on a box wall or a rim arc: a short
wall side or arc makes the same sliver fan triangle at the boundary) merges its two vertices into one, at
the edge's midpoint (an arc: its chord's), with the constraints of the two vertices kept: a vertex on a box wall slides only
along that wall, a box corner stays at the corner, a vertex on a disc's rim is put back on the circle
(radially).  Edges are taken shortest first (ties by vertex index, so the result is deterministic),
and after every collapse the edges at the merged vertex are looked at again (they moved).

A collapse is skipped, and counted in ``edges_kept_short``, where it would spoil a cell: every cell
touching the merged vertex must keep at least three corners (two if one of its sides is a rim arc),
stay strictly convex (each corner's turn above :data:`CONVEX_TOLERANCE` of its two edges' lengths) and
keep a positive area.  So no
cell is ever deleted, every interior face keeps its two cells, and the cells still tile the domain
exactly (their corners are shared), so their areas sum to the box's or disc's area to rounding.

Cells and faces the collapses do not touch keep their arrays bit for bit; a moved face gets its length,
midpoint and the unit normal of its new line (from its lower to its higher cell), a moved cell its
polygon, area and centroid (and, in the disc, its rim arcs: exact circular segments as in
:mod:`grainfrac_yade.geometry.disc`).  Threshold 0 returns the tessellation object itself, untouched.
"""
from __future__ import annotations

import heapq
import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.spatial import cKDTree

from .disc import SAME_POINT_FRACTION, _arc_points, _quadrant_side, _segment_area_moment, _shoelace
from ..errors import GrainfracError
from .tessellation import MIN_FACE_FRACTION, SIDES, Tessellation, _ccw, _polygon_area_centroid

#: A corner of a regularised cell must turn by more than this fraction of the product of its two
#: edges' lengths (cross product / (l1 l2) = sine of the turning angle): strictly convex, no corner
#: flatter than 1e-9 rad, so no edge of zero length and no inverted cell.
CONVEX_TOLERANCE = 1e-9
#: Vertex constraints.
FREE, WALL_X, WALL_Y, CORNER, RIM = 0, 1, 2, 3, 4


@dataclass(frozen=True)
class Regularisation:
    """What :func:`regularise` did: edges collapsed and edges (faces, wall sides, arcs) still shorter than the
    threshold (their collapse refused)."""
    min_edge: float            # m, the threshold (min_edge_fraction x grain size)
    edges_collapsed: int
    edges_kept_short: int


def check_min_edge_fraction(fraction: float, dimension: int):
    """GrainfracError for a positive threshold on a 3D box (regularisation is built for plane cells)."""
    if fraction > 0 and dimension != 2:
        raise GrainfracError(f"specimen.min_edge_fraction = {fraction:g}: edge collapse is built for plane (2D) "
                             "tessellations only, not the 3D box of polyhedra; fix: set specimen.min_edge_fraction "
                             "= 0 with specimen.dimension = 3")


def regularise(tess: Tessellation, min_edge_fraction: float, grain_size: float) -> tuple:
    """(tessellation, :class:`Regularisation`): edges shorter than ``min_edge_fraction`` x
    ``grain_size`` collapsed (module doc).  Fraction 0: ``tess`` itself, untouched."""
    min_edge = min_edge_fraction * grain_size
    if min_edge_fraction == 0:
        return tess, Regularisation(0.0, 0, 0)
    check_min_edge_fraction(min_edge_fraction, tess.dim)
    disc = hasattr(tess, "radius") and tess.radius > 0
    mesh = _disc_mesh(tess, grain_size) if disc else _box_mesh(tess)
    collapsed = mesh.collapse_short(min_edge)
    kept = sum(1 for (u, v) in mesh.edges() if mesh.length(u, v) < min_edge)
    report = Regularisation(min_edge, collapsed, kept)
    if collapsed == 0:
        return tess, report
    return (_rebuild_disc(tess, mesh, grain_size) if disc else _rebuild_box(tess, mesh, grain_size)), report


# --------------------------------------------------------------------------- the mesh of cells and vertices
class _PlaneMesh:
    """Cells as counter-clockwise cycles of shared vertex ids; ``arc[c][k]`` True where the side from
    corner k to corner k+1 of cell c is a rim arc (disc), not a straight side."""

    def __init__(self, pos, kind, cells, arc, centre=None, radius=0.0):
        self.pos = [np.array(p, float) for p in pos]
        self.kind = list(kind)
        self.cells = [list(c) for c in cells]
        self.arc = [list(a) for a in arc]
        self.centre, self.radius = centre, radius
        self.alive = [True] * len(self.pos)
        self.moved = set()
        self.touched = set()
        self.vcells = [set() for _ in self.pos]
        for c, cyc in enumerate(self.cells):
            for v in cyc:
                self.vcells[v].add(c)

    def length(self, u, v) -> float:
        return float(np.linalg.norm(self.pos[u] - self.pos[v]))

    def _straight_sides(self, c):
        cyc, arc = self.cells[c], self.arc[c]
        n = len(cyc)
        return [(cyc[k], cyc[(k + 1) % n]) for k in range(n) if not arc[k]]

    def _sides(self, c):
        cyc = self.cells[c]
        return [(cyc[k], cyc[(k + 1) % len(cyc)]) for k in range(len(cyc))]

    def edges(self) -> list:
        """Sorted (u, v), u < v, of every side of every cell: interior faces, wall sides, rim arcs."""
        return sorted({(min(u, v), max(u, v)) for c in range(len(self.cells)) for u, v in self._sides(c)})

    def _is_edge(self, u, v) -> bool:
        return any((u, v) in self._sides(c) or (v, u) in self._sides(c) for c in self.vcells[u] & self.vcells[v])

    def _merged(self, u, v):
        """(position, kind) of the vertex merging u and v, or None if they must not merge."""
        pu, pv, ku, kv = self.pos[u], self.pos[v], self.kind[u], self.kind[v]
        if ku == CORNER or kv == CORNER:
            return (pu if ku == CORNER else pv).copy(), CORNER
        w = 0.5 * (pu + pv)
        kinds = {ku, kv}
        if WALL_X in kinds and WALL_Y in kinds:
            x_from, y_from = (pu, pv) if ku == WALL_X else (pv, pu)
            return np.array([x_from[0], y_from[1]]), CORNER
        for k, p in ((ku, pu), (kv, pv)):
            if k == WALL_X:
                w[0] = p[0]
                return w, WALL_X
            if k == WALL_Y:
                w[1] = p[1]
                return w, WALL_Y
        if RIM in kinds:
            d = w - self.centre
            return self.centre + self.radius * d / np.linalg.norm(d), RIM
        return w, FREE

    def _try_collapse(self, u, v) -> bool:
        merged = self._merged(u, v)
        if merged is None:
            return False
        w_pos, w_kind = merged
        new_cells = {}
        for c in self.vcells[u] | self.vcells[v]:
            cyc, arc = self.cells[c], self.arc[c]
            n = len(cyc)
            if u in cyc and v in cyc:
                i, j = cyc.index(u), cyc.index(v)
                if (i + 1) % n == j:        # side u -> v goes; u takes v's outgoing side
                    new_arc = list(arc)
                    new_arc[i] = arc[j]
                elif (j + 1) % n == i:      # side v -> u goes; the side into v now ends at u
                    new_arc = list(arc)
                else:
                    return False
                new_cyc = [x for k, x in enumerate(cyc) if k != j]
                new_arc = [a for k, a in enumerate(new_arc) if k != j]
            else:
                new_cyc = [u if x == v else x for x in cyc]
                new_arc = list(arc)
            new_cells[c] = (new_cyc, new_arc)
        for c, (cyc, arc) in new_cells.items():
            pts = np.array([w_pos if x == u else self.pos[x] for x in cyc])
            if not _good_cell(pts, any(arc)):
                return False
        for c, (cyc, arc) in new_cells.items():
            self.cells[c], self.arc[c] = cyc, arc
            self.touched.add(c)
        self.pos[u], self.kind[u] = w_pos, w_kind
        self.alive[v] = False
        self.vcells[u] |= self.vcells[v]
        self.vcells[v] = set()
        self.moved.update((u, v))
        return True

    def collapse_short(self, min_edge: float) -> int:
        """Collapse interior edges shorter than ``min_edge``, shortest first; return how many."""
        heap = [(self.length(u, v), u, v) for u, v in self.edges() if self.length(u, v) < min_edge]
        heapq.heapify(heap)
        refused = set()
        done = 0
        while heap:
            length, u, v = heapq.heappop(heap)
            if not (self.alive[u] and self.alive[v]) or (u, v) in refused or length != self.length(u, v) \
                    or not self._is_edge(u, v):
                continue
            if not self._try_collapse(u, v):
                refused.add((u, v))
                continue
            done += 1
            for c in self.vcells[u]:       # sides around the merged vertex moved: look at them again
                for a, b in self._sides(c):
                    key = (min(a, b), max(a, b))
                    ell = self.length(*key)
                    if ell < min_edge:
                        refused.discard(key)
                        heapq.heappush(heap, (ell, *key))
        return done


def _good_cell(pts: np.ndarray, has_arc: bool) -> bool:
    """A cell's corner polygon (counter-clockwise) is still a proper cell (module doc)."""
    n = len(pts)
    if n < (2 if has_arc else 3):
        return False
    if n == 2:
        return float(np.linalg.norm(pts[1] - pts[0])) > 0
    e = np.roll(pts, -1, axis=0) - pts
    ln = np.linalg.norm(e, axis=1)
    if np.any(ln == 0):
        return False
    e_next = np.roll(e, -1, axis=0)
    cross = e[:, 0] * e_next[:, 1] - e[:, 1] * e_next[:, 0]
    return bool(np.all(cross > CONVEX_TOLERANCE * ln * np.roll(ln, -1)))


# --------------------------------------------------------------------------- box (rectangle)
def _box_mesh(tess: Tessellation) -> _PlaneMesh:
    """Vertices of the rectangle's cells: the polygons share their Voronoi vertices exactly (one array)."""
    ids, pos, cells = {}, [], []
    for poly in tess.cell_vertices:
        cyc = []
        for p in poly:
            key = (float(p[0]), float(p[1]))
            if key not in ids:
                ids[key] = len(pos)
                pos.append(p)
            cyc.append(ids[key])
        cells.append(cyc)
    w, h = tess.box
    kind = []
    for p in pos:
        on_x, on_y = p[0] in (0.0, w), p[1] in (0.0, h)
        kind.append(CORNER if on_x and on_y else WALL_X if on_x else WALL_Y if on_y else FREE)
    return _PlaneMesh(pos, kind, cells, [[False] * len(c) for c in cells])


def _wall_side(p, q, box) -> int | None:
    """Wall code of the side p-q if it lies on a wall, else None."""
    for axis, (lo, hi) in enumerate((("left", "right"), ("bottom", "top"))):
        for wall, name in ((0.0, lo), (box[axis], hi)):
            if p[axis] == wall and q[axis] == wall:
                return SIDES.index(name)
    return None


def _faces(tess: Tessellation, mesh: _PlaneMesh, cell_centroid: np.ndarray, grain_size: float):
    """Interior faces of the regularised mesh: unchanged faces keep their arrays, moved ones are recomputed."""
    old = {(int(a), int(b)): f for f, (a, b) in enumerate(tess.face_cells)}
    sides = {}
    for c in range(len(mesh.cells)):
        for u, v in mesh._straight_sides(c):
            sides.setdefault((min(u, v), max(u, v)), []).append(c)
    min_face = MIN_FACE_FRACTION * grain_size
    rows = []
    for (u, v), cs in sides.items():
        if len(cs) != 2:
            continue
        a, b = min(cs), max(cs)
        f = old.get((a, b))
        if f is not None and u not in mesh.moved and v not in mesh.moved:
            rows.append(((a, b), tess.face_measure[f], tess.face_normal[f], tess.face_midpoint[f],
                         tess.face_vertices[f]))
            continue
        p, q = mesh.pos[u], mesh.pos[v]
        length = float(np.linalg.norm(q - p))
        if length < min_face:
            continue
        mid = 0.5 * (p + q)
        normal = np.array([-(q - p)[1], (q - p)[0]]) / length
        if normal @ (mid - cell_centroid[a]) < 0:
            normal = -normal
        if f is not None and np.linalg.norm(tess.face_vertices[f][0] - q) < np.linalg.norm(tess.face_vertices[f][0] - p):
            p, q = q, p
        rows.append(((a, b), length, normal, mid, np.array([p, q])))
    rows.sort(key=lambda r: r[0])
    return dict(face_cells=np.array([r[0] for r in rows], dtype=np.int64),
                face_measure=np.array([r[1] for r in rows], float),
                face_normal=np.array([r[2] for r in rows], float).reshape(-1, 2),
                face_midpoint=np.array([r[3] for r in rows], float).reshape(-1, 2),
                face_vertices=[r[4] for r in rows])


def _rebuild_box(tess: Tessellation, mesh: _PlaneMesh, grain_size: float) -> Tessellation:
    cell_vertices = list(tess.cell_vertices)
    measure, centroid = tess.cell_measure.copy(), tess.cell_centroid.copy()
    for c in sorted(mesh.touched):
        pts = _ccw(np.array([mesh.pos[v] for v in mesh.cells[c]]))
        cell_vertices[c] = pts
        measure[c], centroid[c] = _polygon_area_centroid(pts)
    # boundary faces: one per (cell, wall), in the original order; the moved ones recomputed
    new_walls = {}
    for c in range(len(mesh.cells)):
        cyc = mesh.cells[c]
        for k in range(len(cyc)):
            p, q = mesh.pos[cyc[k]], mesh.pos[cyc[(k + 1) % len(cyc)]]
            side = _wall_side(p, q, tess.box)
            if side is not None:
                new_walls[(c, side)] = (float(np.linalg.norm(q - p)), 0.5 * (p + q))
    b_cell, b_side, b_meas, b_mid = [], [], [], []
    keys = [(int(c), int(s)) for c, s in zip(tess.boundary_cell, tess.boundary_side)]
    keys += sorted(set(new_walls) - set(keys))
    for f, key in enumerate(keys):
        if key not in new_walls:
            continue
        c, s = key
        if c in mesh.touched or f >= len(tess.boundary_cell):
            meas, mid = new_walls[key]
        else:
            meas, mid = tess.boundary_measure[f], tess.boundary_midpoint[f]
        b_cell.append(c)
        b_side.append(s)
        b_meas.append(meas)
        b_mid.append(mid)
    return replace(tess, cell_vertices=cell_vertices, cell_measure=measure, cell_centroid=centroid,
                   **_faces(tess, mesh, centroid, grain_size),
                   boundary_cell=np.array(b_cell, dtype=np.int64), boundary_side=np.array(b_side, dtype=np.int64),
                   boundary_measure=np.array(b_meas, float), boundary_midpoint=np.array(b_mid, float).reshape(-1, 2))


# --------------------------------------------------------------------------- disc
def _disc_mesh(tess, grain_size: float) -> _PlaneMesh:
    """Vertices of the disc's cells from its exact pieces: interior faces (straight) and rim arcs.

    End points closer than the disc's same-point tolerance are one vertex (the two cells of a face clip
    it separately, so its end points agree only to rounding)."""
    centre, radius = tess.centre, tess.radius
    pieces = []   # (cell, p_start, p_end, is_arc, mid)
    for f, (a, b) in enumerate(tess.face_cells):
        p, q = tess.face_vertices[f]
        for c in (int(a), int(b)):
            pieces.append((c, p, q, False, 0.5 * (p + q)))
    for c, (a0, a1) in zip(tess.boundary_cell, tess.boundary_arc):
        ang = np.array([a0, a1, 0.5 * (a0 + a1)])
        pts = centre + radius * np.column_stack([np.cos(ang), np.sin(ang)])
        pieces.append((int(c), pts[0], pts[1], True, pts[2]))
    ends = np.array([p for pc in pieces for p in (pc[1], pc[2])])
    parent = np.arange(len(ends))

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i
    for i, j in sorted(cKDTree(ends).query_pairs(SAME_POINT_FRACTION * radius)):
        ri, rj = root(i), root(j)
        if ri != rj:
            parent[max(ri, rj)] = min(ri, rj)
    for _ in range(2):   # a second pass closes the gaps left by faces below the smallest face (dropped)
        roots = np.array([root(i) for i in range(len(ends))])
        uniq, vid = np.unique(roots, return_inverse=True)
        rim = np.zeros(len(uniq), bool)
        per_cell = [[] for _ in range(tess.n_cells)]
        for k, (c, p, q, is_arc, mid) in enumerate(pieces):
            s, e = int(vid[2 * k]), int(vid[2 * k + 1])
            if is_arc:
                rim[[s, e]] = True
            else:
                g = tess.cell_centroid[c]
                if (p - g)[0] * (q - g)[1] - (p - g)[1] * (q - g)[0] < 0:
                    s, e = e, s
            per_cell[c].append((math.atan2(mid[1] - tess.cell_centroid[c][1], mid[0] - tess.cell_centroid[c][0]),
                                s, e, is_arc))
        gaps = []
        for pcs in per_cell:
            pcs.sort()
            gaps += [(pcs[k][2], pcs[(k + 1) % len(pcs)][1]) for k in range(len(pcs))
                     if pcs[k][2] != pcs[(k + 1) % len(pcs)][1]]
        if not gaps:
            break
        for e, s in gaps:
            ri, rj = root(int(uniq[e])), root(int(uniq[s]))
            if np.linalg.norm(ends[ri] - ends[rj]) > MIN_FACE_FRACTION * grain_size:
                raise GrainfracError("edge collapse: the sides of a disc cell do not close into a loop; fix: set "
                                     "specimen.min_edge_fraction = 0 and report this seed")
            parent[max(ri, rj)] = min(ri, rj)
    else:
        raise GrainfracError("edge collapse: the sides of a disc cell do not close into a loop; fix: set "
                             "specimen.min_edge_fraction = 0 and report this seed")
    pos = ends[uniq]
    cells = [[p[1] for p in pcs] for pcs in per_cell]
    arcs = [[p[3] for p in pcs] for pcs in per_cell]
    kind = [RIM if r else FREE for r in rim]
    pos = [centre + radius * (p - centre) / np.linalg.norm(p - centre) if r else p for p, r in zip(pos, rim)]
    return _PlaneMesh(pos, kind, cells, arcs, centre=centre, radius=radius)


def _rebuild_disc(tess, mesh: _PlaneMesh, grain_size: float):
    centre, radius = tess.centre, tess.radius
    cell_vertices = list(tess.cell_vertices)
    measure, centroid = tess.cell_measure.copy(), tess.cell_centroid.copy()
    b_cell, b_arc = [], []
    old_arcs = {}
    for c, arc in zip(tess.boundary_cell, tess.boundary_arc):
        old_arcs.setdefault(int(c), []).append(arc)
    for c in range(len(mesh.cells)):
        if c not in mesh.touched:
            for arc in old_arcs.get(c, []):
                b_cell.append(c)
                b_arc.append(tuple(arc))
            continue
        cyc, arc = mesh.cells[c], mesh.arc[c]
        corners = np.array([mesh.pos[v] for v in cyc])
        area, moment = _shoelace(corners)
        sampled = []
        for k in range(len(cyc)):
            sampled.append(corners[k])
            if not arc[k]:
                continue
            end = corners[(k + 1) % len(cyc)]
            a0 = math.atan2(corners[k][1] - centre[1], corners[k][0] - centre[0])
            a1 = math.atan2(end[1] - centre[1], end[0] - centre[0])
            span = (a1 - a0) % (2.0 * math.pi)
            start = (a0 + math.pi) % (2.0 * math.pi) - math.pi
            b_cell.append(c)
            b_arc.append((start, start + span))
            seg_area, seg_moment = _segment_area_moment(start, span, centre, radius)
            area += seg_area
            moment = moment + seg_moment
            sampled.extend(_arc_points(a0, a0 + span, centre, radius)[1:-1])
        measure[c], centroid[c] = area, moment / area
        cell_vertices[c] = np.array(sampled)
    arcs = np.array(b_arc, float).reshape(-1, 2)
    mid_angle = arcs.mean(axis=1)
    return replace(tess, cell_vertices=cell_vertices, cell_measure=measure, cell_centroid=centroid,
                   **_faces(tess, mesh, centroid, grain_size),
                   boundary_cell=np.array(b_cell, dtype=np.int64), boundary_side=_quadrant_side(mid_angle),
                   boundary_measure=radius * (arcs[:, 1] - arcs[:, 0]),
                   boundary_midpoint=centre + radius * np.column_stack([np.cos(mid_angle), np.sin(mid_angle)]),
                   boundary_arc=arcs)
