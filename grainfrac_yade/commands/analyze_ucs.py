"""``analyze-ucs``: table and figure of UCS tests in a study folder (engine, resolution, size, calibration), and
the peak-strength envelope of confined tests (Mohr-Coulomb and Hoek-Brown fits) where a model variant
was tested at two confining stresses or more.  Written into ``STUDY/report/`` (``--out``), as ``analyze``
writes a creep study's report: never into the study folder among its runs."""
from __future__ import annotations

from pathlib import Path

from ..errors import GrainfracError

#: Columns that define a model variant in a UCS study.
VARIANT = ("resolution.spheres_per_cell", "specimen.grain_size", "specimen.width", "specimen.height",
           "resolution.grain_model", "resolution.nodes_per_face", "confinement.stress")
#: Further columns that make a variant; the table names those that differ among its rows ("variant" column).
LOADING_VARIANT = ("calibration.strength_scale", "calibration.stiffness_scale", "calibration.shear_stiffness_ratio_scale",
                   "calibration.tensile_cohesion_ratio_scale", "calibration.inter_mineral_strength_ratio",
                   "calibration.strength_weibull_modulus", "ucs.strain_rate",
                   "numerics.density_scale", "specimen.min_edge_fraction", "numerics.keep_intact_joints")
#: The engine column (:data:`grainfrac_yade.analysis.collect.ENGINE_COLUMN`): runs of two engines are two variants,
#: never averaged together; the first column of ucs_stats.
ENGINE = "engine"
#: The confining stress column: the envelope's abscissa.
CONFINEMENT = "confinement.stress"
MEASURES = ("ucs_pa", "young_pa", "poisson", "crack_initiation_pa", "crack_damage_pa", "wall_s", "steps")
#: The report folder inside the study folder (``analyze``'s too).
REPORT = "report"


def _mean_sd(mean, sd, unit) -> str:
    """``mean +- sd`` in ``unit``, one decimal; the mean alone when there is no spread (one run: sd is nan)."""
    return f"{mean / unit:.1f}" if sd != sd else f"{mean / unit:.1f} +- {sd / unit:.1f}"


def register(sub, common):
    p = sub.add_parser("analyze-ucs", help="summarise UCS runs of a study folder (CSV, markdown, PNG) into "
                                           "FOLDER/report/")
    p.add_argument("folder", help="study folder holding UCS run folders (e.g. results/resolution)")
    p.add_argument("--out", help="report folder (default FOLDER/report, as analyze)")
    p.set_defaults(func=cmd_analyze_ucs)


