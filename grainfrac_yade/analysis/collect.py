"""Collect run folders into one pandas DataFrame (one row per run; unfinished, failed and unreadable runs kept)."""
from __future__ import annotations

import copy
import json
from pathlib import Path

import pandas as pd

from ..errors import GrainfracError
from ..params import RENAMED_KEYS, migrate_tree
from ..params import flatten as flatten_tree
from ..runs.columns import summary_as_today
from ..runs.slurm import FAILED
from ..runs.slurm_states import rows_without_runs

#: Parameter paths copied from each run's params.json into the table (older params.json are read through
#: :func:`~grainfrac_yade.params.migrate_tree`: ``stress_corrosion.mode`` becomes ``stress_corrosion.law``).
PARAM_COLUMNS = ("resolution.spheres_per_cell", "resolution.grain_model", "resolution.nodes_per_face",
                 "resolution.cell_rings", "resolution.cell_ring_growth",
                 "specimen.grain_size", "specimen.width", "specimen.height",
                 "calibration.strength_scale", "calibration.stiffness_scale", "calibration.shear_stiffness_ratio_scale",
                 "calibration.tensile_cohesion_ratio_scale", "calibration.inter_mineral_strength_ratio",
                 "calibration.strength_weibull_modulus", "stress_corrosion.clock",
                 "stress_corrosion.law", "stress_corrosion.reading", "stress_corrosion.beta1", "stress_corrosion.beta2",
                 "stress_corrosion.beta2_normalised", "stress_corrosion.threshold_ratio",
                 "stress_corrosion.threshold_stress", "confinement.stress", "ucs.strain_rate", "creep.ramp_strain_rate",
                 "numerics.density_scale", "specimen.min_edge_fraction", "numerics.keep_intact_joints")
#: summary.json of creep runs made before the degradation laws had names: "mode" -> "law".
_SUMMARY_LAW = RENAMED_KEYS["stress_corrosion.mode"][1]
#: The column naming the mechanical engine that computed a run (``numerics.engine``: "yade" explicit DEM, "static"
#: static equilibrium between bond failures), in every table that lists runs.
ENGINE_COLUMN = "engine"
#: The engine of a run whose params.json and summary.json predate ``numerics.engine``: YADE, the only engine there was.
ENGINE_BEFORE_THE_KEY = "yade"


def check_report_folder(out) -> None:
    """GrainfracError (one line) if report folder ``out`` lies inside a run folder (a report never writes into
    run folders) or is a file; the reports of ``analyze`` and ``analyze-ucs``."""
    out = Path(out).resolve()
    for p in (out, *out.parents):
        if (p / "run.json").exists():
            raise GrainfracError(f"{out}: is inside the run folder {p} (the report never writes into run "
                                 "folders); fix: give --out DIR outside run folders")
    if out.exists() and not out.is_dir():
        raise GrainfracError(f"{out}: exists and is not a folder; fix: choose another --out")


def run_engine(params: dict | None, summary: dict | None) -> str | None:
    """The engine that computed a run: its params.json's ``numerics.engine`` (``params``: the tree as written, before
    :func:`~grainfrac_yade.params.migrate_tree` reads an absent key as YADE), else its summary.json's ``engine``
    (static runs record it), else :data:`ENGINE_BEFORE_THE_KEY` for a run written before the key existed; None
    where the folder holds neither file (nothing written yet that could say)."""
    if params is None and summary is None:
        return None
    for value in (_get(params or {}, "numerics.engine"), (summary or {}).get("engine")):
        if isinstance(value, str) and value:
            return value
    return ENGINE_BEFORE_THE_KEY


def _get(tree: dict, dotted: str):
    node = tree
    for part in dotted.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def flatten(tree: dict, prefix: str = "") -> dict:
    """Nested dict -> {"section.key": value} (lists kept as tuples so that they compare and hash)."""
    return flatten_tree(tree, prefix, hashable=True)


def _read_json(path: Path) -> dict:
    """A JSON object from ``path``; ValueError with a short reason if it is not one."""
    try:
        data = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"{path.name}: {type(exc).__name__}: {exc}") from None
    if not isinstance(data, dict):
        raise ValueError(f"{path.name}: not a JSON object")
    return data


