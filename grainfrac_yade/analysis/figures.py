"""Figures of a creep study (paper Fig. 4, 5, 6 and 9) and of one creep run; each function writes one PNG.

Inputs are plain arrays and DataFrames (history.csv tables, lifetime sets); nothing here reads
run folders. Strain is compression positive and drawn in %.  Pictures of specimens and the crack
map itself are :mod:`grainfrac_yade.analysis.plotting`; everything built from results is here.
"""
from __future__ import annotations

import textwrap
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .plotting import plt
from .fits import CONFIDENCE, LifetimeFit

DPI = 130
PERCENT = 100.0
#: Fit lines extend this far beyond the data's ratio range (driving-stress ratio units).
FIT_MARGIN = 0.02
#: Padding of the strain axis around the creep before the collapse row (fraction of the range).
STRAIN_PAD = 0.08
#: Upward arrows of lower bounds (runs that did not fail) reach this factor times the end time.
LOWER_BOUND_ARROW = 5.0
#: Fractions of the lifetime (or of a run's end time) at which crack maps are drawn, for a run and for a
#: study: early in primary creep, mid-life, tertiary creep and failure, as the points in time of paper
#: Fig. 7 (taken from its Fig. 6 curve).
MAP_FRACTIONS = (0.1, 0.5, 0.9, 1.0)
STAGE_MARKERS = {"primary_end_s": ("o", "end of primary creep"), "tertiary_start_s": ("^", "start of tertiary creep")}


@dataclass
class LifetimeSet:
    """Lifetimes of one data set: failed points (fitted), lower bounds (not failed; drawn only) and the fit."""
    label: str
    ratio: np.ndarray
    lifetime_s: np.ndarray
    fit: LifetimeFit | None = None
    lower_ratio: np.ndarray = field(default_factory=lambda: np.zeros(0))
    lower_time_s: np.ndarray = field(default_factory=lambda: np.zeros(0))
    sources: np.ndarray | None = None   # lab: one label per point
    at_load_ratio: np.ndarray = field(default_factory=lambda: np.zeros(0))   # failed at t = 0 (not fitted)
    ucs_pa: np.ndarray = field(default_factory=lambda: np.zeros(0))   # the UCS each run's ratio refers to [Pa]


def ratio_reference(ucs_pa) -> str:
    """Which UCS a set's ratios divide by, for a legend: one value, or the range over its runs ("" if unknown)."""
    u = np.asarray(ucs_pa, float)
    u = u[np.isfinite(u) & (u > 0)]
    if not len(u):
        return ""
    lo, hi = u.min() / 1e6, u.max() / 1e6
    return f"r = sigma / {lo:.1f} MPa" if round(lo, 1) == round(hi, 1) else f"r = sigma / {lo:.1f}-{hi:.1f} MPa"


@dataclass
class Curve:
    """One run's history for the time plots; ``t_ref_s`` = lifetime (failed) or the run's end time."""
    label: str
    history: pd.DataFrame
    failed: bool
    t_ref_s: float
    stages: dict = field(default_factory=dict)   # primary_end_s, tertiary_start_s (None if unknown)
    broken_ramp: float = 0.0


def _save(fig, path):
    """tight_layout, then a tight bounding box so no title, label or legend is cut at the edges."""
    fig.tight_layout()
    fig.savefig(path, dpi=DPI, bbox_inches="tight", pad_inches=0.08)
    plt.close(fig)
    return path


def _title(ax, text: str, fontsize: float = 10, **kw):
    """Title on one line if it fits inside the figure's width, else wrapped until it does."""
    fig = ax.figure
    title = ax.set_title(text, fontsize=fontsize, **kw)
    renderer = fig.canvas.get_renderer()
    box = ax.get_position()   # the title is centred on the axes: it must fit on both sides of the centre
    centre = 0.5 * (box.x0 + box.x1)
    room = 0.97 * 2 * min(centre, 1 - centre) * fig.bbox.width
    chars = len(text)
    while title.get_window_extent(renderer).width > room and chars > 20:
        chars = int(chars * 0.9)
        title.set_text(textwrap.fill(text, chars))
    return title


