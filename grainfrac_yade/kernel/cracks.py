"""Broken bonds of a scene, counted and drawn the same way for every test and engine.

A scene (:class:`grainfrac_yade.engines.Scene`) keeps per layout bond whether it is broken and its break
mode, the degradation laws' codes (:mod:`grainfrac_yade.law`: ``MODE_TENSION`` 1, ``MODE_SHEAR`` 2, the
codes of YADE's JCFpm crack file), which are the only break-mode codes of the package.
"""
from __future__ import annotations

import numpy as np

from ..law import MODE_SHEAR, MODE_TENSION

#: Name of each break mode in crack tables (cracks.csv ``mode``): a bond broken by the law's corrosion
#: to nothing (mode 3 of the area law) is broken in shear by the scene, and tensile is the rest.
SHEAR_NAME, TENSILE_NAME = "shear", "tensile"


def bond_is_inter(scene) -> np.ndarray:
    """(n_bonds,) True for inter-granular bonds (two minerals)."""
    return scene.specimen.face_is_inter[scene.layout.bond_face]


def broken_counts(scene, broken=None) -> dict:
    """Broken bonds by mode (tensile, shear) and kind (inter-, intra-granular); ``broken``: a mask of
    the bonds to count (default: every broken bond; a mode is set only on broken bonds)."""
    b = scene.broken if broken is None else broken
    inter = bond_is_inter(scene)
    return {"broken_total": int(b.sum()),
            "broken_tensile": int((b & (scene.break_mode == MODE_TENSION)).sum()),
            "broken_shear": int((b & (scene.break_mode == MODE_SHEAR)).sum()),
            "broken_inter": int((b & inter).sum()), "broken_intra": int((b & ~inter).sum())}


def bond_segments(scene, indices) -> np.ndarray:
    """(c, 2, 2) face pieces of bonds [m]: centred on the bond point, as long as the bond's share."""
    lay, t = scene.layout, scene.specimen.tessellation
    idx = np.asarray(indices, dtype=np.int64)
    normal = t.face_normal[lay.bond_face[idx]]
    tangent = np.column_stack([-normal[:, 1], normal[:, 0]])
    half = 0.5 * lay.bond_area[idx] / scene.specimen.thickness
    p = lay.bond_point[idx, :2]
    return np.stack([p - half[:, None] * tangent, p + half[:, None] * tangent], axis=1)


def mode_names(modes) -> np.ndarray:
    """The crack tables' name of each break mode (``shear`` or ``tensile``)."""
    return np.where(np.asarray(modes) == MODE_SHEAR, SHEAR_NAME, TENSILE_NAME)


def crack_table(scene, idx) -> dict:
    """The columns every crack table starts with, for bonds ``idx``: bond, mode, kind, position and the
    orientation of its face (degrees in [0, 180))."""
    normal = scene.specimen.tessellation.face_normal[scene.layout.bond_face[idx]]
    return {"bond": idx, "mode": mode_names(scene.break_mode[idx]),
            "kind": np.where(bond_is_inter(scene)[idx], "inter", "intra"),
            "x_m": scene.layout.bond_point[idx, 0], "y_m": scene.layout.bond_point[idx, 1],
            "face_normal_angle_deg": np.degrees(np.arctan2(normal[:, 1], normal[:, 0])) % 180.0}
