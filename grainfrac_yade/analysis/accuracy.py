"""What accuracy costs in time: the accuracy-cost study's runs -> one row per (knob, setting), a markdown
table and a Pareto figure (error against wall time).

Error of a setting = mean over the (ratio, seed) pairs of |ln t_f - ln t_f,ref|, with t_f,ref the lifetime
of the same ratio and seed under the knob's reference setting; ``error_pct`` = exp(error) - 1 (a factor
on the lifetime, in %).  Pairs where either run has no lifetime (failed at load, not failed, numerical
failure, unfinished) are left out and counted in ``note``.  The slope b is that of the pooled fit
ln t_f = a - b r over the setting's failed runs (Schmidtke & Lajtai's form, paper Eq. 9's exponential
alternative); its change is b - b_ref.  Costs are means per creep run: DEM steps, wall time and the
process's CPU time (``cpu_s``, which neither other jobs on the machine nor a paused run inflate; the
Pareto figure's abscissa where every run has it).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from .accuracy_study import DEFAULT_SETTING, Study, run_index
from .lifetimes import outcome

#: Where a zero error (the reference itself) sits on the log axis of the Pareto figure.
ZERO_ERROR_FLOOR = 1e-3


def label_runs(study: Study, runs: pd.DataFrame) -> pd.DataFrame:
    """``runs`` (:func:`~grainfrac_yade.analysis.collect.collect_runs` of the study folder) with the columns
    setting, test, ratio_planned, seed_planned and outcome; folders that are not the study's are dropped."""
    index = run_index(study)
    rows = []
    for _, row in runs.iterrows():
        where = index.get(Path(row["folder"]))
        if where is None:
            continue
        d = row.to_dict()
        d.update(setting=where[0], test=where[1], ratio_planned=where[2], seed_planned=where[3],
                 outcome=outcome(d) if where[1] == "creep" else d.get("status"))
        rows.append(d)
    return pd.DataFrame(rows)


def creep_strain_before_tertiary(history: pd.DataFrame | None, tertiary_start_s) -> float:
    """Axial strain gained in creep (from creep time 0) up to the start of tertiary creep; NaN if unknown."""
    if history is None or history.empty or tertiary_start_s is None or not math.isfinite(float(tertiary_start_s)):
        return float("nan")
    t = history["creep_time_s"].to_numpy(float)
    eps = history["axial_strain"].to_numpy(float)
    return float(np.interp(float(tertiary_start_s), t, eps) - eps[0])


def history_measures(history: pd.DataFrame | None, tertiary_start_s, clock: str) -> dict:
    """Per-run measures read from history.csv of a run that failed in creep: the creep strain before tertiary
    creep, the DEM steps of the creep phase (after the ramp's row), those of the final relaxation (the
    collapse) and, for the event clock (one history row per relaxation), the mean DEM steps of the
    relaxations that reached equilibrium (every one but the last)."""
    out = {"creep_strain_before_tertiary": creep_strain_before_tertiary(history, tertiary_start_s),
           "creep_dem_steps": float("nan"), "final_relaxation_steps": float("nan"),
           "steps_per_relaxation": float("nan")}
    if history is None or len(history) < 2:
        return out
    steps = history["step"].to_numpy(float)
    out["creep_dem_steps"] = float(steps[-1] - steps[0])
    if clock == "event":
        out["final_relaxation_steps"] = float(steps[-1] - steps[-2])
        if len(history) >= 3:
            out["steps_per_relaxation"] = float(steps[-2] - steps[0]) / (len(history) - 2)
    return out


def lifetimes(labelled: pd.DataFrame) -> dict:
    """{(setting, ratio, seed): lifetime [s]} of the creep runs that failed in creep (t_f > 0)."""
    creep = labelled[(labelled["test"] == "creep") & (labelled["outcome"] == "failed")]
    return {(r.setting, float(r.ratio_planned), int(r.seed_planned)): float(r.lifetime_s)
            for r in creep.itertuples()}


def slope_b(points) -> float:
    """b of the least-squares line ln t = a - b r through ``points`` [(ratio, lifetime)], NaN with fewer than two
    distinct ratios."""
    r = np.array([p[0] for p in points], float)
    t = np.array([p[1] for p in points], float)
    if len(set(r.tolist())) < 2:
        return float("nan")
    slope, _ = np.polyfit(r, np.log(t), 1)
    return float(-slope)


