"""``specimen`` command: tessellate, allocate minerals, lay out bonds; write JSON and PNG (:mod:`._specimen`); and
its yade-batch rows (``yade_scripts/specimen.py``), which add the counts of the scene YADE builds."""
from __future__ import annotations

from pathlib import Path

from ..engines.registry import engine_for
from ..runs.runio import write_json
from ..geometry.specimen import build_specimen
from ._specimen import run_specimen


def run_specimen_in_yade(rows):
    """Entry of ``yade_scripts/specimen.py``: parameters from the batch table; counts read from the scene
    its engine builds.  ``rows``: the engine's reader of the batch table
    (its ``batch_rows``: ``read_table``, ``row_errors``, ``run_folder_name``)."""
    from ..params import load_parameters
    read_table, row_errors, run_folder_name = rows.read_table, rows.row_errors, rows.run_folder_name
    with row_errors():
        overrides, controls = read_table()
        params = load_parameters(overrides=overrides)
        out = controls["out"] or f"results/{controls['study']}/{run_folder_name(controls, overrides)}"
        record = run_specimen(params, int(controls["seed"]), out, overwrite=False)
    scene = engine_for(params).build_scene(build_specimen(params, int(controls["seed"])), params)
    record["n_bonds_yade"] = scene.counts()["n_interactions"]   # breakable bonds
    record["engines"] = scene.engine_names()
    record["dt_critical_yade"] = scene.dt_critical   # equals critical_dem_step_s (the same arithmetic)
    write_json(Path(out) / "specimen.json", {k: v for k, v in record.items() if k != "out"})
    print(f"specimen: {record['n_cells']} cells, {record['n_bonds_yade']} bonds in YADE -> {out}")
