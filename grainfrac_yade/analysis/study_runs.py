"""The runs of a study folder as one table (``analyze``): every run folder with its outcome, ratio, model variant
and first creep crack, parameters older files lack filled with the shipped defaults, and the run's history and
cracks read back (pure pandas; the report itself: :mod:`.study`).

Reads run folders only; run folders are never changed.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import GrainfracError
from ..runs.columns import history_as_today
from ..runs.runio import RESULT_NEUTRAL_KEYS
from . import rescale
from .collect import collect_runs, flatten
from .creep_analysis import MinimumCreepRate, minimum_creep_rate
from .durations import readable_duration
from .lifetimes import classify_runs
from .runparams import default_tree

#: Parameters that do not make a different model (a longer time limit is the same model; how often a run
#: was checkpointed changes nothing it computes).
VARIANT_IGNORE = ("stress_corrosion.creep_time_limit",) + RESULT_NEUTRAL_KEYS
#: Outcomes of creep runs that belong to a model variant.
CREEP_OUTCOMES = ("failed", "failed at load", "not failed", "numerical failure", "failed before test", "unfinished",
                  "run error")
#: Columns of runs.csv (those present); the parameter columns are those of ucs_runs.csv that tell runs apart.
RUN_TABLE = ("run", "folder", "command", "engine", "seed", "variant", "status", "outcome", "driving_stress_ratio", "stress_pa",
             "ucs_pa", "failed", "lifetime_s", "lifetime_readable", "fit_left_out", "min_creep_strain_rate_per_s",
             "min_creep_strain_rate", "creep_time_end_s", "first_creep_crack_s", "numerical_failure", "failure_reason", "clock", "law", "n_events",
             "broken_ramp", "broken_creep", "broken_total", "macrocracks", "n_bonds", "primary_end_s",
             "tertiary_start_s", "steps", "steps_counted", "wall_s", "cpu_s", "specimen.width", "specimen.height", "specimen.grain_size",
             "resolution.grain_model", "resolution.nodes_per_face", "calibration.strength_scale", "calibration.stiffness_scale",
             "stress_corrosion.reading", "stress_corrosion.beta1", "stress_corrosion.beta2",
             "specimen.min_edge_fraction", "creep.ramp_strain_rate",
             "numerics.density_scale", "study", "beta1_run", "time_factor", "code_version", "problem")


def _fmt_value(v) -> str:
    return f"{v:g}" if isinstance(v, float) else str(v)


#: Variant of creep rows without parameters yet (a SLURM row not started, a task that failed before its
#: run folder held params.json) in a study of several variants.
NO_PARAMS_VARIANT = "parameters not written yet"


def variant_labels(runs: pd.DataFrame) -> pd.Series:
    """Label per run naming the parameters that differ among the creep runs ("model" if none).

    Rows without parameters (no params.json yet) name no variant: they join the study's only one, or
    :data:`NO_PARAMS_VARIANT` when there are several."""
    creep = runs["outcome"].isin(CREEP_OUTCOMES)
    has = runs["specimen.width"].notna() if "specimen.width" in runs else pd.Series(False, index=runs.index)
    basis = creep & has if (creep & has).any() else creep
    keys = [c for c in runs.columns if "." in c and c not in VARIANT_IGNORE
            and runs.loc[basis, c].astype(str).nunique() > 1]
    if not keys:
        return pd.Series(np.where(creep, "model", ""), index=runs.index)
    short = {k: k.split(".")[-1] for k in keys}
    if len(set(short.values())) < len(keys):
        short = {k: k for k in keys}
    labels = [", ".join(f"{short[k]}={_fmt_value(r[k])}" for k in keys) if ok else ""
              for ok, r in zip(basis, runs.to_dict("records"))]
    known = sorted({lab for lab, ok in zip(labels, basis) if ok})
    fill = known[0] if len(known) == 1 else NO_PARAMS_VARIANT
    labels = [fill if c and not b else lab for lab, c, b in zip(labels, creep, basis)]
    return pd.Series(labels, index=runs.index)


def fill_missing_params(runs: pd.DataFrame) -> tuple:
    """Parameter columns that some runs lack (params.json written before the key existed) filled
    with the shipped default, so that an older file does not look like another model.
    Returns (runs, {key: number of runs filled})."""
    try:
        defaults = flatten(default_tree())
    except GrainfracError:
        return runs, {}
    runs = runs.copy()
    has_params = runs["specimen.width"].notna() if "specimen.width" in runs else pd.Series(False, index=runs.index)
    filled = {}
    for key, value in defaults.items():
        if key not in runs or key.split(".")[0] in ("sources", "composition", "grains", "contacts"):
            continue   # no run has the key (all alike), or a material table (never assumed)
        missing = has_params & runs[key].isna()
        present = has_params & runs[key].notna()
        if missing.any() and present.any():
            if (isinstance(value, int) and not isinstance(value, bool)
                    and pd.api.types.is_float_dtype(runs.loc[present, key])):
                value = float(value)    # a column with gaps reads its integers as floats: 128 is written 128.0
            runs[key] = runs[key].astype(object)
            for i in runs.index[missing]:
                runs.at[i, key] = value
            filled[key] = int(missing.sum())
    return runs, filled


def load_study(folder, beta1: float | None = None) -> pd.DataFrame:
    """All run folders of a study with ``outcome``, ``ratio`` and ``variant`` (see lifetimes module).

    ``beta1``: every creep time rescaled to this rate (:func:`.rescale.rescale_runs`; GrainfracError
    if a creep run is not rescalable). ``runs.attrs["filled"]``: parameter keys filled with defaults.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise GrainfracError(f"{folder}: study folder not found; fix: give a folder holding run folders "
                             "(e.g. results/lifetime_small)")
    runs = collect_runs(folder, all_params=True)
    if runs.empty:
        raise GrainfracError(f"{folder}: no run folders (no run.json below it); fix: run the study first "
                             "(python3 -m grainfrac_yade creep ... or yade-batch)")
    runs = classify_runs(runs)
    if not runs["outcome"].isin(CREEP_OUTCOMES).any():
        raise GrainfracError(f"{folder}: no creep runs among {len(runs)} run folder(s); fix: analyze a creep study "
                             "(UCS studies: python3 -m grainfrac_yade analyze-ucs)")
    if beta1 is not None:
        runs = rescale.rescale_runs(runs, beta1, CREEP_OUTCOMES)   # before defaults are filled in
    else:
        runs["time_factor"] = 1.0
    runs, filled = fill_missing_params(runs)
    runs["variant"] = variant_labels(runs)
    for col in ("problem", "lifetime_s", "creep_time_end_s", "driving_stress_ratio"):
        if col not in runs:
            runs[col] = np.nan if col != "problem" else None
    runs["problem"] = runs["problem"].astype(object)
    for i in runs.index[runs["outcome"].isin(("unfinished", "run error"))]:
        hist = read_history(runs.at[i, "folder"], runs.at[i, "time_factor"])
        reach = f"; history.csv reaches t = {hist['creep_time_s'].iloc[-1]:.4g} s" if hist is not None and len(hist) \
            else ""
        known = runs.at[i, "problem"]   # a failed task's error, a SLURM row not started yet
        runs.at[i, "problem"] = (known if isinstance(known, str) and known else
                                 "no summary.json (running, stopped or crashed)") + reach
    for i in runs.index[runs["outcome"].isin(("numerical failure", "failed before test"))]:
        runs.at[i, "problem"] = runs.at[i, "failure_reason"] if "failure_reason" in runs else runs.at[i, "outcome"]
    runs["first_creep_crack_s"] = [first_creep_crack(f, tf) if o in CREEP_OUTCOMES else np.nan
                                   for f, tf, o in zip(runs["folder"], runs["time_factor"], runs["outcome"])]
    runs["fit_left_out"] = [FIRST_RELAXATION if no_creep_life(r) else None for r in runs.to_dict("records")]
    runs["lifetime_readable"] = [readable_duration(t) if o == "failed" else None
                                 for t, o in zip(runs["lifetime_s"], runs["outcome"])]
    runs = with_minimum_creep_rates(runs)
    runs.attrs["filled"] = filled
    return runs


