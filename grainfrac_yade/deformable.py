"""Finite-element cells for the DEM: each Voronoi cell a cluster of spheres on its triangle mesh (pure numpy).

The cluster is an image of the static reference's mesh
(:func:`grainfrac_yade.grainmesh.grain_mesh`, contacts at the face corners,
``resolution.nodes_per_face`` per face):

* one sphere per mesh node, the mesh shrunk about the cell's centroid by
  ``1 - inset``, so that the two nodes of a contact pair (one in each cell, at
  the same point of their face) become two spheres a short distance apart,
  along the line of the two centroids;
* each triangle of the shrunk mesh a constant-strain element with its mineral's
  Table 1 moduli (plane strain);
* the breakable Table 2 *bonds* between the spheres of each contact pair,
  carrying the pair's share of the face, with the strip of grain between the
  sphere and the face (``inset`` x the centroid-face distance) in series, as
  :func:`grainfrac_yade.layout.bond_properties` does for rigid cells.

The spheres translate only and the scene takes the plain relative displacement
of two spheres as the shear displacement (the adapter sets both), so every bond
is a two-node spring and every element the plane-strain triangle: the model that
:func:`grainfrac_yade.elastic.cluster_network` solves statically.
"""
from __future__ import annotations

import dataclasses

import numpy as np
from scipy.spatial import cKDTree

from .errors import GrainfracError
from .grainmesh import grain_mesh
from .layout import ClumpLayout
from .params import Parameters
from .specimen import Specimen

#: :func:`contact_radii`: fraction of the largest radius at which unbonded spheres of different cells
#: would touch at the start [1].  At 1 two corner spheres at the ends of a face touch at its middle
#: (a 4 x 8 mm elastic ramp made 62 such contacts and moved bond forces by 6 %); at 0.5 unbonded
#: spheres meet only after a face has slid by about half its length, and a broken bond keeps its
#: faces in contact while they slide by up to a quarter of the shorter adjacent face.
CONTACT_RADIUS_FRACTION = 0.5

def _shrunk_mesh(specimen: Specimen, params: Parameters, inset: float):
    """The reference's mesh (contacts at the face corners) and its node positions shrunk by
    1 - inset about each cell's centroid [m]."""
    t = specimen.tessellation
    mesh = grain_mesh(specimen, params.resolution.nodes_per_face, "corners")
    centroid = t.cell_centroid[mesh.node_cell]
    return mesh, centroid + (1.0 - inset) * (mesh.node_pos - centroid)


def build_fem_layout(specimen: Specimen, params: Parameters) -> ClumpLayout:
    """Finite-element cells (``grain_model = "fem"``) of ``specimen`` at ``resolution.nodes_per_face``
    contact nodes per face and ``resolution.contact_inset`` (see module doc): one sphere per node of
    the shrunk mesh, bonds between contact pairs, and each triangle a constant-strain element with
    its mineral's Table 1 moduli (plane strain), so that the cluster is the reference's mesh itself.

    Masses: each cell's area shared among its spheres in proportion to their Gershgorin stiffness
    (:func:`grainfrac_yade.elastic.node_stiffness`), so that every sphere of a cell has the same
    bound on its oscillation period sqrt(m/K), and the critical DEM step is as long as the cell
    allows.  Each cell keeps its whole mass.
    """
    from .elastic import cluster_network, node_stiffness
    inset = params.resolution.contact_inset
    mesh, pos = _shrunk_mesh(specimen, params, inset)
    layout = _sphere_layout(specimen, mesh, pos, inset)
    layout = dataclasses.replace(
        layout, element_spheres=mesh.triangles.copy(),
        bond_normal=specimen.tessellation.face_normal[layout.bond_face].copy(),
        sphere_radius=contact_radii(pos, layout.sphere_cell, layout.bond_spheres))
    k_sphere = node_stiffness(cluster_network(specimen, params, layout))
    k_cell = np.bincount(layout.sphere_cell, weights=k_sphere, minlength=specimen.n_cells)
    area = specimen.tessellation.cell_measure[layout.sphere_cell] * k_sphere / k_cell[layout.sphere_cell]
    return dataclasses.replace(layout, sphere_area=area)


