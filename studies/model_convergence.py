"""The rows of the model convergence study as a CSV (docs/studies/model_convergence.md): one line per finished UCS
run folder, the discretisation (bonds per face, radial rings, bonds, nodes), the strength, the moduli, the crack
thresholds, the breaks, the cost (CPU, inertial relaxations) and why the run ended, units in the column names;
with ``--elastic``, one line per ``elastic --grains fem`` folder: the moduli and the contact stress tail.

    /usr/bin/python3 -m studies.model_convergence results/model_convergence/* --out docs/studies/model_convergence/ucs_runs.csv
    /usr/bin/python3 -m studies.model_convergence --elastic results/model_convergence_elastic/* --out docs/studies/model_convergence/elastic_tails.csv
    /usr/bin/python3 -m studies.model_convergence --k-series docs/studies/model_convergence/*ucs_runs.csv --out docs/studies/model_convergence/k_series.md

``--k-series`` reads such CSVs back: for each specimen (size, seed), grain interior (rings, grading) and bond
stiffness factor (``calibration.stiffness_scale``; 1 where a CSV lacks the column), the UCS
against K with the paired change from the next coarser K and the three-point extrapolation in the node spacing
h ~ 1 / K (`grainfrac_yade/analysis/mesh_convergence.py`), as a markdown table.

A pure reader of run folders (summary.json, params.json; no YADE).
"""
import argparse
import csv
import json
import math
import sys
from pathlib import Path

from grainfrac_yade.api import ADDED_KEYS, extrapolate, paired_changes

#: The study's criterion: the paired UCS change between the two finest discretisations below this [1].
CONVERGED_CHANGE = 0.05
#: A lateral over axial strain ratio ("nu" of the summary, 10-50 % of the peak) above this [1] is no elastic solid's
#: (plane strain allows at most 0.5): the specimen split into columns before its peak, which then is not a brittle
#: strength but the columns' (small-displacement statics: no buckling).
SPLIT_POISSON = 0.5

#: (column, summary key, factor) of every row: the units are those of the column name.
COLUMNS = (("ucs_mpa", "ucs_pa", 1e-6), ("peak_axial_strain_percent", "peak_axial_strain", 100.0),
           ("young_gpa", "young_pa", 1e-9), ("poisson_1", "poisson", 1.0),
           ("crack_initiation_mpa", "crack_initiation_pa", 1e-6), ("crack_damage_mpa", "crack_damage_pa", 1e-6),
           ("bonds_1", "n_bonds", 1), ("broken_total_1", "broken_total", 1), ("cpu_s", "cpu_s", 1.0),
           ("static_relaxations_1", "static_relaxations", 1), ("static_relaxation_steps_1", "static_relaxation_steps", 1),
           ("static_relaxation_cpu_s", "static_relaxation_cpu_s", 1.0))


#: (column, key of an elastic model's summary, factor) of every elastic row.
ELASTIC_COLUMNS = (("n_nodes_1", "n_nodes", 1), ("young_gpa", "young_pa", 1e-9), ("poisson_1", "poisson", 1.0),
                   ("shear_ratio_p50_1", "shear_stress_ratio_p50", 1.0),
                   ("shear_ratio_p99_1", "shear_stress_ratio_p99", 1.0),
                   ("shear_ratio_max_1", "shear_stress_ratio_max", 1.0),
                   ("tension_ratio_max_1", "tension_stress_ratio_max", 1.0))


def _value(v, factor):
    return None if v is None else (round(v * factor, 6) if isinstance(factor, float) else int(v))


def _discretisation(res: dict) -> dict:
    return {"bonds_per_face_1": res["nodes_per_face"],
            "cell_rings_1": res.get("cell_rings", ADDED_KEYS["resolution.cell_rings"]),
            "cell_ring_growth_1": res.get("cell_ring_growth", ADDED_KEYS["resolution.cell_ring_growth"])}


def elastic_row(folder: Path) -> dict | None:
    """The CSV row of one ``elastic --grains fem`` folder (None where it holds none): the fem cells' moduli and
    contact shear tail (over the applied stress), and the mesh reference's beside them."""
    try:
        s = json.loads((folder / "summary.json").read_text())
        res = json.loads((folder / "params.json").read_text())["resolution"]
    except (OSError, ValueError, KeyError):
        return None
    models = s.get("models", {})
    if "fem" not in models:
        return None
    out = {"run": folder.name, "seed": s["seed"], **_discretisation(res)}
    for name, key, factor in ELASTIC_COLUMNS:
        out[name] = _value(models["fem"].get(key), factor)
    mesh = models.get("mesh", {})
    out["mesh_reference_shear_ratio_p99_1"] = _value(mesh.get("shear_stress_ratio_p99"), 1.0)
    out["mesh_reference_young_gpa"] = _value(mesh.get("young_pa"), 1e-9)
    return out


def row(folder: Path) -> dict | None:
    """The CSV row of one run folder (None where it holds no finished run)."""
    try:
        s = json.loads((folder / "summary.json").read_text())
    except (OSError, ValueError):
        return None
    res = s["params"]["resolution"]
    out = {"run": folder.name, "seed": s["seed"], "width_mm": 1e3 * s["params"]["specimen"]["width"],
           "height_mm": 1e3 * s["params"]["specimen"]["height"], **_discretisation(res),
           "stiffness_scale_1": s["params"]["calibration"]["stiffness_scale"]}
    for name, key, factor in COLUMNS:
        out[name] = _value(s.get(key), factor)
    out.update(peak_reached=s.get("peak_reached"), end_reason=s.get("end_reason"), code_version=s.get("code_version"))
    return out


