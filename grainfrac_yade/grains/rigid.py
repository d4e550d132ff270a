"""Rigid cells: each Voronoi cell one rigid body (pure numpy).

Its spheres, chosen by ``resolution.spheres_per_cell`` (N):

* N = 1: one sphere per cell at its centroid, radius = distance from the
  centroid to the nearest face (the sphere lies inside its cell, so no two
  cells' spheres overlap).  One bond per interior face.
* N > 1 (2D only): a *face-lined clump*.  Sphere size s = mean cell perimeter / N;
  each interior face of length L carries k = max(1, round(L/s)) sphere pairs
  at the centres of k equal sub-segments, one sphere on each side, tangent to
  the face at that point (radius L/(2k), reduced where a neighbouring face of
  the cell is closer), so the pair touches exactly on the face and its bond
  normal is the face normal.  Each pair carries one bond of area A_face/k.
  The cell interior holds no spheres: members of one clump never interact,
  and the clump's mass and inertia are those of the polygon (set by the adapter).
  The realised spheres per cell are therefore ~ n_faces * k (about 6 per
  face pair level), reported as ``mean_spheres_per_cell``.

Both layouts give, for every face, bonds whose areas sum to the face area.  The grain's elasticity
acts in series with each bond (:func:`grainfrac_yade.layout.bond_properties`, ``series_fraction`` 1).

Masses and the critical DEM step: each cell body has its polygon's mass and inertia (about where YADE
puts the body, :func:`inertia_about_bodies`); its own step is the smaller of sqrt(m / K) and
sqrt(I / K_rot), K summing k_n + k_s of the cell's bonds and K_rot (k_n + k_s) |r|^2 with r the lever
arm from the body to the bond point (:func:`body_steps`); the scene's step is the smallest, after
``numerics.step_floor_quantile`` (:func:`grainfrac_yade.dem_step.lift_short_steps`).
"""
from __future__ import annotations

import numpy as np

from ..dem_step import lift_short_steps, oscillation_steps
from ..errors import GrainfracError
from ..layout import BondProperties, ClumpLayout, cell_mass_inertia
from ..params import Parameters
from ..geometry.specimen import Specimen
from ._interface import GrainModel

NAME = "rigid"


def build_layout(specimen: Specimen, spheres_per_cell: int) -> ClumpLayout:
    """Rigid-cell layout of ``specimen`` at resolution ``spheres_per_cell`` (see module doc)."""
    t = specimen.tessellation
    if spheres_per_cell == 1:
        return _single_sphere_layout(specimen)
    if t.dim != 2:
        raise GrainfracError("resolution.spheres_per_cell: clumps of several spheres are built for "
                             "2D specimens only; fix: use spheres_per_cell = 1 with specimen.dimension = 3")
    return _face_lined_layout(specimen, spheres_per_cell)


def _to3d(points: np.ndarray, z: float) -> np.ndarray:
    if points.shape[1] == 3:
        return points
    return np.column_stack([points, np.full(len(points), z)])


