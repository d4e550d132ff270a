"""Laboratory lifetimes and the seed paper's reference values (read from files; nothing invented).

- A user's lab CSV: columns ``driving_stress_ratio``, ``lifetime_s`` and optionally ``source``.
- ``paper_values.csv`` (shared/reference): the paper's UDEC lifetime at 160 MPa
  (``lifetime_at_160mpa``; ratio = 160 MPa / ``ucs_simulated``) and the number of lab specimens.
- ``lab_lifetimes_README.md`` (same folder): the individual lab points of Schmidtke & Lajtai are
  not available; Lajtai & Schmidtke (1986) put the long-term strength of humid LdB granite below
  60 % of its short-term UCS (:data:`LONG_TERM_STRENGTH_RATIO`).
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import GrainfracError
from .fits import check_lifetimes

#: Copies of shared/reference kept in the repository (params/reference/README.md), so that every
#: clone finds them; ``--reference DIR`` reads another folder.
DEFAULT_REFERENCE_DIR = Path(__file__).resolve().parents[2] / "params" / "reference"
PAPER_VALUES = "paper_values.csv"
LAB_PROPERTIES = "ldb_lab_properties.csv"
LAB_README = "lab_lifetimes_README.md"
#: Lajtai & Schmidtke (1986) via lab_lifetimes_README.md: long-term strength of humid LdB granite
#: lies below 60 % of its short-term (dry) UCS, i.e. below driving-stress ratio 0.6.
LONG_TERM_STRENGTH_RATIO = 0.6
LAB_COLUMNS = ("driving_stress_ratio", "lifetime_s")
#: Row of paper_values.csv with the paper's UDEC lifetime; the load [MPa] is in the name.
PAPER_LIFETIME_ROW = re.compile(r"lifetime_at_(\d+(?:\.\d+)?)mpa$")
MPA = 1e6


def read_lab_csv(path) -> pd.DataFrame:
    """Lab lifetimes: ``driving_stress_ratio``, ``lifetime_s`` (finite, > 0) and ``source`` (filled
    with the file name if absent). Lines starting with # are comments."""
    path = Path(path)
    if not path.is_file():
        raise GrainfracError(f"{path}: lab lifetime file not found; fix: give an existing CSV with columns "
                             "driving_stress_ratio,lifetime_s[,source] to --lab")
    try:
        frame = pd.read_csv(path, comment="#", skipinitialspace=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise GrainfracError(f"{path}: not a readable CSV ({str(exc).splitlines()[0] if str(exc) else exc!r}); "
                             "fix: columns driving_stress_ratio,lifetime_s[,source], one specimen per line")
    frame.columns = [str(c).strip() for c in frame.columns]
    for col in LAB_COLUMNS:
        if col not in frame:
            raise GrainfracError(f"{path}: column '{col}' is missing (found: {', '.join(frame.columns)}); fix: "
                                 "header driving_stress_ratio,lifetime_s[,source] (ratio = sigma/sigma_c, "
                                 "lifetime in s)")
    if frame.empty:
        raise GrainfracError(f"{path}: no data rows; fix: one specimen per line below the header")
    for col in LAB_COLUMNS:
        frame[col] = pd.to_numeric(frame[col], errors="coerce")
    check_lifetimes(frame["driving_stress_ratio"], frame["lifetime_s"], str(path))
    if "source" not in frame:
        frame["source"] = path.name
    frame["source"] = frame["source"].fillna(path.name).astype(str)
    return frame[["driving_stress_ratio", "lifetime_s", "source"]].reset_index(drop=True)


def read_paper_values(path) -> dict:
    """``{quantity: (value, unit)}`` from paper_values.csv (numeric values only)."""
    path = Path(path)
    if not path.is_file():
        raise GrainfracError(f"{path}: reference file of the paper's values not found; fix: pass --reference DIR "
                             "(folder holding paper_values.csv) or a lab file with --lab")
    table = pd.read_csv(path, dtype=str)
    out = {}
    for _, row in table.iterrows():
        try:
            out[row["quantity"].strip()] = (float(row["value"]), str(row["unit"]).strip())
        except (TypeError, ValueError):
            continue  # ranges such as 140e6-160e6
    return out


@dataclass(frozen=True)
class PaperReference:
    """The paper's UDEC lifetime point and the lab facts that are known (no lab data points)."""
    stress_pa: float
    lifetime_s: float
    ucs_simulated_pa: float
    lab_specimens: float
    long_term_strength_ratio: float
    values_file: Path
    readme_file: Path
    beta1_pa_s: float = float("nan")   # the paper's stress-corrosion rate (section 4.1)

    @property
    def ratio(self) -> float:
        """Driving-stress ratio of the paper's point: stress / UDEC's simulated UCS."""
        return self.stress_pa / self.ucs_simulated_pa


def paper_reference(reference_dir=None) -> PaperReference:
    """Read the paper's UDEC lifetime (and its load) and the lab specimen count from paper_values.csv."""
    folder = Path(reference_dir) if reference_dir is not None else DEFAULT_REFERENCE_DIR
    values_file = folder / PAPER_VALUES
    values = read_paper_values(values_file)
    rows = [(k, PAPER_LIFETIME_ROW.match(k)) for k in values]
    rows = [(k, m) for k, m in rows if m]
    if not rows or "ucs_simulated" not in values:
        raise GrainfracError(f"{values_file}: rows lifetime_at_<load>mpa and ucs_simulated are required; fix: "
                             "restore the shared reference file")
    key, match = rows[0]
    return PaperReference(stress_pa=float(match.group(1)) * MPA, lifetime_s=values[key][0],
                          ucs_simulated_pa=values["ucs_simulated"][0],
                          lab_specimens=values.get("lab_creep_specimens", (np.nan, ""))[0],
                          long_term_strength_ratio=LONG_TERM_STRENGTH_RATIO, values_file=values_file,
                          readme_file=folder / LAB_README, beta1_pa_s=values.get("beta1", (np.nan, ""))[0])


@dataclass(frozen=True)
class LabProperty:
    """One row of ``ldb_lab_properties.csv``: value and spread in SI units, with its source."""
    name: str
    value: float
    spread: float       # NaN if the file gives none
    source: str


def lab_property(name: str, reference_dir=None) -> LabProperty:
    """The lab property ``name`` (e.g. "uniaxial_compressive_strength") of ``ldb_lab_properties.csv``."""
    path = Path(reference_dir or DEFAULT_REFERENCE_DIR) / LAB_PROPERTIES
    if not path.is_file():
        raise GrainfracError(f"{path}: lab property file not found; fix: copy {LAB_PROPERTIES} from "
                             "../shared/reference into that folder")
    frame = pd.read_csv(path)
    row = frame[frame["property"] == name]
    if row.empty:
        raise GrainfracError(f"{path}: no property '{name}'; fix: one of {', '.join(frame['property'])}")
    r = row.iloc[0]
    return LabProperty(name, float(r["value"]), float(r["spread"]) if pd.notna(r["spread"]) else float("nan"),
                       str(r["source"]))