def k_series(rows: list[dict]) -> str:
    """Markdown: per specimen and interior, the UCS against K (bonds per face), the paired changes, and the
    three-point extrapolation in h = 1 / K with the K it puts within the criterion of its limit. Runs that
    ended without a peak (``peak_reached`` False) or split before it (nu above :data:`SPLIT_POISSON`) are shown
    with their stress and left out of the changes and the extrapolation."""
    groups, no_peak = {}, {}
    for r in rows:
        key = (float(r["width_mm"]), float(r["height_mm"]), int(r["seed"]), int(r["cell_rings_1"]),
               float(r["cell_ring_growth_1"]), float(r.get("stiffness_scale_1", 1.0)))
        groups.setdefault(key, {})
        if r.get("peak_reached", "True") == "False":
            no_peak.setdefault(key, {})[int(r["bonds_per_face_1"])] = f"no peak ({float(r['ucs_mpa']):.1f} at the end)"
        elif r.get("poisson_1") not in (None, "") and float(r["poisson_1"]) > SPLIT_POISSON:
            no_peak.setdefault(key, {})[int(r["bonds_per_face_1"])] = (
                f"split ({float(r['ucs_mpa']):.1f} at {float(r['peak_axial_strain_percent']):.3g} %, "
                f"nu {float(r['poisson_1']):.2f})")
        else:
            groups[key][int(r["bonds_per_face_1"])] = float(r["ucs_mpa"])
    lines = ["| specimen [mm] | seed | rings (grading) | bond stiffness x | K: UCS [MPa] (change) | extrapolation over the three finest |",
             "|---|---|---|---|---|---|"]
    for key, by_k in sorted(groups.items()):
        w, h, seed, rings, growth, stiffness = key
        ks = sorted(by_k)
        ucs = [by_k[k] for k in ks]
        changes = paired_changes(ucs)
        shown = {**no_peak.get(key, {}),
                 **{k: f"{u:.1f}" + ("" if i == 0 else f" ({100 * changes[i]:+.1f} %)")
                    for i, (k, u) in enumerate(zip(ks, ucs))}}
        cells = ", ".join(f"{k}: {text}" for k, text in sorted(shown.items()))
        fit, why = extrapolate([1.0 / k for k in ks], ucs)
        if fit is None:
            note = why
        else:
            k_needed = 1.0 / fit.spacing_within(CONVERGED_CHANGE)
            note = (f"limit {fit.limit:.1f} MPa, order {fit.order:.2f}; within {100 * CONVERGED_CHANGE:.0f} % "
                    f"of the limit from K = {math.ceil(k_needed)}")
        lines.append(f"| {w:g} x {h:g} | {seed} | {rings} ({growth:g}) | {stiffness:g} | {cells} | {note} |")
    return "\n".join(lines) + "\n"


def read_csvs(paths, what: str) -> list[dict] | None:
    """The rows of the CSVs ``paths``; None, after one line naming the file and ``what`` to give, if one is unreadable."""
    try:
        return [r for path in paths for r in csv.DictReader(open(path, newline=""))]
    except OSError as e:
        print(f"error: {e.filename}: cannot read ({e.strerror}); fix: give {what}", file=sys.stderr)
        return None


def write_markdown(make, n_rows: int, out: Path, sources, what: str) -> int:
    """Write the markdown ``make()`` returns at ``out`` (exit status 0), or say in one line that the CSVs
    ``sources`` lack or mangle a column and name ``what`` to give (2; nothing written)."""
    try:
        text = make()
    except (KeyError, ValueError) as e:
        print(f"error: {', '.join(map(str, sources))}: a row lacks or mangles column {e}; fix: give {what}",
              file=sys.stderr)
        return 2
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)
    print(f"{n_rows} rows -> {out}")
    return 0


def write_rows(rows: list[dict], out: Path) -> None:
    """``rows`` (dicts with the same keys) as a CSV at ``out``, its folder made; says how many."""
    out.parent.mkdir(parents=True, exist_ok=True)
    with open(out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"{len(rows)} rows -> {out}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folders", nargs="+", type=Path)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--elastic", action="store_true", help="the folders are elastic --grains fem runs")
    ap.add_argument("--k-series", action="store_true", help="the arguments are ucs_runs CSVs of this script: "
                    "write the UCS against K as a markdown table")
    a = ap.parse_args(argv)
    if a.k_series:
        rows = read_csvs(a.folders, "ucs_runs CSVs of this script")
        return 2 if rows is None else write_markdown(lambda: k_series(rows), len(rows), a.out, a.folders,
                                                     "ucs_runs CSVs written by this script")
    rows = sorted((r for r in map(elastic_row if a.elastic else row, a.folders) if r),
                  key=lambda r: (r["cell_ring_growth_1"], r["cell_rings_1"], r["bonds_per_face_1"], r["run"]))
    if not rows:
        print("error: no finished run among the folders; fix: give run folders that hold a summary.json", file=sys.stderr)
        return 2
    write_rows(rows, a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
