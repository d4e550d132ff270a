"""Uniaxial (and confined) compressive strength without a loading rate (pure).

The sequentially linear path of :mod:`.cascade` in the platen closure from the intact specimen (under the
constant lateral traction of the confinement, if any, applied first with an equal axial stress), recording the
platen stress at every break.  The strength is the largest platen stress on the path (paper section 3.1: the
peak of the stress-strain curve); the run ends once the stress falls below ``stop_stress_ratio`` of that peak
(``ucs.stop_stress_ratio``, as the YADE test) or at ``max_strain`` (then the peak is a lower bound).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import NumericalFailure
from .cascade import Path
from .failure import FailureRule
from .solver import Equilibrium

#: Why a UCS path ended.
POST_PEAK, MAX_STRAIN, ALL_BROKEN = "post-peak", "max_strain", "nothing left to break"


@dataclass
class UcsResult:
    peak_stress: float          # [Pa], compression positive (the deviator under confinement)
    peak_strain: float          # [1]
    young: float                # initial tangent E = dS/d(strain) [Pa]
    end: str
    strain: np.ndarray          # (rows,) at every break [1]
    stress_before: np.ndarray   # [Pa] where the bond reached its strength
    stress_after: np.ndarray    # [Pa] after the cascade at that closure
    broken: np.ndarray          # (rows,) bonds broken so far
    broken_at_peak: int


def ucs_path(eq: Equilibrium, max_strain: float, stop_stress_ratio: float, confinement: float = 0.0,
             path: Path | None = None) -> UcsResult:
    """The strength of ``eq``'s network (module doc); ``confinement`` [Pa] must equal the one ``eq`` was built with."""
    net = eq.net
    path = path or Path(eq)
    state = eq.initial(0.0)
    if confinement > 0:   # the hydrostatic stage: the axial stress brought to the confinement
        state, reason = path.hold(state, confinement, _no_collapse())
        if reason:
            raise ValueError(f"the specimen does not hold its confinement: {reason}")
    _, _, _, p1 = eq.response(state)
    young = p1 * net.height
    peak = {"s": -math.inf, "e": 0.0, "n": 0}
    end = [MAX_STRAIN]

    def stop(st, records):
        rec = records[-1] if records else None
        if rec is not None:
            dev = rec.stress_before - confinement
            if dev > peak["s"]:
                peak.update(s=dev, e=rec.closure / net.height, n=int(st.broken.sum()) - len(rec.bonds))
            if rec.stress_after - confinement < stop_stress_ratio * peak["s"]:
                end[0] = POST_PEAK
                return True
        if st.broken.all():
            end[0] = ALL_BROKEN
            return True
        return False

    try:
        state = path.run_closure(state, max_strain * net.height, stop)
    except NumericalFailure as exc:      # reported with the path so far; the peak before it stands if passed
        end[0] = f"numerical failure: {exc}"
        state = path.last_state
    last_dev = state.stress - confinement
    if last_dev > peak["s"]:
        peak.update(s=last_dev, e=state.closure / net.height, n=int(state.broken.sum()))
    recs = path.records
    counts = np.cumsum([len(r.bonds) for r in recs]) if recs else np.zeros(0, int)
    return UcsResult(peak["s"], peak["e"], young, end[0], np.array([r.closure / net.height for r in recs]),
                     np.array([r.stress_before for r in recs]), np.array([r.stress_after for r in recs]),
                     counts, peak["n"])


def _no_collapse():
    return FailureRule(0.0)
