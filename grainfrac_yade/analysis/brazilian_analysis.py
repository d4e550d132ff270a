"""Results of a Brazilian disc test, from its history and its broken bonds (pure numpy).

Tensile strength (ISRM 1978 suggested method; Hondros 1959 for a point load):

    sigma_t = 2 P / (pi D t)

P the peak load on the jaws [N], D the diameter, t the thickness [m] (the 2D model's layer
thickness: P is proportional to t, so sigma_t is not).  For a load spread as a uniform
pressure over arcs 2 alpha about the loaded diameter, Hondros' solution gives at the disc's
centre the horizontal tension

    sigma_xx(0) = 2 P / (pi D t) x (sin 2 alpha - alpha) / alpha

(:func:`hondros_centre_factor`: 0.990 for 2 alpha = 10 deg, 0.977 for 15 deg); the standard
formula, reported as the strength, ignores it.

The failure load P is the load at the split: the peak before the load first falls below
:data:`SPLIT_DROP_RATIO` of its peak so far with bonds broken since that peak
(:func:`split_peak_index`).  A disc whose halves are then crushed between the jaws may carry a
higher load later (measured: face-lined clumps with weak tension, 12.3 then 17.5 MPa); that is
not its tensile strength and is reported apart (``max_tensile_stress_pa``).

Central crack (the split a valid Brazilian test shows): a broken bond is *central* when its
contact point lies in the vertical band |x - x_c| <= D/6 about the loaded diameter, the middle
third of the disc's width (:data:`CENTRAL_BAND_HALF_WIDTH`).  That band holds 41.6 % of the
disc's area (:func:`central_band_area_fraction`), so scattered damage puts about that share of
the broken bonds there; a central crack puts a majority (> 0.5).  Both the share of broken
bonds and the share of all bonds in the band are reported.
"""
from __future__ import annotations

import math

import numpy as np

from ..post_peak import dropped_past_peak

#: Half-width of the central band about the loaded diameter, as a fraction of the diameter.
CENTRAL_BAND_HALF_WIDTH = 1.0 / 6.0
#: The split: the load falls below this fraction of its peak so far, with bonds broken since that peak.
SPLIT_DROP_RATIO = 0.8
#: Crack initiation: the first broken bonds, this fraction of those broken at the end (at least
#: INITIATION_MIN_BONDS), locate where cracking started.
INITIATION_FRACTION, INITIATION_MIN_BONDS = 0.05, 3


def tensile_stress(load, diameter: float, thickness: float):
    """Brazilian tensile stress 2 P / (pi D t) [Pa] of a load P [N] on a disc D x t [m]."""
    return 2.0 * np.asarray(load, float) / (math.pi * diameter * thickness)


def hondros_centre_factor(loading_arc: float) -> float:
    """(sin 2 alpha - alpha) / alpha: the centre's tension over 2 P / (pi D t) for a load spread
    uniformly over the arc 2 alpha = ``loading_arc`` [rad] (Hondros 1959); 1 for a point load."""
    alpha = 0.5 * loading_arc
    return 1.0 if alpha == 0 else (math.sin(2 * alpha) - alpha) / alpha


def central_band_area_fraction(half_width: float = CENTRAL_BAND_HALF_WIDTH) -> float:
    """Share of a disc's area within |x| <= ``half_width`` x D of a diameter:
    (2/pi) (u sqrt(1 - u^2) + asin u), u = 2 x half_width."""
    u = min(1.0, 2.0 * half_width)
    return 2.0 / math.pi * (u * math.sqrt(1.0 - u * u) + math.asin(u))


def in_central_band(points, centre, diameter: float, half_width: float = CENTRAL_BAND_HALF_WIDTH) -> np.ndarray:
    """(n,) True where points (n, >=2) [m] lie within ``half_width`` x D of the vertical diameter."""
    pts = np.atleast_2d(np.asarray(points, float))
    return np.abs(pts[:, 0] - centre[0]) <= half_width * diameter


