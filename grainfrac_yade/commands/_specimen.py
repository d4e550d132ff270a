"""The ``specimen`` command's run folder (what ``demo`` also writes): tessellate, allocate minerals, lay out bonds;
write specimen.json and specimen.png."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..grains import critical_dem_step, layout_for
from ..analysis.plotting import specimen_figure
from ..runs.runio import commit_run_dir, prepare_run_dir, write_json
from ..geometry.specimen import build_specimen


def specimen_record(specimen, layout, params=None) -> dict:
    """``specimen.json`` content: specimen summary plus bond counts of the layout and, given ``params``, the
    critical DEM step of its scene (:func:`grainfrac_yade.dem_step.critical_dem_step`, computed without YADE:
    what a run of this specimen will cost before it starts)."""
    is_inter = specimen.face_is_inter[layout.bond_face]
    face_sum = np.bincount(layout.bond_face, weights=layout.bond_area, minlength=specimen.tessellation.n_faces)
    summary = specimen.summary()
    summary.update({
        "spheres_per_cell_parameter": None,
        "n_spheres": layout.n_spheres,
        "mean_spheres_per_cell": layout.n_spheres / specimen.n_cells,
        "n_bonds": layout.n_bonds,
        "n_bonds_inter": int(is_inter.sum()),
        "n_bonds_intra": int((~is_inter).sum()),
        "max_face_area_mismatch_rel": float(np.max(np.abs(face_sum / specimen.face_area - 1.0))),
    })
    if params is not None:
        summary["grain_model"] = params.resolution.grain_model
        summary["min_edge_fraction"] = params.specimen.min_edge_fraction
        summary["critical_dem_step_s"] = critical_dem_step(specimen, params, layout)
        summary["dem_step_s"] = params.numerics.timestep_safety * summary["critical_dem_step_s"]
    return summary


def bond_network_segments(specimen, layout) -> tuple:
    """(b, 2, 2) segments joining the two cell centroids of each bond, and is_inter."""
    t = specimen.tessellation
    cells = t.face_cells[layout.bond_face]
    seg = np.stack([t.cell_centroid[cells[:, 0], :2], t.cell_centroid[cells[:, 1], :2]], axis=1)
    return seg, specimen.face_is_inter[layout.bond_face]


def run_specimen(params, seed: int, out, draw_bonds: bool = False, overwrite: bool = False) -> dict:
    out = prepare_run_dir(out, "specimen", params, seed, overwrite=overwrite)
    specimen = build_specimen(params, seed)
    layout = layout_for(specimen, params)
    record = specimen_record(specimen, layout, params)
    record["spheres_per_cell_parameter"] = params.resolution.spheres_per_cell
    write_json(Path(out) / "specimen.json", record)
    specimen_figure(specimen, Path(out) / "specimen.png",
                    bonds=bond_network_segments(specimen, layout) if draw_bonds else None)
    record["out"] = str(commit_run_dir(out))
    return record