def contact_radii(pos: np.ndarray, cell: np.ndarray, bonded: np.ndarray) -> np.ndarray:
    """(s,) sphere radii [m]: ``CONTACT_RADIUS_FRACTION`` x half the distance to the nearest sphere
    of another cell that is not bonded to it, so that no two unbonded spheres of different cells
    touch at the start, nor after any elastic deformation.

    Bonds acting on their face's plane (``ClumpLayout.bond_normal``) hold a broken face in contact
    while it slides by less than the smaller sphere's diameter (YADE's smooth joint), and spheres of
    different cells that come together later meet as new frictional contacts: the larger the radii,
    the longer a crack's faces keep touching.  Spheres of one cell never interact (the scene gives
    each cell its own collision mask).
    """
    n = len(pos)
    partners = {(int(a), int(b)) for a, b in bonded} | {(int(b), int(a)) for a, b in bonded}
    tree = cKDTree(pos)
    radius = np.full(n, np.inf)
    k = min(n, 16)
    while np.isinf(radius).any() and k <= n:
        todo = np.flatnonzero(np.isinf(radius))
        dist, idx = tree.query(pos[todo], k=k)
        for row, i in enumerate(todo):
            for d, j in zip(dist[row], idx[row]):
                if j < n and cell[j] != cell[i] and (int(i), int(j)) not in partners:
                    radius[i] = 0.5 * CONTACT_RADIUS_FRACTION * d
                    break
        if k == n:
            break
        k = min(n, 4 * k)
    if np.isinf(radius).any():
        raise GrainfracError("contact radii: a sphere has no unbonded sphere of another cell (a specimen of "
                             "one cell?); fix: use a larger specimen")
    return radius


def element_apex(triangles: np.ndarray) -> np.ndarray:
    """(e,) for each triangle one of its nodes, the fewest distinct nodes that cover all triangles
    (greedy: the node in most uncovered triangles first; a fan mesh's centroid covers its cell).

    YADE's elements are tetrahedra: each triangle becomes one, its fourth node lifted out of the
    plane above the apex and moving with it (see the adapter), which needs one lifted node per apex.
    """
    tri = np.asarray(triangles)
    apex = np.full(len(tri), -1, dtype=np.int64)
    while (apex < 0).any():
        open_tri = np.flatnonzero(apex < 0)
        counts = np.bincount(tri[open_tri].ravel())
        node = int(np.argmax(counts))
        apex[open_tri[(tri[open_tri] == node).any(axis=1)]] = node
    return apex


def _sphere_layout(specimen: Specimen, mesh, pos: np.ndarray, inset: float) -> ClumpLayout:
    """One sphere per node of ``mesh`` at ``pos``, bonds between contact pairs, the triangles' areas
    lumped on their corners."""
    area = mesh.triangle_areas()
    sphere_area = np.bincount(mesh.triangles.ravel(), weights=np.repeat(area / 3, 3), minlength=mesh.n_nodes)
    dist, _ = cKDTree(pos).query(pos, k=2)
    radius = 0.5 * dist[:, 1]                       # half the distance to the nearest other sphere
    faces = mesh.contact_face
    z = specimen.thickness / 2.0
    points = mesh.node_pos[mesh.contact_nodes[:, 0]]     # the contact point on the face
    return ClumpLayout(
        sphere_cell=mesh.node_cell.copy(), sphere_center=np.column_stack([pos, np.full(len(pos), z)]),
        sphere_radius=radius, bond_spheres=mesh.contact_nodes.copy(), bond_face=faces.copy(),
        bond_area=mesh.contact_share * specimen.face_area[faces],
        bond_point=np.column_stack([points, np.full(len(points), z)]),
        rigid_cells=False, sphere_area=sphere_area, series_fraction=inset)
