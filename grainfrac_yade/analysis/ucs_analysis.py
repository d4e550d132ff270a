"""Specimen-scale results of a uniaxial compression test, from its history (pure numpy).

Conventions: compression positive (axial stress and strain); lateral strain
negative in expansion; volumetric strain of the plane model eps_v = eps_a + eps_l.
"""
from __future__ import annotations

import numpy as np

#: Stress window, as fractions of the peak, for Young's modulus and Poisson's ratio
#: (ISRM-style tangent fit on the pre-peak loading branch).
ELASTIC_WINDOW = (0.10, 0.50)
#: Crack initiation: first stress at which the broken-bond count reaches this fraction of the
#: count at peak and keeps growing (at least CI_MIN_BONDS bonds), i.e. "first sustained breaking".
CI_FRACTION_OF_PEAK_COUNT = 0.02
CI_MIN_BONDS = 3


def elastic_constants(stress, axial_strain, lateral_strain, peak_index=None):
    """Young's modulus [Pa] and Poisson's ratio: least-squares slopes between 10 and 50 % of peak.

    E = d(sigma)/d(eps_a) (tangent modulus averaged over the window);
    nu = -d(eps_l)/d(eps_a) over the same points.
    """
    stress, ea, el = (np.asarray(x, float) for x in (stress, axial_strain, lateral_strain))
    ip = int(np.argmax(stress)) if peak_index is None else peak_index
    peak = stress[ip]
    sel = np.zeros(len(stress), bool)
    sel[: ip + 1] = (stress[: ip + 1] >= ELASTIC_WINDOW[0] * peak) & (stress[: ip + 1] <= ELASTIC_WINDOW[1] * peak)
    if sel.sum() < 3:
        return float("nan"), float("nan")
    young = np.polyfit(ea[sel], stress[sel], 1)[0]
    poisson = -np.polyfit(ea[sel], el[sel], 1)[0]
    return float(young), float(poisson)


def crack_initiation_stress(stress, broken_count):
    """Axial stress at the first sustained bond breaking [Pa] (see CI_FRACTION_OF_PEAK_COUNT)."""
    stress, n = np.asarray(stress, float), np.asarray(broken_count, float)
    ip = int(np.argmax(stress))
    threshold = max(CI_MIN_BONDS, CI_FRACTION_OF_PEAK_COUNT * n[ip])
    hit = np.flatnonzero(n[: ip + 1] >= threshold)
    return float(stress[hit[0]]) if len(hit) else float("nan")


def crack_volumetric_strain(stress, axial_strain, lateral_strain, young, poisson):
    """Crack volumetric strain of the plane model [1] (Martin & Chandler 1994, in 2D):
    eps_v^crack = eps_v - (1 - nu) sigma / E, the measured area strain eps_a + eps_l less the elastic one
    of a uniaxial stress sigma (eps_a = sigma / E, eps_l = -nu sigma / E).  Negative when cracks dilate."""
    stress = np.asarray(stress, float)
    ev = np.asarray(axial_strain, float) + np.asarray(lateral_strain, float)
    return ev - (1.0 - poisson) * stress / young


def crack_initiation_volumetric_stress(stress, axial_strain, lateral_strain, young, poisson,
                                       fraction=CI_FRACTION_OF_PEAK_COUNT):
    """Crack initiation as the lab reads it [Pa]: the stress from which the crack volumetric strain
    (:func:`crack_volumetric_strain`) leaves zero for good, i.e. after the last pre-peak point where its
    dilation is at most ``fraction`` of the dilation at the peak (nan if there is none at the peak)."""
    stress = np.asarray(stress, float)
    ip = int(np.argmax(stress))
    dilation = -crack_volumetric_strain(stress, axial_strain, lateral_strain, young, poisson)[: ip + 1]
    if not dilation[ip] > 0:
        return float("nan")
    below = np.flatnonzero(dilation <= fraction * dilation[ip])
    if len(below) == 0:
        return float(stress[0])
    return float(stress[min(below[-1] + 1, ip)])


def crack_damage_stress(stress, axial_strain, lateral_strain):
    """Axial stress at the onset of volumetric strain reversal [Pa]: max of eps_a + eps_l before peak.

    NaN where the history ends at its largest stress with the volumetric strain still growing there (a test
    stopped at ``ucs.max_strain`` before its peak): no reversal was seen, and the last point, a lower bound of
    the strength, is no crack damage stress."""
    stress = np.asarray(stress, float)
    ip = int(np.argmax(stress))
    ev = np.asarray(axial_strain, float)[: ip + 1] + np.asarray(lateral_strain, float)[: ip + 1]
    top = int(np.argmax(ev))
    if top == ip == len(stress) - 1:
        return float("nan")
    return float(stress[top])


def ucs_summary(history: dict) -> dict:
    """UCS, E, Poisson, crack initiation and crack damage stress from history columns."""
    s = np.asarray(history["axial_stress_pa"], float)
    ea, el = history["axial_strain"], history["lateral_strain"]
    ip = int(np.argmax(s))
    young, poisson = elastic_constants(s, ea, el, ip)
    return {
        "ucs_pa": float(s[ip]),
        "peak_axial_strain": float(np.asarray(ea)[ip]),
        "young_pa": young,
        "young_method": "tangent: least-squares slope of stress vs axial strain between 10 and 50 % of peak",
        "poisson": poisson,
        "crack_initiation_pa": crack_initiation_stress(s, history["broken_total"]),
        "crack_damage_pa": crack_damage_stress(s, ea, el),
    }