#: Why a failed run is left out of the lifetime fits (column ``fit_left_out``; empty for a fitted run).
FIRST_RELAXATION = "failed in the relaxation after its first creep event: no creep life"


def no_creep_life(row: dict) -> bool:
    """Whether a failed run collapsed in the relaxation after its first creep event (summary.json
    ``failed_in_first_relaxation``; in summaries older than the key: an event-clock run with one event or none):
    its lifetime is one bond's corrosion time, not a creep life, and it is left out of the fits."""
    if row.get("outcome") != "failed":
        return False
    flag = row.get("failed_in_first_relaxation")
    if isinstance(flag, (bool, np.bool_)):
        return bool(flag)
    clock = row.get("clock") if isinstance(row.get("clock"), str) else row.get("stress_corrosion.clock")
    events = pd.to_numeric(pd.Series([row.get("n_events")]), errors="coerce").iloc[0]
    return clock == "event" and bool(events <= 1)


#: The summary key of the minimum creep strain rate [1/s] and of its status ("resolved" or why not).
MIN_RATE, MIN_RATE_STATUS = "min_creep_strain_rate_per_s", "min_creep_strain_rate"


def with_minimum_creep_rates(runs: pd.DataFrame) -> pd.DataFrame:
    """``runs`` with :data:`MIN_RATE` and :data:`MIN_RATE_STATUS` for every failed run: as its summary.json gives
    them (rescaled with its times), else, for a run written before the keys, from its history.csv as the run
    would have (:func:`~grainfrac_yade.analysis.creep_analysis.minimum_creep_rate` of the history before the
    collapse row)."""
    runs = runs.copy()
    for col in (MIN_RATE, MIN_RATE_STATUS):
        if col not in runs:
            runs[col] = np.nan
    runs[MIN_RATE_STATUS] = runs[MIN_RATE_STATUS].astype(object)
    for i in runs.index[(runs["outcome"] == "failed") & runs[MIN_RATE_STATUS].isna()]:
        hist = read_history(runs.at[i, "folder"], runs.at[i, "time_factor"])
        life = pd.to_numeric(pd.Series([runs.at[i, "lifetime_s"]]), errors="coerce").iloc[0]
        if hist is None or len(hist) < 2:
            rate = MinimumCreepRate(None, "no history.csv")
        else:
            rate = minimum_creep_rate(hist["creep_time_s"].to_numpy(float)[:-1],
                                      hist["axial_strain"].to_numpy(float)[:-1], life)
        runs.at[i, MIN_RATE] = np.nan if rate.rate_per_s is None else rate.rate_per_s
        runs.at[i, MIN_RATE_STATUS] = rate.unresolved or "resolved"
    return runs


