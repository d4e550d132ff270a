"""Collect run folders into one pandas DataFrame (one row per run; unfinished runs kept)."""
from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

#: Parameter paths copied from each run's params.json into the table.
PARAM_COLUMNS = ("resolution.spheres_per_cell", "specimen.grain_size", "specimen.width", "specimen.height",
                 "calibration.strength_scale", "calibration.stiffness_scale", "stress_corrosion.clock",
                 "stress_corrosion.mode", "stress_corrosion.beta1")


def _get(tree: dict, dotted: str):
    node = tree
    for part in dotted.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def collect_runs(root) -> pd.DataFrame:
    """One row per folder under ``root`` holding a run.json; ``status`` is finished or unfinished."""
    rows = []
    for run_json in sorted(Path(root).rglob("run.json")):
        folder = run_json.parent
        run = json.loads(run_json.read_text())
        row = {"run": str(folder.relative_to(root)) if folder != Path(root) else ".",
               "command": run.get("command"), "seed": run.get("seed")}
        params_file = folder / "params.json"
        if params_file.exists():
            params = json.loads(params_file.read_text())
            row.update({k: _get(params, k) for k in PARAM_COLUMNS})
        summary_file = folder / "summary.json"
        if summary_file.exists():
            summary = json.loads(summary_file.read_text())
            row.update({k: v for k, v in summary.items() if not isinstance(v, (dict, list))})
            row["status"] = "finished"
        else:
            row["status"] = "unfinished"
        rows.append(row)
    return pd.DataFrame(rows)


def group_stats(frame: pd.DataFrame, by, values) -> pd.DataFrame:
    """Mean, standard deviation and count of ``values`` per group of ``by`` (finished runs)."""
    done = frame[frame["status"] == "finished"]
    agg = done.groupby(list(by))[list(values)].agg(["mean", "std", "count"])
    agg.columns = [f"{v}_{s}" for v, s in agg.columns]
    return agg.reset_index()
