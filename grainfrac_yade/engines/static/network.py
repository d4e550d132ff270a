"""The static contact network of a specimen: bonds, grains, platens and sides (pure numpy/scipy).

Built from :mod:`grainfrac_yade.elastic`'s network builders (``rigid_network``, ``cluster_network``), so the
kinematics are YADE's as the elastic reference has them: every bond is a spring between two nodes whose
relative displacement at the contact is

    du_n = C_n u,   du_s = C_t u      (rows of ``elastic._spring_rows``; opening positive),

and whose forces act on the nodes through the force rows G_n, G_t (the torque arms of the JCFpm law; equal to
C for fem cells).  The grains' own stiffness K_g holds the constant-strain triangles of fem cells (and the
rolling regularisation of rigid cells, ``elastic.ROLLING_REGULARISATION``).  Loading as ``elastic.solve_uniaxial``:
every node of a cell touching the top (bottom) wall moves with that platen in y by -d/2 (+d/2), d the platen
closure [m]; rotations of platen cells blocked; lateral motion free (smooth platens).

Bonds are kept in a canonical order (by their contact point, then their nodes' positions, rounded:
:func:`.ties.canonical_order`), so that nothing the engine decides depends on how the input numbered them; ``order``
maps back.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ...elastic import (ROLLING_REGULARISATION, Network, _dof_map, _spring_rows, _triangle_b, build_network,
                       stiffness_matrix)
from ...errors import GrainfracError
from ...layout import bond_properties
from .ties import canonical_order


@dataclass
class StaticNetwork:
    """Everything the equilibrium needs, bonds in canonical order (arrays of length m over bonds)."""
    ndof: int
    dofs: np.ndarray            # (n, 3) dof of (ux, uy, theta) per node, -1 where none
    node_pos: np.ndarray        # (n, 2) [m]
    node_cell: np.ndarray       # (n,)
    bond_nodes: np.ndarray      # (m, 2)
    cn: sp.csr_matrix           # (m, ndof) normal relative displacement rows [1]
    ct: sp.csr_matrix           # (m, ndof) tangential rows
    gn: sp.csr_matrix           # (m, ndof) generalised force of a unit normal force
    gt: sp.csr_matrix           # (m, ndof) of a unit shear force
    k_grain: sp.csr_matrix      # (ndof, ndof) triangles (+ rolling regularisation) [N/m]
    kn: np.ndarray              # (m,) [N/m]
    ks: np.ndarray              # (m,) [N/m]
    area: np.ndarray            # (m,) intact bond area A0 [m^2]
    tensile_strength: np.ndarray    # (m,) J^T [Pa]
    cohesion: np.ndarray        # (m,) J^C [Pa]
    tan_friction: np.ndarray    # (m,) tan(phi)
    tan_residual: np.ndarray    # (m,) tan(phi_r)
    key_point: np.ndarray       # (m, 2) contact point: the tie rule's and the order's key [m]
    order: np.ndarray           # (m,) input bond number of each canonical bond
    bond_face: np.ndarray       # (m,) face of each bond (the tessellation's; several bonds per face with fem cells)
    top: np.ndarray             # (n,) bool: node moves with the top platen
    bottom: np.ndarray          # (n,) bool
    left: np.ndarray            # (n,) bool: node of a cell on the left side (confinement)
    right: np.ndarray           # (n,) bool
    side_weight: np.ndarray     # (n,) share of its side's height carried by each side node [m]
    width: float                # [m]
    height: float               # [m]
    thickness: float            # [m]

    @property
    def n_bonds(self) -> int:
        return len(self.kn)

    def force_rows(self, broken: np.ndarray):
        """(G_n, G_t) of the current bonds: YADE's torque-arm rows for intact bonds, the kinematic rows (C) for
        broken contacts.  Broken contacts act through the same rows they are measured by (a symmetric contact
        tangent): with rigid cells' torque arms the open/close and stick/slip statuses cycled without end
        (measured on 4 x 8 mm, seed 1); for fem cells both rows are the same."""
        if not broken.any() or (self.gn is self.cn and self.gt is self.ct):
            return self.gn, self.gt
        keep, swap = sp.diags((~broken).astype(float)), sp.diags(broken.astype(float))
        return (keep @ self.gn + swap @ self.cn).tocsr(), (keep @ self.gt + swap @ self.ct).tocsr()

    def platen_vector(self) -> np.ndarray:
        """(ndof,) displacement of every platen dof per unit closure: -1/2 on top, +1/2 at the bottom."""
        e = np.zeros(self.ndof)
        e[self.dofs[self.top, 1]] = -0.5
        e[self.dofs[self.bottom, 1]] = 0.5
        return e

    def confinement_force(self, stress: float) -> np.ndarray:
        """(ndof,) dead load of a constant lateral traction ``stress`` [Pa, compression positive] on both sides:
        each side node carries its share of the side's height x thickness, pushing inward."""
        f = np.zeros(self.ndof)
        w = stress * self.side_weight * self.thickness
        f[self.dofs[self.left, 0]] += w[self.left]
        f[self.dofs[self.right, 0]] -= w[self.right]
        return f


