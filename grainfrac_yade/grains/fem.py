"""Finite-element cells for the DEM: each Voronoi cell a cluster of spheres on its triangle mesh (pure numpy).

The cluster is an image of the static reference's mesh
(:func:`grainfrac_yade.geometry.grainmesh.grain_mesh`, contacts at the face corners,
``resolution.nodes_per_face`` per face, ``resolution.cell_rings`` radial rings: 1 = one fan of
triangles about the centroid):

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

Masses and the critical DEM step: each cell's mass is shared among its spheres in proportion to the
Gershgorin bound K of each sphere's stiffness row (elements and bonds,
:func:`grainfrac_yade.elastic.node_stiffness`, assembled once when the layout is built), so that
every sphere of a cell has the same bound sqrt(m / K) on its oscillation period; the scene's step is
the smallest, after ``numerics.step_floor_quantile``.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from scipy.spatial import cKDTree

from ..dem_step import lift_short_steps
from ..elastic import cluster_network, node_stiffness
from ..errors import GrainfracError
from ..geometry.grainmesh import grain_mesh
from ..layout import BondProperties, ClumpLayout, cell_mass_inertia
from ..params import Parameters
from ..geometry.specimen import Specimen
from ._interface import GrainModel

NAME = "fem"

#: :func:`contact_radii`: fraction of the largest radius at which unbonded spheres of different cells
#: would touch at the start [1].  At 1 two corner spheres at the ends of a face touch at its middle
#: (a 4 x 8 mm elastic ramp made 62 such contacts and moved bond forces by 6 %); at 0.5 unbonded
#: spheres meet only after a face has slid by about half its length, and a broken bond keeps its
#: faces in contact while they slide by up to a quarter of the shorter adjacent face.
CONTACT_RADIUS_FRACTION = 0.5
#: Blocked DOFs of the spheres of fem cells: in-plane translation only, the two-node springs and
#: plane elements that the static solve (:func:`grainfrac_yade.elastic.cluster_network`) assumes.
#: Measured on the retired spring lattice (4 x 8 mm, seed 1, 2 nodes per face, axial strain 3e-4):
#: "zXYZ" with plain kinematics (below) gave the static solve's E and nu (89.8 against 89.6 GPa,
#: 0.208 against 0.209); "zXY" (free spin, as rigid cells) with YADE's default kinematics gave
#: E 80.5 GPa, nu 0.255 and a DEM step 4.6 x shorter (the rotation of the smallest spheres sets it).
BLOCKED_DOFS = "zXYZ"
#: Why a resumed run of fem cells is not bit-identical (measured: 3 x 6 mm fem UCS resumed at DEM step
#: 20,179: E -6e-5, crack initiation -4e-5, peak +5e-7 relative, the same 26 bonds broken in the same
#: modes, up to 17 DEM steps apart; docs/resuming.md).
RESUME_NOTE = ("finite-element cells: YADE keys an element's nodes by their memory address, which O.load changes, "
               "so the element sums its nodes in another order: the resumed run differs from an uninterrupted one "
               "by rounding that grows (measured: E within 1e-4 relative)")


@dataclass(frozen=True, kw_only=True)
class FemLayout(ClumpLayout):
    """The spheres and bonds of fem cells (every sphere a body of its own), and their elements."""
    #: (e, 3) sphere triangles: each a constant-strain element of its cell's mineral (plane strain,
    #: Table 1), the mesh on which the spheres sit
    element_spheres: np.ndarray
    #: (b, 2) unit normal of each bond's face (from the face's cell a to b): bonds act on their face's
    #: plane (YADE's smooth-joint kinematics: opening and sliding measured along and across the face,
    #: as the reference's contacts)
    bond_normal: np.ndarray
    #: (s,) cell area lumped on each sphere [m^2] (its mass share) and (s,) Gershgorin bound of its
    #: stiffness row [N/m] (:func:`grainfrac_yade.elastic.node_stiffness`); both set by
    #: :func:`build_fem_layout` once the elements are assembled
    sphere_area: np.ndarray | None = None
    sphere_stiffness: np.ndarray | None = None
    model: ClassVar[str] = NAME

    @property
    def n_elements(self) -> int:
        return len(self.element_spheres)


def _shrunk_mesh(specimen: Specimen, params: Parameters, inset: float):
    """The reference's mesh (contacts at the face corners, ``resolution.cell_rings`` radial rings) and its
    node positions shrunk by 1 - inset about each cell's centroid [m]."""
    t = specimen.tessellation
    mesh = grain_mesh(specimen, params.resolution.nodes_per_face, "corners", params.resolution.cell_rings,
                      params.resolution.cell_ring_growth)
    centroid = t.cell_centroid[mesh.node_cell]
    return mesh, centroid + (1.0 - inset) * (mesh.node_pos - centroid)