def _fit_lines(ax, fit: LifetimeFit, ratios, colour, label):
    lo, hi = max(np.min(ratios) - FIT_MARGIN, 1e-3), np.max(ratios) + FIT_MARGIN
    grid = np.linspace(lo, hi, 200)
    pct = f"{CONFIDENCE:.0%}"
    ax.plot(grid, fit.lifetime_exponential(grid), color=colour, lw=1.4,
            label=f"{label}: ln t = {fit.a:.3g} - {fit.b:.3g} r")
    ax.plot(grid, fit.lifetime_power(grid), color=colour, lw=1.2, ls="--",
            label=f"{label}: t = {np.exp(fit.ln_A):.3g} s r^-{fit.n:.3g}")
    if fit.exponential.dof > 0:
        ax.fill_between(grid, *fit.band_exponential(grid), color=colour, alpha=0.15, lw=0,
                        label=f"{label}: {pct} band (mean line)")
        ax.fill_between(grid, *fit.band_power(grid), color=colour, alpha=0.08, lw=0, hatch="//",
                        label=f"{label}: {pct} band, power law (hatched)")


def lifetime_figure(path, model_sets, lab: LifetimeSet | None = None, reference=None, time_note: str | None = None):
    """Lifetime vs driving-stress ratio, log time (paper Fig. 4): model points, lower bounds, both fits
    with confidence bands; lab points and fits, or the paper's UDEC value and the 1986 bound.
    ``time_note`` (e.g. rescaled times) goes into the title and the legend's title."""
    fig, ax = plt.subplots(figsize=(12.5, 5.6))
    colours = plt.cm.tab10.colors
    all_ratios = []
    for k, s in enumerate(model_sets):
        c = colours[k % 10]
        ref = ratio_reference(s.ucs_pa)
        if len(s.ratio):
            ax.scatter(s.ratio, s.lifetime_s, s=22, color=c, edgecolors="k", linewidths=0.4, zorder=3,
                       label=f"{s.label}: failed runs ({len(s.ratio)})" + (f"; {ref} (its runs' UCS)" if ref else ""))
        if len(s.lower_ratio):
            ax.scatter(s.lower_ratio, s.lower_time_s, s=30, facecolors="none", edgecolors=c, marker="o", zorder=3,
                       label=f"{s.label}: not failed by end time (lower bound, not fitted; {len(s.lower_ratio)})")
            ax.errorbar(s.lower_ratio, s.lower_time_s, yerr=[np.zeros(len(s.lower_time_s)),
                                                             (LOWER_BOUND_ARROW - 1) * s.lower_time_s],
                        lolims=True, fmt="none", ecolor=c, elinewidth=0.8, capsize=0)
        if s.fit is not None:
            _fit_lines(ax, s.fit, s.ratio, c, s.label)
        if len(s.at_load_ratio):
            # ln 0 has no place on a log axis: drawn on the bottom edge (axes coordinates in y)
            ax.scatter(s.at_load_ratio, np.full(len(s.at_load_ratio), 0.01), marker="x", color=c, s=30, zorder=3,
                       transform=ax.get_xaxis_transform(), clip_on=False,
                       label=f"{s.label}: failed at load, t = 0 (bottom edge; not fitted; {len(s.at_load_ratio)})")
        all_ratios += list(s.ratio) + list(s.lower_ratio) + list(s.at_load_ratio)
    if lab is not None:
        sources = lab.sources if lab.sources is not None else np.array([lab.label] * len(lab.ratio))
        for k, src in enumerate(pd.unique(sources)):
            sel = sources == src
            ax.scatter(lab.ratio[sel], lab.lifetime_s[sel], s=20, marker="sdv^<>"[k % 6], color="0.35",
                       facecolors="none", zorder=2, label=f"lab: {src} ({int(sel.sum())})")
        if lab.fit is not None:
            _fit_lines(ax, lab.fit, lab.ratio, "0.2", "lab")
        all_ratios += list(lab.ratio)
    if reference is not None:
        as_published = (f", as published (beta1 = {reference.beta1_pa_s:g} Pa/s, not rescaled)"
                        if time_note and np.isfinite(getattr(reference, "beta1_pa_s", np.nan)) else "")
        ax.scatter([reference.ratio], [reference.lifetime_s], marker="*", s=140, color="gold", edgecolors="k",
                   zorder=4, label=f"paper (UDEC): {reference.stress_pa / 1e6:.0f} MPa, "
                                   f"r = {reference.stress_pa / 1e6:.0f} / {reference.ucs_simulated_pa / 1e6:.1f} MPa "
                                   f"(UDEC's UCS) = {reference.ratio:.3f}, t = {reference.lifetime_s:.4g} s"
                                   f"{as_published}")
        all_ratios += [reference.ratio, reference.long_term_strength_ratio]
    lo = min(all_ratios) - 0.05 if all_ratios else 0.5
    hi = max(all_ratios) + 0.05 if all_ratios else 1.0
    ax.set_xlim(lo, hi)
    if reference is not None:
        lts = reference.long_term_strength_ratio
        ax.axvspan(lo, lts, color="0.85", alpha=0.6, lw=0, zorder=0,
                   label=f"Lajtai & Schmidtke 1986: long-term strength < {lts:.0%} of UCS (lies here)")
        ax.axvline(lts, color="0.4", lw=1, ls=":")
    ax.set_yscale("log")
    ax.set_xlabel("driving-stress ratio sigma / sigma_c [-] (sigma_c: each set's own UCS, in the legend)")
    ax.set_ylabel("lifetime (time to failure) [s]")
    _title(ax, "Lifetime vs driving-stress ratio (paper Fig. 4)" + (f" - {time_note}" if time_note else ""))
    ax.grid(True, which="major", alpha=0.3)
    # legend beside the axes: with several studies it would hide points inside
    leg = ax.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0), framealpha=0.85, title=time_note,
                    title_fontsize=6.5)
    if time_note:
        leg.get_title().set_fontweight("bold")
    return _save(fig, path)