def crack_location(bond_points, broken, break_step, centre, diameter: float) -> dict:
    """Where the broken bonds lie (see module doc).

    ``bond_points`` (b, >=2) [m] of all bonds; ``broken`` (b,) bool; ``break_step`` (b,) DEM step
    of each break.  Returns the central-band share of broken bonds and of all bonds, the count
    in and out of the band, and the median distance from the centre over the radius of the
    first broken bonds (:data:`INITIATION_FRACTION`).
    """
    pts = np.asarray(bond_points, float)[:, :2]
    broken = np.asarray(broken, bool)
    band = in_central_band(pts, centre, diameter)
    n_broken = int(broken.sum())
    idx = np.flatnonzero(broken)
    out = {"central_band_half_width_m": CENTRAL_BAND_HALF_WIDTH * diameter,
           "broken_in_central_band": int((band & broken).sum()),
           "broken_outside_central_band": int((~band & broken).sum()),
           "central_band_fraction": float((band & broken).sum() / n_broken) if n_broken else float("nan"),
           "central_band_bond_fraction": float(band.mean()) if len(band) else float("nan"),
           "first_cracks_radius_ratio": float("nan")}
    if n_broken:
        first = idx[np.argsort(np.asarray(break_step)[idx], kind="stable")]
        first = first[:max(INITIATION_MIN_BONDS, int(math.ceil(INITIATION_FRACTION * n_broken)))]
        r = np.linalg.norm(pts[first] - np.asarray(centre, float)[:2], axis=1) / (0.5 * diameter)
        out["first_cracks_radius_ratio"] = float(np.median(r))
    return out


def splits(load: float, peak_load: float, broken: int, broken_at_peak: int, strain: float = 0.0,
           min_strain: float = 0.0) -> bool:
    """Whether a row is the split: :func:`grainfrac_yade.post_peak.dropped_past_peak` at
    :data:`SPLIT_DROP_RATIO` against the peak of the rows before it (``min_strain``:
    ``brazilian.stop_min_strain``, a drop in the start transient is not the split)."""
    return dropped_past_peak(load, peak_load, broken, broken_at_peak, SPLIT_DROP_RATIO, strain, min_strain)


def split_peak_index(load, broken, strain=None, min_strain: float = 0.0) -> tuple:
    """(index of the failure load, index of the split or None): the split is the first row that
    :func:`splits` against the peak of the rows before it; the failure load is that peak.  No split: the
    largest load (a lower bound).  ``strain`` (needed if ``min_strain`` > 0), ``min_strain``: as
    :func:`splits`; a transient peak before ``min_strain`` is then overtaken by the real one."""
    load, broken = np.asarray(load, float), np.asarray(broken)
    strain = np.zeros(len(load)) if strain is None or min_strain <= 0 else np.asarray(strain, float)
    ip = 0
    for i in range(1, len(load)):
        if splits(load[i], load[ip], broken[i], broken[ip], strain[i], min_strain):
            return ip, i
        if load[i] > load[ip]:
            ip = i
    return (int(np.argmax(load)) if len(load) else 0), None


def brazilian_summary(history: dict, diameter: float, thickness: float, min_strain: float = 0.0) -> dict:
    """Failure load (at the split), tensile strength, the diametral strain there, and the largest load
    of the whole test, from history columns; ``min_strain``: as :func:`split_peak_index`."""
    load = np.asarray(history["load_n"], float)
    if not len(load):
        return dict.fromkeys(("peak_load_n", "peak_load_per_thickness_n_per_m", "tensile_strength_pa",
                              "peak_diametral_strain", "split_found", "max_tensile_stress_pa"))
    ip, split = split_peak_index(load, history["broken_total"], history["diametral_strain"], min_strain)
    return {"peak_load_n": float(load[ip]),
            "peak_load_per_thickness_n_per_m": float(load[ip] / thickness),
            "tensile_strength_pa": float(tensile_stress(load[ip], diameter, thickness)),
            "peak_diametral_strain": float(history["diametral_strain"][ip]),
            "split_found": split is not None,
            "max_tensile_stress_pa": float(tensile_stress(load.max(), diameter, thickness))}
