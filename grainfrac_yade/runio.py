"""Run folders: plain files a person can open (JSON, CSV, PNG).

Every run folder records its resolved parameters, seed and code version.
Files are written to a temporary name and renamed, so an interrupted run never
leaves a half-written file; an existing run is never overwritten unless asked.
"""
from __future__ import annotations

import datetime as _dt
import json
import math
import os
import platform
import subprocess
import sys
from pathlib import Path

from . import __version__
from .errors import GrainfracError

#: Files whose presence marks a folder as holding a finished or running run.
RUN_MARKERS = ("run.json",)


def code_version() -> str:
    """Package version plus the git commit of the source tree (``+dirty`` if modified)."""
    root = Path(__file__).resolve().parent.parent
    try:
        rev = subprocess.run(["git", "-C", str(root), "describe", "--always", "--dirty", "--abbrev=12"],
                             capture_output=True, text=True, timeout=10)
        if rev.returncode == 0 and rev.stdout.strip():
            return f"{__version__}+{rev.stdout.strip()}"
    except (OSError, subprocess.SubprocessError):
        pass
    return __version__


def summary_header(params, seed) -> dict:
    """summary.json keys shared by UCS and creep runs: seed, code version, all parameters, and at the
    top level how the cells are realised (``spheres_per_cell``, ``grain_model``, ``nodes_per_face``)."""
    r = params.resolution
    return {"seed": seed, "code_version": code_version(), "params": params.to_dict(),
            "spheres_per_cell": r.spheres_per_cell, "grain_model": r.grain_model, "nodes_per_face": r.nodes_per_face}


def _clean(value):
    """JSON-safe copy: NaN/inf become None, numpy scalars become Python numbers."""
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if hasattr(value, "item") and not isinstance(value, (str, bytes)):
        try:
            value = value.item()
        except (ValueError, AttributeError):
            value = value.tolist()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def write_json(path, data) -> Path:
    """Write ``data`` as indented JSON atomically."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "w") as fh:
        json.dump(_clean(data), fh, indent=2, sort_keys=False)
        fh.write("\n")
    os.replace(tmp, path)
    return path


def write_csv(path, frame) -> Path:
    """Write a pandas DataFrame (or dict of columns) as CSV atomically."""
    import pandas as pd
    path = Path(path)
    frame = frame if isinstance(frame, pd.DataFrame) else pd.DataFrame(frame)
    tmp = path.with_name(path.name + ".tmp")
    frame.to_csv(tmp, index=False)
    os.replace(tmp, path)
    return path


def prepare_run_dir(out, command: str, params, seed, overwrite: bool = False, argv=None) -> Path:
    """Create ``out`` and write ``run.json`` (command, seed, code version) and ``params.json``.

    Refuses a folder that already holds a run unless ``overwrite``.
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise GrainfracError(f"{out}: exists and is not a folder; fix: choose another --out")
    if not overwrite and any((out / m).exists() for m in RUN_MARKERS):
        raise GrainfracError(f"{out}: already holds a run (run.json); fix: choose another --out "
                             "or pass --overwrite to replace it")
    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "params.json", params.to_dict())
    write_json(out / "run.json", {
        "command": command, "argv": list(sys.argv if argv is None else argv), "seed": seed,
        "code_version": code_version(), "python": sys.version.split()[0], "platform": platform.platform(),
        "started": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
    })
    return out