def _pre_collapse(curve: Curve) -> pd.DataFrame:
    """History rows before the collapse row of a failed run (the failure row would dominate the scale)."""
    h = curve.history
    return h.iloc[:-1] if curve.failed and len(h) > 2 else h


def _strain_limits(curves, key="axial_strain"):
    vals = np.concatenate([_pre_collapse(c)[key].to_numpy(float) for c in curves]) * PERCENT
    vals = vals[np.isfinite(vals)]
    if not len(vals):
        return None
    lo, hi = vals.min(), vals.max()
    pad = STRAIN_PAD * max(hi - lo, 1e-6)
    return lo - pad, hi + 3 * pad


#: Part of the plasma colour map used for curves (its bright yellow end is hard to see on white).
CMAP_TOP = 0.85


def _ratio_colours(curves):
    cmap = plt.cm.plasma
    return [cmap(CMAP_TOP * k / max(len(curves) - 1, 1)) for k in range(len(curves))]


def strain_time_figure(path, curves, normalised: bool = False, time_note: str | None = None):
    """Axial strain vs creep time for several loads (paper Fig. 5), creep stages marked.

    ``normalised``: time axis t / t_ref (lifetime or the run's end); else log creep time [s].
    The collapse row of a failed run leaves the top of the axis (failure).
    """
    fig, ax = plt.subplots(figsize=(7, 4.6))
    stage_labels = set()
    for c, colour in zip(curves, _ratio_colours(curves)):
        t = c.history["creep_time_s"].to_numpy(float)
        eps = c.history["axial_strain"].to_numpy(float) * PERCENT
        x = t / c.t_ref_s if normalised else t
        sel = np.isfinite(x) & (np.ones_like(x, bool) if normalised else x > 0)
        if not sel.any():
            continue
        if not normalised and sel.sum() < 2:
            # one positive creep time (e.g. the event clock jumped from the load straight to failure): no curve on a
            # log axis; a dashed line at that time keeps the run in the figure, not only in its legend
            ax.axvline(x[sel][0], color=colour, lw=1.1, ls="--",
                       label=f"{c.label}{'' if c.failed else ' (not failed)'}: one creep time, t = {x[sel][0]:.4g} s "
                             "(no curve on a log axis)")
            continue
        ax.plot(x[sel], eps[sel], color=colour, lw=1.1, drawstyle="steps-post",
                label=c.label + ("" if c.failed else " (not failed)"))
        pre = _pre_collapse(c)
        for key, (marker, text) in STAGE_MARKERS.items():
            ts = c.stages.get(key)
            if ts is None or not np.isfinite(ts) or ts <= 0:
                continue
            e = np.interp(ts, pre["creep_time_s"], pre["axial_strain"]) * PERCENT
            ax.plot(ts / c.t_ref_s if normalised else ts, e, marker=marker, color=colour, mec="k", ms=6, ls="none",
                    label=text if text not in stage_labels else None, zorder=4)
            stage_labels.add(text)
    limits = _strain_limits(curves)
    if limits:
        ax.set_ylim(*limits)
    if normalised:
        ax.set_xlabel("normalised creep time t / t_f [-] (t_f: lifetime, or end time if not failed)")
        ax.set_xlim(0, 1.02)
    else:
        ax.set_xscale("log")
        ax.set_xlabel("creep time [s]" + (f" ({time_note})" if time_note else ""))
    ax.set_ylabel("axial strain [%]")
    _title(ax, "Axial strain vs creep time" + (" (normalised)" if normalised else "") + " (paper Fig. 5); "
           "failure leaves the top")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=6, loc="upper left")
    return _save(fig, path)


