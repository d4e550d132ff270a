"""The state of a YADE scene (:class:`.scene.GrainScene`): its checkpoint and its engine-neutral form.

* checkpoint: ``O.save`` / ``O.load`` of YADE's whole scene, the bond, law and integrator handles fetched anew
  after a load (:meth:`GrainSceneState.rebind`), and the bond bookkeeping a checkpoint keeps beside the file;
* the engine-neutral state (:class:`grainfrac_yade.engines.SceneState`): exported from the scene, or put into a
  freshly built one (a run that changes engine mid-way).
"""
from __future__ import annotations

import numpy as np

from .._interface import SceneState
from ...errors import GrainfracError


class GrainSceneState:
    """The state methods of :class:`.scene.GrainScene` (a mixin: it reads the scene's fields)."""

    # ------------------------------------------------------------------ state
    def node_bodies(self) -> np.ndarray:
        """The bodies that move the cells, cell by cell (one per rigid cell, one per sphere of an fem cell)."""
        return np.concatenate([np.atleast_1d(b) for b in self.cell_bodies]).astype(np.int64)

    def node_cells(self) -> np.ndarray:
        """The cell of each of :meth:`node_bodies`."""
        return np.repeat(np.arange(len(self.cell_bodies)), [len(np.atleast_1d(b)) for b in self.cell_bodies])

    def node_positions(self) -> np.ndarray:
        """(n_nodes, 3) current positions of :meth:`node_bodies` [m]."""
        bodies = self.O.bodies
        return np.array([tuple(bodies[int(b)].state.pos) for b in self.node_bodies()])

    def checkpoint_state(self) -> dict:
        """What a checkpoint's state.json keeps of the scene beside :meth:`save`'s file: its size (a checkpoint
        of another scene is refused) and the bookkeeping of the breaks the law has counted."""
        return {"n_bodies": len(self.O.bodies), "n_bonds": self.n_bonds, "cracks_seen": self._cracks_seen,
                "tens_seen": self._tens_seen, "erased_by_sliding": self.erased_by_sliding}

    def restore_checkpoint(self, where, scene_file, saved: dict, arrays: dict, confinement=None):
        """Replace this scene (freshly built from the same specimen and parameters) by the checkpoint ``where``'s:
        ``O.load`` of ``scene_file``, the handles fetched anew, the permanent forces of ``confinement`` set
        again (YADE does not save them; None: unconfined), and the bond bookkeeping from ``saved``
        (:meth:`checkpoint_state`) and ``arrays``.  GrainfracError (one line) for another scene's checkpoint,
        an unreadable scene file or a crack count that is not the checkpoint's."""
        O = self.O
        n_bodies = len(O.bodies)
        if saved["n_bodies"] != n_bodies or saved["n_bonds"] != self.n_bonds:
            raise GrainfracError(f"{where}: checkpoint of another scene ({saved['n_bodies']} bodies, "
                                 f"{saved['n_bonds']} bonds; rebuilt: {n_bodies}, {self.n_bonds}); fix: start the "
                                 "run again with --overwrite")
        try:
            O.load(str(scene_file))
        except (RuntimeError, OSError, EOFError, ValueError) as exc:   # truncated or garbage: YADE's gzip/boost errors
            raise GrainfracError(f"{scene_file}: the checkpoint's scene is unreadable ({type(exc).__name__}: "
                                 f"{exc}; truncated or not a YADE scene); fix: start the run again with --overwrite") from None
        self.rebind()
        if confinement is not None:
            confinement.apply()   # permanent forces are not saved with the scene
        self.broken, self.break_mode, self.break_step = (np.array(arrays[k]) for k in ("broken", "break_mode", "break_step"))
        self._cracks_seen, self._tens_seen = saved["cracks_seen"], saved["tens_seen"]
        # checkpoints written before the count was kept: none was counted then
        self.erased_by_sliding = saved.get("erased_by_sliding", 0)
        if self.law.nbTensCracks + self.law.nbShearCracks != self._cracks_seen:
            raise GrainfracError(f"{where}: the loaded scene's crack count ({self.law.nbTensCracks + self.law.nbShearCracks}) "
                                 f"is not the checkpoint's ({self._cracks_seen}); fix: start the run again with --overwrite")

    def save(self, path):
        """``O.save``: YADE's whole scene (bodies, interactions, engines, counters; no forces), exact doubles."""
        self.O.save(str(path))

    def restore(self, path):
        """``O.load`` of a scene :meth:`save` wrote from a scene of the same specimen and parameters, and the
        handles fetched anew (:func:`.checkpoint.rebind_scene`); the bond bookkeeping is the caller's."""
        self.O.load(str(path))
        self.rebind()

    def rebind(self):
        """After ``O.load``: fetch the bond interactions, the law and the integrator anew (the replaced scene's
        handles are stale); GrainfracError if a bond's interaction is missing."""
        from yade import wrapper as w
        O = self.O
        body = self.sphere_body

        def pairs(spheres):
            out = []
            for i, j in spheres:
                try:
                    out.append(O.interactions[int(body[i]), int(body[j])])
                except (IndexError, KeyError, RuntimeError, ValueError):
                    raise GrainfracError(f"checkpoint: no interaction between bodies {int(body[i])} and "
                                         f"{int(body[j])} after O.load; fix: start the run again with --overwrite") from None
            return out

        self.interactions = pairs(self.layout.bond_spheres)
        loops = [e for e in O.engines if isinstance(e, w.InteractionLoop)]
        self.law = next(f for f in loops[0].lawDispatcher.functors
                        if isinstance(f, w.Law2_ScGeom_JCFpmPhys_JointedCohesiveFrictionalPM))
        self.newton = next(e for e in O.engines if isinstance(e, w.NewtonIntegrator))

    def export_state(self, platens=None) -> SceneState:
        """The scene's state in the engine-neutral form (:class:`grainfrac_yade.engines.SceneState`)."""
        bodies = self.O.bodies
        states = [bodies[int(b)].state for b in self.node_bodies()]
        pos = np.array([tuple(st.pos) for st in states]).reshape(-1, 3)
        phys = [i.phys for i in self.interactions]
        normal = np.array([tuple(ph.normalForce) for ph in phys]).reshape(-1, 3)
        shear = np.array([tuple(ph.shearForce) for ph in phys]).reshape(-1, 3)
        return SceneState(
            steps=int(self.steps), time=float(self.time), node_cell=self.node_cells(), node_position=pos,
            node_displacement=pos - self.node_origin,
            node_velocity=np.array([tuple(st.vel) for st in states]).reshape(-1, 3),
            node_rotation=np.array([_z_angle(st.ori * q0.conjugate()) for st, q0 in zip(states, self.node_orientation0)]),
            node_angular_velocity=np.array([st.angVel[2] for st in states]),
            bond_broken=self.broken.copy(), bond_mode=self.break_mode.copy(), bond_break_step=self.break_step.copy(),
            bond_tensile_capacity=np.array([ph.FnMax for ph in phys]),
            bond_cohesive_capacity=np.array([ph.FsMax for ph in phys]),
            bond_normal_stiffness=np.array([ph.kn for ph in phys]), bond_shear_stiffness=np.array([ph.ks for ph in phys]),
            bond_tan_friction=np.array([ph.tanFrictionAngle for ph in phys]),
            bond_normal_force=-normal, bond_shear_force=-shear,
            bond_reference_gap=np.array([ph.initD for ph in phys]),
            bond_slip=np.array([ph.jointCumulativeSliding for ph in phys]),
            bond_plane_normal=(np.array([tuple(ph.jointNormal) for ph in phys]).reshape(-1, 3) if self.model.bonds_on_faces
                               else np.zeros((len(phys), 3))),
            platens=None if platens is None else platens.state_dict())

    def apply_state(self, state: SceneState):
        """Put ``state`` (of a scene of the same specimen, layout and parameters, from any engine) into this
        freshly built scene, before its first step: nodes, bonds, counters.  The bonds are marked as not
        fresh, so that YADE's law keeps their reference gap and forces instead of zeroing them."""
        nodes = self.node_bodies()
        if len(nodes) != len(state.node_position) or self.n_bonds != len(state.bond_broken):
            raise GrainfracError(f"a state of {len(state.node_position)} nodes and {len(state.bond_broken)} bonds "
                                 f"does not fit this scene ({len(nodes)} nodes, {self.n_bonds} bonds); fix: build "
                                 "the scene from the specimen, layout and parameters the state was made with")
        from yade import Quaternion, Vector3
        bodies = self.O.bodies
        for n, b in enumerate(nodes):
            body = bodies[int(b)]
            st = body.state
            # in-plane position from the state, the body's own out-of-plane position kept: a plane model's bodies
            # never move in z, and where a body is a clump (an fem cell's apex sphere and its lifted ghost node)
            # its z is the clump's centroid, not the sphere's centre another engine reports
            x, y = state.node_position[n][:2]
            st.pos = Vector3(float(x), float(y), st.pos[2])
            st.ori = Quaternion(Vector3(0, 0, 1), float(state.node_rotation[n])) * self.node_orientation0[n]
            st.vel = Vector3(*state.node_velocity[n])
            st.angVel = Vector3(0, 0, float(state.node_angular_velocity[n]))
            if body.isClump:   # members follow the clump's pose (YADE moves them only in a step)
                for member, (rel_pos, rel_ori) in body.shape.members.items():
                    ms = bodies[member].state
                    ms.pos = st.pos + st.ori * rel_pos
                    ms.ori = st.ori * rel_ori
        for k, inter in enumerate(self.interactions):
            ph = inter.phys
            ph.FnMax, ph.FsMax = float(state.bond_tensile_capacity[k]), float(state.bond_cohesive_capacity[k])
            ph.kn, ph.ks = float(state.bond_normal_stiffness[k]), float(state.bond_shear_stiffness[k])
            ph.tanFrictionAngle = float(state.bond_tan_friction[k])
            ph.normalForce = Vector3(*(-state.bond_normal_force[k]))
            ph.shearForce = Vector3(*(-state.bond_shear_force[k]))
            ph.initD = float(state.bond_reference_gap[k])
            ph.jointCumulativeSliding = float(state.bond_slip[k])
            if self.model.bonds_on_faces:   # YADE's smooth joint: its normal as the bond's first step aligned it
                ph.jointNormal = Vector3(*state.bond_plane_normal[k])
            if state.bond_broken[k]:
                ph.isCohesive, ph.isBroken = False, True
            inter.iterMadeReal = -1   # not fresh: the law would reset initD and the forces in the next step
        self.broken = np.array(state.bond_broken, dtype=bool)
        self.break_mode = np.array(state.bond_mode, dtype=np.int8)
        self.break_step = np.array(state.bond_break_step, dtype=np.int64)
        self.step_offset, self.time_offset = int(state.steps), float(state.time)


def _z_angle(ori) -> float:
    """Rotation [rad] of a quaternion about z (a plane model's bodies rotate about z only)."""
    axis, angle = ori.toAxisAngle()
    return float(angle if axis[2] >= 0 else -angle)