def _mean(values) -> float:
    values = [v for v in values if v is not None and math.isfinite(v)]
    return float(np.mean(values)) if values else float("nan")


def setting_rows(study: Study, labelled: pd.DataFrame, measures=None) -> pd.DataFrame:
    """One row per (knob, setting): the default setting once per knob, every other setting under its own
    (a knob none of whose settings is in ``study``, e.g. in the quick subset, is left out).

    ``measures``: {(setting, ratio, seed): :func:`history_measures` of that run} (optional; NaN where missing).
    """
    life = lifetimes(labelled)
    measures = measures or {}
    rows = []
    for knob in study.knobs.values():
        if not any(s.knob == knob.name for s in study.settings):
            continue
        ref = knob.reference
        members = [s for s in study.settings if s.knob == knob.name or s.name in (DEFAULT_SETTING, ref)]
        for s in members:
            rows.append(_row(study, labelled, life, measures, knob, s, ref))
    return pd.DataFrame(rows)


def _row(study, labelled, life, measures, knob, setting, ref) -> dict:
    mine = labelled[labelled["setting"] == setting.name] if len(labelled) else labelled
    creep = mine[mine["test"] == "creep"] if len(mine) else mine
    ucs_source = setting.name if setting.ucs_test else DEFAULT_SETTING
    ucs_runs = labelled[(labelled["setting"] == ucs_source) & (labelled["test"] == "ucs")
                        & (labelled["status"] == "finished")] if len(labelled) else labelled
    pairs = [(r, s) for r in study.ratios for s in study.seeds]
    errors, missing = [], 0
    for r, s in pairs:
        a, b = life.get((setting.name, r, s)), life.get((ref, r, s))
        if a is None or b is None:
            missing += 1
        else:
            errors.append(abs(math.log(a) - math.log(b)))
    b_here = slope_b([(r, t) for (name, r, _), t in life.items() if name == setting.name])
    b_ref = slope_b([(r, t) for (name, r, _), t in life.items() if name == ref])
    out = {"knob": knob.name, "setting": setting.name, "reference": ref, "what": setting.what,
           "creep_runs_finished": int((creep["status"] == "finished").sum()) if len(creep) else 0,
           "creep_runs_planned": len(pairs),
           "ucs_mpa": _mean(ucs_runs.get("ucs_pa", pd.Series(dtype=float)) / 1e6) if len(ucs_runs) else float("nan"),
           "young_gpa": _mean(ucs_runs.get("young_pa", pd.Series(dtype=float)) / 1e9) if len(ucs_runs) else float("nan"),
           "ucs_from": ucs_source}
    for r in study.ratios:
        t = [life[(setting.name, r, s)] for s in study.seeds if (setting.name, r, s) in life]
        out[f"lifetime_geomean_r{r:g}_s"] = float(np.exp(np.mean(np.log(t)))) if t else float("nan")
    out.update(error_ln_mean=_mean(errors), error_ln_max=max(errors) if errors else float("nan"),
               error_pct=(math.exp(_mean(errors)) - 1) * 100 if errors else float("nan"),
               pairs_compared=len(errors), slope_b=b_here, slope_b_change=b_here - b_ref)
    for key in ("creep_strain_before_tertiary", "creep_dem_steps", "final_relaxation_steps", "steps_per_relaxation"):
        out[key] = _mean([measures.get((setting.name, r, s), {}).get(key) for r, s in pairs])
    done = creep[creep["status"] == "finished"] if len(creep) else creep
    for col, name in (("broken_total", "microcracks_at_end"), ("macrocracks", "macrocracks_at_end"),
                      ("n_events", "events"), ("steps", "dem_steps_per_run"), ("wall_s", "wall_s_per_run"),
                      ("cpu_s", "cpu_s_per_run")):
        out[name] = _mean(done[col].astype(float)) if len(done) and col in done else float("nan")
    notes = []
    if missing:
        notes.append(f"{missing} of {len(pairs)} (ratio, seed) pairs without a lifetime here or in the reference")
    outcomes = creep["outcome"].value_counts().to_dict() if len(creep) else {}
    others = {k: v for k, v in outcomes.items() if k != "failed"}
    if others:
        notes.append(", ".join(f"{v} {k}" for k, v in sorted(others.items())))
    out["note"] = "; ".join(notes)
    return out