def broken_creep(curve: Curve) -> np.ndarray:
    """Bonds broken since the start of creep: history column broken_creep, else broken_total - ramp breaks."""
    h = curve.history
    if "broken_creep" in h:
        return h["broken_creep"].to_numpy(float)
    return h["broken_total"].to_numpy(float) - curve.broken_ramp


def bonds_strain_figure(path, curve: Curve, mark_times=(), time_note: str | None = None):
    """Broken bonds (creep phase) and axial strain vs creep time at one load (paper Fig. 6), two y axes;
    creep stages as vertical lines, ``mark_times`` [s] (crack-map times) as labelled ticks."""
    h = curve.history
    t = h["creep_time_s"].to_numpy(float)
    fig, ax = plt.subplots(figsize=(7, 4.6))
    ax.plot(t, h["axial_strain"].to_numpy(float) * PERCENT, color="tab:blue", drawstyle="steps-post",
            label="axial strain")
    limits = _strain_limits([curve])
    if limits:
        ax.set_ylim(*limits)
    ax.set_xlabel("creep time [s]")
    ax.set_ylabel("axial strain [%]", color="tab:blue")
    ax2 = ax.twinx()
    nb = broken_creep(curve)
    ax2.plot(t, nb, color="tab:red", lw=1.0, drawstyle="steps-post", label="broken bonds (creep phase)")
    ax2.set_ylabel("broken bonds since creep start [-]", color="tab:red")
    for key, (marker, text) in STAGE_MARKERS.items():
        ts = curve.stages.get(key)
        if ts is not None and np.isfinite(ts):
            ax.axvline(ts, color="grey", ls=":", lw=0.9)
            ax.text(ts, ax.get_ylim()[0], " " + text, rotation=90, va="bottom", fontsize=7)
    for k, tm in enumerate(mark_times):
        ax.axvline(tm, color="tab:green", lw=0.6, alpha=0.7)
        ax.text(tm, ax.get_ylim()[1], f"({chr(ord('a') + k)})", ha="center", va="bottom", fontsize=7,
                color="tab:green")
    state = f"lifetime {curve.t_ref_s:.4g} s" if curve.failed else f"not failed by {curve.t_ref_s:.4g} s"
    _title(ax, f"{curve.label}: {state} (paper Fig. 6)" + (f"; {time_note}" if time_note else ""), fontsize=9,
           pad=14)
    lines = ax.get_legend_handles_labels()
    lines2 = ax2.get_legend_handles_labels()
    ax.legend(lines[0] + lines2[0], lines[1] + lines2[1], fontsize=7, loc="center left")
    ax.grid(True, alpha=0.3)
    return _save(fig, path)


