"""A study folder -> the paper's figures and tables plus report.md (``analyze`` command).

Reads run folders only (run.json, params.json, summary.json, history.csv, cracks.csv) and writes
into the report folder only; run folders are never changed. Several study folders can be shown
together (each labelled by its folder name and fitted separately); with ``beta1`` every creep
time is rescaled exactly to another stress-corrosion rate (see :mod:`.rescale`).
"""
from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import GrainfracError
from ..runs.runio import write_csv
from . import crack_phases, crackmaps, creep_rates, figures, rescale
from .collect import ENGINE_COLUMN, check_report_folder, code_version_note
from .figures import MAP_FRACTIONS, Curve, LifetimeSet
from .fits import coefficient_table, distinct_ratios, fit_lifetimes
from .labdata import paper_reference, read_lab_csv
from .lifetimes import _num, confinement_lifetimes, lifetime_stats, representatives, with_confinement_columns
from .report import CONFINEMENT_TABLE, CRACK_PHASE_TABLE, ReportContent, coefficients_markdown, markdown_table, render_report, STATS_COLUMNS
from .runparams import rebuild_specimen
from .study_runs import (CREEP_OUTCOMES, NO_PARAMS_VARIANT, RUN_TABLE, VARIANT_IGNORE, _read_csv,  # noqa: F401
                         fill_missing_params, first_creep_crack, load_studies, load_study, read_cracks, read_history,
                         study_names, variant_labels)

#: Decades of lifetime scatter that count as "orders of magnitude" when comparing with the lab.
ORDER_OF_MAGNITUDE = 1.0


def fitted(runs: pd.DataFrame) -> pd.Series:
    """True for the runs no reason leaves out of the lifetime fits (column ``fit_left_out`` empty)."""
    if "fit_left_out" not in runs:
        return pd.Series(True, index=runs.index)
    return runs["fit_left_out"].isna()


def left_out_note(g: pd.DataFrame) -> str:
    """The fit note naming the failed runs of ``g`` left out of the fits, each with its lifetime, and why."""
    out = g[(g["outcome"] == "failed") & ~fitted(g)]
    if not len(out):
        return ""
    runs = ", ".join(f"{r['run']} (t = {_num(r['lifetime_s']):.3g} s)" for r in out.to_dict("records"))
    reasons = "; ".join(sorted(set(out["fit_left_out"])))
    return f"; {len(out)} left out of the fit ({reasons}): {runs}"


def lifetime_sets(runs: pd.DataFrame) -> list:
    """One :class:`LifetimeSet` per model variant: failed points (t > 0, fitted; not those
    :func:`fitted` leaves out) and lower bounds."""
    sets = []
    for variant, g in runs[runs["outcome"].isin(CREEP_OUTCOMES)].groupby("variant", sort=True):
        failed = g[(g["outcome"] == "failed") & g["ratio"].notna() & fitted(g)]
        lower = g[(g["outcome"] == "not failed") & g["ratio"].notna()]
        ratio, life = failed["driving_stress_ratio"].to_numpy(float), failed["lifetime_s"].to_numpy(float)
        fit = fit_lifetimes(ratio, life, source=f"{variant} runs") if len(ratio) else None
        end = lower["creep_time_end_s"].to_numpy(float)
        pos = end > 0   # a run that ended at t = 0 gives no bound on a log axis
        at_load = g[(g["outcome"] == "failed at load") & g["ratio"].notna()]
        sets.append(LifetimeSet(label=variant, ratio=ratio, lifetime_s=life, fit=fit,
                                lower_ratio=lower["driving_stress_ratio"].to_numpy(float)[pos],
                                lower_time_s=end[pos],
                                at_load_ratio=at_load["driving_stress_ratio"].to_numpy(float),
                                ucs_pa=pd.to_numeric(g["ucs_pa"], errors="coerce").to_numpy(float)
                                if "ucs_pa" in g else np.zeros(0)))
    return sets



def _factor(row: dict) -> float:
    f = _num(row.get("time_factor", 1.0))
    return f if math.isfinite(f) and f > 0 else 1.0