def grain_stiffness(net: Network, dofs, ndof) -> sp.csr_matrix:
    """The constant-strain triangles' stiffness K_e = area B^T D B (as ``elastic.stiffness_matrix``; empty for
    rigid cells)."""
    if not len(net.tri_nodes):
        return sp.csr_matrix((ndof, ndof))
    bm, area = _triangle_b(net)
    ke = area[:, None, None] * np.einsum("eji,ejk,ekl->eil", bm, net.tri_stiffness, bm)
    tidx = dofs[net.tri_nodes][:, :, :2].reshape(-1, 6)
    rows, cols = np.repeat(tidx, 6, axis=1).ravel(), np.tile(tidx, (1, 6)).ravel()
    return sp.coo_matrix((ke.reshape(len(ke), -1).ravel(), (rows, cols)), shape=(ndof, ndof)).tocsr()


def _side_nodes(specimen, node_cell):
    t = specimen.tessellation
    left = np.isin(node_cell, t.cells_on_side("left"))
    right = np.isin(node_cell, t.cells_on_side("right"))
    return left, right


def _side_weights(node_pos, node_cell, side_mask, height):
    """Each side node's share of the side's height [m]: the side's height split evenly among its cells
    (by their count), then among each cell's nodes; sums to the height on each side."""
    w = np.zeros(len(node_pos))
    for mask in side_mask:
        idx = np.flatnonzero(mask)
        if not len(idx):
            continue
        cells, inv, counts = np.unique(node_cell[idx], return_inverse=True, return_counts=True)
        w[idx] = height / len(cells) / counts[inv]
    return w


