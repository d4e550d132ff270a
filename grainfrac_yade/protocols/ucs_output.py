"""A UCS (or confined compression) test into a run folder: summary.json, history.csv, cracks.csv, the
stress-strain figure and the crack map at the peak (the test itself: :mod:`.ucs`).  Engine-neutral: the
test runs on the engine of the parameters (``numerics.engine``)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..analysis.ucs_analysis import ucs_summary
from ..geometry.specimen import build_specimen
from ..params import require_plane
from ..runs.runio import commit_run_dir, prepare_run_dir, remove_checkpoints, summary_header, write_csv, write_json
from . import ucs as ucs_test
from ..kernel.cracks import bond_segments, crack_table
from .snapshots import AXIAL_STRAIN, StrainSeries


#: summary.json keys measured from the stress-strain curve: null when a numerical failure ended the run.
MEASURES = ("ucs_pa", "peak_axial_strain", "young_pa", "young_method", "poisson", "crack_initiation_pa",
            "crack_damage_pa")


def run_ucs_to_folder(params, seed, out, overwrite=False, progress=None, resume=False, vtk_every=None) -> dict:
    """Run a UCS test into ``out``; summary.json is written last (it marks the run finished).

    Checkpoints go to ``out/checkpoint/`` every ``numerics.checkpoint_interval`` s of wall time and are
    removed once summary.json is written.  ``resume``: go on from the checkpoint in ``out`` instead of
    starting (``out`` keeps its run.json and params.json).  ``vtk_every``: VTK series in ``out/vtk/`` at
    every k-th history row and the end (None: none; not carried across a resume)."""
    from ..analysis.figures import run_stress_strain_figure
    from ..analysis.plotting import crack_map
    require_plane(params, "ucs")
    out = Path(out) if resume else prepare_run_dir(out, "ucs", params, seed, overwrite=overwrite)
    specimen = build_specimen(params, seed)
    outputs = {"checkpoint_folder": out, "run_values": {"seed": seed}}
    if resume:
        history, result, scene, (broken_peak, mode_peak) = ucs_test.resume_ucs(specimen, params, out, progress=progress)
    else:
        snapshot = StrainSeries(out / "vtk", vtk_every, AXIAL_STRAIN) if vtk_every else None
        history, result, scene, (broken_peak, mode_peak) = ucs_test.run_ucs(specimen, params, progress=progress,
                                                                            snapshot=snapshot, **outputs)
    # a numerical failure has no result: the curve before it is kept in history.csv, measured nothing
    no_result = result["numerical_failure"] or result.get("failed_before_test")
    summary = dict.fromkeys(MEASURES) if no_result else ucs_summary(history)
    summary.update(result)
    summary.update(summary_header(params, seed), n_cells=specimen.n_cells)
    write_csv(out / "history.csv", history)
    write_cracks(out / "cracks.csv", scene)
    if len(history["step"]):   # none when the specimen broke apart before the axial stage
        run_stress_strain_figure(history, summary, out / "stress_strain.png")
    idx = np.flatnonzero(broken_peak)
    at = ("the end of the isotropic stage" if result.get("failed_before_test") else
          "the largest stress before the numerical failure" if result["numerical_failure"] else
          f"peak ({summary['ucs_pa'] / 1e6:.0f} MPa)")
    crack_map(specimen, out / "crack_map_peak.png", bond_segments(scene, idx), mode_peak[idx],
              title=f"cracks at {at}, seed {seed}")
    write_json(out / "summary.json", summary)   # last: marks the run finished
    remove_checkpoints(out)                     # a finished run has nothing to resume
    commit_run_dir(out)                         # a replacing run (--overwrite) takes the old one's place
    return summary


def write_cracks(path, scene):
    """cracks.csv: one row per broken bond (step of its break, mode, kind, position, orientation)."""
    idx = np.flatnonzero(scene.broken)
    table = crack_table(scene, idx)
    write_csv(path, {"bond": table.pop("bond"), "step": scene.break_step[idx], **table})
