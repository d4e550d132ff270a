"""Spheres that realise each Voronoi cell, and the bonds between them (pure numpy).

Two layouts, chosen by ``resolution.spheres_per_cell`` (N):

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

Both layouts give, for every face, bonds whose areas sum to the face area.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import GrainfracError
from .params import Parameters
from .specimen import Specimen


@dataclass(frozen=True)
class ClumpLayout:
    """Spheres (grouped by cell) and bonds (grouped by face)."""
    sphere_cell: np.ndarray     # (s,) cell of each sphere
    sphere_center: np.ndarray   # (s, 3) [m]; 2D specimens lie in the plane z = thickness/2
    sphere_radius: np.ndarray   # (s,) [m]
    bond_spheres: np.ndarray    # (b, 2) sphere indices, first in the face's cell a
    bond_face: np.ndarray       # (b,) face index
    bond_area: np.ndarray       # (b,) [m^2]
    bond_point: np.ndarray      # (b, 3) contact point on the face [m]
    #: False for finite-element cells (``resolution.grain_model = "fem"``): every sphere is a
    #: body of its own, and the spheres of one cell are held together by the elements below
    rigid_cells: bool = True
    sphere_area: np.ndarray | None = None            # (s,) cell area lumped on each sphere [m^2] (mass share)
    #: (e, 3) sphere triangles of finite-element cells (``grain_model = "fem"``): each a constant-strain
    #: element of its cell's mineral (plane strain, Table 1), the mesh on which the spheres sit
    element_spheres: np.ndarray | None = None
    #: (b, 2) unit normal of each bond's face (from the face's cell a to b) where bonds act on their
    #: face's plane (YADE's smooth-joint kinematics: opening and sliding measured along and across the
    #: face, as the reference's contacts); None: along the line of the two sphere centres
    bond_normal: np.ndarray | None = None
    #: fraction of the centroid-to-face distance of grain in series with each bond (1: rigid cells,
    #: whose elasticity lives in the bonds; the inset of fem cells, whose elements carry the rest)
    series_fraction: float = 1.0

    @property
    def n_elements(self) -> int:
        return 0 if self.element_spheres is None else len(self.element_spheres)

    @property
    def n_spheres(self) -> int:
        return len(self.sphere_cell)

    @property
    def n_bonds(self) -> int:
        return len(self.bond_face)


def build_layout(specimen: Specimen, spheres_per_cell: int) -> ClumpLayout:
    """Sphere layout of ``specimen`` at resolution ``spheres_per_cell`` (see module doc)."""
    t = specimen.tessellation
    if spheres_per_cell == 1:
        return _single_sphere_layout(specimen)
    if t.dim != 2:
        raise GrainfracError("resolution.spheres_per_cell: clumps of several spheres are built for "
                             "2D specimens only; fix: use spheres_per_cell = 1 with specimen.dimension = 3")
    return _face_lined_layout(specimen, spheres_per_cell)


def layout_for(specimen: Specimen, params: Parameters) -> ClumpLayout:
    """The layout of ``params.resolution``: rigid cells (``spheres_per_cell``) or fem cells."""
    if params.resolution.grain_model == "fem":
        from .deformable import build_fem_layout
        return build_fem_layout(specimen, params)
    return build_layout(specimen, params.resolution.spheres_per_cell)


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


def mineral_pair_table(names, params: Parameters, attr: str) -> np.ndarray:
    """(m, m) Table 2 value ``attr`` of every pair of the minerals ``names`` (mixed pairs averaged)."""
    return np.array([[getattr(params.contact(a, b), attr) for b in names] for a in names])


@dataclass(frozen=True)
class BondProperties:
    """Per-bond elastic and strength properties (arrays of length n_bonds)."""
    normal_stiffness: np.ndarray     # N/m
    shear_stiffness: np.ndarray      # N/m
    tensile_strength: np.ndarray     # Pa, J^T
    cohesion: np.ndarray             # Pa, J^C
    friction_angle: np.ndarray       # rad, phi
    residual_friction_angle: np.ndarray  # rad, phi_r
    residual_tensile_strength: np.ndarray  # Pa
    residual_cohesion: np.ndarray    # Pa


def bond_properties(specimen: Specimen, layout: ClumpLayout, params: Parameters) -> BondProperties:
    """Stiffness and strength of every bond (paper Tables 1 and 2, series springs).

    Grain elasticity acts in series with the contact stiffness of Table 2.
    For a bond of area A on a face between cells a and b, with l_a and l_b the
    distances from the cells' centroids to the face:

        k_n,bond = A / (1/k_n + l_a/E'_a + l_b/E'_b)
        k_s,bond = A / (1/k_s + l_a/G_a  + l_b/G_b)

    where k_n, k_s [Pa/m] are the pair's contact stiffnesses (Table 2, mixed
    pairs averaged), G = E/(2(1+nu)) and E' = E/(1-nu^2) in 2D (plane strain,
    as UDEC) or E' = E in 3D (Table 1).  Strengths are stresses [Pa]; the
    adapter multiplies them by A.  The calibration factors of
    ``params.calibration`` scale both stiffnesses and both strengths of every
    bond (one factor each, so Table 2's ratios stay).
    """
    t = specimen.tessellation
    names = specimen.mineral_names
    plane_strain = t.dim == 2
    grains = [params.grains[m] for m in names]
    e_mod = np.array([g.young / (1 - g.poisson**2) if plane_strain else g.young for g in grains])
    g_mod = np.array([g.shear_modulus for g in grains])
    table = {attr: mineral_pair_table(names, params, attr)
             for attr in ("normal_stiffness", "shear_stiffness", "tensile_strength", "cohesion", "friction_angle",
                          "residual_friction_angle", "residual_tensile_strength", "residual_cohesion")}
    face = layout.bond_face
    cells = t.face_cells[face]
    ma, mb = specimen.mineral[cells[:, 0]], specimen.mineral[cells[:, 1]]
    mid = t.face_midpoint[face]
    normal = t.face_normal[face]
    la = layout.series_fraction * np.abs(((mid - t.cell_centroid[cells[:, 0]]) * normal).sum(1))
    lb = layout.series_fraction * np.abs(((mid - t.cell_centroid[cells[:, 1]]) * normal).sum(1))
    area = layout.bond_area
    kn = area / (1 / table["normal_stiffness"][ma, mb] + la / e_mod[ma] + lb / e_mod[mb])
    ks = area / (1 / table["shear_stiffness"][ma, mb] + la / g_mod[ma] + lb / g_mod[mb])
    pick = {k: v[ma, mb] for k, v in table.items()}
    cal = params.calibration
    return BondProperties(normal_stiffness=kn * cal.stiffness_scale, shear_stiffness=ks * cal.stiffness_scale,
                          tensile_strength=pick["tensile_strength"] * cal.strength_scale,
                          cohesion=pick["cohesion"] * cal.strength_scale,
                          friction_angle=pick["friction_angle"],
                          residual_friction_angle=pick["residual_friction_angle"],
                          residual_tensile_strength=pick["residual_tensile_strength"],
                          residual_cohesion=pick["residual_cohesion"])


def cell_mass_inertia(specimen: Specimen, params: Parameters, density_scale: float = 1.0):
    """Mass [kg] and polar moment of inertia about the centroid [kg m^2] of each cell.

    2D: polygon area x thickness x density; inertia = density x thickness x J_z
    (polar second moment of the polygon).  3D: volume x density; inertia of the
    sphere of equal volume (rotations matter little for one-sphere cells).
    """
    t = specimen.tessellation
    rho = np.array([params.grains[m].density for m in specimen.mineral_names])[specimen.mineral] * density_scale
    if t.dim == 2:
        mass = rho * t.cell_measure * specimen.thickness
        jz = np.array([_polygon_polar_moment(v - c) for v, c in zip(t.cell_vertices, t.cell_centroid)])
        return mass, rho * specimen.thickness * jz
    mass = rho * t.cell_measure
    r = np.cbrt(3 * t.cell_measure / (4 * math.pi))
    return mass, 0.4 * mass * r**2


def step_floor_factors(cell_step, quantile: float) -> np.ndarray:
    """(n,) factors >= 1 on each cell's mass and inertia that raise every cell's own critical DEM step
    to at least the ``quantile`` of all cells' steps (per-cell density scaling; a step sqrt(m / k)
    grows as the square root of the factor).  ``quantile`` 0: all ones (off).  Statics do not depend
    on masses; only how fast the few stiffest, lightest cells (slivers) oscillate changes."""
    step = np.asarray(cell_step, float)
    if not 0.0 <= quantile <= 1.0:
        raise ValueError(f"quantile must lie in [0, 1], got {quantile!r}")
    if step.size == 0 or not np.all(np.isfinite(step) & (step > 0)):
        raise ValueError("every cell's critical step must be finite and positive")
    if quantile == 0.0:
        return np.ones_like(step)
    floor = float(np.quantile(step, quantile))
    return np.maximum(1.0, (floor / step) ** 2)


def _polygon_polar_moment(v: np.ndarray) -> float:
    """Polar second moment of area J_z = I_x + I_y of a CCW polygon about the origin [m^4]."""
    x, y = v[:, 0], v[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    ix = (cross * (y * y + y * yn + yn * yn)).sum() / 12.0
    iy = (cross * (x * x + x * xn + xn * xn)).sum() / 12.0
    return float(ix + iy)