def build_fem_layout(specimen: Specimen, params: Parameters) -> FemLayout:
    """Finite-element cells of ``specimen`` at ``resolution.nodes_per_face`` contact nodes per face and
    ``resolution.contact_inset`` (see module doc): one sphere per node of the shrunk mesh, bonds
    between contact pairs carrying each pair's share of the face, and each triangle a constant-strain
    element with its mineral's Table 1 moduli (plane strain), so that the cluster is the reference's
    mesh itself.  Each cell's area is shared among its spheres in proportion to their stiffness
    (module doc); each cell keeps its whole area, so its whole mass.
    """
    t = specimen.tessellation
    if t.dim != 2:
        raise GrainfracError("resolution.grain_model: fem cells are built for 2D specimens only; fix: use "
                             'grain_model = "rigid" with specimen.dimension = 3')
    inset = params.resolution.contact_inset
    mesh, pos = _shrunk_mesh(specimen, params, inset)
    faces = mesh.contact_face
    z = specimen.thickness / 2.0
    points = mesh.node_pos[mesh.contact_nodes[:, 0]]     # the contact point on the face
    layout = FemLayout(
        sphere_cell=mesh.node_cell.copy(), sphere_center=np.column_stack([pos, np.full(len(pos), z)]),
        sphere_radius=contact_radii(pos, mesh.node_cell, mesh.contact_nodes), bond_spheres=mesh.contact_nodes.copy(),
        bond_face=faces.copy(), bond_area=mesh.contact_share * specimen.face_area[faces],
        bond_point=np.column_stack([points, np.full(len(points), z)]), series_fraction=inset,
        element_spheres=mesh.triangles.copy(), bond_normal=t.face_normal[faces].copy())
    k_sphere = node_stiffness(cluster_network(specimen, params, layout))
    k_cell = np.bincount(layout.sphere_cell, weights=k_sphere, minlength=specimen.n_cells)
    area = t.cell_measure[layout.sphere_cell] * k_sphere / k_cell[layout.sphere_cell]
    return dataclasses.replace(layout, sphere_area=area, sphere_stiffness=k_sphere)


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


def sphere_mass_inertia(specimen: Specimen, layout: FemLayout, cell_mass: np.ndarray):
    """Mass [kg] and inertia [kg m^2] of each sphere.

    Mass: the cell's areal mass (cell mass / cell area, i.e. density x density scale x thickness)
    times the area lumped on the sphere (``layout.sphere_area``), so a cell's spheres carry its
    mass.  Inertia: a disc's 0.5 m r^2 on all three axes (pseudo-2D).
    """
    areal = cell_mass / specimen.tessellation.cell_measure
    mass = areal[layout.sphere_cell] * layout.sphere_area
    return mass, 0.5 * mass * layout.sphere_radius**2


class FemCells(GrainModel):
    """Each cell a cluster of spheres on its triangle mesh, held together by finite elements (module doc)."""
    name = NAME
    rotating = "Z" not in BLOCKED_DOFS
    resume_note = RESUME_NOTE
    bonds_on_faces = True

    def build_layout(self, specimen: Specimen, params: Parameters) -> FemLayout:
        return build_fem_layout(specimen, params)

    def masses_and_step(self, specimen: Specimen, params: Parameters, layout: FemLayout, props: BondProperties,
                        body_pos: np.ndarray | None = None) -> tuple:
        """Per sphere: (mass, inertia, critical step [s]): sqrt(m / K) with K ``layout.sphere_stiffness``."""
        cell_mass, _ = cell_mass_inertia(specimen, params, params.numerics.density_scale)
        k = layout.sphere_stiffness
        mass, inertia = sphere_mass_inertia(specimen, layout, cell_mass)
        floor = params.numerics.step_floor_quantile
        if floor > 0:
            mass, inertia = lift_short_steps(floor, np.sqrt(mass / k), layout.sphere_cell, mass, inertia)
        with np.errstate(divide="ignore"):
            return mass, inertia, float(np.sqrt(mass / k).min())


MODEL = FemCells()
