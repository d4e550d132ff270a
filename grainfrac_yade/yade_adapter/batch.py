"""Parameters for scripts run by ``yade`` / ``yade-batch`` (YADE's ``readParamsFromTable``).

Every parameter path (``section.key``, the names of ``--set``) is a possible
column of a batch table, plus ``seed``, ``out`` and ``study``.  Values are read
with YADE's own ``readParamsFromTable`` (each cell is a Python expression, so text is
quoted: ``'deformable'``) and validated like files.
"""
from __future__ import annotations

import os
import re

from ..errors import GrainfracError
from ..params import default_files, flatten, read_toml
from . import load_yade

#: Table columns that are not model parameters: run controls, with defaults.
RUN_COLUMNS = {"seed": 1, "out": "", "study": "default", "description": ""}


def parameter_defaults() -> dict:
    """Flattened shipped parameters: {"section.key": value}."""
    merged = {}
    for path in default_files():
        merged.update(flatten(read_toml(path)))
    return merged


def read_table(extra_columns=None) -> tuple:
    """Read this run's row (or the defaults outside a batch).

    Returns (overrides list of (key, value), run controls dict).
    """
    yade = load_yade()
    from yade import utils
    defaults = parameter_defaults()
    run_defaults = dict(RUN_COLUMNS, **(extra_columns or {}))
    try:
        utils.readParamsFromTable(noTableOk=True, **defaults, **run_defaults)
    except NameError as exc:   # YADE evaluates every cell as Python: an unknown column, or text without quotes
        raise GrainfracError(f"batch table row {os.environ.get('YADE_BATCH', '')}: {exc}; fix: columns are "
                             f"parameter paths (section.key) or {', '.join(run_defaults)}, and text cells are "
                             "quoted, e.g. 'deformable'") from None
    table = yade.params.table
    overrides = [(k, getattr(table, k)) for k, v in defaults.items() if getattr(table, k) != v]
    controls = {k: getattr(table, k) for k in run_defaults}
    if not controls["description"] and explicit_description_column():
        controls["description"] = yade.O.tags["description"]
    return overrides, controls


def explicit_description_column() -> bool:
    """True if the running yade-batch table has its own ``description`` column.

    YADE puts the row's description in ``O.tags["description"]`` and synthesizes one
    ("col=value,...") when the table has none; only an explicit one names the run folder.
    """
    spec = os.environ.get("YADE_BATCH", "")
    if not spec:
        return False
    table = spec.rsplit(":", 1)[0]
    try:
        with open(table) as fh:
            for line in fh:
                if line.strip() and not line.lstrip().startswith("#"):
                    return "description" in line.split()
    except OSError:
        return False
    return False


def run_folder_name(controls: dict, overrides) -> str:
    """Folder name of a batch row: its description, else the overridden values and seed."""
    desc = controls.get("description") or "_".join(f"{k.split('.')[-1]}={v}" for k, v in overrides)
    desc = f"{desc}_seed{controls['seed']}" if "seed" not in desc else desc
    return re.sub(r"[^A-Za-z0-9_.=+-]+", "_", desc).strip("_") or f"seed{controls['seed']}"
