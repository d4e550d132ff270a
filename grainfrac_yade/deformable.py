"""Deformable cells for the DEM: each Voronoi cell a cluster of spheres on its triangle mesh (pure numpy).

The cluster is an image of the static reference's mesh
(:func:`grainfrac_yade.grainmesh.grain_mesh`, contacts at the face corners,
``resolution.nodes_per_face`` per face):

* one sphere per mesh node, the mesh shrunk about the cell's centroid by
  ``1 - inset``, so that the two nodes of a contact pair (one in each cell, at
  the same point of their face) become two spheres a short distance apart,
  along the line of the two centroids;
* unbreakable *links* along the mesh edges, each a normal spring carrying the
  diagonal of its triangles' edge stiffness (:func:`edge_springs`, from the
  plane-strain moduli of Table 1), with no shear spring (``LINK_SHEAR_FRACTION``),
  all scaled by one factor (:func:`link_scale`) so that the specimen's Young's
  modulus is the mesh reference's;
* the breakable Table 2 *bonds* between the spheres of each contact pair,
  carrying the pair's share of the face, with the strip of grain between the
  sphere and the face (``inset`` x the centroid-face distance) in series, as
  :func:`grainfrac_yade.layout.bond_properties` does for rigid cells.

The spheres translate only and the scene takes the plain relative displacement
of two spheres as the shear displacement (the adapter sets both), so every link
and bond is a two-node spring: the model that
:func:`grainfrac_yade.elastic.cluster_network` solves statically.  Rotating
spheres, whose shear lever arms in YADE are the sphere radii, tripled the
contact shear tail of the static solve.

A pair spring cannot carry the coupling between the elongations of a triangle's
edges, so the lattice is not the mesh: with E matched, Poisson's ratio and the
contact shear tail are what the validation compares (README, "Deformable
grains").  Masses: :func:`stiffness_lumped_area`.  Radii are half the distance
to the nearest other sphere: no two spheres overlap at the start, so the
collider makes no contact that is not a bond or a link.
"""
from __future__ import annotations

import dataclasses

import numpy as np
from scipy.spatial import cKDTree

from .elastic import plane_strain_matrix
from .errors import GrainfracError
from .grainmesh import grain_mesh
from .layout import ClumpLayout, bond_properties
from .params import Parameters
from .specimen import Specimen

#: Shear stiffness of the links as a fraction of their normal stiffness [1].  The spheres do not
#: rotate, so a link's shear spring acts on the relative translation of its ends and resists the
#: rigid rotation of its edge: a cell with such links resists turning as a whole, which no grain
#: does (a 4 x 8 mm specimen with shear springs near the normal ones reached a UCS of 1451 MPa,
#: 6 x its rigid-cell value).  Normal springs alone are objective; the triangulated cluster stays
#: rigid against every deformation without them.  Static solves (10 x 20 mm, seeds 1, 3, 5, inset
#: 0.05): 0 / 0.01 / 0.05 gave Poisson's ratio +9 / +7 / 0 % against the mesh reference.
LINK_SHEAR_FRACTION = 0.0
#: How much stiffer the contacts are made when :func:`link_scale` measures the grains alone [1].
PATCH_CONTACT_FACTOR = 1e4
#: :func:`contact_radii`: fraction of the largest radius at which unbonded spheres of different cells
#: would touch at the start [1].  At 1 two corner spheres at the ends of a face touch at its middle
#: (a 4 x 8 mm elastic ramp made 62 such contacts and moved bond forces by 6 %); at 0.5 unbonded
#: spheres meet only after a face has slid by about half its length, and a broken bond keeps its
#: faces in contact while they slide by up to a quarter of the shorter adjacent face.
CONTACT_RADIUS_FRACTION = 0.5
#: :func:`link_scale`: relative tolerance on the lattice's Young's modulus and most secant steps.
LINK_SCALE_TOLERANCE = 1e-4
LINK_SCALE_ITERATIONS = 8