def curve_label(row: dict, with_variant: bool) -> str:
    stress = _num(row.get("stress_pa")) / 1e6
    text = f"r = {row['driving_stress_ratio']:.3f}" + (f" ({stress:.0f} MPa)" if math.isfinite(stress) else "") + \
        f", seed {row.get('seed')}"
    return f"{row['variant']}: {text}" if with_variant else text


def make_curve(row: dict, with_variant: bool) -> Curve | None:
    """Curve of a finished run, or None without a usable history or a positive reference time."""
    hist = read_history(row["folder"], _factor(row))
    failed = row["outcome"] in ("failed", "failed at load")
    t_ref = _num(row.get("lifetime_s") if failed else row.get("creep_time_end_s"))
    if hist is None or len(hist) < 2 or not (t_ref > 0):
        return None
    stages = {k: _num(row.get(k)) for k in figures.STAGE_MARKERS}
    return Curve(curve_label(row, with_variant), hist, failed, t_ref, stages, _num(row.get("broken_ramp")) or 0.0)


def choose_focus(reps: pd.DataFrame, ratio: float | None):
    """The representative run nearest ``ratio`` (failed runs first); None if there is none."""
    for outcomes in (("failed",), ("not failed",)):
        cand = reps[reps["outcome"].isin(outcomes)]
        if len(cand):
            target = ratio if ratio is not None else float(cand["ratio"].median())
            return cand.loc[(cand["ratio"] - target).abs().idxmin()]
    return None


def _spread_text(stats: pd.DataFrame, lab_stats: pd.DataFrame | None, reference) -> list:
    text = []
    if len(stats):
        top = stats.loc[stats["spread_decades"].idxmax()]
        size = ("less than one decade, narrower than" if top["spread_decades"] < ORDER_OF_MAGNITUDE
                else "one decade or more, comparable with")
        text.append(f"Model: largest scatter {top['spread_decades']:.2f} decades (max/min) at r = "
                    f"{top['driving_stress_ratio']:.4g} ({top['dataset']}, {int(top['n'])} seeds): {size} the lab's "
                    "scatter of orders of magnitude at one ratio.")
    if lab_stats is not None and len(lab_stats):
        top = lab_stats.loc[lab_stats["spread_decades"].idxmax()]
        text.append(f"Lab file: largest scatter {top['spread_decades']:.2f} decades at r = "
                    f"{top['driving_stress_ratio']:.4g} ({int(top['n'])} specimens).")
    elif lab_stats is not None:
        text.append("Lab file: no ratio with three or more specimens: no lab scatter statistics.")
    if reference is not None:
        n = reference.lab_specimens
        text.append(f"Known from {reference.readme_file.name}: Schmidtke & Lajtai's lab lifetimes "
                    f"({n:.0f} specimens per {reference.values_file.name}) scatter by orders of magnitude at one "
                    "driving-stress ratio (rock heterogeneity); the individual points are not available.")
    return text


def _rescale_text(runs: pd.DataFrame, beta1: float, source: str, reference) -> list:
    creep = runs[runs["outcome"].isin(CREEP_OUTCOMES)]
    b_run = sorted(set(pd.to_numeric(creep["beta1_run"], errors="coerce").dropna()))
    factors = sorted(set(pd.to_numeric(creep["time_factor"], errors="coerce").dropna()))
    text = [f"**All creep times in this report are rescaled** from the runs' beta1 = "
            f"{', '.join(f'{b:g}' for b in b_run)} Pa/s to beta1 = {beta1:g} Pa/s ({source}): "
            f"t' = t x beta1_run / beta1 = t x {', '.join(f'{f:.6g}' for f in factors)} (lifetimes, end times, "
            "creep stages, history and crack times, lower bounds; the fitted a shifts by ln(factor), b and n are "
            "unchanged).",
            f"Why this is exact: {rescale.WHY_EXACT}. Every creep run here was checked: event clock, strength "
            "mode, rate_form beta (paper-clock, area-mode or physical-rate runs are refused).",
            "Not rescaled: wall-clock times, DEM steps, driving-stress ratios, strains and crack counts (they do "
            "not depend on beta1)."]
    if reference is not None and math.isfinite(reference.beta1_pa_s):
        text.append(f"The paper's UDEC point is drawn as published (beta1 = {reference.beta1_pa_s:g} Pa/s, "
                    "paper clock): it is not rescaled.")
    return text