def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from points p (..., 2) to segments a-b (..., 2)."""
    ab = b - a
    u = np.clip(((p - a) * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-300), 0.0, 1.0)
    return np.linalg.norm(p - (a + u[..., None] * ab), axis=-1)


def _cell_face_distance(t, cell: int, point: np.ndarray) -> float:
    """Distance from ``point`` to the nearest edge (2D) or face plane (3D) of ``cell``."""
    verts = t.cell_vertices[cell]
    if t.dim == 2:
        return float(_segment_distance(point, verts, np.roll(verts, -1, axis=0)).min())
    from scipy.spatial import ConvexHull
    eq = ConvexHull(verts).equations  # n.x + d <= 0 inside
    return float(np.min(-(eq[:, :3] @ point + eq[:, 3])))


def _single_sphere_layout(specimen: Specimen) -> ClumpLayout:
    t = specimen.tessellation
    z = specimen.thickness / 2.0
    radius = np.array([_cell_face_distance(t, i, t.cell_centroid[i]) for i in range(t.n_cells)])
    return ClumpLayout(
        sphere_cell=np.arange(t.n_cells), sphere_center=_to3d(t.cell_centroid, z), sphere_radius=radius,
        bond_spheres=t.face_cells.copy(), bond_face=np.arange(t.n_faces),
        bond_area=specimen.face_area.copy(), bond_point=_to3d(t.face_midpoint, z))


def _face_lined_layout(specimen: Specimen, spheres_per_cell: int) -> ClumpLayout:
    t = specimen.tessellation
    z = specimen.thickness / 2.0
    perimeter = np.bincount(t.face_cells.ravel(), weights=np.repeat(t.face_measure, 2), minlength=t.n_cells)
    perimeter += np.bincount(t.boundary_cell, weights=t.boundary_measure, minlength=t.n_cells)
    size = perimeter.mean() / spheres_per_cell
    sphere_cell, centers, radii, pairs, faces, areas, points = [], [], [], [], [], [], []
    face_area = specimen.face_area
    for f, (a, b) in enumerate(t.face_cells):
        v0, v1 = t.face_vertices[f]
        length = t.face_measure[f]
        k = max(1, int(round(length / size)))
        n = t.face_normal[f]
        for j in range(k):
            x = v0 + (j + 0.5) / k * (v1 - v0)
            r = length / (2 * k)
            # keep both spheres inside their cells: r <= half the distance from x to the cell's other edges
            for cell in (a, b):
                verts = t.cell_vertices[cell]
                d = _segment_distance(x, verts, np.roll(verts, -1, axis=0))
                others = d[d > 1e-9 * length]
                if len(others):
                    r = min(r, 0.5 * others.min())
            ia = len(sphere_cell)
            sphere_cell += [a, b]
            centers += [x - r * n, x + r * n]
            radii += [r, r]
            pairs.append((ia, ia + 1))
            faces.append(f)
            areas.append(face_area[f] / k)
            points.append(x)
    return ClumpLayout(
        sphere_cell=np.array(sphere_cell), sphere_center=_to3d(np.array(centers), z),
        sphere_radius=np.array(radii), bond_spheres=np.array(pairs, dtype=np.int64),
        bond_face=np.array(faces, dtype=np.int64), bond_area=np.array(areas),
        bond_point=_to3d(np.array(points), z))


def body_positions(layout: ClumpLayout, n_cells: int) -> np.ndarray:
    """(n_cells, 3) where YADE puts each rigid cell's body: its sphere's centre, or for a clump the mean
    of its members' centres weighted by their volumes (YADE's clump without discretisation: members'
    masses, one material per cell)."""
    w = layout.sphere_radius ** 3
    pos = np.zeros((n_cells, 3))
    total = np.bincount(layout.sphere_cell, weights=w, minlength=n_cells)
    for axis in range(3):
        pos[:, axis] = np.bincount(layout.sphere_cell, weights=w * layout.sphere_center[:, axis],
                                   minlength=n_cells) / total
    single = np.bincount(layout.sphere_cell, minlength=n_cells) == 1
    pos[layout.sphere_cell[single[layout.sphere_cell]]] = layout.sphere_center[single[layout.sphere_cell]]
    return pos


def inertia_about_bodies(specimen: Specimen, mass: np.ndarray, inertia: np.ndarray, body_pos: np.ndarray) -> np.ndarray:
    """The polygon inertia about each cell body's reference point ``body_pos`` (n, >= dim) instead of the
    centroid (parallel-axis theorem)."""
    dim = specimen.tessellation.dim
    return inertia + mass * ((body_pos[:, :dim] - specimen.tessellation.cell_centroid) ** 2).sum(1)


def body_steps(layout: ClumpLayout, props: BondProperties, specimen: Specimen, mass: np.ndarray,
               inertia: np.ndarray, body_pos: np.ndarray) -> np.ndarray:
    """Each cell body's own critical DEM step [s]: the smaller of sqrt(m/K) and sqrt(I/K_rot).

    ``mass``, ``inertia`` per cell; ``body_pos`` (n, 3) the cell bodies' positions.  K sums k_n + k_s
    of a cell's bonds; K_rot sums (k_n + k_s) |r|^2 with r the lever arm from the cell body to the
    bond point.
    """
    cells = specimen.tessellation.face_cells[layout.bond_face]
    lever = np.concatenate([layout.bond_point - body_pos[cells[:, 0]],
                            layout.bond_point - body_pos[cells[:, 1]]])
    return oscillation_steps(specimen.n_cells, cells, props.normal_stiffness + props.shear_stiffness,
                             (lever**2).sum(1), mass, inertia)


class RigidCells(GrainModel):
    """Each cell one rigid body that translates and spins in the plane (see module doc)."""
    name = NAME
    rotating = True

    def build_layout(self, specimen: Specimen, params: Parameters) -> ClumpLayout:
        return build_layout(specimen, params.resolution.spheres_per_cell)

    def masses_and_step(self, specimen: Specimen, params: Parameters, layout: ClumpLayout, props: BondProperties,
                        body_pos: np.ndarray | None = None) -> tuple:
        """Per cell body: (mass, inertia about the body, critical step [s]); ``body_pos`` (n, 3) default
        :func:`body_positions`."""
        body_pos = body_positions(layout, specimen.n_cells) if body_pos is None else body_pos
        mass, inertia = cell_mass_inertia(specimen, params, params.numerics.density_scale)
        inertia = inertia_about_bodies(specimen, mass, inertia, body_pos)
        floor = params.numerics.step_floor_quantile
        if floor > 0:
            own = body_steps(layout, props, specimen, mass, inertia, body_pos)
            mass, inertia = lift_short_steps(floor, own, np.arange(specimen.n_cells), mass, inertia)
        return mass, inertia, float(body_steps(layout, props, specimen, mass, inertia, body_pos).min())


MODEL = RigidCells()
