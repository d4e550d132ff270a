"""VTK snapshots of a creep run for ParaView: cells (moved polygons) and bonds (state, remaining strength).

Written by our own legacy-VTK writer (:mod:`grainfrac_yade.vtkio`), not YADE's
VTKRecorder, which crashed on its second write here (shared/yade_notes.md, Output).
Reads each cell body once (position, orientation) and each bond's forces once:
about 2-3 us per bond, so a paper-size snapshot costs tens of milliseconds.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..vtkio import cluster_rigid_motion, rigid_motion, write_polygons, write_segments
from .scene import bond_segments


def sphere_positions(scene) -> np.ndarray:
    """(s, 3) current positions of the layout's spheres [m] (deformable cells: one body each)."""
    return np.array([tuple(scene.O.bodies[int(b)].state.pos) for b in scene.sphere_body])


def cell_motion(scene):
    """(n, 2+) positions [m] of the cell centroids and (n,) rotation angles about z [rad].

    Rigid cells: the cell bodies' positions and rotations.  Deformable cells: the least-squares
    rigid motion (translation + rotation) of each cell's spheres, weighted by their lumped areas.
    """
    if not scene.layout.rigid_cells:
        lay = scene.layout
        return cluster_rigid_motion(lay.sphere_center, sphere_positions(scene), lay.sphere_cell, lay.sphere_area,
                                    scene.specimen.tessellation.cell_centroid)
    pos, angle = [], []
    for b in scene.cell_body:
        st = scene.O.bodies[int(b)].state
        axis, ang = st.ori.toAxisAngle()
        pos.append(tuple(st.pos))
        angle.append(float(ang) * float(axis[2]))
    return np.array(pos), np.array(angle)


def bond_shift(scene, pos) -> np.ndarray:
    """(b, 2) displacement [m] drawn for each bond: the mean of its two cells' (rigid) or two spheres'
    (deformable) displacements; ``pos``: the cell positions of :func:`cell_motion`."""
    lay, tess = scene.layout, scene.specimen.tessellation
    if not lay.rigid_cells:
        disp = sphere_positions(scene)[:, :2] - lay.sphere_center[:, :2]
        return 0.5 * (disp[lay.bond_spheres[:, 0]] + disp[lay.bond_spheres[:, 1]])
    cells_of_bond = scene.bond_cells
    return 0.5 * (pos[cells_of_bond[:, 0], :2] + pos[cells_of_bond[:, 1], :2]
                  - tess.cell_centroid[cells_of_bond[:, 0], :2] - tess.cell_centroid[cells_of_bond[:, 1], :2])


def write_snapshot(scene, corr, folder, index: int, creep_time: float) -> list:
    """cells_<index>.vtk and bonds_<index>.vtk in ``folder`` at ``creep_time`` [s]; returns the paths.

    Bond data: state (0 intact, 1 tensile crack, 2 shear crack), inter (1 inter-granular),
    remaining tensile strength and cohesion [Pa] and their fraction of the initial values,
    normal (tension +) and shear stress [Pa].
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    spec, tess = scene.specimen, scene.specimen.tessellation
    pos, angle = cell_motion(scene)
    polygons = rigid_motion(tess.cell_vertices, tess.cell_centroid, pos, angle)
    title = f"creep time {creep_time:.9g} s"
    cells = write_polygons(folder / f"cells_{index:04d}.vtk", polygons,
                           {"mineral": spec.mineral, "clump": spec.clump_label}, title=title)
    segments = bond_segments(scene, np.arange(scene.n_bonds)) + bond_shift(scene, pos)[:, None, :]
    tensile, cohesion = (np.array(x, float) for x in corr.strengths())
    tensile[scene.broken] = 0.0
    cohesion[scene.broken] = 0.0
    fn, fs = scene.bond_forces()
    bonds = write_segments(folder / f"bonds_{index:04d}.vtk", segments, {
        "state": scene.break_mode.astype(int), "inter": scene.bond_is_inter.astype(int),
        "tensile_strength_pa": tensile, "cohesion_pa": cohesion,
        "tensile_strength_fraction": tensile / corr.tensile0, "cohesion_fraction": cohesion / corr.cohesion0,
        "normal_stress_pa": fn / corr.area0, "shear_stress_pa": fs / corr.area0}, title=title)
    return [cells, bonds]