def damage_figure(path, curves):
    """Damage index D_n = N(t) / N(t_f) (paper Eq. 9) vs normalised time t / t_f (paper Fig. 9)."""
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for c, colour in zip(curves, _ratio_colours(curves)):
        h = c.history
        d = h["damage_index"].to_numpy(float) if "damage_index" in h else broken_creep(c) / max(broken_creep(c)[-1], 1)
        ax.plot(h["creep_time_s"].to_numpy(float) / c.t_ref_s, d, color=colour, drawstyle="steps-post", label=c.label)
    ax.set_xlabel("normalised time t / t_f [-]")
    ax.set_ylabel("damage index D_n = N(t) / N(t_f) [-]")
    ax.set_xlim(0, 1.02)
    ax.set_ylim(0, 1.05)
    _title(ax, "Damage index (paper Eq. 9, Fig. 9)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")
    return _save(fig, path)


# ----------------------------------------------------------------------------- one run (creep, UCS, elastic solve)
def run_bond_stress_figure(table, stress, path):
    """One run: histograms of bond normal and shear stress at the start of the creep phase (the tail
    that paper Eq. 7 turns into lifetimes)."""
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    for ax, key, label in ((axes[0], "normal_stress_pa", "normal stress (tension +) [MPa]"),
                           (axes[1], "shear_stress_pa", "shear stress [MPa]")):
        ax.hist(np.asarray(table[key]) / 1e6, bins=60, log=True)
        ax.set_xlabel(label)
        ax.set_ylabel("bonds")
    fig.suptitle(f"bond stresses at the creep load {stress / 1e6:.0f} MPa (after the ramp)")
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def run_strain_time_figure(hist, summary, path):
    """One run: axial strain and creep cracks against creep time, creep stages marked (paper Fig. 6)."""
    t = hist["creep_time_s"]
    strain = hist["axial_strain"] * 100
    fig, ax = plt.subplots(figsize=(6, 4.2))
    ax.plot(t, strain, drawstyle="steps-post", label="axial strain")
    if summary["failed"] and len(strain) > 2:
        # scale to the creep before the collapse row; the collapse is marked, not drawn to scale
        lo, hi = strain[:-1].min(), strain[:-1].max()
        pad = 0.1 * max(hi - lo, 1e-6)
        ax.set_ylim(lo - pad, hi + 3 * pad)
        ax.annotate(f"failure (strain {strain[-1]:.2f} %)", xy=(t[-1], hi + 2.5 * pad), ha="right", fontsize=7,
                    xytext=(t[-1], hi + 2.5 * pad))
    for key, label in (("primary_end_s", "end of primary"), ("tertiary_start_s", "start of tertiary")):
        if summary.get(key) is not None:
            ax.axvline(summary[key], color="grey", ls=":", lw=0.8)
            ax.text(summary[key], ax.get_ylim()[0], " " + label, rotation=90, va="bottom", fontsize=7)
    ax2 = ax.twinx()
    ax2.plot(t, hist["broken_creep"], color="tab:red", lw=0.8, drawstyle="steps-post", label="broken bonds (creep)")
    if summary["failed"] and len(t) > 2:
        ax2.set_ylim(0, 1.3 * max(hist["broken_creep"][:-1].max(), 1))
    ax2.set_ylabel("broken bonds since creep start", color="tab:red")
    ax.set_xlabel("creep time [s]")
    ax.set_ylabel("axial strain [%]")
    state = ("numerical failure: no result" if summary.get("numerical_failure") else
             f"lifetime {summary['lifetime_s']:.4g} s" if summary["failed"] else "not failed")
    ax.set_title(f"{summary['stress_pa'] / 1e6:.0f} MPa ({summary['clock']} clock): {state}")
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)