def animation_note(run_folder, out) -> str | None:
    """Report line linking the focus run's crack-growth animation (``animate``; not made here, rendering
    costs seconds per run); None when the run has none."""
    from .animation import GIF_NAME, MP4_NAME
    run_folder = Path(run_folder)
    gif = run_folder / GIF_NAME
    if not gif.is_file():
        return None
    links = [f"[{name}]({Path(os.path.relpath(run_folder / name, out)).as_posix()})"
             for name in (GIF_NAME, MP4_NAME) if (run_folder / name).is_file()]
    return f"Crack-growth animation of the run of the crack maps ({run_folder.name}): " + ", ".join(links) + "."


def _grains(focus, cracks) -> tuple:
    """(specimen or None, report line): the focus run's specimen rebuilt and verified, else why not."""
    try:
        rebuilt = rebuild_specimen(focus["folder"], focus.get("seed"), n_bonds=_num(focus.get("n_bonds")),
                                   cracks=cracks)
    except GrainfracError as exc:
        return None, f"Crack maps: grains not drawn, specimen outline only: {exc}"
    except Exception as exc:   # a tessellation failure must not stop the report
        return None, (f"Crack maps: grains not drawn, specimen outline only: rebuilding the specimen of "
                      f"{focus['folder']} failed ({type(exc).__name__}: {exc})")
    return rebuilt.specimen, f"Crack maps drawn on the run's grains (cells coloured by mineral): {rebuilt.note}."


