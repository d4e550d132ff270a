"""Stress corrosion of a scene's bonds, the engine-neutral half: a degradation law's state on every bond.

The law (:mod:`grainfrac_yade.law`, built once from ``[stress_corrosion]``) and its per-bond state
(:class:`~grainfrac_yade.law.BondState`: strengths J^T, J^C of paper Eq. 7, or area fractions) are pure
numpy.  :class:`BondCorrosion` keeps them with each bond's intact values (area A0, strengths, stiffness,
friction) and the creep time, steps the law under frozen stresses and gives its state for checkpoints.
The stresses it steps the law under are read off the scene's bond forces (:meth:`BondCorrosion.stresses`,
through the scene interface); what the law says a bond can carry is written into an engine's bonds by that
engine's subclass (YADE: :class:`grainfrac_yade.engines.yade.corrosion_engine.StressCorrosion`; static:
:class:`grainfrac_yade.engines.static.engine.StaticCorrosion`).
"""
from __future__ import annotations

import numpy as np

from ..law import Stresses, build_law, check_finite, degrade_step
from ..law.readings import build_reading

#: Names of the law's state arrays in checkpoints (state_dict), with the value of an intact bond.
STATE_KEYS = {"tensile_strength": "tensile_strength_pa", "cohesion": "cohesion_pa", "area_fraction": "area_fraction"}


class BondCorrosion:
    """A degradation law's state on the bonds of ``scene`` (:class:`grainfrac_yade.engines.Scene`: its layout's
    ``bond_area`` and its bond properties ``props``, :func:`grainfrac_yade.layout.bond_properties`)."""

    def __init__(self, scene, sc_params):
        layout, props = scene.layout, scene.props
        self.scene = scene
        self.p = sc_params
        self.law = build_law(sc_params)
        self.reading = build_reading(sc_params.reading, layout)
        self.area0 = layout.bond_area.copy()
        self.tensile0 = props.tensile_strength.copy()
        self.cohesion0 = props.cohesion.copy()
        self.kn0 = props.normal_stiffness.copy()
        self.ks0 = props.shear_stiffness.copy()
        self.tan_phi = np.tan(props.friction_angle)
        self.state = self.law.initial_state(self.tensile0, self.cohesion0, self.tan_phi)
        self.creep_time = 0.0
        #: broken bonds whose contact stiffness was given back (laws that change stiffness)
        self.restored = np.zeros(layout.n_bonds, bool)

    def stresses(self, idx) -> Stresses:
        """sigma (tension positive) and tau [Pa] per intact area A0 of bonds ``idx``, from the scene's bond forces,
        and the stresses that drive their corrosion (the reading's, :mod:`grainfrac_yade.law.readings`).

        NumericalFailure if a force is NaN or infinite."""
        idx = np.asarray(idx, dtype=np.int64)
        fn, fs = self.scene.bond_forces(idx)
        check_finite("bond normal force", fn, idx)
        check_finite("bond shear force", fs, idx)
        normal, shear = fn / self.area0[idx], fs / self.area0[idx]
        rate_normal, rate_shear = self.reading.driving(idx, normal, shear, self.scene)
        check_finite("driving normal stress", rate_normal, idx)
        check_finite("driving shear stress", rate_shear, idx)
        return Stresses(idx, normal, shear, rate_normal, rate_shear)

    def intact(self) -> np.ndarray:
        """The scene's intact bonds."""
        return np.flatnonzero(~self.scene.broken)

    def strengths(self, idx=None):
        """What bonds ``idx`` can carry now, per intact area: (J^T, J^C) [Pa] (all bonds by default)."""
        state = self.state if idx is None else self.state.subset(idx)
        jt, jc, _ = self.law.strengths(state)
        return jt, jc

    def advance(self, dt, stresses: Stresses):
        """The law over creep time ``dt`` under frozen ``stresses`` (the paper clock's step); state only."""
        self.state = degrade_step(self.law, self.state, stresses, dt)
        self.creep_time += dt

    def state_dict(self) -> dict:
        """Whole state (for checkpoints): the law's arrays as lists, creep time."""
        out = {"creep_time": self.creep_time, "law": self.law.name, "restored": np.flatnonzero(self.restored).tolist()}
        intact = {"tensile_strength": self.tensile0, "cohesion": self.cohesion0,
                  "area_fraction": np.ones(len(self.restored))}
        for name, key in STATE_KEYS.items():
            values = self.state.arrays.get(name, intact[name])
            out[key] = values.tolist()
        return out

    def load_arrays(self, state: dict):
        """Restore :meth:`state_dict` output (the state only; an engine writes it into its bonds)."""
        self.creep_time = float(state["creep_time"])
        arrays = {name: np.array(state[STATE_KEYS[name]], float) for name in self.law.state_names}
        self.state = self.law.initial_state(self.tensile0, self.cohesion0, self.tan_phi).replaced(
            np.arange(len(self.tensile0)), arrays)
        self.restored = np.zeros(len(self.tensile0), bool)
        self.restored[np.asarray(state.get("restored", []), dtype=np.int64)] = True