def run_stress_strain_figure(history, summary, path):
    """One UCS run: axial, lateral and volumetric strain against axial stress, CI and CD marked."""
    ea = np.asarray(history["axial_strain"]) * 100
    el = np.asarray(history["lateral_strain"]) * 100
    s = np.asarray(history["axial_stress_pa"]) / 1e6
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(ea, s, label="axial strain")
    ax.plot(el, s, label="lateral strain")
    ax.plot(ea + el, s, "--", lw=0.8, label="volumetric strain (plane)")
    for key, label in (("crack_initiation_pa", "CI"), ("crack_damage_pa", "CD")):
        if summary.get(key) is not None and np.isfinite(summary[key]):
            ax.axhline(summary[key] / 1e6, color="grey", lw=0.6, ls=":")
            ax.text(ax.get_xlim()[0], summary[key] / 1e6, f" {label}", va="bottom", fontsize=7)
    ax.set_xlabel("strain [%] (compression positive)")
    ax.set_ylabel("axial stress [MPa]")
    confining = summary.get("confining_stress_pa") or 0.0
    if summary["numerical_failure"]:
        ax.set_title("numerical failure: no result")
    else:
        strength = (f"UCS {summary['ucs_pa'] / 1e6:.1f} MPa" if not confining else
                    f"peak {summary['ucs_pa'] / 1e6:.1f} MPa at sigma_3 = {confining / 1e6:g} MPa")
        ax.set_title(f"{strength}, E {_measure(summary['young_pa'], 1e9)} GPa, nu {_measure(summary['poisson'], 1, 2)}")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)


def envelope_figure(path, sigma3, sigma1, mohr_coulomb, hoek_brown, lab_ucs=None, title: str = ""):
    """Peak axial stress against confining stress: every test, the Mohr-Coulomb line and the
    Hoek-Brown curve (:mod:`.envelope`), and the lab UCS at sigma_3 = 0 (a LabProperty) if given."""
    s3, s1 = np.asarray(sigma3, float) / 1e6, np.asarray(sigma1, float) / 1e6
    x = np.linspace(0.0, s3.max() * 1.1, 100)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(s3, s1, "o", ms=4, color="k", alpha=0.7, label="model: peak of each test")
    ax.plot(x, mohr_coulomb.peak(x * 1e6) / 1e6, "-", label=(
        f"Mohr-Coulomb: phi {mohr_coulomb.friction_angle_deg:.1f} deg, c {mohr_coulomb.cohesion / 1e6:.1f} MPa"))
    if hoek_brown is not None:
        ax.plot(x, hoek_brown.peak(x * 1e6) / 1e6, "--", label=(
            f"Hoek-Brown: sigma_ci {hoek_brown.sigma_ci / 1e6:.0f} MPa, m_i {hoek_brown.m_i:.1f}"))
    if lab_ucs is not None:
        ax.errorbar([0.0], [lab_ucs.value / 1e6], yerr=[lab_ucs.spread / 1e6], fmt="s", color="tab:red", capsize=3,
                    label=textwrap.shorten(f"lab UCS ({lab_ucs.source})", 60))
    ax.set_xlabel("confining stress sigma_3 [MPa]")
    ax.set_ylabel("peak axial stress sigma_1 [MPa]")
    ax.legend(fontsize=7)
    _title(ax, title or "peak strength envelope")
    _save(fig, path)


