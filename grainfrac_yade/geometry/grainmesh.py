"""Triangle meshes of Voronoi cells with contact nodes on their faces (pure numpy).

Each cell is meshed on its own: a ring of boundary nodes (the polygon's
vertices plus ``nodes_per_face`` contact positions on every face), optional
inner rings, and the centroid, joined by linear triangles.  Cells never share
a node: two cells meet only through *contact pairs*, one node of each cell at
the same point of their common face, each carrying a share of the face.

``contacts="corners"`` puts the K nodes of a face at equal spacing including
both ends, with trapezoid shares (K = 2: the two corner sub-contacts of UDEC's
deformable blocks, each carrying half the face); ``contacts="midpoints"`` puts
them at the centres of K equal sub-segments, each carrying 1/K.

Used by the static elastic reference (:mod:`grainfrac_yade.elastic`) and by the
DEM's fem cells (:mod:`grainfrac_yade.grains.fem`), so both discretise a
face alike.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import GrainfracError
from .specimen import Specimen

#: Polygon edges shorter than this fraction of the grain size are not subdivided (no face, no contact).
MIN_EDGE_FRACTION = 1e-3
#: Contact placements along a face (see module doc).
CONTACT_PLACEMENTS = ("corners", "midpoints")


@dataclass(frozen=True)
class GrainMesh:
    """Nodes, triangles and contact pairs of a meshed specimen (2D)."""
    node_pos: np.ndarray        # (n, 2) [m]
    node_cell: np.ndarray       # (n,) cell of each node
    triangles: np.ndarray       # (e, 3) node indices, counter-clockwise
    triangle_cell: np.ndarray   # (e,)
    contact_nodes: np.ndarray   # (m, 2) node of the face's cell a, node of cell b
    contact_face: np.ndarray    # (m,) face index
    contact_share: np.ndarray   # (m,) fraction of the face carried by the pair

    @property
    def n_nodes(self) -> int:
        return len(self.node_pos)

    def triangle_areas(self) -> np.ndarray:
        """(e,) triangle areas [m^2]."""
        p = self.node_pos[self.triangles]
        d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
        return 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])


def face_node_positions(nodes_per_face: int, contacts: str) -> tuple:
    """Positions of a face's contact nodes as fractions of its length, and their shares of the face.

    ``corners``: K >= 2 nodes at j/(K-1), trapezoid shares; ``midpoints``: K nodes at
    (j + 1/2)/K, equal shares 1/K.
    """
    k = nodes_per_face
    if contacts == "corners":
        if k < 2:
            raise GrainfracError("grain mesh: contacts at corners need --nodes-per-face >= 2; "
                                 "fix: give 2 or more, or --contacts midpoints")
        s = np.arange(k) / (k - 1)
        w = np.full(k, 1.0 / (k - 1))
        w[[0, -1]] *= 0.5
        return s, w
    if contacts == "midpoints":
        return (np.arange(k) + 0.5) / k, np.full(k, 1.0 / k)
    raise GrainfracError(f"grain mesh: contacts {contacts!r} unknown; fix: use one of {list(CONTACT_PLACEMENTS)}")


def _edge_faces(t):
    """Dict from a rounded edge-midpoint key to (face, v0) for the interior faces."""
    scale = 1e-9 * float(np.max(t.box))
    out = {}
    for f, (v0, v1) in enumerate(t.face_vertices):
        key = tuple(np.round(0.5 * (v0 + v1) / scale).astype(np.int64))
        out[key] = (f, v0)
    return out, scale


def ring_fractions(rings: int, growth: float = 1.0) -> list:
    """Where the inner rings sit, outermost first, as fractions of the way from the centroid to the boundary.

    The ``rings`` layers between the boundary and the centroid's fan have thicknesses in the geometric
    ratio ``growth`` from the boundary inwards, t_i = q^(i-1) / sum_j q^(j-1), i = 1..rings: layer k ends
    at 1 - sum_{i<=k} t_i. ``growth`` = 1 gives the uniform rings k / rings exactly; ``growth`` > 1 puts
    thin layers at the boundary, where the bonds read the stress, and thick ones inside.
    """
    if growth == 1.0:
        return [k / rings for k in range(rings - 1, 0, -1)]
    weights = growth ** np.arange(rings)
    depth = np.cumsum(weights)[:-1] / weights.sum()
    return [float(1.0 - d) for d in depth]


def grain_mesh(specimen: Specimen, nodes_per_face: int = 2, contacts: str = "corners",
               rings: int = 1, ring_growth: float = 1.0) -> GrainMesh:
    """Mesh every cell of a 2D specimen (see module doc).

    ``rings`` > 1 refines each cell radially: the boundary ring is repeated at
    the fractions :func:`ring_fractions` (``ring_growth`` = 1: k/rings) of the
    way to the centroid and neighbouring rings are joined by triangles (the
    angular resolution is set by ``nodes_per_face``).
    """
    if rings < 1:
        raise GrainfracError("grain mesh: rings must be >= 1; fix: give a whole number >= 1")
    if not ring_growth > 0:
        raise GrainfracError(f"grain mesh: ring growth {ring_growth} must be > 0; fix: give 1 for uniform rings")
    fractions = ring_fractions(rings, ring_growth)
    t = specimen.tessellation
    if t.dim != 2:
        raise GrainfracError("grain mesh: built for 2D specimens only; fix: use specimen.dimension = 2")
    s_face, w_face = face_node_positions(nodes_per_face, contacts)
    edge_faces, scale = _edge_faces(t)
    min_edge = MIN_EDGE_FRACTION * float(np.sqrt(t.cell_measure.mean()))
    pos, cell_of, tris, tri_cell = [], [], [], []
    face_node = {}   # (cell, face, j) -> node
    for c in range(t.n_cells):
        verts = t.cell_vertices[c]
        nv = len(verts)
        ring = []
        vertex_node = []
        for v in verts:
            vertex_node.append(len(pos))
            pos.append(v)
            cell_of.append(c)
        for i in range(nv):
            p, q = verts[i], verts[(i + 1) % nv]
            ring.append(vertex_node[i])
            key = tuple(np.round(0.5 * (p + q) / scale).astype(np.int64))
            hit = edge_faces.get(key)
            length = float(np.linalg.norm(q - p))
            if hit is None and length < min_edge:
                continue
            if hit is None:                         # wall edge: subdivide like a face, no contacts
                interior = s_face[(s_face > 0) & (s_face < 1)]
                for s in interior:
                    ring.append(len(pos))
                    pos.append(p + s * (q - p))
                    cell_of.append(c)
                continue
            f, v0 = hit
            forward = np.allclose(p, v0, atol=scale * 10)
            v1 = t.face_vertices[f][1]
            order = range(len(s_face)) if forward else range(len(s_face) - 1, -1, -1)
            for j in order:
                s = s_face[j]
                if s == 0.0:
                    face_node[(c, f, j)] = vertex_node[i] if forward else vertex_node[(i + 1) % nv]
                elif s == 1.0:
                    face_node[(c, f, j)] = vertex_node[(i + 1) % nv] if forward else vertex_node[i]
                else:
                    face_node[(c, f, j)] = len(pos)
                    ring.append(len(pos))
                    pos.append(t.face_vertices[f][0] + s * (v1 - t.face_vertices[f][0]))
                    cell_of.append(c)
        centre = len(pos)
        pos.append(t.cell_centroid[c])
        cell_of.append(c)
        # inner rings at the fractions of the way from the centroid to the boundary ring
        outer = ring
        levels = [outer]
        for fraction in fractions:
            level = []
            for n in outer:
                level.append(len(pos))
                pos.append(t.cell_centroid[c] + fraction * (pos[n] - t.cell_centroid[c]))
                cell_of.append(c)
            levels.append(level)
        inner = levels[-1]
        for a, b in zip(inner, inner[1:] + inner[:1]):
            tris.append((centre, a, b))
            tri_cell.append(c)
        for lo, hi in zip(levels[1:], levels[:-1]):        # quads between two rings, two triangles each
            for i in range(len(hi)):
                j = (i + 1) % len(hi)
                tris += [(lo[i], hi[i], hi[j]), (lo[i], hi[j], lo[j])]
                tri_cell += [c, c]
    pos = np.array(pos)
    cell_of = np.array(cell_of)
    tris = np.array(tris, dtype=np.int64)
    pairs, faces, shares = [], [], []
    for f in range(t.n_faces):
        a, b = t.face_cells[f]
        for j in range(len(s_face)):
            na, nb = face_node.get((a, f, j)), face_node.get((b, f, j))
            if na is not None and nb is not None:
                pairs.append((na, nb))
                faces.append(f)
                shares.append(w_face[j])
    return GrainMesh(node_pos=np.array(pos), node_cell=np.array(cell_of), triangles=np.array(tris, dtype=np.int64),
                     triangle_cell=np.array(tri_cell, dtype=np.int64),
                     contact_nodes=np.array(pairs, dtype=np.int64).reshape(-1, 2),
                     contact_face=np.array(faces, dtype=np.int64), contact_share=np.array(shares))
