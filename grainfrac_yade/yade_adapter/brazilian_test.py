"""Strain-controlled Brazilian disc test: diametral compression between two rigid jaws.

ISRM (1978) suggested method: a disc of diameter D and thickness t is loaded along a diameter
until it splits; its tensile strength is sigma_t = 2 P / (pi D t) at the peak load P
(:mod:`grainfrac_yade.brazilian_analysis`).

The jaws are cells of the disc, as the UCS test's platens are (:mod:`.platens`): the cells whose
rim arc overlaps an arc of ``brazilian.loading_arc_deg`` about the top (bottom) end of the
vertical diameter move together at a constant speed along it, their rotation blocked, and across
it fixed (``platen_lateral = "fixed"``, the default: rough steel jaws, and no rigid rotation of
the disc left free) or free (smooth).  Rigid jaw cells make curved jaws of the disc's own radius
that grip the rim over the loaded arc: the load goes in through the same bonds (Table 2, series
stiffness) as everywhere else.  Why not two YADE wall or box bodies: the cells are spheres at the
cells' centroids, inside the rim; a wall would touch them there, not at the rim, over one point
per cell, with a sphere-wall contact law and stiffness foreign to Table 2, and it would need a
contact model of its own.  The jaws' arc is reported as realised (``loaded_arc_deg``: the union
of the jaw cells' rim arcs, wider than the nominal arc by up to a cell on each side).

Measures: load P = mean of the two jaws' reactions along the diameter [N] (force on the layer of
thickness t); diametral strain = jaw closure / D; horizontal strain = change of the distance
between the rim cells at the two ends of the horizontal diameter / D (compression positive, so
the disc's widening is negative, as the UCS test's lateral strain).

The test ends once the load falls below ``brazilian.stop_load_ratio`` of its peak with bonds
broken since the peak (the split), or at ``brazilian.max_strain`` (the peak is then a lower
bound), or on a numerical failure (no result); ``end_reason`` says which.
"""
from __future__ import annotations

import math
import time

import numpy as np

from ..disc import DiscTessellation
from ..errors import GrainfracError, NumericalFailure
from .levers import Levers, apply_levers, new_breaks
from .scene import broken_counts, build_scene, check_value, softened_past_peak

#: DOFs blocked on jaw cells: y prescribed, z and all rotations blocked; x too when fixed.
JAW_BLOCKED = {"free": "yzXYZ", "fixed": "xyzXYZ"}


class DiscJaws:
    """The two jaws of a disc scene: cells at the ends of the vertical diameter; velocity and measures."""

    name = "DiscJaws"

    def __init__(self, scene, loading_arc: float, lateral: str = "fixed"):
        t = scene.specimen.tessellation
        if not isinstance(t, DiscTessellation):
            raise GrainfracError("Brazilian test: the specimen is not a disc; fix: build it with "
                                 "grainfrac_yade.disc.build_disc_specimen")
        self.scene = scene
        self.diameter, self.centre = t.diameter, t.centre
        half = 0.5 * loading_arc
        self.top = t.cells_in_arc(0.5 * math.pi, half)
        self.bottom = np.setdiff1d(t.cells_in_arc(-0.5 * math.pi, half), self.top)
        self.left = np.setdiff1d(t.cells_in_arc(math.pi, 0.0), np.concatenate([self.top, self.bottom]))
        self.right = np.setdiff1d(t.cells_in_arc(0.0, 0.0), np.concatenate([self.top, self.bottom, self.left]))
        if not (len(self.bottom) and len(self.left) and len(self.right)):
            raise GrainfracError(f"Brazilian test: a disc of {t.n_cells} cells has no separate cells at the two jaws "
                                 "and the ends of the horizontal diameter; fix: use a larger disc or smaller grains")
        self.loaded_arc_deg = [self._arc_deg(self.top, 0.5 * math.pi), self._arc_deg(self.bottom, -0.5 * math.pi)]
        O = scene.O
        self._top, self._bottom, self._left, self._right = (
            [O.bodies[int(b)] for b in scene.bodies_of(cells)] for cells in (self.top, self.bottom, self.left, self.right))
        for b in self._top + self._bottom:
            b.state.blockedDOFs = JAW_BLOCKED[lateral]
            b.state.vel = (0, 0, 0)
            b.state.angVel = (0, 0, 0)
        self.y0 = self._y(self._top) - self._y(self._bottom)
        self.x0 = self._x(self._right) - self._x(self._left)
        self.velocity = 0.0

    def _arc_deg(self, cells, pole: float) -> float:
        """Angle [deg] the union of ``cells``' rim arcs spans (measured from the pole both ways)."""
        t = self.scene.specimen.tessellation
        arcs = t.boundary_arc[np.isin(t.boundary_cell, cells)]
        mid = (arcs.mean(axis=1) - pole + math.pi) % (2 * math.pi) - math.pi   # arc midpoints from the pole
        arcs = arcs[np.abs(mid) < 0.5 * math.pi] - (arcs.mean(axis=1) - mid)[np.abs(mid) < 0.5 * math.pi, None]
        return float(math.degrees(arcs[:, 1].max() - arcs[:, 0].min()))

    @staticmethod
    def _y(bodies) -> float:
        return float(np.mean([b.state.pos[1] for b in bodies]))

    @staticmethod
    def _x(bodies) -> float:
        return float(np.mean([b.state.pos[0] for b in bodies]))

    def set_closing_speed(self, speed: float):
        """Jaws approach each other at ``speed`` [m/s] (half each), along the vertical diameter."""
        self.velocity = speed
        for b in self._top:
            b.state.vel = (b.state.vel[0], -0.5 * speed, 0)
        for b in self._bottom:
            b.state.vel = (b.state.vel[0], 0.5 * speed, 0)

    def diametral_strain(self) -> float:
        """Jaw closure over the diameter (shortening positive) [1]."""
        return (self.y0 - (self._y(self._top) - self._y(self._bottom))) / self.diameter

    def horizontal_strain(self) -> float:
        """Change of the horizontal diameter's end-cell distance over D (compression positive) [1]."""
        return -((self._x(self._right) - self._x(self._left)) - self.x0) / self.diameter

    def load(self) -> float:
        """Mean reaction of the two jaws along the diameter (compression positive) [N]."""
        f = self.scene.O.forces.f
        top = sum(f(b.id)[1] for b in self._top)
        bottom = sum(f(b.id)[1] for b in self._bottom)
        return 0.5 * (top - bottom)


