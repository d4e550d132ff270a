"""VTK time series of a run for ParaView: cells (moved polygons) and bonds (state, strengths, stresses).

Any engine: this module only reads the scene through the scene interface
(:class:`grainfrac_yade.engines.Scene`: ``cell_motion``, ``bond_shift``, ``bond_forces`` and the bonds'
bookkeeping) and collects arrays; :mod:`grainfrac_yade.vtkio` writes them as
XML ``.vtp`` files and ``.pvd`` collections with VTK's writer (not YADE's VTKRecorder, which
crashed on its second write here: shared/yade_notes.md, Output).  Reads each cell body once
(position, orientation) and each bond's forces once: about 2-3 us per bond, so a paper-size
snapshot costs tens of milliseconds.

Series in ``folder``: ``cells_NNNN.vtp`` + ``cells.pvd`` and ``bonds_NNNN.vtp`` + ``bonds.pvd``
(``prefix`` in front of both names for further series of one run, e.g. ``life_``).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..vtkio import (BOND_KIND_NAMES, BOND_STATE_NAMES, rigid_motion, series_file,
                     time_field, write_polygons, write_pvd, write_segments)
from ..kernel.cracks import bond_is_inter, bond_segments

#: The time of each kind of run: (field-data name, unit) of the .pvd timestep.
CREEP_TIME = ("creep_time", "s")
AXIAL_STRAIN = ("axial_strain", "1")
DIAMETRAL_STRAIN = ("diametral_strain", "1")


def code_tables(specimen) -> dict:
    """Field data naming the integer codes: mineral index, bond state, bond kind (entry k names code k)."""
    return {"mineral_names": list(specimen.mineral_names), "bond_state_names": list(BOND_STATE_NAMES),
            "bond_kind_names": list(BOND_KIND_NAMES)}


def cell_arrays(specimen) -> dict:
    """Per-cell data: mineral index and name, cell id, mineral clump."""
    names = np.array(specimen.mineral_names)
    return {"mineral": specimen.mineral, "mineral_name": names[specimen.mineral],
            "cell_id": np.arange(specimen.n_cells), "clump": specimen.clump_label}


def bond_base_arrays(scene, broken, mode, break_time, break_time_name) -> dict:
    """Per-bond data every series has: id, state (0 intact, 1 tensile, 2 shear crack), its name, kind
    (1 inter-granular), the two cells and the break time (NaN: intact)."""
    state = np.where(broken, mode, 0).astype(int)
    cells = scene.specimen.tessellation.face_cells[scene.layout.bond_face]
    return {"bond_id": np.arange(scene.n_bonds), "state": state, "state_name": np.array(BOND_STATE_NAMES)[state],
            "inter": bond_is_inter(scene).astype(int), "cell_a": cells[:, 0], "cell_b": cells[:, 1],
            break_time_name: np.where(broken, break_time, np.nan)}


class Series:
    """Cell and bond snapshots of one run at increasing times, each written with its ``.pvd``.

    ``time``: (name, unit) of the timestep (:data:`CREEP_TIME`, :data:`AXIAL_STRAIN`, ...);
    ``times``: the times already written (a resumed run's), so the next file gets the next index.
    """

    def __init__(self, folder, time=CREEP_TIME, times=(), prefix=""):
        self.folder, self.time, self.prefix = Path(folder), time, prefix
        self.times = [float(t) for t in times]

    def files(self, kind: str) -> list:
        return [series_file(self.prefix + kind, k) for k in range(len(self.times))]

    def add(self, time: float, polygons, cells: dict, segments, bonds: dict, field: dict) -> list:
        """Write the snapshot at ``time`` and both collections; returns the two new file paths."""
        self.folder.mkdir(parents=True, exist_ok=True)
        k = len(self.times)
        field = {**time_field(time, *self.time), **field}
        out = [write_polygons(self.folder / series_file(self.prefix + "cells", k), polygons, cells, field),
               write_segments(self.folder / series_file(self.prefix + "bonds", k), segments, bonds, field)]
        self.times.append(float(time))
        for kind in ("cells", "bonds"):
            write_pvd(self.folder / f"{self.prefix}{kind}.pvd", self.times, self.files(kind))
        return out

    def snapshot(self, scene, time: float, extra_bonds: dict | None = None, field: dict | None = None,
                 break_time=None, break_time_name="break_dem_step") -> list:
        """The scene's current state at ``time``: moved polygons, bonds with stresses per intact area
        and ``extra_bonds`` arrays; break time: ``break_time`` (default the DEM step of each break)."""
        spec, tess = scene.specimen, scene.specimen.tessellation
        pos, angle = scene.cell_motion()
        polygons = rigid_motion(tess.cell_vertices, tess.cell_centroid, pos, angle)
        segments = bond_segments(scene, np.arange(scene.n_bonds)) + scene.bond_shift(pos)[:, None, :]
        fn, fs = scene.bond_forces()
        area = scene.layout.bond_area
        if break_time is None:
            break_time = scene.break_step.astype(float)
        bonds = bond_base_arrays(scene, scene.broken, scene.break_mode, break_time, break_time_name)
        bonds.update({"normal_stress_pa": fn / area, "shear_stress_pa": fs / area})
        bonds.update(extra_bonds if extra_bonds is not None else initial_strengths(scene))
        return self.add(time, polygons, cell_arrays(spec), segments, bonds,
                        {**code_tables(spec), **(field or {})})


def initial_strengths(scene) -> dict:
    """Tensile strength and cohesion [Pa] of a test without stress corrosion: the initial ones (the scene's
    ``props``), 0 once broken."""
    props = scene.props
    return {"tensile_strength_pa": np.where(scene.broken, 0.0, props.tensile_strength),
            "cohesion_pa": np.where(scene.broken, 0.0, props.cohesion)}


def creep_bond_arrays(scene, corr, macro_time, creep_time) -> dict:
    """Creep bonds: remaining tensile strength and cohesion [Pa] and their fraction of the initial
    values (0 once broken), and ``macro`` (1: the bond's face was fully separated by ``creep_time``)."""
    tensile, cohesion = (np.array(x, float) for x in corr.strengths())
    tensile[scene.broken] = 0.0
    cohesion[scene.broken] = 0.0
    return {"tensile_strength_pa": tensile, "cohesion_pa": cohesion,
            "tensile_strength_fraction": tensile / corr.tensile0, "cohesion_fraction": cohesion / corr.cohesion0,
            "macro": (macro_time <= creep_time).astype(int)}


def write_creep_snapshot(series: Series, run, creep_time: float) -> list:
    """A creep run's current state at ``creep_time`` [s] (break times in creep time, -1: the ramp)."""
    return series.snapshot(run.scene, creep_time, creep_bond_arrays(run.scene, run.corr, run.macro_time, creep_time),
                           break_time=run.break_time, break_time_name="break_time_s")


def write_life_series(run, folder, times, fractions) -> Series:
    """Snapshots at given creep ``times`` [s] written after the run (``fractions``: of the lifetime,
    recorded in field data): the bond states then, from each bond's break time and mode (a bond
    never heals), on the undeformed specimen.  Positions, strengths and stresses at those times are
    not kept during the run; the regular series holds them at the times it was written."""
    sc = run.scene
    spec, tess = sc.specimen, sc.specimen.tessellation
    series = Series(folder, CREEP_TIME, prefix="life_")
    segments = bond_segments(sc, np.arange(sc.n_bonds))
    for t, frac in zip(times, fractions):
        broken = sc.broken & (run.break_time <= t)
        bonds = bond_base_arrays(sc, broken, sc.break_mode, run.break_time, "break_time_s")
        bonds["macro"] = (broken & (run.macro_time <= t)).astype(int)
        series.add(t, tess.cell_vertices, cell_arrays(spec), segments, bonds,
                   {**code_tables(spec), "life_fraction": np.array([float(frac)])})
    return series


class StrainSeries:
    """Snapshots of a strain-controlled test (UCS, Brazilian) at every ``every``-th history row and at
    the end, the timestep being the strain (``time``: :data:`AXIAL_STRAIN` or :data:`DIAMETRAL_STRAIN`)."""

    def __init__(self, folder, every: int, time=AXIAL_STRAIN):
        self.series, self.every = Series(folder, time), int(every)
        self._row = -1   # history row of the last snapshot

    def row(self, scene, n_rows: int, strain: float):
        """Called after history row ``n_rows`` (1-based) was recorded at ``strain``."""
        if n_rows % self.every == 0:
            self.write(scene, n_rows, strain)

    def write(self, scene, n_rows: int, strain: float):
        if n_rows != self._row and (not self.series.times or strain > self.series.times[-1]):
            self.series.snapshot(scene, strain)
            self._row = n_rows
