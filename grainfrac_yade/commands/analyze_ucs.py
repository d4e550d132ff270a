"""``analyze-ucs``: table and figure of UCS tests in a study folder (resolution, size, calibration)."""
from __future__ import annotations

from pathlib import Path

#: Columns that define a model variant in a UCS study.
VARIANT = ("resolution.spheres_per_cell", "specimen.grain_size", "specimen.width", "specimen.height",
           "resolution.grain_model", "resolution.nodes_per_face")
MEASURES = ("ucs_pa", "young_pa", "poisson", "crack_initiation_pa", "crack_damage_pa", "wall_s", "dem_steps")


def register(sub, common):
    p = sub.add_parser("analyze-ucs", help="summarise UCS runs of a study folder (CSV, markdown, PNG)")
    p.add_argument("folder")
    p.set_defaults(func=cmd_analyze_ucs)


def cmd_analyze_ucs(args) -> int:
    import pandas as pd

    from ..analysis import collect_runs, group_stats
    from ..analysis.study import fill_missing_params
    from ..errors import GrainfracError
    folder = Path(args.folder)
    runs = collect_runs(folder)
    if runs.empty or "ucs_pa" not in runs:
        raise GrainfracError(f"{folder}: no finished UCS runs (summary.json with ucs_pa); fix: run the study first")
    runs = runs[runs["command"] == "ucs"]
    runs, _ = fill_missing_params(runs)   # keys that older params.json lack: the shipped defaults
    stats = group_stats(runs, VARIANT, MEASURES)
    runs.to_csv(folder / "ucs_runs.csv", index=False)
    stats.to_csv(folder / "ucs_stats.csv", index=False)
    lines = ["| cells | spheres/cell | grain [mm] | specimen [mm] | n | UCS [MPa] | E [GPa] | Poisson | CI/UCS "
             "| CD/UCS | DEM steps | wall [s] |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for _, r in stats.iterrows():
        lines.append(
            f"| {cells_label(r['resolution.grain_model'], r['resolution.nodes_per_face'])} "
            f"| {r[VARIANT[0]]:.0f} | {r[VARIANT[1]] * 1e3:.2f} "
            f"| {r[VARIANT[2]] * 1e3:.1f} x {r[VARIANT[3]] * 1e3:.1f} "
            f"| {r['ucs_pa_count']:.0f} | {r['ucs_pa_mean'] / 1e6:.1f} +- {r['ucs_pa_std'] / 1e6:.1f} "
            f"| {r['young_pa_mean'] / 1e9:.1f} +- {r['young_pa_std'] / 1e9:.1f} | {r['poisson_mean']:.3f} "
            f"| {r['crack_initiation_pa_mean'] / r['ucs_pa_mean']:.2f} "
            f"| {r['crack_damage_pa_mean'] / r['ucs_pa_mean']:.2f} "
            f"| {r['dem_steps_mean']:.0f} | {r['wall_s_mean']:.1f} |")
    failed = runs[runs.get("numerical_failure", pd.Series(False, index=runs.index)).eq(True)]
    if len(failed):   # no UCS (null): left out of n and of every mean
        lines.append("")
        lines += [f"numerical failure (no result, not counted): {r['run']}: {r['end_reason']}"
                  for _, r in failed.iterrows()]
    (folder / "ucs_stats.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


def cells_label(grain_model, nodes_per_face) -> str:
    """The cells column of ucs_stats.md: "rigid", "deformable, k/face" (spring lattice) or
    "fem, k/face" (finite elements).  A run without grain_model (params.json older than the key) had
    rigid cells, the only kind there was."""
    if grain_model in ("deformable", "fem"):
        return f"{grain_model}, {nodes_per_face:.0f}/face"
    return "rigid"