def cmd_analyze_ucs(args) -> int:
    import pandas as pd

    from ..analysis.collect import check_report_folder, collect_runs, group_stats
    from ..analysis.study import fill_missing_params
    folder = Path(args.folder)
    if not folder.is_dir():
        raise GrainfracError(f"{folder}: study folder not found; fix: give a folder holding UCS run folders "
                             "(e.g. results/resolution)")
    runs = collect_runs(folder)
    ucs = runs[runs["command"] == "ucs"] if "command" in runs else runs.iloc[:0]
    finished = ucs[ucs["status"] == "finished"] if "status" in ucs else ucs.iloc[:0]
    if finished.empty:
        kinds = runs["command"].fillna("unknown").value_counts() if "command" in runs else {}
        held = ", ".join(f"{n} {k}" for k, n in kinds.items()) or "none"
        hint = (f"analyze a creep study with python3 -m grainfrac_yade analyze {folder}" if "creep" in kinds
                else "run the UCS study first")
        raise GrainfracError(f"{folder}: no finished UCS runs (run folders: {held}); fix: {hint}")
    runs = ucs.copy()
    for key in MEASURES:   # a study whose every UCS run ended as a numerical failure has null measures
        if key not in runs:
            runs[key] = float("nan")
    out = Path(getattr(args, "out", None) or folder / REPORT)
    check_report_folder(out)
    out.mkdir(parents=True, exist_ok=True)
    runs, _ = fill_missing_params(runs)   # keys that older params.json lack: the shipped defaults
    runs[CONFINEMENT] = runs[CONFINEMENT].fillna(0.0).astype(float)   # runs older than the key were uniaxial
    by = (ENGINE,) + VARIANT + tuple(k for k in LOADING_VARIANT if k in runs)
    stats = group_stats(runs, by, MEASURES)
    runs.to_csv(out / "ucs_runs.csv", index=False)
    stats.to_csv(out / "ucs_stats.csv", index=False)
    varying = [k for k in by[1 + len(VARIANT):] if stats[k].astype(str).nunique() > 1]
    lines = ["| engine | cells | spheres/cell | grain [mm] | specimen [mm] | sigma_3 [MPa] | " + ("variant | " if varying else "")
             + "n | peak [MPa] | E [GPa] | Poisson | CI/peak | CD/peak | steps (yade: DEM steps; static, hybrid: "
             "equilibria solved) | wall [s] |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|" + ("---|" if varying else "")]
    for _, r in stats.iterrows():
        variant = (", ".join(f"{k.split('.', 1)[1]} {_cell(r[k])}" for k in varying) + " | ") if varying else ""
        lines.append(
            f"| {r[ENGINE]} | {cells_label(r['resolution.grain_model'], r['resolution.nodes_per_face'])} "
            f"| {r[VARIANT[0]]:.0f} | {r[VARIANT[1]] * 1e3:.2f} "
            f"| {r[VARIANT[2]] * 1e3:.1f} x {r[VARIANT[3]] * 1e3:.1f} | {r[CONFINEMENT] / 1e6:g} | {variant}"
            f"{r['ucs_pa_count']:.0f} | {_mean_sd(r['ucs_pa_mean'], r['ucs_pa_std'], 1e6)} "
            f"| {_mean_sd(r['young_pa_mean'], r['young_pa_std'], 1e9)} | {r['poisson_mean']:.3f} "
            f"| {r['crack_initiation_pa_mean'] / r['ucs_pa_mean']:.2f} "
            f"| {r['crack_damage_pa_mean'] / r['ucs_pa_mean']:.2f} "
            f"| {r['steps_mean']:.0f} | {r['wall_s_mean']:.1f} |")
    failed = runs[runs.get("numerical_failure", pd.Series(False, index=runs.index)).eq(True)]
    if len(failed):   # no UCS (null): left out of n and of every mean
        lines.append("")
        lines += [f"numerical failure (no result, not counted): {r['run']}: {r['end_reason']}"
                  for _, r in failed.iterrows()]
    lines += envelopes(runs, folder, out)
    (out / "ucs_stats.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    print(f"written: {out}")
    return 0


def envelopes(runs, folder, out) -> list:
    """Mohr-Coulomb and Hoek-Brown fits of every model variant tested at two confining stresses or
    more: envelope.csv (one row per variant), envelope_<k>.png in ``out``; returns markdown lines (``folder``:
    the study, named in the fits' refusals)."""
    import pandas as pd

    from ..analysis.envelope import fit_hoek_brown, fit_mohr_coulomb
    from ..analysis.figures import envelope_figure
    from ..analysis.labdata import lab_property
    done = runs[(runs["status"] == "finished") & runs["ucs_pa"].notna()]
    others = [ENGINE] + [v for v in VARIANT if v != CONFINEMENT] + [k for k in LOADING_VARIANT if k in runs]
    rows, lines = [], []
    for values, group in done.groupby(others, dropna=False):
        key = dict(zip(others, values))
        if group[CONFINEMENT].nunique() < 2:
            continue
        s3, s1 = group[CONFINEMENT].to_numpy(float), group["ucs_pa"].to_numpy(float)
        mc = fit_mohr_coulomb(s3, s1, str(folder))
        try:
            hb, hb_note = fit_hoek_brown(s3, s1, str(folder)), ""
        except GrainfracError as exc:
            hb, hb_note = None, str(exc)
        k = len(rows) + 1
        label = (f"{key[ENGINE]} engine, {cells_label(key['resolution.grain_model'], key['resolution.nodes_per_face'])} "
                 f"cells, spheres per cell {key['resolution.spheres_per_cell']:.0f}, {key['specimen.width'] * 1e3:.1f} x "
                 f"{key['specimen.height'] * 1e3:.1f} mm, grain {key['specimen.grain_size'] * 1e3:.2f} mm")
        rows.append({"variant": label, ENGINE: key[ENGINE], "n_tests": len(group), "sigma3_max_pa": s3.max(),
                     "mc_unconfined_strength_pa": mc.unconfined_strength, "mc_passive_coefficient": mc.passive_coefficient,
                     "mc_friction_angle_deg": mc.friction_angle_deg, "mc_cohesion_pa": mc.cohesion, "mc_r2": mc.line.r2,
                     "hb_sigma_ci_pa": hb.sigma_ci if hb else None, "hb_m_i": hb.m_i if hb else None,
                     "hb_r2": hb.r2 if hb else None, "figure": f"envelope_{k}.png"})
        envelope_figure(out / f"envelope_{k}.png", s3, s1, mc, hb, lab_property("uniaxial_compressive_strength"),
                        title=f"peak strength envelope: {label}")
        lines += ["", f"Envelope {k} ({label}; {len(group)} tests, sigma_3 0-{s3.max() / 1e6:g} MPa; envelope_{k}.png): "
                  f"Mohr-Coulomb C_0 {mc.unconfined_strength / 1e6:.1f} MPa, q {mc.passive_coefficient:.2f}, "
                  f"phi {mc.friction_angle_deg:.1f} deg, c {mc.cohesion / 1e6:.1f} MPa (R^2 {mc.line.r2:.3f}); "
                  + (f"Hoek-Brown sigma_ci {hb.sigma_ci / 1e6:.1f} MPa, m_i {hb.m_i:.1f} (R^2 {hb.r2:.3f})" if hb
                     else f"Hoek-Brown: no fit ({hb_note})")]
    if rows:
        pd.DataFrame(rows).to_csv(out / "envelope.csv", index=False)
    return lines


def _cell(value) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def cells_label(grain_model, nodes_per_face) -> str:
    """The cells column of ucs_stats.md: "rigid" or "fem, k/face" (finite elements); a run of the
    retired spring lattice (grain_model "deformable" in an older params.json) "lattice (retired),
    k/face".  A run without grain_model (params.json older than the key) had rigid cells, the only
    kind there was."""
    if grain_model == "fem":
        return f"fem, {nodes_per_face:.0f}/face"
    if grain_model == "deformable":
        return f"lattice (retired), {nodes_per_face:.0f}/face"
    return "rigid"