def crack_phase_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Cracks by phase of the life (:func:`.crack_phases.crack_phases`) of every failed run with a
    cracks.csv, one block of rows per run; the inter-granular share of all bonds from the run's
    bond_stresses_start.csv where it has one."""
    blocks = []
    for r in runs[runs["outcome"] == "failed"].to_dict("records"):
        cracks = read_cracks(r["folder"], _factor(r))
        life = _num(r.get("lifetime_s"))
        if cracks is None or not (math.isfinite(life) and life > 0):
            continue
        bonds = _read_csv(Path(r["folder"]) / "bond_stresses_start.csv", ("inter",))
        inter = None if bonds is None else bonds["inter"].astype(str).str.lower().eq("true").to_numpy()
        block = crack_phases.crack_phases(cracks, life, inter)
        blocks.append(block.assign(run=r["run"], engine=r.get(ENGINE_COLUMN), seed=r.get("seed"),
                                   variant=r.get("variant"), driving_stress_ratio=r.get("driving_stress_ratio"),
                                   lifetime_s=life))
    columns = ["run", ENGINE_COLUMN, "seed", "variant", "driving_stress_ratio", "lifetime_s", *crack_phases.COLUMNS]
    if not blocks:
        return pd.DataFrame(columns=columns)
    return pd.concat(blocks, ignore_index=True)[columns]


def analyze_study(folder, lab=None, out=None, reference_dir=None, focus_ratio=None,
                  map_fractions=MAP_FRACTIONS, beta1=None, beta1_source=None, grains=True) -> Path:
    """Write figures, tables and report.md for the study in ``folder``; return the report's path.

    ``folder``: a study folder, or a list of them (shown together, each fitted separately;
    ``out`` is then required). ``lab``: CSV of lab lifetimes (driving_stress_ratio,
    lifetime_s[, source]); without it the paper's UDEC value and the Lajtai & Schmidtke (1986)
    bound from ``reference_dir`` are drawn. ``focus_ratio``: ratio of the run shown in the
    one-load figures (default: the paper's 160 MPa point's ratio, else the median).
    ``beta1`` [Pa/s]: show every creep time at this rate (exact for event-clock strength-mode
    runs, others refused; ``beta1_source`` names where the value came from). ``grains``: draw
    the run's grains under the crack maps (specimen rebuilt from params.json and the seed).
    """
    folders = [Path(f) for f in folder] if isinstance(folder, (list, tuple)) else [Path(folder)]
    if not folders:
        raise GrainfracError("no study folder given; fix: name one or more study folders")
    if len(folders) > 1 and out is None:
        raise GrainfracError(f"{len(folders)} study folders given but no report folder; fix: add --out DIR "
                             "(the report of several studies belongs to none of them)")
    if beta1 is not None:
        beta1 = rescale.check_beta1(beta1, beta1_source or "--beta1")
    runs = load_studies(folders, beta1)
    folder = folders[0]
    out = Path(out) if out is not None else folder / "report"
    check_report_folder(out)
    lab_frame = read_lab_csv(lab) if lab is not None else None   # bad lab input fails before anything is written
    if lab is None:
        reference = paper_reference(reference_dir)
    else:
        try:
            reference = paper_reference(reference_dir)
        except GrainfracError:
            reference = None   # only used to choose the focus run when a lab file is given
    out.mkdir(parents=True, exist_ok=True)
    content = ReportContent(study=folder.resolve(), out=out.resolve(), runs=runs, coefficients=pd.DataFrame(),
                            studies=[f.resolve() for f in folders])
    time_note = None
    if beta1 is not None:
        content.banner = _rescale_text(runs, beta1, beta1_source or "--beta1", reference)
        time_note = f"times rescaled to beta1 = {beta1:g} Pa/s (exact, event clock)"
    filled = runs.attrs.get("filled", {})
    if filled:
        content.notes.append("Keys missing from older params.json files, taken as the shipped defaults when "
                             "comparing runs (variants): " + ", ".join(f"{k} ({n} run(s))" for k, n in filled.items())
                             + ".")

    versions = code_version_note(runs)
    if versions:
        content.notes.append(versions)

    # lifetimes: model sets, lab set, fits, coefficient table
    sets = lifetime_sets(runs)
    multi = len(sets) > 1
    for s in sets:
        g = runs[runs["variant"] == s.label]
        k = distinct_ratios(s.ratio) if len(s.ratio) else 0
        n_load = int((g["outcome"] == "failed at load").sum())
        note = (f"{s.label}: {len(s.ratio)} failed run(s) at {k} distinct ratio(s)"
                + (" fitted" if s.fit is not None else ": fit skipped (needs failed runs at 2 or more ratios)"))
        note += left_out_note(g)
        note += f"; {int((g['outcome'] == 'not failed').sum())} run(s) did not fail (lower bounds, drawn, not fitted)"
        note += f"; {n_load} failed at load (t = 0, not in the log fit)" if n_load else ""
        n_num = int((g["outcome"] == "numerical failure").sum())
        note += f"; {n_num} numerical failure(s) (no result: not fitted, not a lower bound)" if n_num else ""
        n_apart = int((g["outcome"] == "failed before test").sum())
        note += f"; {n_apart} broke apart before the test (no result: not fitted)" if n_apart else ""
        n_err = int((g["outcome"] == "run error").sum())
        note += f"; {n_err} run error(s) (the task failed, error in problem: not used)" if n_err else ""
        note += f"; {int((g['outcome'] == 'unfinished').sum())} unfinished (not used)."
        content.fit_notes.append(note)
    lab_set = None
    if lab_frame is not None:
        lab_fit = fit_lifetimes(lab_frame["driving_stress_ratio"], lab_frame["lifetime_s"], source=str(lab))
        lab_set = LifetimeSet("lab", lab_frame["driving_stress_ratio"].to_numpy(float),
                              lab_frame["lifetime_s"].to_numpy(float), lab_fit,
                              sources=lab_frame["source"].to_numpy(str))
        srcs = ", ".join(pd.unique(lab_frame["source"]))
        content.lab_text.append(f"Lab file `{Path(lab).resolve()}`: {len(lab_frame)} specimen(s) "
                                f"({srcs}) at {distinct_ratios(lab_set.ratio)} ratio(s), fitted with the same laws"
                                + ("." if lab_fit is not None else "; fewer than 2 distinct ratios: no lab fit."))
        content.lab_text.append("With a lab file the paper's UDEC value and the Lajtai & Schmidtke (1986) bound are "
                                "not drawn (run without --lab to see them).")
    else:
        content.lab_text += [
            f"No lab file given (--lab). The individual lab lifetimes of Schmidtke & Lajtai "
            f"({reference.lab_specimens:.0f} specimens, paper Fig. 4) are not available "
            f"(`{reference.readme_file}`); none are drawn or invented.",
            f"Drawn instead: the paper's UDEC lifetime {reference.lifetime_s:.6g} s at "
            f"{reference.stress_pa / 1e6:.0f} MPa, ratio {reference.stress_pa / 1e6:.0f} / "
            f"{reference.ucs_simulated_pa / 1e6:.1f} MPa = {reference.ratio:.4f} (`{reference.values_file}`), and "
            f"the Lajtai & Schmidtke (1986) bound: the long-term strength of humid LdB granite lies below "
            f"{reference.long_term_strength_ratio:.0%} of its short-term UCS (shaded ratio < "
            f"{reference.long_term_strength_ratio:g}).",
        ]
    fits = {s.label: s.fit for s in sets}
    if lab_set is not None:
        fits["lab"] = lab_set.fit
    content.coefficients = coefficient_table(fits)
    write_csv(out / "lifetime_fits.csv", content.coefficients)
    (out / "lifetime_fits.md").write_text(coefficients_markdown(content.coefficients) + "\n")
    figures.lifetime_figure(out / "lifetime.png", sets, lab=lab_set, reference=None if lab_set else reference,
                            time_note=time_note)
    content.figures.append(("lifetime.png", "Lifetime vs driving-stress ratio with static-fatigue fits (Fig. 4)"))

    # lifetime against confinement (confined creep runs at fixed deviatoric ratios)
    confined = with_confinement_columns(runs)
    if confined.loc[confined["outcome"].isin(CREEP_OUTCOMES), "confining_stress_mpa"].nunique() > 1:
        table = confinement_lifetimes(confined)
        write_csv(out / "lifetime_confinement.csv", table)
        (out / "lifetime_confinement.md").write_text(markdown_table(table, CONFINEMENT_TABLE) + "\n")
        figures.confinement_lifetime_figure(out / "lifetime_confinement.png", confined, table, time_note=time_note)
        content.figures.append(("lifetime_confinement.png", "Lifetime vs confining stress at fixed deviatoric "
                                                            "driving-stress ratios"))
        content.tables.append("lifetime_confinement.md")

    # scatter per ratio
    stats = [lifetime_stats(s.ratio, s.lifetime_s).assign(dataset=s.label) for s in sets]
    lab_stats = None
    if lab_set is not None:
        lab_stats = lifetime_stats(lab_set.ratio, lab_set.lifetime_s).assign(dataset="lab")
        stats.append(lab_stats)
    content.stats = pd.concat(stats, ignore_index=True)
    content.spread_text = _spread_text(content.stats[content.stats["dataset"] != "lab"], lab_stats,
                                       reference)
    write_csv(out / "lifetime_stats.csv", content.stats[list(STATS_COLUMNS)])
    (out / "lifetime_stats.md").write_text(markdown_table(content.stats, STATS_COLUMNS) + "\n")

    # time histories of one run per (variant, ratio)
    reps = representatives(runs)
    curves = [(r, make_curve(r, multi)) for r in reps.to_dict("records")]
    curves = [(r, c) for r, c in curves if c is not None]
    if curves:
        cs = [c for _, c in curves]
        figures.strain_time_figure(out / "strain_time.png", cs, time_note=time_note)
        figures.strain_time_figure(out / "strain_time_normalised.png", cs, normalised=True)
        content.figures += [("strain_time.png", "Axial strain vs creep time, one run per load (Fig. 5)"),
                            ("strain_time_normalised.png", "Axial strain vs normalised time t / t_f (Fig. 5)")]
    else:
        for name in ("strain_time.png", "strain_time_normalised.png"):
            content.skipped.append((name, "no finished run with a history.csv and a positive end time"))
    rates = creep_rates.strain_rate_table(runs, lambda r: read_history(r["folder"], _factor(r)))
    write_csv(out / "strain_rate.csv", rates)
    content.tables.append("strain_rate.csv")
    shown = reps[reps["run"].isin(set(rates["run"]))]
    if len(shown):
        creep_rates.strain_rate_figure(out / "strain_rate.png", rates, shown)
        content.figures.append(("strain_rate.png", "Axial creep strain rate vs normalised time, one run per load, "
                                                   "with the minimum (secondary) creep strain rate"))
    else:
        content.skipped.append(("strain_rate.png", "no failed run whose history resolves its creep stages (at least "
                                                   "9 creep times before the collapse)"))
    failed_curves = [(r, c) for r, c in curves if r["outcome"] == "failed"]
    if failed_curves:
        pick = [failed_curves[0]] if len(failed_curves) == 1 else \
            [min(failed_curves, key=lambda rc: rc[0]["ratio"]), max(failed_curves, key=lambda rc: rc[0]["ratio"])]
        figures.damage_figure(out / "damage_index.png", [c for _, c in pick])
        content.figures.append(("damage_index.png", "Damage index vs normalised time, low and high load (Fig. 9)"))
    else:
        content.skipped.append(("damage_index.png", "no failed run with lifetime > 0 and a history.csv"))

    # one load: bonds and strain, crack maps
    target = focus_ratio if focus_ratio is not None else (reference.ratio if reference is not None else None)
    curve_by_folder = {r["folder"]: c for r, c in curves}
    focus = choose_focus(reps[reps["folder"].isin(curve_by_folder)], target)
    if focus is None:
        for name in ("bonds_strain.png", "crack_maps_mode.png", "crack_maps_kind.png"):
            content.skipped.append((name, "no finished run with a usable history.csv"))
    else:
        curve = curve_by_folder[focus["folder"]]
        fracs = sorted(set(float(f) for f in map_fractions))
        times = [f * curve.t_ref_s for f in fracs]
        word = "t_f" if curve.failed else "t_end"
        labels = [f"({chr(ord('a') + k)}) {f:.2f} {word} = {t:.3g} s" for k, (f, t) in enumerate(zip(fracs, times))]
        figures.bonds_strain_figure(out / "bonds_strain.png", curve, mark_times=times, time_note=time_note)
        content.figures.append(("bonds_strain.png", f"Broken bonds and axial strain vs creep time at one load, "
                                                    f"{curve.label} (Fig. 6; (a)-(d): crack-map times)"))
        cracks = read_cracks(focus["folder"], _factor(focus))
        dims = [_num(focus.get(k)) for k in ("specimen.width", "specimen.height", "specimen.grain_size")]
        if cracks is None:
            reason = "cracks.csv missing or lacking columns in " + str(focus["folder"])
        elif not all(math.isfinite(d) and d > 0 for d in dims):
            reason = "params.json lacks specimen.width/height/grain_size in " + str(focus["folder"])
        else:
            reason = None
            specimen = None
            if grains:
                specimen, grain_text = _grains(focus, cracks)
                content.notes.append(grain_text)
            else:
                content.notes.append("Crack maps: grains not drawn (--no-grains); specimen outline only.")
            for by in ("mode", "kind"):
                name = f"crack_maps_{by}.png"
                crackmaps.crack_maps_figure(out / name, cracks, times, labels, *dims, colour_by=by, title=curve.label,
                                            specimen=specimen)
                content.figures.append((name, f"Crack maps at fractions of the lifetime, coloured by "
                                              f"{crackmaps.TITLES[by]}" + (", on the run's grains" if specimen else
                                                                           ", specimen outline") + " (Fig. 7/8)"))
        if reason:
            content.skipped += [(f"crack_maps_{by}.png", reason) for by in ("mode", "kind")]
        note = animation_note(focus["folder"], out)
        if note:
            content.notes.append(note)

    if len(folders) > 1:
        content.notes.append("Several studies: runs are labelled by study (column study; run = study/run) and each "
                             "study (or each variant within a study) is fitted and drawn separately.")
    elif multi:
        content.notes.append("The creep runs differ in parameters (see column variant): each variant is fitted "
                             "and drawn separately.")
    other = int((runs["outcome"] == "not creep").sum())
    if other:
        content.notes.append(f"{other} run folder(s) of other commands (e.g. UCS) are listed but not analysed here.")
    phases = crack_phase_table(runs)
    if len(phases):
        write_csv(out / "crack_phases.csv", phases)
        (out / "crack_phases.md").write_text(markdown_table(phases, CRACK_PHASE_TABLE) + "\n")
        content.tables += ["crack_phases.csv", "crack_phases.md"]
    table = runs[[c for c in RUN_TABLE if c in runs]]
    write_csv(out / "runs.csv", table)
    content.tables = ["runs.csv", "lifetime_fits.csv", "lifetime_fits.md", "lifetime_stats.csv",
                      "lifetime_stats.md"] + content.tables
    report = out / "report.md"
    report.write_text(render_report(content))
    return report
