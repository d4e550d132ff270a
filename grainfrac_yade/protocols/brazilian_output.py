"""A Brazilian disc test into a run folder: summary.json, history.csv, cracks.csv, the load-strain figure
and the crack maps at the peak and at the end (the test itself: :mod:`.brazilian`).  Engine-neutral:
the test runs on the engine of the parameters (``numerics.engine``)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..analysis.brazilian_analysis import (CENTRAL_BAND_HALF_WIDTH, brazilian_summary, central_band_area_fraction,
                                           crack_location, hondros_centre_factor, in_central_band)
from ..geometry.specimen import build_disc_specimen
from ..params import require_plane
from ..runs.runio import commit_run_dir, prepare_run_dir, remove_checkpoints, summary_header, write_csv, write_json
from . import brazilian as brazilian_test
from ..kernel.cracks import bond_segments, crack_table
from ..kernel.levers import Levers, new_breaks
from .snapshots import DIAMETRAL_STRAIN, StrainSeries


#: summary.json keys measured from the load curve: null when a numerical failure ended the run.
MEASURES = ("peak_load_n", "peak_load_per_thickness_n_per_m", "tensile_strength_pa", "peak_diametral_strain")


def require_disc_model(params):
    """GrainfracError unless the specimen is plane (the disc is a 2D tessellation).  Both grain models run
    it: fem cells mesh a rim cell's polygon with its arcs sampled every ``disc.ARC_SAMPLE_DEG`` or less
    (the chords' sag leaves out 1.9e-4 of a 5 mm disc's area, 1.7e-4 of a 10 mm one's: seed 1), while
    its mass is the exact cell's."""
    require_plane(params, "brazilian")


def run_brazilian_to_folder(params, seed, out, overwrite=False, progress=None, levers=None, resume=False,
                            vtk_every=None) -> dict:
    """Run a Brazilian test into ``out``; summary.json is written last (it marks the run finished).

    ``levers``: :class:`~grainfrac_yade.kernel.levers.Levers` (None: none).  Checkpoints go to
    ``out/checkpoint/`` every ``numerics.checkpoint_interval`` s of wall time and are removed once
    summary.json is written; ``resume``: go on from the checkpoint in ``out`` (its levers with it).
    ``vtk_every``: VTK series in ``out/vtk/`` at every k-th history row and the end (None: none; not
    carried across a resume)."""
    from ..analysis.figures import run_brazilian_load_figure
    require_disc_model(params)
    specimen = build_disc_specimen(params, seed)     # bad geometry stops before the folder is made
    if resume:
        out = Path(out)
        history, result, scene, (broken_peak, mode_peak) = brazilian_test.resume_brazilian(specimen, params, out,
                                                                                               progress=progress)
    else:
        out = prepare_run_dir(out, "brazilian", params, seed, overwrite=overwrite)
        levers = levers or Levers()
        snapshot = StrainSeries(out / "vtk", vtk_every, DIAMETRAL_STRAIN) if vtk_every else None
        history, result, scene, (broken_peak, mode_peak) = brazilian_test.run_brazilian(
            specimen, params, progress=progress, levers=levers, checkpoint_folder=out,
            run_values={"seed": seed, "levers": levers.to_dict()}, snapshot=snapshot)
    t = specimen.tessellation
    diameter = t.diameter
    summary = dict.fromkeys(MEASURES) if result["numerical_failure"] else \
        brazilian_summary(history, diameter, specimen.thickness, params.brazilian.stop_min_strain)
    ucs = params.calibration.reference_ucs
    sigma = summary["tensile_strength_pa"]
    summary["reference_ucs_pa"] = ucs
    summary["reference_ucs_over_tensile_strength"] = ucs / sigma if sigma else None
    summary["loading_arc_deg"] = params.brazilian.loading_arc_deg
    summary["hondros_centre_factor"] = hondros_centre_factor(math.radians(params.brazilian.loading_arc_deg))
    summary.update(result)
    summary["hondros_centre_factor_realised"] = hondros_centre_factor(math.radians(np.mean(result["loaded_arc_deg"])))
    points = scene.layout.bond_point
    summary.update(crack_location(points, new_breaks(scene), scene.break_step, t.centre, diameter))
    at_peak = crack_location(points, broken_peak, scene.break_step, t.centre, diameter)
    summary["broken_at_peak"] = int(broken_peak.sum())
    summary["central_band_fraction_at_peak"] = at_peak["central_band_fraction"]
    summary["central_band_area_fraction"] = central_band_area_fraction(CENTRAL_BAND_HALF_WIDTH)
    summary.update(summary_header(params, seed), n_cells=specimen.n_cells, diameter_m=diameter,
                   thickness_m=specimen.thickness)
    write_csv(out / "history.csv", history)
    write_disc_cracks(out / "cracks.csv", scene)
    run_brazilian_load_figure(history, summary, out / "load_strain.png")
    draw_crack_maps(scene, summary, broken_peak, mode_peak, out)
    write_json(out / "summary.json", summary)   # last: marks the run finished
    remove_checkpoints(out)                     # a finished run has nothing to resume
    commit_run_dir(out)                         # a replacing run (--overwrite) takes the old one's place
    return summary


def write_disc_cracks(path, scene):
    """cracks.csv: one row per bond broken during the test (DEM step, mode, kind, position, orientation, and
    whether it lies in the central band); slits (the engine's levers) are left out."""
    idx = np.flatnonzero(new_breaks(scene))
    t = scene.specimen.tessellation
    table = crack_table(scene, idx)
    write_csv(path, {"bond": table.pop("bond"), "step": scene.break_step[idx], **table,
                     "central_band": in_central_band(scene.layout.bond_point[idx], t.centre, t.diameter)})


def band_guides(tessellation) -> np.ndarray:
    """(2, 2, 2) the central band's two edges x = x_c +- D/6, clipped to the disc [m]."""
    c, r = tessellation.centre, tessellation.radius
    dx = CENTRAL_BAND_HALF_WIDTH * 2 * r
    dy = math.sqrt(r * r - dx * dx)
    return np.array([[[c[0] + s * dx, c[1] - dy], [c[0] + s * dx, c[1] + dy]] for s in (-1, 1)])


def draw_crack_maps(scene, summary, broken_peak, mode_peak, out):
    """crack_map_peak.png (broken bonds at the failure load, the peak before the split) and crack_map_end.png
    (at the end of the test), with the central band's edges dashed."""
    from ..analysis.plotting import crack_map
    specimen, seed = scene.specimen, summary["seed"]
    guides = band_guides(specimen.tessellation)
    sigma = summary["tensile_strength_pa"]
    at = "the largest load before the numerical failure" if summary["numerical_failure"] else \
        f"the failure load (sigma_t {sigma / 1e6:.1f} MPa)"
    idx = np.flatnonzero(broken_peak)
    crack_map(specimen, out / "crack_map_peak.png", bond_segments(scene, idx), mode_peak[idx],
              title=f"cracks at {at}, seed {seed}", guides=guides)
    idx = np.flatnonzero(new_breaks(scene))
    frac = summary["central_band_fraction"]
    crack_map(specimen, out / "crack_map_end.png", bond_segments(scene, idx), scene.break_mode[idx],
              title=f"cracks at the end, seed {seed}: {frac if frac is None else round(frac, 2)} in the band "
                    "|x - x_c| <= D/6", guides=guides)
