"""Markdown of a study report: tables and text only (the numbers come from the caller)."""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

MISSING = "-"


def fmt(value, spec: str = "") -> str:
    """``value`` formatted with ``spec``; None/NaN as "-"; strings unchanged (pipes escaped)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return MISSING
    if isinstance(value, str):
        return value.replace("|", "\\|")
    try:
        return format(value, spec)
    except (TypeError, ValueError):
        return str(value)


def markdown_table(frame: pd.DataFrame, columns: dict) -> str:
    """``columns``: {column: (header, format spec)}; columns missing from ``frame`` are shown as "-"."""
    head = "| " + " | ".join(h for h, _ in columns.values()) + " |"
    rule = "|" + "---|" * len(columns)
    rows = ["| " + " | ".join(fmt(r.get(c), spec) for c, (_, spec) in columns.items()) + " |"
            for r in frame.to_dict("records")]
    return "\n".join([head, rule, *rows])


#: Quantities of the coefficient table, shown as rows with one column per data set.
COEFFICIENT_ROWS = (
    ("n_points", "points fitted", "d"), ("n_ratios", "distinct ratios", "d"),
    ("a_ln_s", "a in ln t = a - b r [ln s]", ".4g"), ("a_se", "  standard error of a", ".3g"),
    ("a_ci95", "  95 % interval of a (+-)", ".3g"), ("b", "b [-]", ".4g"), ("b_se", "  standard error of b", ".3g"),
    ("b_ci95", "  95 % interval of b (+-)", ".3g"), ("r2_exponential", "R^2 (ln t vs r)", ".4f"),
    ("n", "n in t = A r^-n [-]", ".4g"), ("n_se", "  standard error of n", ".3g"),
    ("n_ci95", "  95 % interval of n (+-)", ".3g"), ("ln_A_ln_s", "ln A [ln s]", ".4g"),
    ("ln_A_se", "  standard error of ln A", ".3g"), ("A_s", "A [s]", ".4g"), ("r2_power", "R^2 (ln t vs ln r)", ".4f"),
)


def coefficients_markdown(coefficients: pd.DataFrame) -> str:
    """Fitted coefficients side by side: one column per data set (model variants, lab)."""
    sets = coefficients.to_dict("records")
    lines = ["| quantity | " + " | ".join(fmt(s["dataset"]) for s in sets) + " |", "|---|" + "---|" * len(sets)]
    for key, label, spec in COEFFICIENT_ROWS:
        lines.append(f"| {label} | " + " | ".join(fmt(s.get(key), spec) for s in sets) + " |")
    return "\n".join(lines)


#: The crack counts of the run table and the figures, defined once (as in docs/reference/output_files.md).
CRACK_COUNTS = ("Crack counts: *cracks* are broken bonds (microcracks) of the ramp and of creep; *creep cracks* those "
                "broken at the held load (cracks = ramp cracks + creep cracks); *macrocracks* the cracks whose face is "
                "fully separated, ramp or creep: a subset of the cracks (never more), not of the creep cracks. The "
                "crack maps title each panel \"N cracks, M of them macro\" at its time.")

#: The minimum creep strain rate of the run table, defined once (as in docs/reference/output_files.md).
MIN_RATE_WORDS = ("*min creep rate*: the minimum (secondary) axial creep strain rate of a failed run, the secant rate "
                  "between the end of primary and the start of tertiary creep (summary.json "
                  "min_creep_strain_rate_per_s; where the history does not resolve the stages, runs.csv "
                  "min_creep_strain_rate says why). *lifetime*: the lifetime in the unit that reads best.")

RUN_COLUMNS = {
    "link": ("run", ""), "engine": ("engine", ""), "seed": ("seed", ""), "variant": ("variant", ""), "driving_stress_ratio": ("ratio", ".4f"),
    "stress_mpa": ("stress [MPa]", ".1f"), "status": ("status", ""), "outcome": ("outcome", ""),
    "lifetime_s": ("lifetime [s]", ".4g"), "lifetime_readable": ("lifetime", ""),
    "min_creep_strain_rate_per_s": ("min creep rate [1/s]", ".3g"), "creep_time_end_s": ("end of creep [s]", ".4g"),
    "n_events": ("events", ".0f"), "broken_total": ("cracks", ".0f"), "broken_creep": ("creep cracks", ".0f"),
    "macrocracks": ("macrocracks", ".0f"),
    "wall_s": ("wall [s]", ".0f"), "problem": ("problem", ""),
}

CONFINEMENT_TABLE = {
    "law": ("law", ""), "engine": ("engine", ""), "ratio": ("ratio", ".3f"), "confining_stress_mpa": ("sigma_3 [MPa]", "g"), "n": ("n", "d"),
    "n_failed": ("failed", "d"), "lifetime_geomean_s": ("geometric mean lifetime [s]", ".3g"),
    "lifetime_min_s": ("min [s]", ".3g"), "lifetime_max_s": ("max [s]", ".3g"),
}
CRACK_PHASE_TABLE = {
    "run": ("run", ""), "engine": ("engine", ""), "seed": ("seed", ""), "driving_stress_ratio": ("ratio", ".3f"),
    "phase": ("phase", ""),
    "cracks": ("cracks (bonds)", "d"), "tensile_share": ("tensile", ".2f"),
    "axial_share": ("axial (plane within 30 deg of the load)", ".2f"), "inter_share": ("inter-granular", ".2f"),
}
STATS_COLUMNS = {
    "dataset": ("data set", ""), "driving_stress_ratio": ("ratio", ".4f"), "n": ("n", "d"),
    "geomean_lifetime_s": ("geometric mean lifetime [s]", ".4g"), "geomean_lifetime_readable": ("(readable)", ""),
    "sd_log10_lifetime": ("sd of log10 t [decades]", ".3f"),
    "min_lifetime_s": ("min [s]", ".4g"), "max_lifetime_s": ("max [s]", ".4g"),
    "spread_decades": ("max/min [decades]", ".2f"),
}


#: The outcomes as the report's first line counts them: what each means for a run (a specimen that *failed* gave a
#: lifetime; nothing crashed).
OUTCOME_WORDS = {"failed": "failed by creep (a lifetime each)", "failed at load": "failed at load (t = 0)",
                 "not failed": "not failed (lower bounds)", "numerical failure": "numerical failure (no result)",
                 "failed before test": "broke apart before the test (no result)",
                 "unfinished": "unfinished (no summary.json)", "run error": "run error (the task failed)",
                 "not creep": "not creep runs"}


@dataclass
class ReportContent:
    """Everything the report shows; figures are file names inside the report folder."""
    study: Path
    out: Path
    runs: pd.DataFrame
    coefficients: pd.DataFrame
    fit_notes: list = field(default_factory=list)
    lab_text: list = field(default_factory=list)
    stats: pd.DataFrame | None = None
    spread_text: list = field(default_factory=list)
    figures: list = field(default_factory=list)      # (file name, caption)
    skipped: list = field(default_factory=list)      # (file name, reason)
    tables: list = field(default_factory=list)       # file names of CSV/markdown tables
    notes: list = field(default_factory=list)
    studies: list = field(default_factory=list)      # all study folders (several: shown together)
    banner: list = field(default_factory=list)       # shown first, prominently (e.g. rescaled times)


def _runs_for_table(content: ReportContent) -> pd.DataFrame:
    runs = content.runs.copy()
    runs["link"] = [f"[{r}]({Path(os.path.relpath(f, content.out)).as_posix()})"
                    for r, f in zip(runs["run"], runs["folder"])]
    if "stress_pa" in runs:
        runs["stress_mpa"] = pd.to_numeric(runs["stress_pa"], errors="coerce") / 1e6
    return runs


def render_report(c: ReportContent) -> str:
    counts = c.runs["outcome"].value_counts()
    studies = c.studies or [c.study]
    if len(studies) == 1:
        lines = [f"# Creep study report: {c.study.name}", "", f"Study folder: `{c.study}`. "]
    else:
        names = sorted(set(c.runs["study"])) if "study" in c.runs else [s.name for s in studies]
        lines = [f"# Creep study report: {' + '.join(names)}", "",
                 f"{len(studies)} study folders, each labelled by its name and fitted separately: "
                 + ", ".join(f"`{s}`" for s in studies) + ". "]
    lines[-1] += f"{len(c.runs)} run folder(s): " + ", ".join(f"{n} {OUTCOME_WORDS.get(k, k)}"
                                                              for k, n in counts.items()) + "."
    lines.append("")
    if c.banner:   # a block quote: paragraphs separated by ">" lines
        for k, t in enumerate(c.banner):
            lines += ([">"] if k else []) + [f"> {t}"]
        lines.append("")
    lines += ["## Runs", "",
             "Every folder holding a run.json or failed.json is listed, and every SLURM row without one. "
             "Outcomes: *failed* (the specimen failed by creep: lifetime = creep time at failure, "
             "fitted unless fit_left_out says why not, e.g. a run that failed in the relaxation after its first "
             "creep event: no creep life), *failed at load* (failed at creep time 0: no creep life, not in the log "
             "fit), "
             "*not failed* (the run ended without failure: its end time is a lower bound of the lifetime, drawn "
             "as an open marker with an arrow and **not used in the fit**), *numerical failure* (the run stopped on NaN or "
             "infinite numbers or a stalled creep clock, reason in failure_reason: no result, neither a lifetime "
             "nor a lower bound), *failed before test* (a confined specimen broke apart in the isotropic stage, "
             "reason in failure_reason: no creep test, no result), *unfinished* (no summary.json: "
             "running, stopped or crashed, or a SLURM row not started yet), *run error* (no summary.json; the batch "
             "task that ran it failed and recorded its error line in failed.json, shown as problem), "
             "*unreadable* (a JSON file that cannot be parsed, or a failed run without a "
             "valid lifetime).", "", CRACK_COUNTS, "", MIN_RATE_WORDS, "",
             markdown_table(_runs_for_table(c), RUN_COLUMNS), ""]
    lines += ["## Lifetime vs driving-stress ratio (paper Fig. 4)", "",
              "Fitted by least squares in ln t: the static-fatigue line ln t_f = a - b r and the power law "
              "t_f = A r^-n (ln t_f = ln A - n ln r); r = sigma / sigma_c. Standard errors from the parameter "
              "covariance, 95 % intervals and the band of the mean line with Student's t (N - 2 degrees of "
              "freedom).", ""]
    lines += [f"- {n}" for n in c.fit_notes] + [""]
    if len(c.coefficients):
        lines += [coefficients_markdown(c.coefficients), ""]
    else:
        lines += ["No data set had lifetimes at two or more distinct ratios: no coefficients.", ""]
    lines += ["### Lab data", ""] + [f"- {t}" for t in c.lab_text] + [""]
    lines += ["## Lifetime scatter per load level", ""]
    if c.stats is not None and len(c.stats):
        lines += [markdown_table(c.stats, STATS_COLUMNS), ""]
    else:
        lines += ["No ratio has three or more failed runs (seeds): no scatter statistics.", ""]
    lines += [f"- {t}" for t in c.spread_text] + [""]
    lines += ["## Figures", ""]
    for name, caption in c.figures:
        lines += [f"### {caption}", "", f"![{caption}]({name})", ""]
    if c.skipped:
        lines += ["Figures not drawn:", ""] + [f"- `{n}`: {why}" for n, why in c.skipped] + [""]
    if c.tables:
        lines += ["## Tables", ""] + [f"- [{n}]({n})" for n in c.tables] + [""]
    if c.notes:
        lines += ["## Notes", ""] + [f"- {n}" for n in c.notes] + [""]
    return "\n".join(lines)