def study_names(folders) -> list:
    """Short distinct labels of study folders: the folder name, with parents added where names repeat."""
    paths = [Path(f).resolve() for f in folders]
    depth = 1
    while True:
        names = ["/".join(p.parts[-depth:]) for p in paths]
        if len(set(names)) == len(names) or depth >= max(len(p.parts) for p in paths):
            return names
        depth += 1


def load_studies(folders, beta1: float | None = None) -> pd.DataFrame:
    """Runs of one or several studies. With several, runs are labelled by study (column ``study``,
    ``run`` = study/run) and each study's variants become "study" or "study: variant"."""
    folders = [Path(f) for f in folders]
    if len(folders) == 1:
        runs = load_study(folders[0], beta1)
        runs["study"] = study_names(folders)[0]
        return runs
    frames, filled = [], {}
    for folder, name in zip(folders, study_names(folders)):
        runs = load_study(folder, beta1)
        for k, n in runs.attrs.get("filled", {}).items():
            filled[k] = filled.get(k, 0) + n
        runs["study"] = name
        runs["run"] = [f"{name}/{r}" for r in runs["run"]]
        creep = runs["outcome"].isin(CREEP_OUTCOMES)
        several = runs.loc[creep, "variant"].nunique() > 1
        runs["variant"] = [(f"{name}: {v}" if several else name) if c else "" for v, c in zip(runs["variant"], creep)]
        frames.append(runs)
    runs = pd.concat(frames, ignore_index=True)
    runs.attrs["filled"] = filled
    return runs


def _read_csv(path: Path, required) -> pd.DataFrame | None:
    """A run's CSV, or None if missing, unreadable or lacking ``required`` columns (never raises)."""
    try:
        frame = history_as_today(pd.read_csv(path))   # step columns of older runs by today's names
    except (OSError, pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError):
        return None
    return frame if all(c in frame for c in required) else None


def read_history(folder, time_factor: float = 1.0) -> pd.DataFrame | None:
    """history.csv of a run (creep times multiplied by ``time_factor``), or None."""
    hist = _read_csv(Path(folder) / "history.csv", ("creep_time_s", "axial_strain"))
    return rescale.scale_times(hist, time_factor, rescale.HISTORY_TIME_COLUMNS)


def read_cracks(folder, time_factor: float = 1.0) -> pd.DataFrame | None:
    """cracks.csv of a run (creep times >= 0 multiplied by ``time_factor``), or None.  Cracks of the ramp get
    the creep time -1 in the frame (:data:`grainfrac_yade.analysis.crack_phases.RAMP_TIME`): files with a
    ``phase`` column leave their creep time empty, older files wrote -1."""
    cracks = _read_csv(Path(folder) / "cracks.csv", ("creep_time_s", "mode", "kind", "x_m", "y_m",
                                                     "face_normal_angle_deg"))
    if cracks is not None and "phase" in cracks:
        from .crack_phases import RAMP_TIME
        cracks["creep_time_s"] = cracks["creep_time_s"].where(cracks["phase"] != "ramp", RAMP_TIME)
    return rescale.scale_times(cracks, time_factor, rescale.CRACK_TIME_COLUMNS)


def first_creep_crack(folder, time_factor: float = 1.0) -> float:
    """Creep time [s] of a run's first creep crack (the first bond broken at the held load; the paper's first
    microcrack at 0.26 s, section 4.1) from its cracks.csv; NaN without cracks.csv or without creep cracks."""
    cracks = read_cracks(folder, time_factor)
    if cracks is None:
        return np.nan
    creep = cracks["creep_time_s"][cracks["creep_time_s"] >= 0]
    return float(creep.min()) if len(creep) else np.nan
