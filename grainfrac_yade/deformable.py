"""Deformable cells for the DEM: each Voronoi cell a cluster of spheres on its triangle mesh (pure numpy).

The cluster is an image of the static reference's mesh
(:func:`grainfrac_yade.grainmesh.grain_mesh`, contacts at the face corners):

* one sphere per mesh node, the mesh shrunk about the cell's centroid by
  ``1 - inset`` so that the two nodes of a contact pair (one in each cell, at
  the same point of their face) become two spheres a short distance apart,
  along the line of the two centroids;
* unbreakable *links* along the mesh edges, whose normal and shear springs are
  fitted per triangle (non-negative least squares) to the triangle's
  plane-strain stiffness ``A D`` of its mineral (Table 1) under uniform strain:
  a normal spring k on an edge of length L and direction n stores
  ``k L^2 (n.eps.n)^2 / 2``, a shear spring g stores ``g L^2 (t.eps.n)^2 / 2``;
* the breakable Table 2 *bonds* between the spheres of each contact pair,
  carrying the pair's share of the face, with the strip of grain between the
  sphere and the face (``inset`` x the centroid-face distance) in series, as
  :func:`grainfrac_yade.layout.bond_properties` does for rigid cells.

The spheres do not rotate (the adapter blocks their rotation): YADE's shear
kinematics take lever arms equal to the sphere radii, which for links much
longer than the spheres makes a rotating lattice resist rigid rotation and
gave contact shear tails 2-3 times the mesh reference's in static solves; with
translations only, a link is a plain two-node spring.

Sphere masses lump one third of each adjacent triangle's (unshrunk) area, so a
cell's spheres carry its whole mass.  Radii are half the distance to the
nearest other sphere: no two spheres overlap at the start, so the collider
makes no contact that is not a bond or a link.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import nnls

from .elastic import plane_strain_matrix
from .grainmesh import grain_mesh
from .layout import ClumpLayout
from .params import Parameters
from .specimen import Specimen

#: Fraction of the way from a face node to its cell's centroid by which each sphere is moved in [1].
#: Small enough that the cluster spans nearly the whole cell, large enough that the two spheres of
#: a contact pair are distinct (about 0.05 mm apart for 1 mm grains).  Static solves of 10 x 20 mm,
#: seed 1, 2 nodes per face: insets 0.05 / 0.1 / 0.2 gave a contact shear p99 of 0.69 / 0.63 / 0.55
#: of the applied stress against the mesh reference's 0.87 (larger insets put more grain in series
#: with the bonds and less in the links).
DEFAULT_INSET = 0.05
#: Shear stiffness of normal-only links as a fraction of their normal stiffness [1]: keeps every
#: sphere's rotation restrained (a static solve stays regular) without acting on the strain.
LINK_SHEAR_FLOOR = 1e-3


def _edge_coefficients(d: np.ndarray):
    """Voigt rows (xx, yy, 2xy) of the normal and shear strain of edges with unit directions ``d`` (k, 2)."""
    nx, ny = d[:, 0], d[:, 1]
    tx, ty = -ny, nx
    normal = np.column_stack([nx * nx, ny * ny, nx * ny])
    shear = np.column_stack([tx * nx, ty * ny, 0.5 * (tx * ny + ty * nx)])
    return normal, shear


_UPPER = np.triu_indices(3)


def fit_triangle_springs(corners: np.ndarray, target: np.ndarray, shear: bool = True) -> np.ndarray:
    """Non-negative normal and shear springs on the 3 edges of a triangle matching ``target``.

    ``corners`` (3, 2) [m]; ``target`` (3, 3) the Voigt stiffness x area [N/m x m^2 = N m] to
    match under uniform strain.  Returns (3, 2): (k_n, k_s) [N/m] of edges (0,1), (1,2), (2,0).
    """
    ends = np.roll(corners, -1, axis=0) - corners
    length = np.linalg.norm(ends, axis=1)
    normal, shear_row = _edge_coefficients(ends / length[:, None])
    columns = [(length[e] ** 2 * np.outer(normal[e], normal[e]))[_UPPER] for e in range(3)]
    if shear:
        columns += [(length[e] ** 2 * np.outer(shear_row[e], shear_row[e]))[_UPPER] for e in range(3)]
    k, _ = nnls(np.column_stack(columns), target[_UPPER])
    out = np.zeros((3, 2))
    out[:, 0] = k[:3]
    if shear:
        out[:, 1] = k[3:]
    return out


def build_deformable_layout(specimen: Specimen, params: Parameters, inset: float = DEFAULT_INSET,
                            link_shear: bool = True, rings: int = 1) -> ClumpLayout:
    """Deformable cells of ``specimen`` at ``resolution.nodes_per_face`` contact nodes per face."""
    t = specimen.tessellation
    mesh = grain_mesh(specimen, params.resolution.nodes_per_face, "corners", rings)
    centroid = t.cell_centroid[mesh.node_cell]
    pos = centroid + (1.0 - inset) * (mesh.node_pos - centroid)
    # lumped areas (unshrunk triangles) and link springs fitted per (shrunk) triangle
    area = mesh.triangle_areas()
    sphere_area = np.bincount(mesh.triangles.ravel(), weights=np.repeat(area / 3, 3), minlength=mesh.n_nodes)
    names = specimen.mineral_names
    d_min = plane_strain_matrix([params.grains[m].young for m in names], [params.grains[m].poisson for m in names])
    d_min = d_min * specimen.thickness
    links = {}
    for tri, cell, a in zip(mesh.triangles, mesh.triangle_cell, area):
        springs = fit_triangle_springs(pos[tri], a * d_min[specimen.mineral[cell]], link_shear)
        for e in range(3):
            i, j = int(tri[e]), int(tri[(e + 1) % 3])
            key = (min(i, j), max(i, j))
            links[key] = links.get(key, 0.0) + springs[e]
    link_pairs = np.array(sorted(links), dtype=np.int64)
    link_k = np.array([links[tuple(p)] for p in link_pairs])
    if not link_shear:
        link_k[:, 1] = LINK_SHEAR_FLOOR * link_k[:, 0]
    # radii: half the distance to the nearest other sphere
    from scipy.spatial import cKDTree
    dist, _ = cKDTree(pos).query(pos, k=2)
    radius = 0.5 * dist[:, 1]
    faces = mesh.contact_face
    z = specimen.thickness / 2.0
    pos3 = np.column_stack([pos, np.full(len(pos), z)])
    points = mesh.node_pos[mesh.contact_nodes[:, 0]]     # the contact point on the face
    return ClumpLayout(
        sphere_cell=mesh.node_cell.copy(), sphere_center=pos3, sphere_radius=radius,
        bond_spheres=mesh.contact_nodes.copy(), bond_face=faces.copy(),
        bond_area=mesh.contact_share * specimen.face_area[faces],
        bond_point=np.column_stack([points, np.full(len(points), z)]),
        rigid_cells=False, link_spheres=link_pairs, link_normal_stiffness=link_k[:, 0],
        link_shear_stiffness=link_k[:, 1], sphere_area=sphere_area, series_fraction=inset)