def collect_runs(root, all_params: bool = False) -> pd.DataFrame:
    """One row per folder under ``root`` holding a run.json or a failed.json, plus, in a SLURM study
    (``root/slurm/study.json``, :mod:`grainfrac_yade.runs.slurm`), one per row without such a folder yet.

    ``status`` is ``finished`` (summary.json present), ``unfinished`` (no summary.json yet),
    ``failed`` (no summary.json, and a failed.json holding the error line of a batch task that ended
    without one: ``problem``), ``pending`` (a SLURM row not started or without a folder yet) or
    ``unreadable`` (a JSON file that cannot be parsed; ``problem`` says which). ``folder`` is the
    run folder's path; ``engine`` the mechanical engine that computed the run (:func:`run_engine`). With ``all_params`` every parameter of params.json becomes a column
    (dotted name); otherwise only :data:`PARAM_COLUMNS`.
    """
    root = Path(root)
    rows = []
    folders = sorted({p.parent for p in root.rglob("run.json")} | {p.parent for p in root.rglob(FAILED)})
    for folder in folders:
        run_json = folder / "run.json"
        row = {"run": str(folder.relative_to(root)) if folder != root else ".", "folder": str(folder)}
        try:
            failed = _read_json(folder / FAILED) if (folder / FAILED).exists() else None
            run = _read_json(run_json) if run_json.exists() else {k: failed.get(k) for k in ("command", "seed")}
            row.update({"command": run.get("command"), ENGINE_COLUMN: None, "seed": run.get("seed"),
                        "code_version": run.get("code_version")})   # the engine filled in below, its place here
            params_file = folder / "params.json"
            params = summary = written = None
            if params_file.exists():
                params = _read_json(params_file)
                written = copy.deepcopy(params)   # as written: migrate_tree gives an absent engine key "yade"
                migrate_tree(params)
                row.update(flatten(params) if all_params else {k: _get(params, k) for k in PARAM_COLUMNS})
            summary_file = folder / "summary.json"
            if summary_file.exists():
                summary = summary_as_today(_read_json(summary_file))   # keys of older runs by today's names
                if "mode" in summary and "law" not in summary:
                    summary["law"] = _SUMMARY_LAW.get(summary.pop("mode"))
                row.update({k: v for k, v in summary.items() if not isinstance(v, (dict, list))})
                row["status"] = "finished"
            elif failed is not None:
                row.update(status="failed", problem=f"run failed: {failed.get('error') or 'no error line recorded'}"
                           + (f" (log {failed['log']})" if failed.get("log") else ""))
            else:
                row["status"] = "unfinished"
            row[ENGINE_COLUMN] = run_engine(written, summary)
        except ValueError as exc:
            row.update(status="unreadable", problem=str(exc))
        rows.append(row)
    rows += rows_without_runs(root, folders)
    return pd.DataFrame(rows)


def code_version_note(frame: pd.DataFrame) -> str | None:
    """A warning when the finished runs of ``frame`` were made by more than one code version (the
    ``code_version`` of their run.json: package version, git commit, ``-dirty`` for an edited
    tree), None otherwise."""
    if "code_version" not in frame or "status" not in frame:
        return None
    versions = frame.loc[frame["status"] == "finished", "code_version"].dropna()
    counts = versions.value_counts()
    if len(counts) < 2:
        return None
    return ("Warning: the finished runs come from " + str(len(counts)) + " code versions ("
            + ", ".join(f"{v}: {n} run(s)" for v, n in counts.items())
            + "); results may differ between them for reasons other than their parameters.")


def group_stats(frame: pd.DataFrame, by, values) -> pd.DataFrame:
    """Mean, standard deviation and count of ``values`` per group of ``by`` (finished runs; a run
    lacking a ``by`` value, e.g. a key its params.json predates, is a group of its own, not dropped)."""
    done = frame[frame["status"] == "finished"]
    agg = done.groupby(list(by), dropna=False)[list(values)].agg(["mean", "std", "count"])
    agg.columns = [f"{v}_{s}" for v, s in agg.columns]
    return agg.reset_index()