def edge_springs(corners: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Normal springs [N/m] on the 3 edges (0,1), (1,2), (2,0) of a triangle standing for ``target``.

    Under uniform strain eps (Voigt xx, yy, 2xy) the edges elongate by delta = M eps with
    ``M[e] = L_e (n_x^2, n_y^2, n_x n_y)``, a one-to-one map for a non-degenerate triangle, so the
    triangle's strain energy ``eps^T T eps / 2`` (``target`` T = area x D x thickness [N m]) is
    ``delta^T S delta / 2`` with the edge stiffness S = M^-T T M^-1.  A spring joins two nodes
    only, so it can carry the diagonal of S, never its coupling terms: the springs are diag(S),
    positive for every triangle (S is positive definite), so no triangle is a mechanism.
    """
    ends = np.roll(corners, -1, axis=0) - corners
    length = np.linalg.norm(ends, axis=1)
    n = ends / length[:, None]
    m_inv = np.linalg.inv(length[:, None] * np.column_stack([n[:, 0] ** 2, n[:, 1] ** 2, n[:, 0] * n[:, 1]]))
    return np.diag(m_inv.T @ target @ m_inv).copy()


def _shrunk_mesh(specimen: Specimen, params: Parameters, inset: float):
    """The reference's mesh (contacts at the face corners) and its node positions shrunk by
    1 - inset about each cell's centroid [m]."""
    t = specimen.tessellation
    mesh = grain_mesh(specimen, params.resolution.nodes_per_face, "corners")
    centroid = t.cell_centroid[mesh.node_cell]
    return mesh, centroid + (1.0 - inset) * (mesh.node_pos - centroid)


def _cluster_geometry(specimen: Specimen, params: Parameters, inset: float):
    """Mesh, sphere centres (the mesh shrunk by 1 - inset about each centroid), link pairs and their
    unscaled springs [N/m] (one link per mesh edge, :func:`edge_springs` summed over its triangles)."""
    mesh, pos = _shrunk_mesh(specimen, params, inset)
    names = specimen.mineral_names
    d_min = plane_strain_matrix([params.grains[m].young for m in names],
                                [params.grains[m].poisson for m in names]) * specimen.thickness
    tri_area = mesh.triangle_areas()
    k = np.array([edge_springs(pos[tri], a * d_min[specimen.mineral[c]])
                  for tri, c, a in zip(mesh.triangles, mesh.triangle_cell, tri_area)])
    edges = np.concatenate([mesh.triangles[:, [0, 1]], mesh.triangles[:, [1, 2]], mesh.triangles[:, [2, 0]]])
    pairs, inverse = np.unique(np.sort(edges, axis=1), axis=0, return_inverse=True)
    return mesh, pos, pairs, np.bincount(inverse.ravel(), weights=k.T.ravel())


def link_scale(specimen: Specimen, params: Parameters, inset: float,
               unscaled: ClumpLayout | None = None) -> float:
    """Factor on every link so that the specimen has the deformable-block reference's stiffness [1].

    Dropping the coupling terms of the edge stiffness (:func:`edge_springs`) makes a cluster too
    stiff, by a factor set by the shapes of the triangles.  First guess: the specimen all of its
    most abundant mineral, contacts ``PATCH_CONTACT_FACTOR`` x stiffer (the grains alone), solved
    as the triangle mesh and as the lattice; the ratio of the two Young's moduli.  Then, with the
    real contacts, the factor is refined by the secant method until the lattice's Young's modulus
    equals the mesh reference's (:func:`grainfrac_yade.elastic.deformable_network`, same contact
    nodes, same platens) within ``LINK_SCALE_TOLERANCE``.  Poisson's ratio and the contact stress
    tail are not fitted: they validate the lattice.  ``unscaled``: the specimen's layout before
    scaling (:func:`_layout`), when the caller has it.
    """
    from .elastic import deformable_network, cluster_network, solve_uniaxial
    from .specimen import specimen_from_tessellation
    k = params.resolution.nodes_per_face
    stiff = dataclasses.replace(params, calibration=dataclasses.replace(
        params.calibration, stiffness_scale=params.calibration.stiffness_scale * PATCH_CONTACT_FACTOR))
    main = int(np.argmax(np.bincount(specimen.mineral, weights=specimen.tessellation.cell_measure)))
    one = specimen_from_tessellation(specimen.tessellation, np.full(specimen.n_cells, main),
                                     specimen.mineral_names, specimen.thickness, specimen.seed)
    guess = (solve_uniaxial(deformable_network(one, stiff, k), one).young
             / solve_uniaxial(cluster_network(one, stiff, _layout(one, stiff, inset)), one).young)
    target = solve_uniaxial(deformable_network(specimen, params, k), specimen).young
    unscaled = unscaled or _layout(specimen, params, inset)

    def misfit(scale):
        lattice = cluster_network(specimen, params, _scaled(unscaled, scale))
        return solve_uniaxial(lattice, specimen).young / target - 1.0

    a, b = guess, 1.2 * guess
    fa, fb = misfit(a), misfit(b)
    for _ in range(LINK_SCALE_ITERATIONS):
        if abs(fb) < LINK_SCALE_TOLERANCE or fb == fa:
            break
        a, b, fa = b, b - fb * (b - a) / (fb - fa), fb
        fb = misfit(b)
    return float(b)


def build_deformable_layout(specimen: Specimen, params: Parameters) -> ClumpLayout:
    """Deformable cells of ``specimen`` at ``resolution.nodes_per_face`` contact nodes per face and
    ``resolution.contact_inset`` (see module doc), links scaled by :func:`link_scale`."""
    inset = params.resolution.contact_inset
    unscaled = _layout(specimen, params, inset)
    layout = _scaled(unscaled, link_scale(specimen, params, inset, unscaled))
    return dataclasses.replace(layout, sphere_area=stiffness_lumped_area(specimen, params, layout))


def stiffness_lumped_area(specimen: Specimen, params: Parameters, layout: ClumpLayout) -> np.ndarray:
    """Each cell's area shared among its spheres in proportion to their spring stiffness [m^2].

    Masses act only on the dynamics of these quasi-static tests, not on any equilibrium: spread so,
    every sphere of a cell has the same oscillation period sqrt(m/K), and the critical DEM step is
    about twice as long as with the triangles' areas lumped on their corners (10 x 20 mm, seed 1:
    1.07e-7 against 5.2e-8 s at density scale 100).  Each cell keeps its whole mass.
    """
    props = bond_properties(specimen, layout, params)
    ends = np.concatenate([layout.bond_spheres, layout.link_spheres])
    k = np.concatenate([props.normal_stiffness + props.shear_stiffness,
                        layout.link_normal_stiffness + layout.link_shear_stiffness])
    k_sphere = np.bincount(ends.ravel(), weights=np.repeat(k, 2), minlength=layout.n_spheres)
    k_cell = np.bincount(layout.sphere_cell, weights=k_sphere, minlength=specimen.n_cells)
    return specimen.tessellation.cell_measure[layout.sphere_cell] * k_sphere / k_cell[layout.sphere_cell]


def _scaled(layout: ClumpLayout, scale: float) -> ClumpLayout:
    """``layout`` with every link's springs multiplied by ``scale``."""
    link_k = layout.link_normal_stiffness * scale
    return dataclasses.replace(layout, link_normal_stiffness=link_k, link_shear_stiffness=LINK_SHEAR_FRACTION * link_k)


def build_fem_layout(specimen: Specimen, params: Parameters) -> ClumpLayout:
    """Finite-element cells (``grain_model = "fem"``): the spheres and bonds of
    :func:`build_deformable_layout`, and in place of links each triangle of the shrunk mesh a
    constant-strain element with its mineral's Table 1 moduli (plane strain), so that the cluster
    is the reference's mesh itself: no fitted factor, Poisson's coupling included.

    Masses: each cell's area shared among its spheres in proportion to their Gershgorin stiffness
    (:func:`grainfrac_yade.elastic.node_stiffness`), so that every sphere of a cell has the same
    bound on its oscillation period (the reasoning of :func:`stiffness_lumped_area`).
    """
    from .elastic import cluster_network, node_stiffness
    inset = params.resolution.contact_inset
    mesh, pos = _shrunk_mesh(specimen, params, inset)
    layout = _sphere_layout(specimen, mesh, pos, inset, None, None)
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


def _layout(specimen: Specimen, params: Parameters, inset: float) -> ClumpLayout:
    """The deformable layout with unscaled links (scale 1) and the triangles' lumped areas."""
    mesh, pos, link_pairs, link_k = _cluster_geometry(specimen, params, inset)
    return _sphere_layout(specimen, mesh, pos, inset, link_pairs, link_k)


def _sphere_layout(specimen: Specimen, mesh, pos: np.ndarray, inset: float, link_pairs, link_k) -> ClumpLayout:
    """One sphere per node of ``mesh`` at ``pos``, bonds between contact pairs, links if given, the
    triangles' areas lumped on their corners."""
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
        rigid_cells=False, link_spheres=link_pairs, link_normal_stiffness=link_k,
        link_shear_stiffness=None if link_k is None else LINK_SHEAR_FRACTION * link_k, sphere_area=sphere_area,
        series_fraction=inset)