def confinement_lifetime_figure(path, runs: pd.DataFrame, table: pd.DataFrame, time_note: str | None = None):
    """Creep lifetime against confining stress at fixed driving-stress ratios, one series per law, engine and
    ratio: each failed run (dots), runs that did not fail (open triangles at their end time: lower
    bounds) and the geometric mean of the failed ones (line)."""
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for k, ((law, engine, ratio), g) in enumerate(table.groupby(["law", "engine", "ratio"])):
        colour = f"C{k}"
        sel = (runs["law_label"] == law) & (runs["engine_label"] == engine) & (runs["ratio"] == ratio)
        failed = runs[sel & (runs["outcome"] == "failed")]
        ax.plot(failed["confining_stress_mpa"], failed["lifetime_s"], "o", ms=4, color=colour, alpha=0.7)
        alive = runs[sel & (runs["outcome"] == "not failed")]
        ax.plot(alive["confining_stress_mpa"], alive["creep_time_end_s"], "^", mfc="none", color=colour)
        ok = g["lifetime_geomean_s"] > 0
        ax.plot(g.loc[ok, "confining_stress_mpa"], g.loc[ok, "lifetime_geomean_s"], "-", color=colour,
                label=f"{law}, {engine}, ratio {ratio:g} (geometric mean of failed runs)")
    ax.set_yscale("log")
    ax.set_xlabel("confining stress sigma_3 [MPa]")
    ax.set_ylabel("lifetime [s]" + (f" ({time_note})" if time_note else ""))
    ax.legend(fontsize=7)
    _title(ax, "creep lifetime at a fixed deviatoric driving-stress ratio against confinement "
               "(open triangles: not failed, lower bounds)")
    _save(fig, path)


def run_brazilian_load_figure(history, summary, path):
    """Brazilian stress 2P/(pi D t) against diametral and horizontal strain."""
    s = np.asarray(history["tensile_stress_pa"]) / 1e6
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(np.asarray(history["diametral_strain"]) * 100, s, label="diametral strain (jaw closure / D)")
    ax.plot(np.asarray(history["horizontal_strain"]) * 100, s, label="horizontal strain (widening negative)")
    ax.set_xlabel("strain [%] (compression positive)")
    ax.set_ylabel("2 P / (pi D t) [MPa]")
    ax.set_title("numerical failure: no result" if summary["numerical_failure"] else
                 f"sigma_t {summary['tensile_strength_pa'] / 1e6:.1f} MPa, D {summary['diameter_m'] * 1e3:g} mm, "
                 f"seed {summary['seed']}")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)


def _measure(value, unit=1e6, digits=1) -> str:
    """``value / unit`` with ``digits`` decimals; "-" if not measured (None or NaN)."""
    return "-" if value is None or not np.isfinite(value) else f"{value / unit:.{digits}f}"


def contact_stress_histograms(ratios: dict, path, title: str = ""):
    """One elastic solve: histograms of contact shear and tension over the applied stress, one line per model."""
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.8))
    for ax, k, label in ((axes[0], 0, "contact shear stress / applied stress"),
                         (axes[1], 1, "contact tension / applied stress")):
        top = max(float(np.percentile(r[k], 99.9)) for r in ratios.values())
        bins = np.linspace(0, max(top, 1e-12) * 1.05, 60)
        for name, r in ratios.items():
            ax.hist(r[k], bins=bins, histtype="step", density=True, lw=1.2,
                    label=f"{name}: p99 {np.percentile(r[k], 99):.2f}, max {r[k].max():.2f}")
        ax.set_yscale("log")
        ax.set_xlabel(label)
        ax.set_ylabel("density")
        ax.legend(fontsize=7)
    fig.suptitle(f"static elastic solve, uniaxial compression: {title}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)
