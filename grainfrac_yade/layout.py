"""The data of a grain model's spheres and bonds, and what every model derives from it (pure numpy).

:class:`ClumpLayout` holds the spheres that realise the Voronoi cells (grouped by cell) and the bonds
between them (grouped by face); the grain models of :mod:`grainfrac_yade.grains` build it (the
subclass :class:`grainfrac_yade.grains.fem.FemLayout` adds the finite elements).  Every face's bonds
have areas that sum to the face area.  :func:`bond_properties` gives every bond its Table 2 stiffness
(with the grain in series) and strengths, :func:`cell_mass_inertia` every cell its mass and inertia,
:func:`step_floor_factors` the per-cell density scaling of ``numerics.step_floor_quantile``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .contact_strength import face_strength_multipliers
from .params import Parameters, calibrated_contact
from .geometry.specimen import Specimen


@dataclass(frozen=True)
class ClumpLayout:
    """Spheres (grouped by cell) and bonds (grouped by face) of rigid cells; the base of every layout.

    ``model`` (a class attribute, not a field) names the grain model of :mod:`grainfrac_yade.grains`
    that builds and runs this kind of layout."""
    sphere_cell: np.ndarray     # (s,) cell of each sphere
    sphere_center: np.ndarray   # (s, 3) [m]; 2D specimens lie in the plane z = thickness/2
    sphere_radius: np.ndarray   # (s,) [m]
    bond_spheres: np.ndarray    # (b, 2) sphere indices, first in the face's cell a
    bond_face: np.ndarray       # (b,) face index
    bond_area: np.ndarray       # (b,) [m^2]
    bond_point: np.ndarray      # (b, 3) contact point on the face [m]
    #: fraction of the centroid-to-face distance of grain in series with each bond (1: rigid cells,
    #: whose elasticity lives in the bonds; the inset of fem cells, whose elements carry the rest)
    series_fraction: float = 1.0
    model: ClassVar[str] = "rigid"

    @property
    def n_spheres(self) -> int:
        return len(self.sphere_cell)

    @property
    def n_bonds(self) -> int:
        return len(self.bond_face)


def mineral_pair_table(names, params: Parameters, attr: str) -> np.ndarray:
    """(m, m) Table 2 value ``attr`` of every pair of the minerals ``names`` (mixed pairs averaged), with
    the pair-wise levers of ``params.calibration`` (:func:`grainfrac_yade.params.calibrated_contact`)."""
    cal = params.calibration
    return np.array([[getattr(calibrated_contact(params.contact(a, b), a != b, cal), attr) for b in names]
                     for a in names])


@dataclass(frozen=True)
class BondProperties:
    """Per-bond elastic and strength properties (arrays of length n_bonds)."""
    normal_stiffness: np.ndarray     # N/m
    shear_stiffness: np.ndarray      # N/m
    tensile_strength: np.ndarray     # Pa, J^T
    cohesion: np.ndarray             # Pa, J^C
    friction_angle: np.ndarray       # rad, phi
    residual_friction_angle: np.ndarray  # rad, phi_r
    residual_tensile_strength: np.ndarray  # Pa
    residual_cohesion: np.ndarray    # Pa


def bond_properties(specimen: Specimen, layout: ClumpLayout, params: Parameters) -> BondProperties:
    """Stiffness and strength of every bond (paper Tables 1 and 2, series springs).

    Grain elasticity acts in series with the contact stiffness of Table 2.
    For a bond of area A on a face between cells a and b, with l_a and l_b the
    distances from the cells' centroids to the face:

        k_n,bond = A / (1/k_n + l_a/E'_a + l_b/E'_b)
        k_s,bond = A / (1/k_s + l_a/G_a  + l_b/G_b)

    where k_n, k_s [Pa/m] are the pair's contact stiffnesses (Table 2, mixed
    pairs averaged), G = E/(2(1+nu)) and E' = E/(1-nu^2) in 2D (plane strain,
    as UDEC) or E' = E in 3D (Table 1).  Strengths are stresses [Pa]; the
    adapter multiplies them by A.  The calibration factors of
    ``params.calibration`` scale both stiffnesses and both strengths of every
    bond (one factor each, so Table 2's ratios stay); its pair-wise levers act
    on the pair's values (:func:`mineral_pair_table`), and every bond's J^T and
    J^C are multiplied by its face's Weibull multiplier (unit mean, modulus
    ``calibration.strength_weibull_modulus``, drawn from the specimen's seed:
    :func:`grainfrac_yade.contact_strength.face_strength_multipliers`).
    """
    t = specimen.tessellation
    names = specimen.mineral_names
    plane_strain = t.dim == 2
    grains = [params.grains[m] for m in names]
    e_mod = np.array([g.young / (1 - g.poisson**2) if plane_strain else g.young for g in grains])
    g_mod = np.array([g.shear_modulus for g in grains])
    table = {attr: mineral_pair_table(names, params, attr)
             for attr in ("normal_stiffness", "shear_stiffness", "tensile_strength", "cohesion", "friction_angle",
                          "residual_friction_angle", "residual_tensile_strength", "residual_cohesion")}
    face = layout.bond_face
    cells = t.face_cells[face]
    ma, mb = specimen.mineral[cells[:, 0]], specimen.mineral[cells[:, 1]]
    mid = t.face_midpoint[face]
    normal = t.face_normal[face]
    la = layout.series_fraction * np.abs(((mid - t.cell_centroid[cells[:, 0]]) * normal).sum(1))
    lb = layout.series_fraction * np.abs(((mid - t.cell_centroid[cells[:, 1]]) * normal).sum(1))
    area = layout.bond_area
    kn = area / (1 / table["normal_stiffness"][ma, mb] + la / e_mod[ma] + lb / e_mod[mb])
    ks = area / (1 / table["shear_stiffness"][ma, mb] + la / g_mod[ma] + lb / g_mod[mb])
    pick = {k: v[ma, mb] for k, v in table.items()}
    cal = params.calibration
    face_factor = face_strength_multipliers(t.n_faces, cal.strength_weibull_modulus, specimen.seed)[face]
    return BondProperties(normal_stiffness=kn * cal.stiffness_scale, shear_stiffness=ks * cal.stiffness_scale,
                          tensile_strength=pick["tensile_strength"] * cal.strength_scale * face_factor,
                          cohesion=pick["cohesion"] * cal.strength_scale * face_factor,
                          friction_angle=pick["friction_angle"],
                          residual_friction_angle=pick["residual_friction_angle"],
                          residual_tensile_strength=pick["residual_tensile_strength"],
                          residual_cohesion=pick["residual_cohesion"])


def cell_mass_inertia(specimen: Specimen, params: Parameters, density_scale: float = 1.0):
    """Mass [kg] and polar moment of inertia about the centroid [kg m^2] of each cell.

    2D: polygon area x thickness x density; inertia = density x thickness x J_z
    (polar second moment of the polygon).  3D: volume x density; inertia of the
    sphere of equal volume (rotations matter little for one-sphere cells).
    """
    t = specimen.tessellation
    rho = np.array([params.grains[m].density for m in specimen.mineral_names])[specimen.mineral] * density_scale
    if t.dim == 2:
        mass = rho * t.cell_measure * specimen.thickness
        jz = np.array([_polygon_polar_moment(v - c) for v, c in zip(t.cell_vertices, t.cell_centroid)])
        return mass, rho * specimen.thickness * jz
    mass = rho * t.cell_measure
    r = np.cbrt(3 * t.cell_measure / (4 * math.pi))
    return mass, 0.4 * mass * r**2


def step_floor_factors(cell_step, quantile: float) -> np.ndarray:
    """(n,) factors >= 1 on each cell's mass and inertia that raise every cell's own critical DEM step
    to at least the ``quantile`` of all cells' steps (per-cell density scaling; a step sqrt(m / k)
    grows as the square root of the factor).  ``quantile`` 0: all ones (off).  Statics do not depend
    on masses; only how fast the few stiffest, lightest cells (slivers) oscillate changes."""
    step = np.asarray(cell_step, float)
    if not 0.0 <= quantile <= 1.0:
        raise ValueError(f"quantile must lie in [0, 1], got {quantile!r}")
    if step.size == 0 or not np.all(np.isfinite(step) & (step > 0)):
        raise ValueError("every cell's critical step must be finite and positive")
    if quantile == 0.0:
        return np.ones_like(step)
    floor = float(np.quantile(step, quantile))
    return np.maximum(1.0, (floor / step) ** 2)


def _polygon_polar_moment(v: np.ndarray) -> float:
    """Polar second moment of area J_z = I_x + I_y of a CCW polygon about the origin [m^4]."""
    x, y = v[:, 0], v[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    ix = (cross * (y * y + y * yn + yn * yn)).sum() / 12.0
    iy = (cross * (x * x + x * xn + xn * xn)).sum() / 12.0
    return float(ix + iy)