def from_network(net: Network, *, top, bottom, left, right, width, height, thickness, tensile_strength,
                 cohesion, friction_angle, residual_friction_angle, area=None, key_point=None) -> StaticNetwork:
    """A :class:`StaticNetwork` of an :class:`grainfrac_yade.elastic.Network` (every spring a bond) with
    platen and side node masks and per-spring strengths (Pa, rad; input order).  ``key_point``: (m, 2) contact
    points (default: the midpoints of the two nodes plus their arms)."""
    m = len(net.spring_kn)
    area = net.spring_area if area is None else np.asarray(area, float)
    if m == 0 or not np.all(np.isfinite(area)) or np.any(area <= 0):
        raise GrainfracError("static network: every spring must be a bond with a finite, positive area; "
                             "fix: build it from a rigid or fem layout")
    if key_point is None:
        pa = net.node_pos[net.spring_nodes[:, 0]] + net.spring_arm[:, 0]
        pb = net.node_pos[net.spring_nodes[:, 1]] + net.spring_arm[:, 1]
        key_point = 0.5 * (pa + pb)
    order = canonical_order(np.asarray(key_point)[:, :2], net.node_pos[net.spring_nodes[:, 0]],
                            net.node_pos[net.spring_nodes[:, 1]])
    k_all, dofs = stiffness_matrix(net)      # for the rolling regularisation scale, as elastic.solve_uniaxial
    _, ndof = _dof_map(net)
    idx, cn, ct = _spring_rows(net, dofs, shear_scale=net.spring_shear_translation_scale)
    _, fn, ft = _spring_rows(net, dofs, net.spring_torque_arm)

    def rows(coef):
        r = np.repeat(np.arange(m), 6)
        c, v = idx.ravel(), coef.ravel()
        keep = c >= 0
        inv = np.empty(m, np.int64)
        inv[order] = np.arange(m)
        return sp.csr_matrix((v[keep], (inv[r[keep]], c[keep])), shape=(m, ndof))

    cn_m, ct_m, gn_m, gt_m = rows(cn), rows(ct), rows(fn), rows(ft)
    k_grain = grain_stiffness(net, dofs, ndof)
    rot = dofs[:, 2][dofs[:, 2] >= 0]
    if len(rot):
        reg = ROLLING_REGULARISATION * np.abs(k_all.diagonal()[rot]).max()
        k_grain = (k_grain + sp.csr_matrix((np.full(len(rot), reg), (rot, rot)), shape=k_all.shape)).tocsr()
    side_w = _side_weights(net.node_pos, net.node_cell, (left, right), height)
    o = order
    return StaticNetwork(
        ndof=ndof, dofs=dofs, node_pos=net.node_pos, node_cell=net.node_cell, bond_nodes=net.spring_nodes[o],
        cn=cn_m, ct=ct_m, gn=gn_m, gt=gt_m, k_grain=k_grain, kn=net.spring_kn[o].astype(float),
        ks=net.spring_ks[o].astype(float), area=area[o], tensile_strength=np.asarray(tensile_strength, float)[o],
        cohesion=np.asarray(cohesion, float)[o], tan_friction=np.tan(np.asarray(friction_angle, float))[o],
        tan_residual=np.tan(np.asarray(residual_friction_angle, float))[o], key_point=np.asarray(key_point)[o, :2],
        order=o, bond_face=np.asarray(net.spring_face, np.int64)[o], top=np.asarray(top, bool),
        bottom=np.asarray(bottom, bool) & ~np.asarray(top, bool),
        left=np.asarray(left, bool), right=np.asarray(right, bool), side_weight=side_w, width=float(width),
        height=float(height), thickness=float(thickness))


def build_static_network(specimen, params, layout, bond_permutation=None) -> StaticNetwork:
    """The static network of ``specimen`` under the grain model that built ``layout`` (rigid or fem cells),
    with the bonds' Table 2 strengths and friction (:func:`grainfrac_yade.layout.bond_properties`).
    ``bond_permutation``: the same bonds numbered otherwise (input bond k is layout bond permutation[k])."""
    net = build_network(specimen, params, layout.model, layout)
    props = bond_properties(specimen, layout, params)
    if bond_permutation is not None:
        q = np.asarray(bond_permutation)
        net = Network(node_pos=net.node_pos, node_rotates=net.node_rotates, node_cell=net.node_cell,
                      spring_nodes=net.spring_nodes[q], spring_normal=net.spring_normal[q],
                      spring_arm=net.spring_arm[q],
                      spring_kn=net.spring_kn[q], spring_ks=net.spring_ks[q], spring_area=net.spring_area[q],
                      spring_face=net.spring_face[q], tri_nodes=net.tri_nodes, tri_stiffness=net.tri_stiffness,
                      spring_torque_arm=None if net.spring_torque_arm is None else net.spring_torque_arm[q],
                      spring_shear_translation_scale=None if net.spring_shear_translation_scale is None
                      else net.spring_shear_translation_scale[q])
        props = type(props)(**{k: v[q] for k, v in vars(props).items()})
        layout_point = layout.bond_point[q]
    else:
        layout_point = layout.bond_point
    t = specimen.tessellation
    top = np.isin(net.node_cell, t.cells_on_side("top"))
    bottom = np.isin(net.node_cell, t.cells_on_side("bottom")) & ~top
    left, right = _side_nodes(specimen, net.node_cell)
    return from_network(net, top=top, bottom=bottom, left=left, right=right, width=float(t.box[0]),
                        height=float(t.box[1]), thickness=specimen.thickness,
                        tensile_strength=props.tensile_strength, cohesion=props.cohesion,
                        friction_angle=props.friction_angle, residual_friction_angle=props.residual_friction_angle,
                        key_point=layout_point[:, :2])
