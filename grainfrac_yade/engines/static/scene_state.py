"""A static scene's state, engine-neutral (:class:`grainfrac_yade.engines.SceneState`): what the static scene
(:class:`.scene.StaticScene`) exports of its solved state and puts into a fresh scene from another engine's (or its
own) state, with the bond frame and reference gaps a dynamic engine measures (pure numpy).

The static engine keeps each broken contact's shear reference s_p (its plastic slip) in ``bond_slip`` and the
closure in the platens' dict; node velocities are zero (a relaxed state).
"""
from __future__ import annotations

import numpy as np

from .._interface import SceneState
from ...errors import GrainfracError
from ...grains import model_of
from . import contacts as cl
from .solver import State


class SceneStateExchange:
    """The state exchange of :class:`.scene.StaticScene` (module doc): its ``net``, ``state``, ``path``, ``layout``,
    ``specimen``, ``eq`` and bond bookkeeping read and written."""

    def _bond_frame(self):
        """(normal, tangent) unit vectors of every layout bond in 3D: the face normal, pointing from the bond's first
        sphere to its second, and its in-plane perpendicular (z x n)."""
        lay = self.layout
        n = self.specimen.tessellation.face_normal[lay.bond_face][:, :2].astype(float)
        a, b = lay.sphere_center[lay.bond_spheres[:, 0], :2], lay.sphere_center[lay.bond_spheres[:, 1], :2]
        n = np.where((((b - a) * n).sum(1) < 0)[:, None], -n, n)
        z = np.zeros((len(n), 1))
        return np.hstack([n, z]), np.hstack([-n[:, 1:2], n[:, 0:1], z])

    def _reference_gap(self, normal) -> np.ndarray:
        """Each bond's stress-free normal gap as the layout made it [m]: the spheres' overlap r_a + r_b - |c_b - c_a|
        for bonds between spheres, and their distance along the face normal for bonds on their face's plane
        (the grain model's ``bonds_on_faces``), as a dynamic engine measures it."""
        lay = self.layout
        a, b = lay.bond_spheres[:, 0], lay.bond_spheres[:, 1]
        d = lay.sphere_center[b] - lay.sphere_center[a]
        if model_of(lay).bonds_on_faces:
            return np.abs((d * normal).sum(1))
        return lay.sphere_radius[a] + lay.sphere_radius[b] - np.linalg.norm(d, axis=1)

    def export_state(self, platens=None) -> SceneState:
        """The scene's state, engine-neutral; static extras: ``bond_slip`` holds each contact's shear reference s_p
        [m], the platens' dict the closure [m] (what :func:`scene_from_state` re-solves from).  Node velocities are
        zero (a relaxed state)."""
        net, st, inv = self.net, self.state, self.canon
        nodes = len(net.node_pos)
        disp = np.zeros((nodes, 3))
        disp[:, :2] = self.node_positions() - net.node_pos[:, :2]
        rot = np.where(net.dofs[:, 2] >= 0, st.u[np.maximum(net.dofs[:, 2], 0)], 0.0)
        pos = np.column_stack([net.node_pos[:, :2], np.full(nodes, 0.5 * self.specimen.thickness)]) + disp
        normal, tangent = self._bond_frame()
        fn, fs = st.fn[inv], st.fs[inv]
        intact = ~st.broken[inv]
        area = net.area[inv]
        return SceneState(
            steps=int(self.steps), time=float(self._time), node_cell=net.node_cell.copy(), node_position=pos,
            node_displacement=disp, node_velocity=np.zeros((nodes, 3)), node_rotation=rot,
            node_angular_velocity=np.zeros(nodes), bond_broken=self.broken.copy(), bond_mode=self.break_mode.copy(),
            bond_break_step=self.break_step.copy(),
            bond_tensile_capacity=np.where(intact, self.path.jt[inv] * area, 0.0),
            bond_cohesive_capacity=np.where(intact, self.path.jc[inv] * area, 0.0),
            bond_normal_stiffness=net.kn[inv].copy(), bond_shear_stiffness=net.ks[inv].copy(),
            bond_tan_friction=np.where(intact, net.tan_friction[inv], net.tan_residual[inv]),
            bond_normal_force=fn[:, None] * normal, bond_shear_force=fs[:, None] * tangent,
            bond_reference_gap=self._reference_gap(normal), bond_slip=st.s_p[inv].copy(),
            bond_plane_normal=normal if model_of(self.layout).bonds_on_faces else np.zeros((self.n_bonds, 3)),
            platens=None if platens is None else platens.state_dict())

    def displacements(self, state: SceneState) -> np.ndarray:
        """The network's displacement vector [m, rad] of ``state``'s node displacements and rotations."""
        net = self.net
        u = np.zeros(net.ndof)
        for col in range(2):
            ok = net.dofs[:, col] >= 0
            u[net.dofs[ok, col]] = state.node_displacement[ok, col]
        ok = net.dofs[:, 2] >= 0
        u[net.dofs[ok, 2]] = state.node_rotation[ok]
        return u

    def apply_state(self, state: SceneState) -> None:
        """Put ``state`` into this freshly built scene and solve the equilibrium there: displacements, broken set,
        strengths, shear references; the statuses follow from the return mapping and the solve (module doc)."""
        net = self.net
        if len(state.node_position) != len(net.node_pos) or len(state.bond_broken) != self.n_bonds:
            raise GrainfracError(f"a state of {len(state.node_position)} nodes and {len(state.bond_broken)} bonds does "
                                 f"not fit this static scene ({len(net.node_pos)} nodes, {self.n_bonds} bonds); fix: "
                                 "build the scene from the specimen, layout and parameters the state was made with")
        u = self.displacements(state)
        order = net.order
        broken = np.asarray(state.bond_broken, bool)[order]
        area = net.area
        self.path.jt = np.where(broken, net.tensile_strength, np.asarray(state.bond_tensile_capacity)[order] / area)
        self.path.jc = np.where(broken, net.cohesion, np.asarray(state.bond_cohesive_capacity)[order] / area)
        s_p = np.asarray(state.bond_slip, float)[order]
        closure = (float(state.platens["closure"]) if state.platens and "closure" in state.platens
                   else float(np.mean(state.node_displacement[net.bottom, 1])
                              - np.mean(state.node_displacement[net.top, 1])))
        dn, ds = net.cn @ u, net.ct @ u
        status, sign, _ = cl.trial_status(dn, ds, broken, s_p, net.kn, net.ks, net.tan_residual)
        m = self.n_bonds
        base = State(closure, u, broken, status, sign, s_p, np.zeros(m), np.zeros(m), 0.0,
                     np.asarray(state.bond_mode, int)[order].copy())
        self.state = self.eq.solve(closure, base)
        self.broken = np.array(state.bond_broken, bool)
        self.break_mode = np.array(state.bond_mode, np.int8)
        self.break_step = np.array(state.bond_break_step, np.int64)
        self._time = float(state.time)
        self._steps_offset = int(state.steps) - self.eq.counters.equilibria
