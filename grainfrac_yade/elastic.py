"""Static linear-elastic reference of a 2D specimen in uniaxial compression (pure numpy/scipy).

What a DEM model of the paper's grains should reproduce before anything breaks:
the specimen's Young's modulus and Poisson's ratio, and how strongly the
contacts concentrate stress (the tail of contact shear and tension over the
applied stress), which Eq. 7 turns exponentially into lifetimes.  Three
models of one specimen, all linear, all solved exactly by one sparse solve:

``rigid``
    The project's rigid cells: one body per cell (translation + rotation) and
    the YADE bonds of :mod:`grainfrac_yade.grains.rigid` with their
    series stiffness, with YADE's contact kinematics (normal along the line of
    sphere centres; rotations act on lever arms equal to the sphere radii, as
    ``Ig2_Sphere_Sphere_ScGeom`` with ``avoidGranularRatcheting``).
``mesh``
    The paper's deformable UDEC blocks: each cell a fan of linear (constant
    strain) triangles from its centroid, plane strain with its mineral's
    Table 1 moduli; cells joined at face nodes by Table 2 springs (k_n, k_s
    [Pa/m] x the node's share of the face).  ``contacts="corners"`` puts the
    K nodes of a face at equal spacing including both ends, each carrying its
    trapezoid share (K = 2: UDEC's corner sub-contacts, each half the face);
    ``contacts="midpoints"`` puts them at the centres of K equal sub-segments,
    each carrying 1/K of the face.
``fem``
    The YADE finite-element cells (:mod:`grainfrac_yade.grains.fem`) solved
    statically: every sphere a body (translation only), bonds as YADE springs,
    and the cell's interior as the constant-strain triangles on which the
    spheres sit.

Loading: the cells with a face on the top (bottom) wall form rigid-in-y
platens closing by ``strain`` x height (rotation blocked, lateral motion free,
as :mod:`grainfrac_yade.engines.yade.platens`); one lateral degree of freedom
is pinned.  Ratios do not depend on the applied strain (linear model).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .errors import GrainfracError
from .geometry.grainmesh import grain_mesh
from .layout import ClumpLayout, bond_properties, mineral_pair_table
from .params import Parameters
from .geometry.specimen import Specimen

#: Applied axial strain [1]; any value gives the same ratios and moduli (linear model).
DEFAULT_STRAIN = 1e-4
#: Rotational stiffness added to every rotation, relative to the largest [1]: pins the free rolling
#: of two spheres joined by one bond without changing any force (the rigid solve moves by < 1e-9).
ROLLING_REGULARISATION = 1e-12


@dataclass
class Network:
    """Nodes with 2 (or 3, with rotation) degrees of freedom, springs and constant-strain triangles.

    Springs act at a contact point: the relative displacement there is
    ``(u_b + theta_b z x arm_b) - (u_a + theta_a z x arm_a)``, split into its
    normal (along ``normal``, a -> b; opening positive) and tangential parts.
    Springs with a finite ``area`` are contacts (bonds), the others internal links.
    """
    node_pos: np.ndarray        # (n, 2) [m]
    node_rotates: np.ndarray    # (n,) bool: has a rotation degree of freedom
    node_cell: np.ndarray       # (n,) cell of each node
    spring_nodes: np.ndarray    # (m, 2)
    spring_normal: np.ndarray   # (m, 2) unit
    spring_arm: np.ndarray      # (m, 2, 2) lever arms of sides a and b [m]
    spring_kn: np.ndarray       # (m,) [N/m]
    spring_ks: np.ndarray       # (m,) [N/m]
    spring_area: np.ndarray     # (m,) [m^2]; NaN for internal links
    spring_face: np.ndarray     # (m,) face index; -1 for internal links
    tri_nodes: np.ndarray       # (e, 3)
    tri_stiffness: np.ndarray   # (e, 3, 3) plane-strain D x thickness [N/m]
    #: (m, 2, 2) lever arms of the forces' torques where they differ from the kinematic arms
    #: (YADE: the contact point, radius - penetration/2, while the shear increment uses the radius)
    spring_torque_arm: np.ndarray | None = None
    #: (m,) factor on the relative translation in the shear displacement (YADE's
    #: ``avoidGranularRatcheting``: (r_a + r_b) / distance, which makes a rigid rotation shear-free)
    spring_shear_translation_scale: np.ndarray | None = None

    @property
    def n_nodes(self) -> int:
        return len(self.node_pos)


def plane_strain_matrix(young: np.ndarray, poisson: np.ndarray) -> np.ndarray:
    """(k, 3, 3) plane-strain elasticity matrices D [Pa] (Voigt: xx, yy, 2xy) of isotropic grains (Table 1)."""
    e, nu = np.asarray(young, float), np.asarray(poisson, float)
    f = e / ((1 + nu) * (1 - 2 * nu))
    d = np.zeros((len(e), 3, 3))
    d[:, 0, 0] = d[:, 1, 1] = f * (1 - nu)
    d[:, 0, 1] = d[:, 1, 0] = f * nu
    d[:, 2, 2] = f * (1 - 2 * nu) / 2
    return d


# --------------------------------------------------------------------------- assembly and solve
def _dof_map(net: Network):
    """(n, 3) global dof index of (ux, uy, theta) per node; -1 where a node has no rotation."""
    n = net.n_nodes
    dofs = np.full((n, 3), -1, dtype=np.int64)
    per_node = np.where(net.node_rotates, 3, 2)
    start = np.concatenate([[0], np.cumsum(per_node)[:-1]])
    dofs[:, 0] = start
    dofs[:, 1] = start + 1
    dofs[net.node_rotates, 2] = start[net.node_rotates] + 2
    return dofs, int(per_node.sum())


def _spring_rows(net: Network, dofs: np.ndarray, arm=None, shear_scale=None):
    """Dof indices (m, 6) and coefficients of the normal and tangential relative displacement (m, 6).

    ``shear_scale`` multiplies the relative translation in the tangential row.  With ``arm`` = the
    torque arms and no scale, the same rows are the generalised forces of unit spring forces.
    """
    arm = net.spring_arm if arm is None else arm
    n = net.spring_normal
    t = np.column_stack([-n[:, 1], n[:, 0]])
    a, b = net.spring_nodes[:, 0], net.spring_nodes[:, 1]
    idx = np.column_stack([dofs[a, 0], dofs[a, 1], dofs[a, 2], dofs[b, 0], dofs[b, 1], dofs[b, 2]])

    def coefficients(d, scale=1.0):
        # z x arm = (-arm_y, arm_x); its component along d is the rotation's lever
        lever_a = d[:, 0] * -arm[:, 0, 1] + d[:, 1] * arm[:, 0, 0]
        lever_b = d[:, 0] * -arm[:, 1, 1] + d[:, 1] * arm[:, 1, 0]
        ds = d * np.reshape(scale, (-1, 1))
        return np.column_stack([-ds[:, 0], -ds[:, 1], -lever_a, ds[:, 0], ds[:, 1], lever_b])

    return idx, coefficients(n), coefficients(t, 1.0 if shear_scale is None else shear_scale)


def _triangle_b(net: Network):
    """(e, 3, 6) strain-displacement matrices and (e,) areas of the constant-strain triangles."""
    p = net.node_pos[net.tri_nodes]                      # (e, 3, 2)
    x, y = p[..., 0], p[..., 1]
    b = np.roll(y, -1, axis=1) - np.roll(y, 1, axis=1)   # y_j - y_k
    c = np.roll(x, 1, axis=1) - np.roll(x, -1, axis=1)   # x_k - x_j
    area = 0.5 * (x[:, 0] * b[:, 0] + x[:, 1] * b[:, 1] + x[:, 2] * b[:, 2])
    if np.any(area <= 0):
        raise GrainfracError("elastic reference: a grain triangle has no area (degenerate cell); "
                             "fix: use another seed or fewer Lloyd iterations")
    bm = np.zeros((len(p), 3, 6))
    bm[:, 0, 0::2] = b
    bm[:, 1, 1::2] = c
    bm[:, 2, 0::2] = c
    bm[:, 2, 1::2] = b
    return bm / (2 * area[:, None, None]), area


def stiffness_matrix(net: Network):
    """Global sparse stiffness matrix and the dof map."""
    dofs, ndof = _dof_map(net)
    rows, cols, vals = [], [], []
    idx, cn, ct = _spring_rows(net, dofs, shear_scale=net.spring_shear_translation_scale)
    _, fn, ft = _spring_rows(net, dofs, net.spring_torque_arm)
    for k, c, f in ((net.spring_kn, cn, fn), (net.spring_ks, ct, ft)):
        block = k[:, None, None] * f[:, :, None] * c[:, None, :]
        rows.append(np.repeat(idx, 6, axis=1).ravel())
        cols.append(np.tile(idx, (1, 6)).ravel())
        vals.append(block.reshape(len(k), -1).ravel())
    if len(net.tri_nodes):
        bm, area = _triangle_b(net)
        ke = area[:, None, None] * np.einsum("eji,ejk,ekl->eil", bm, net.tri_stiffness, bm)
        tidx = dofs[net.tri_nodes][:, :, :2].reshape(-1, 6)
        rows.append(np.repeat(tidx, 6, axis=1).ravel())
        cols.append(np.tile(tidx, (1, 6)).ravel())
        vals.append(ke.reshape(len(ke), -1).ravel())
    rows, cols, vals = (np.concatenate(v) for v in (rows, cols, vals))
    keep = (rows >= 0) & (cols >= 0)
    k = sp.coo_matrix((vals[keep], (rows[keep], cols[keep])), shape=(ndof, ndof)).tocsr()
    return k, dofs


@dataclass(frozen=True)
class ElasticSolution:
    """Displacements, moduli and contact forces of one static solve."""
    young: float                 # E = applied stress / axial strain [Pa]
    poisson: float               # lateral expansion / axial shortening [1]
    applied_stress: float        # platen stress, compression positive [Pa]
    strain: float                # applied axial strain [1]
    normal_force: np.ndarray     # (m,) per spring, tension positive [N]
    shear_force: np.ndarray      # (m,) per spring, signed along the tangent [N]
    displacement: np.ndarray     # (n, 3) ux, uy, theta per node (theta 0 where not a dof)


def solve_uniaxial(net: Network, specimen: Specimen, strain: float = DEFAULT_STRAIN,
                   platens: str = "cells") -> ElasticSolution:
    """Compress ``net`` between smooth rigid platens by ``strain`` and solve the static equilibrium.

    ``platens="cells"``: every node of the cells touching the top (bottom) wall
    moves with the platen, as the YADE tests drive them; ``"wall"``: only the
    nodes lying on the walls (triangle meshes; the patch test).
    """
    t = specimen.tessellation
    width, height = float(t.box[0]), float(t.box[1])
    if platens == "cells":
        top = np.isin(net.node_cell, t.cells_on_side("top"))
        bottom = np.isin(net.node_cell, t.cells_on_side("bottom")) & ~top
    elif platens == "wall":
        tol = 1e-9 * height
        top = np.abs(net.node_pos[:, 1] - height) < tol
        bottom = np.abs(net.node_pos[:, 1]) < tol
    else:
        raise GrainfracError(f"elastic: platens {platens!r} unknown; fix: use 'cells' or 'wall'")
    k, dofs = stiffness_matrix(net)
    ndof = k.shape[0]
    u = np.zeros(ndof)
    fixed = np.zeros(ndof, dtype=bool)
    u[dofs[top, 1]] = -0.5 * strain * height
    u[dofs[bottom, 1]] = 0.5 * strain * height
    fixed[dofs[top | bottom, 1]] = True
    rot = dofs[top | bottom, 2]
    fixed[rot[rot >= 0]] = True
    fixed[dofs[np.flatnonzero(bottom)[0], 0]] = True     # pin the lateral rigid translation
    free = ~fixed
    # Two spheres joined by a single bond may roll on each other at no cost (JCFpm has no rolling
    # stiffness): forces do not depend on that mode, so a vanishing rotational stiffness pins it.
    rot_dofs = dofs[:, 2][dofs[:, 2] >= 0]
    if len(rot_dofs):
        k = k + sp.csr_matrix((np.full(len(rot_dofs), ROLLING_REGULARISATION * np.abs(k.diagonal()[rot_dofs]).max()),
                               (rot_dofs, rot_dofs)), shape=k.shape)
    kff = k[free][:, free].tocsc()
    rhs = -k[free][:, fixed] @ u[fixed]
    u[free] = spla.spsolve(kff, rhs)
    if not np.all(np.isfinite(u)):
        raise GrainfracError("elastic reference: the stiffness matrix is singular (a cell or sphere "
                             "is not connected); fix: check the specimen's bonds")
    reaction = k @ u
    stress = 0.5 * (reaction[dofs[bottom, 1]].sum() - reaction[dofs[top, 1]].sum()) / (width * specimen.thickness)
    if platens == "wall":
        left = np.abs(net.node_pos[:, 0]) < 1e-9 * width
        right = np.abs(net.node_pos[:, 0] - width) < 1e-9 * width
    else:
        left = np.isin(net.node_cell, t.cells_on_side("left"))
        right = np.isin(net.node_cell, t.cells_on_side("right"))
    lateral = (u[dofs[right, 0]].mean() - u[dofs[left, 0]].mean()) / width
    idx, cn, ct = _spring_rows(net, dofs, shear_scale=net.spring_shear_translation_scale)
    uu = np.where(idx >= 0, u[np.maximum(idx, 0)], 0.0)
    disp = np.column_stack([u[dofs[:, 0]], u[dofs[:, 1]], np.where(dofs[:, 2] >= 0, u[np.maximum(dofs[:, 2], 0)], 0)])
    return ElasticSolution(young=stress / strain, poisson=lateral / strain, applied_stress=stress, strain=strain,
                           normal_force=net.spring_kn * (cn * uu).sum(1),
                           shear_force=net.spring_ks * (ct * uu).sum(1), displacement=disp)


# --------------------------------------------------------------------------- statistics
def contact_statistics(net: Network, sol: ElasticSolution) -> dict:
    """Contact stresses over the applied stress: per contact spring and summed per face.

    Shear: |F_s| / area; tension: max(F_n, 0) / area (compression counts as 0).
    Keys ``shear_stress_ratio_p50/p99/max``, ``tension_stress_ratio_p50/p99/max``
    and the same with ``face_`` for forces summed over each face's springs
    divided by the face's contact area.
    """
    c = np.isfinite(net.spring_area)
    area, face = net.spring_area[c], net.spring_face[c]
    shear = np.abs(sol.shear_force[c]) / area / sol.applied_stress
    tension = np.maximum(sol.normal_force[c], 0) / area / sol.applied_stress
    faces, inv = np.unique(face, return_inverse=True)
    face_area = np.bincount(inv, weights=area)
    face_shear = np.abs(np.bincount(inv, weights=sol.shear_force[c])) / face_area / sol.applied_stress
    face_tension = np.maximum(np.bincount(inv, weights=sol.normal_force[c]), 0) / face_area / sol.applied_stress
    out = {}
    for prefix, values in (("shear_stress_ratio", shear), ("tension_stress_ratio", tension),
                           ("face_shear_stress_ratio", face_shear), ("face_tension_stress_ratio", face_tension)):
        out[f"{prefix}_p50"] = float(np.percentile(values, 50))
        out[f"{prefix}_p99"] = float(np.percentile(values, 99))
        out[f"{prefix}_max"] = float(values.max())
    out["n_contacts"] = int(c.sum())
    out["n_faces"] = int(len(faces))
    return out


def contact_ratios(net: Network, sol: ElasticSolution):
    """Per contact spring: (shear, tension) stress over the applied stress (for histograms)."""
    c = np.isfinite(net.spring_area)
    return (np.abs(sol.shear_force[c]) / net.spring_area[c] / sol.applied_stress,
            np.maximum(sol.normal_force[c], 0) / net.spring_area[c] / sol.applied_stress)


# --------------------------------------------------------------------------- model builders
def _spring_geometry(center_a, radius_a, center_b, radius_b, body_a, body_b):
    """Normal along the centre line and YADE's lever arms from the bodies.

    Kinematic arms: the sphere radii along the normal, and the relative translation scaled by
    (r_a + r_b) / distance (``Ig2_Sphere_Sphere_ScGeom`` with ``avoidGranularRatcheting``); torque
    arms: to the contact point, radius - penetration/2 (the JCFpm law's torques).  Returns
    (normal, kinematic arms, torque arms, translation scale).
    """
    d = center_b - center_a
    dist = np.linalg.norm(d, axis=1)
    normal = d / dist[:, None]
    half_pen = 0.5 * (radius_a + radius_b - dist)

    def arms(ra, rb):
        return np.stack([(center_a - body_a) + ra[:, None] * normal, (center_b - body_b) - rb[:, None] * normal], axis=1)

    return normal, arms(radius_a, radius_b), arms(radius_a - half_pen, radius_b - half_pen), \
        (radius_a + radius_b) / dist


def rigid_network(specimen: Specimen, params: Parameters, layout: ClumpLayout) -> Network:
    """Rigid cells of ``layout`` with the project's bonds and series springs."""
    t = specimen.tessellation
    _require_2d(t)
    props = bond_properties(specimen, layout, params)
    s = layout.bond_spheres
    cells = layout.sphere_cell[s]
    c2 = layout.sphere_center[:, :2]
    normal, arm, torque_arm, shear_scale = _spring_geometry(c2[s[:, 0]], layout.sphere_radius[s[:, 0]], c2[s[:, 1]],
                                   layout.sphere_radius[s[:, 1]], t.cell_centroid[cells[:, 0]],
                                   t.cell_centroid[cells[:, 1]])
    return Network(node_pos=t.cell_centroid.copy(), node_rotates=np.ones(t.n_cells, dtype=bool),
                   node_cell=np.arange(t.n_cells), spring_nodes=cells, spring_normal=normal, spring_arm=arm,
                   spring_kn=props.normal_stiffness, spring_ks=props.shear_stiffness,
                   spring_area=layout.bond_area.copy(), spring_face=layout.bond_face.copy(),
                   tri_nodes=np.zeros((0, 3), dtype=np.int64), tri_stiffness=np.zeros((0, 3, 3)),
                   spring_torque_arm=torque_arm, spring_shear_translation_scale=shear_scale)


def cluster_network(specimen: Specimen, params: Parameters, layout) -> Network:
    """The YADE finite-element cells of ``layout`` (a :class:`grainfrac_yade.grains.fem.FemLayout`):
    every sphere a body that translates only (rotations blocked, see :mod:`grainfrac_yade.grains.fem`),
    bonds as YADE springs acting on their faces' planes, finite elements as constant-strain triangles of
    the cell's mineral (plane strain, Table 1)."""
    _require_2d(specimen.tessellation)
    props = bond_properties(specimen, layout, params)
    c2, r = layout.sphere_center[:, :2], layout.sphere_radius
    pairs = layout.bond_spheres
    # spheres translate only and the scene takes the plain relative displacement (no ratcheting
    # guard): the arms play no part
    normal, arm, _, _ = _spring_geometry(c2[pairs[:, 0]], r[pairs[:, 0]], c2[pairs[:, 1]], r[pairs[:, 1]],
                                         c2[pairs[:, 0]], c2[pairs[:, 1]])
    normal[:layout.n_bonds] = layout.bond_normal      # bonds acting on their face's plane
    tri = layout.element_spheres
    names = specimen.mineral_names
    d_min = plane_strain_matrix([params.grains[m].young for m in names],
                                [params.grains[m].poisson for m in names]) * specimen.thickness
    tri_stiffness = d_min[specimen.mineral[layout.sphere_cell[tri[:, 0]]]]
    return Network(node_pos=c2.copy(), node_rotates=np.zeros(layout.n_spheres, dtype=bool),
                   node_cell=layout.sphere_cell.copy(), spring_nodes=pairs, spring_normal=normal, spring_arm=arm,
                   spring_kn=props.normal_stiffness, spring_ks=props.shear_stiffness,
                   spring_area=layout.bond_area.copy(), spring_face=layout.bond_face.copy(),
                   tri_nodes=tri, tri_stiffness=tri_stiffness)


def node_stiffness(net: Network) -> np.ndarray:
    """(n,) largest absolute row sum of the stiffness matrix over each node's degrees of freedom [N/m].

    Gershgorin's bound: with lumped masses m, no mode of the network oscillates faster than
    omega^2 = max over nodes of node_stiffness / m, whatever couples the nodes (springs or elements).
    """
    k, dofs = stiffness_matrix(net)
    row = np.asarray(abs(k).sum(axis=1)).ravel()
    per_dof = np.where(dofs >= 0, row[np.maximum(dofs, 0)], 0.0)
    return per_dof.max(axis=1)


def _require_2d(t):
    if t.dim != 2:
        raise GrainfracError("elastic reference: built for 2D specimens only; fix: use specimen.dimension = 2")


def mesh_network(specimen: Specimen, params: Parameters, nodes_per_face: int = 2,
                       contacts: str = "corners", rings: int = 1, ring_growth: float = 1.0) -> Network:
    """The deformable-block reference: triangles with their mineral's Table 1 moduli (plane strain),
    cells joined at face nodes by Table 2 springs (k_n, k_s [Pa/m] x the node's share of the face)."""
    _require_2d(specimen.tessellation)
    mesh = grain_mesh(specimen, nodes_per_face, contacts, rings, ring_growth)
    names = specimen.mineral_names
    grains = [params.grains[m] for m in names]
    d_min = plane_strain_matrix([g.young for g in grains], [g.poisson for g in grains]) * specimen.thickness
    area = mesh.contact_share * specimen.face_area[mesh.contact_face]
    kn, ks = contact_stiffness(specimen, params, mesh.contact_face)
    m = len(area)
    return Network(node_pos=mesh.node_pos, node_rotates=np.zeros(mesh.n_nodes, dtype=bool),
                   node_cell=mesh.node_cell, spring_nodes=mesh.contact_nodes,
                   spring_normal=specimen.tessellation.face_normal[mesh.contact_face],
                   spring_arm=np.zeros((m, 2, 2)), spring_kn=kn * area, spring_ks=ks * area,
                   spring_area=area, spring_face=mesh.contact_face,
                   tri_nodes=mesh.triangles, tri_stiffness=d_min[specimen.mineral[mesh.triangle_cell]])


def contact_stiffness(specimen: Specimen, params: Parameters, faces: np.ndarray):
    """Table 2 normal and shear stiffness [Pa/m] of the mineral pair of each face (mixed pairs
    averaged), times ``calibration.stiffness_scale``."""
    kn, ks = (mineral_pair_table(specimen.mineral_names, params, a) for a in ("normal_stiffness", "shear_stiffness"))
    fm = specimen.mineral[specimen.tessellation.face_cells[faces]]
    scale = params.calibration.stiffness_scale
    return kn[fm[:, 0], fm[:, 1]] * scale, ks[fm[:, 0], fm[:, 1]] * scale


#: The static models: the mesh reference, and the DEM grain models whose layouts are solved statically.
GRAIN_MODELS = ("rigid", "mesh", "fem")
#: The static network of a DEM grain model's layout, by ``ClumpLayout.model``.
LAYOUT_NETWORKS = {"rigid": rigid_network, "fem": cluster_network}


def build_network(specimen: Specimen, params: Parameters, grains: str, layout: ClumpLayout | None = None,
                  nodes_per_face: int = 2, contacts: str = "corners", rings: int = 1) -> Network:
    """The network of one model (see module doc): the mesh reference, or the layout of a DEM grain model
    (``layout``, built by :mod:`grainfrac_yade.grains`; required for ``rigid`` and ``fem``)."""
    if grains == "mesh":
        return mesh_network(specimen, params, nodes_per_face, contacts, rings, params.resolution.cell_ring_growth)
    if grains not in LAYOUT_NETWORKS:
        raise GrainfracError(f"elastic: grains {grains!r} unknown; fix: use one of {list(GRAIN_MODELS)}")
    if layout is None or layout.model != grains:
        raise ValueError(f"elastic: the {grains} network needs a {grains} layout (grainfrac_yade.grains)")
    return LAYOUT_NETWORKS[grains](specimen, params, layout)


def elastic_summary(specimen: Specimen, params: Parameters, grains: str, layout: ClumpLayout | None = None,
                    nodes_per_face: int = 2, contacts: str = "corners", rings: int = 1,
                    strain: float = DEFAULT_STRAIN, platens: str = "cells"):
    """(summary dict, network, solution) of one model in uniaxial compression (``layout``: see
    :func:`build_network`)."""
    net = build_network(specimen, params, grains, layout, nodes_per_face, contacts, rings)
    sol = solve_uniaxial(net, specimen, strain, platens)
    summary = {"grains": grains, "young_pa": sol.young, "poisson": sol.poisson,
               "applied_stress_pa": sol.applied_stress, "axial_strain": strain,
               "n_nodes": net.n_nodes, "n_triangles": int(len(net.tri_nodes)),
               **contact_statistics(net, sol)}
    if grains == "mesh":
        summary.update(nodes_per_face=nodes_per_face, contacts=contacts, rings=rings)
    return summary, net, sol