def crack_counts(scene) -> dict:
    """Bonds broken during the test by mode and kind (:func:`.scene.broken_counts` without the slits of
    :mod:`.levers`, which are broken before loading)."""
    return broken_counts(scene, new_breaks(scene))


def run_brazilian(specimen, params, progress=None, scene=None, levers=None, snapshot=None):
    """Run the test; return (history columns, result dict, scene, snapshot at the failure load).

    The snapshot (bonds broken, their modes) is taken at the failure load: the peak before the split
    (:func:`grainfrac_yade.brazilian_analysis.split_peak_index`, the same rows), else at the largest
    load.  ``levers``: :class:`.levers.Levers` applied to the scene before loading (None: none).
    Broken counts and the snapshot leave out slits.  ``snapshot``: a :class:`.vtk_output.StrainSeries`
    (VTK files, timestep the diametral strain; it only reads the scene), None: no VTK output.
    """
    from ..brazilian_analysis import SPLIT_DROP_RATIO, tensile_stress
    t0 = time.time()
    scene = scene or build_scene(specimen, params)
    applied = apply_levers(scene, levers or Levers(), specimen.seed)
    bz = params.brazilian
    jaws = DiscJaws(scene, math.radians(bz.loading_arc_deg), bz.platen_lateral)
    scene.extras.append(jaws)
    jaws.set_closing_speed(bz.strain_rate * jaws.diameter)
    dt = scene.O.dt
    steps_per_row = max(1, int(round(bz.record_strain_increment / (bz.strain_rate * dt))))
    thickness = specimen.thickness
    cols = {k: [] for k in ("dem_step", "dem_time_s", "diametral_strain", "horizontal_strain", "load_n",
                            "tensile_stress_pa", "broken_total", "broken_tensile", "broken_shear", "broken_inter",
                            "broken_intra")}
    peak, broken_at_peak, peak_snapshot = 0.0, 0, (new_breaks(scene), scene.break_mode.copy())
    split_snapshot = None
    numerical, peak_reached = False, False
    try:
        while True:
            scene.run(steps_per_row)
            load = jaws.load()
            strain = jaws.diametral_strain()
            row = dict(dem_step=scene.O.iter, dem_time_s=scene.O.time, diametral_strain=strain,
                       horizontal_strain=jaws.horizontal_strain(), load_n=load,
                       tensile_stress_pa=float(tensile_stress(load, jaws.diameter, thickness)), **crack_counts(scene))
            for k, v in row.items():
                check_value(k, v, scene.O.iter)
            for k, v in row.items():
                cols[k].append(v)
            if snapshot is not None:
                snapshot.row(scene, len(cols["dem_step"]), strain)
            if (split_snapshot is None and load < SPLIT_DROP_RATIO * peak
                    and row["broken_total"] > broken_at_peak):   # the split: the failure load is behind us
                split_snapshot = peak_snapshot
            if load > peak:
                peak, broken_at_peak = load, row["broken_total"]
                if split_snapshot is None:
                    peak_snapshot = (new_breaks(scene), scene.break_mode.copy())
            if progress and len(cols["dem_step"]) % 50 == 0:
                progress(f"strain {strain:.6f}  sigma {row['tensile_stress_pa'] / 1e6:6.2f} MPa  "
                         f"broken {row['broken_total']}")
            if softened_past_peak(load, peak, row["broken_total"], broken_at_peak, bz.stop_load_ratio):
                peak_reached = True
                end = f"post-peak: the load fell below {bz.stop_load_ratio:g} x its peak"
                break
            if strain >= bz.max_strain:
                end = (f"diametral strain reached brazilian.max_strain = {bz.max_strain:g} before the load fell "
                       f"below {bz.stop_load_ratio:g} x its peak: the largest load is a lower bound of the strength")
                break
    except NumericalFailure as exc:
        numerical, end = True, f"numerical failure: {exc}"
        if progress:
            progress(end)
    if snapshot is not None and cols["dem_step"] and not numerical:
        snapshot.write(scene, len(cols["dem_step"]), cols["diametral_strain"][-1])
    result = {"dem_steps": int(scene.O.iter), "wall_s": time.time() - t0, "dem_timestep_s": dt,
              "n_bonds": scene.n_bonds, **crack_counts(scene), "numerical_failure": numerical,
              "peak_reached": peak_reached, "end_reason": end,
              "jaw_cells": [len(jaws.top), len(jaws.bottom)], "loaded_arc_deg": jaws.loaded_arc_deg, **applied}
    return cols, result, scene, split_snapshot or peak_snapshot
