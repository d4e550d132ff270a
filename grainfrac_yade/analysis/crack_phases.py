"""Cracks by phase of a creep life: how many bonds break in the ramp, in the first half of the life,
between 0.5 and 0.9 t_f, before the end and in the final relaxation, and of what mode, orientation
and contact kind (the progressive damage of paper section 4.1, Fig. 6-8: microcracks first at random,
mostly tensile and parallel to the load, then shear and inclined cracks, then the macroscopic
shear band).

Input: a run's cracks.csv (one row per broken bond: ``creep_time_s`` with -1 for the ramp, ``mode``
tensile/shear, ``kind`` inter/intra, ``face_normal_angle_deg`` in [0, 180) from the x axis) and its
lifetime.  A crack face is *axial* when its plane lies within :data:`AXIAL_WITHIN_DEG` of the load
axis (y): its normal is then within that angle of x.  For faces of random orientation the axial
share is 2 x 30 / 180 = 1/3.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

#: Degrees between a crack face's plane and the load axis within which the crack counts as axial.
AXIAL_WITHIN_DEG = 30.0
#: Creep-time value of cracks made in the ramp to the load (cracks.csv convention).
RAMP_TIME = -1.0
#: Phases of a failed creep life as fractions of t_f: (name, lower, upper), lower < t / t_f <= upper;
#: the first creep phase includes t = 0 (the relaxation right after the ramp).
LIFE_PHASES = (("0-0.5 t_f", -np.inf, 0.5), ("0.5-0.9 t_f", 0.5, 0.9), ("0.9 t_f to before t_f", 0.9, 1.0))
#: Share of the creep cracks (first in creep time) shown as the early microcracks.
EARLY_FRACTION = 0.1
COLUMNS = ("phase", "cracks", "tensile_share", "axial_share", "inter_share")


def axial(face_normal_angle_deg) -> np.ndarray:
    """True where a face's plane lies within AXIAL_WITHIN_DEG of the load axis (normal near x)."""
    a = np.asarray(face_normal_angle_deg, float) % 180.0
    return (a <= AXIAL_WITHIN_DEG) | (a >= 180.0 - AXIAL_WITHIN_DEG)


def _row(name: str, part: pd.DataFrame) -> dict:
    n = len(part)
    share = (lambda mask: float(np.mean(mask)) if n else float("nan"))
    return {"phase": name, "cracks": n,
            "tensile_share": share(part["mode"].to_numpy(str) == "tensile"),
            "axial_share": share(axial(part["face_normal_angle_deg"].to_numpy(float))),
            "inter_share": share(part["kind"].to_numpy(str) == "inter")}


def crack_phases(cracks: pd.DataFrame, lifetime_s: float, bond_inter=None) -> pd.DataFrame:
    """One row per phase (ramp, the LIFE_PHASES, final relaxation at t = t_f): crack count and the shares
    of tensile, axial and inter-granular cracks (NaN for an empty phase); then the first
    EARLY_FRACTION of the creep cracks, and, given ``bond_inter`` (one bool per bond of the specimen:
    inter-granular), the inter-granular share of all bonds to compare with.  ``lifetime_s`` > 0: the
    creep time at failure; cracks at exactly that time are the final relaxation's."""
    if not np.isfinite(lifetime_s) or lifetime_s <= 0:
        raise ValueError(f"lifetime_s must be a positive creep time, got {lifetime_s!r}")
    t = cracks["creep_time_s"].to_numpy(float)
    ramp = t == RAMP_TIME
    creep = ~ramp
    frac = np.where(creep, t / lifetime_s, np.nan)
    rows = [_row("ramp", cracks[ramp])]
    rows += [_row(name, cracks[creep & (frac > lo) & (frac <= hi) & (t < lifetime_s)])
             for name, lo, hi in LIFE_PHASES]
    rows.append(_row("final relaxation (t = t_f)", cracks[creep & (t >= lifetime_s)]))
    rows.append(_row(f"first {EARLY_FRACTION:.0%} of creep cracks", early_creep_cracks(cracks)))
    if bond_inter is not None:
        inter = np.asarray(bond_inter, bool)
        rows.append({"phase": "bonds intact at the start of creep", "cracks": len(inter), "tensile_share": float("nan"),
                     "axial_share": float("nan"), "inter_share": float(np.mean(inter)) if len(inter) else float("nan")})
    return pd.DataFrame(rows, columns=list(COLUMNS))


def early_creep_cracks(cracks: pd.DataFrame, fraction: float | None = None) -> pd.DataFrame:
    """The first ``fraction`` (default EARLY_FRACTION) of the creep cracks in order of creep time, ramp
    cracks left out: do the first microcracks prefer mineral boundaries (paper Fig. 8)?"""
    fraction = EARLY_FRACTION if fraction is None else fraction
    creep = cracks[cracks["creep_time_s"].to_numpy(float) != RAMP_TIME]
    if creep.empty:
        return creep
    return creep.sort_values("creep_time_s", kind="stable").head(max(1, int(round(fraction * len(creep)))))