def markdown_table(table: pd.DataFrame, ratios) -> str:
    """The study's table as markdown (the README's and docs/accuracy_cost.md's)."""
    life_cols = [f"lifetime_geomean_r{r:g}_s" for r in ratios]
    head = (["knob", "setting", "UCS [MPa]", "E [GPa]"] + [f"t_f r={r:g} [s]" for r in ratios]
            + ["error (mean abs d ln t_f)", "error [%]", "b", "db", "creep strain to tertiary", "micro / macro cracks",
               "DEM steps / run", "steps / relaxation", "final relaxation steps", "CPU [s] / run", "wall [s] / run", "runs", "note"])
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]

    def f(v, fmt):
        return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else format(v, fmt)
    for r in table.to_dict("records"):
        ref = " (ref)" if r["setting"] == r["reference"] else ""
        ucs = f(r["ucs_mpa"], ".1f") + ("" if r["ucs_from"] == r["setting"] else "*")
        cells = ([r["knob"], f"{r['setting']}{ref}", ucs, f(r["young_gpa"], ".1f")]
                 + [f(r[c], ".3g") for c in life_cols]
                 + [f(r["error_ln_mean"], ".3f"), f(r["error_pct"], ".1f"), f(r["slope_b"], ".1f"),
                    f(r["slope_b_change"], "+.1f"), f(r["creep_strain_before_tertiary"], ".2e"),
                    f"{f(r['microcracks_at_end'], '.0f')} / {f(r['macrocracks_at_end'], '.0f')}",
                    f(r["dem_steps_per_run"], ".0f"), f(r["steps_per_relaxation"], ".0f"),
                    f(r["final_relaxation_steps"], ".0f"), f(r["cpu_s_per_run"], ".1f"), f(r["wall_s_per_run"], ".1f"),
                    f"{r['creep_runs_finished']}/{r['creep_runs_planned']}", r["note"] or ""])
        lines.append("| " + " | ".join(str(c) for c in cells) + " |")
    lines.append("")
    lines.append("UCS marked * is the default setting's (the knob does not change the loading test).")
    return "\n".join(lines) + "\n"


def pareto_figure(table: pd.DataFrame, path, title: str = "What accuracy costs in time"):
    """Error against cost per creep run (CPU time where every run has it, else wall time), log axes, one
    series per knob; an error of 0 (a reference, or a setting equal to it) sits at :data:`ZERO_ERROR_FLOOR`, hollow."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cost = "cpu_s_per_run" if np.isfinite(table["cpu_s_per_run"]).all() else "wall_s_per_run"
    fig, ax = plt.subplots(figsize=(7.5, 5))
    markers = "osD^vP*X"
    for i, (knob, group) in enumerate(table.groupby("knob", sort=False)):
        g = group[np.isfinite(group[cost]) & np.isfinite(group["error_ln_mean"])]
        if g.empty:
            continue
        err = np.maximum(g["error_ln_mean"].to_numpy(float), ZERO_ERROR_FLOOR)
        line = ax.plot(g[cost], err, ls="none", marker=markers[i % len(markers)], label=knob)[0]
        zero = g["error_ln_mean"].to_numpy(float) <= 0
        if zero.any():
            ax.plot(g[cost][zero], err[zero], ls="none", marker=markers[i % len(markers)], ms=11,
                    mfc="none", color=line.get_color())
        for w, e, name in zip(g[cost], err, g["setting"]):
            ax.annotate(name, (w, e), fontsize=6, xytext=(3, 3), textcoords="offset points")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(("CPU" if cost == "cpu_s_per_run" else "wall") + " time per creep run [s] (one core)")
    ax.set_ylabel("error: mean |ln t_f - ln t_f,ref| over seeds and ratios")
    ax.set_title(title + f"\n(error 0, each knob's reference and settings equal to it: hollow, at {ZERO_ERROR_FLOOR:g})",
                 fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path
