"""What every degradation law offers, and the plain data it works on (pure numpy).

A law is built once from the parameters (:func:`grainfrac_yade.law.build_law`) and is then a pure
function of its arguments: it keeps no per-bond data.  The per-bond data is a :class:`BondState`
(constant intact strengths and friction, plus the arrays the law evolves); the stresses are a
:class:`Stresses` (per intact area A0, for a subset of bonds, under which creep time passes
with the forces frozen).  :func:`grainfrac_yade.law.creep_step` combines the calls of one event
of the event clock.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

#: Bonds whose time to failure is within this relative distance of the interval fail at its end.
EVENT_REL_TOL = 1e-12


@dataclass(frozen=True)
class Stresses:
    """Stresses of the bonds ``index`` (numbers into the scene's bond list) at frozen forces.

    ``normal``: sigma = F_n / A0, tension positive [Pa]; ``shear``: tau = |F_s| / A0 >= 0 [Pa];
    A0 is the bond's intact area (the area law divides by its remaining fraction itself).  The failure
    criteria (paper Eq. 4-5) read these.  ``rate_normal``, ``rate_shear``: the stresses that drive the rate of
    paper Eq. 7 (:mod:`grainfrac_yade.law.readings`); the bonds' own (``normal``, ``shear``) unless given.
    """
    index: np.ndarray
    normal: np.ndarray
    shear: np.ndarray
    rate_normal: np.ndarray = None
    rate_shear: np.ndarray = None

    def __post_init__(self):
        if self.rate_normal is None:
            object.__setattr__(self, "rate_normal", self.normal)
        if self.rate_shear is None:
            object.__setattr__(self, "rate_shear", self.shear)

    @classmethod
    def of(cls, index, normal, shear, rate_normal=None, rate_shear=None) -> "Stresses":
        as_float = (lambda x: None if x is None else np.asarray(x, float))
        return cls(np.asarray(index, dtype=np.int64), np.asarray(normal, float), np.asarray(shear, float),
                   as_float(rate_normal), as_float(rate_shear))

    def take(self, positions) -> "Stresses":
        """The stresses at ``positions`` (into these arrays)."""
        return Stresses(self.index[positions], self.normal[positions], self.shear[positions],
                        self.rate_normal[positions], self.rate_shear[positions])


@dataclass(frozen=True)
class BondState:
    """Per-bond data of a degradation law.

    ``tensile_strength0``, ``cohesion0``: intact J^T0, J^C0 [Pa]; ``tan_friction``: tan(phi) [-];
    ``arrays``: what the law evolves (its :attr:`DegradationLaw.state_names`), one value per bond.
    All arrays have one entry per bond of the set (the scene's bonds, or a subset of them).
    """
    tensile_strength0: np.ndarray
    cohesion0: np.ndarray
    tan_friction: np.ndarray
    arrays: Mapping[str, np.ndarray] = field(default_factory=dict)

    def __getitem__(self, name) -> np.ndarray:
        return self.arrays[name]

    def __len__(self) -> int:
        return len(self.tensile_strength0)

    def subset(self, index) -> "BondState":
        """The state of bonds ``index`` (copies)."""
        return BondState(self.tensile_strength0[index], self.cohesion0[index], self.tan_friction[index],
                         {k: v[index] for k, v in self.arrays.items()})

    def replaced(self, index, new: Mapping[str, np.ndarray]) -> "BondState":
        """A copy whose law arrays at bonds ``index`` are ``new`` (the other bonds and constants kept)."""
        arrays = {k: v.copy() for k, v in self.arrays.items()}
        for k, v in new.items():
            arrays[k][index] = v
        return BondState(self.tensile_strength0, self.cohesion0, self.tan_friction, arrays)


class DegradationLaw:
    """Interface of a degradation law (one module per law in :mod:`grainfrac_yade.law`).

    Every method takes a :class:`BondState` and :class:`Stresses` of the same bonds (same length)
    and returns arrays of that length; none changes its arguments.

    Attributes
    ----------
    name : str
        The value of ``stress_corrosion.law`` that selects it.
    state_names : tuple of str
        The per-bond arrays it evolves (e.g. ``("tensile_strength", "cohesion")``).
    exact_jump : bool
        True if stiffness does not change as the law acts, so the stresses stay frozen until a bond
        fails and the event clock may jump straight to the next failure; False if it must stop
        whenever a bond has lost ``max_strength_loss_fraction`` (of its intact area) to let the
        DEM redistribute the load.
    time_scales_with_beta1 : bool
        True if every time the law gives is exactly proportional to 1/beta1 (one factor on beta1
        moves a whole study along the time axis).
    """
    name = ""
    state_names: tuple = ()
    exact_jump = True
    time_scales_with_beta1 = False

    def initial_state(self, tensile_strength0, cohesion0, tan_friction) -> BondState:
        """The state of intact bonds."""
        raise NotImplementedError

    def rate(self, state: BondState, stresses: Stresses):
        """Loss rates of the two channels now: (tensile, shear) [Pa/s] (area law: [1/s] of area)."""
        raise NotImplementedError

    def degrade(self, state: BondState, stresses: Stresses, dt) -> dict:
        """The law arrays after creep time ``dt`` [s] under the frozen stresses (failure not checked)."""
        raise NotImplementedError

    def time_to_failure(self, state: BondState, stresses: Stresses):
        """(t [s], mode): creep time to failure under the frozen stresses (inf: never) and its mode."""
        raise NotImplementedError

    def at_failure(self, new: dict, state: BondState, stresses: Stresses, positions, modes) -> dict:
        """``new`` (from :meth:`degrade`) with the bonds at ``positions`` set exactly on their failure point."""
        raise NotImplementedError

    def step(self, state: BondState, stresses: Stresses, dt, positions, modes) -> dict:
        """The law arrays at the end of an event-clock interval of length ``dt``: every bond degraded,
        the failing ones (``positions``, ``modes``) exactly on their failure point."""
        new = self.degrade(state, stresses, dt)
        return self.at_failure(new, state, stresses, positions, modes)

    def failed_now(self, state: BondState, stresses: Stresses):
        """(tensile_failed, shear_failed) of the bonds now."""
        raise NotImplementedError

    def strengths(self, state: BondState):
        """What a bond can carry now, per intact area: (J^T, J^C) [Pa] and the stiffness fraction
        (None: stiffness unchanged)."""
        raise NotImplementedError

    def interval(self, state: BondState, stresses: Stresses, time_left: float, cap_fraction: float):
        """The next creep interval of the event clock: (dt [s], positions of the bonds that fail at its
        end, their modes).

        dt = min(earliest time to failure, ``time_left``), and for laws without ``exact_jump`` also the
        earliest time at which a bond has lost ``cap_fraction`` of its intact capacity (so the DEM can
        redistribute the load).  inf if nothing can fail and no time limit is set.  The bonds that fail
        are those whose time to failure is within EVENT_REL_TOL of dt.
        """
        t_fail, modes = self.time_to_failure(state, stresses)
        t_first = float(t_fail.min()) if len(t_fail) else math.inf
        dt = min(t_first, time_left)
        failing = np.flatnonzero(t_fail <= dt * (1 + EVENT_REL_TOL)) if math.isfinite(dt) else np.empty(0, np.int64)
        return dt, failing, modes[failing]

    def describe(self) -> str:
        """One line: the law and its constants."""
        return self.name
