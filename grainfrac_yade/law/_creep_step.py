"""One event of the event clock as a pure function: :func:`creep_step`.

The YADE adapter reads the bond forces of the intact bonds (as :class:`Stresses`), calls
:func:`creep_step`, writes the strengths it returns and hands the failing bonds to the contact law;
everything in between is here and in the law.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._interface import BondState, DegradationLaw, Stresses


@dataclass(frozen=True)
class CreepStep:
    """What one creep interval does: its length, the new state, and the bonds failing at its end."""
    dt: float                  # creep time of the interval [s]; inf: nothing can fail (nothing changed)
    state: BondState           # all bonds; those of ``stresses`` degraded for dt
    failing: np.ndarray        # bond numbers that fail at the end of the interval
    modes: np.ndarray          # their failure modes (MODE_TENSION, MODE_SHEAR, MODE_CORRODED)
    positions: np.ndarray      # their positions in ``stresses``

    @property
    def stalled(self) -> bool:
        """Nothing to do: no finite interval, or an interval of length 0 in which nothing fails."""
        return not math.isfinite(self.dt) or (self.dt <= 0 and not len(self.failing))


def creep_step(law: DegradationLaw, clock, state: BondState, stresses: Stresses) -> CreepStep:
    """The next creep interval of the event clock under the frozen ``stresses`` of the intact bonds.

    dt = min(earliest time to failure, time left to ``clock.time_limit``; for laws that change
    stiffness also the earliest loss of ``clock.max_strength_loss_fraction`` of a bond's intact
    capacity); every bond of ``stresses`` is degraded for dt (exact under frozen stresses) and the
    failing ones are set exactly on their failure point.  ``clock`` is only read (an
    :class:`~grainfrac_yade.clocks.EventClock`; the caller advances it).
    """
    index = stresses.index
    sub = state.subset(index)
    time_left = max(clock.time_limit - clock.creep_time, 0.0)
    dt, positions, modes = law.interval(sub, stresses, time_left, clock.max_strength_loss_fraction)
    if not math.isfinite(dt) or dt < 0:
        return CreepStep(dt, state, np.empty(0, np.int64), np.empty(0, int), np.empty(0, np.int64))
    new = law.step(sub, stresses, dt, positions, modes)
    return CreepStep(dt, state.replaced(index, new), index[positions], np.asarray(modes), np.asarray(positions))


def degrade_step(law: DegradationLaw, state: BondState, stresses: Stresses, dt: float) -> BondState:
    """``state`` with the bonds of ``stresses`` degraded for creep time ``dt`` (the paper clock's step)."""
    sub = state.subset(stresses.index)
    return state.replaced(stresses.index, law.degrade(sub, stresses, dt))
