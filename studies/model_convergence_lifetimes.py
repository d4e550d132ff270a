"""The creep rows of the model convergence study (docs/studies/model_convergence.md): one CSV line per finished creep
run folder (the discretisation, the degradation law and the reading of the driving stress, the held stress, the lifetime, the events, the
cost), and from such CSVs the lifetime against bonds per face K as a markdown table, units in the column names.

    /usr/bin/python3 -m studies.model_convergence_lifetimes results/model_convergence_creep/* --out docs/studies/model_convergence/lifetime_runs.csv
    /usr/bin/python3 -m studies.model_convergence_lifetimes --series docs/studies/model_convergence/lifetime_runs.csv --ucs docs/studies/model_convergence/*ucs_runs.csv --out docs/studies/model_convergence/lifetime_series.md

``--series`` lays the rows out twice, each with the change d ln t_f from the next coarser K (the study's criterion:
|d ln t_f| < 0.5 between the two finest):

* at a ratio r of each discretisation's own UCS: the rows whose given UCS is the UCS a ``--ucs`` CSV (of
  ``studies.model_convergence``) holds for the same specimen, seed, interior and K (within
  :data:`OWN_UCS_TOLERANCE`);
* at one held stress: the rows of one specimen, seed, interior and reading held at the same stress (to
  :data:`HELD_STRESS_DIGITS` decimals of a MPa) at two or more K.

Rows that repeat one discretisation and load (the cells' interiors condensed out or not: the same lifetime to
round-off) show the last of the CSV's order (law, reading, held stress, K, run name).

A pure reader of run folders (summary.json); no YADE.
"""
import argparse
import json
import sys
from pathlib import Path

from grainfrac_yade.api import ADDED_KEYS, log_changes
from studies.model_convergence import read_csvs, write_markdown, write_rows

#: The study's criterion on the lifetime: |d ln t_f| between the two finest discretisations below this [1].
CONVERGED_LOG_CHANGE = 0.5
#: Relative distance within which a creep row's given UCS is the UCS run's own: the UCS CSVs round to 1e-6 MPa,
#: the batch tables give 10 significant digits [1].
OWN_UCS_TOLERANCE = 1e-6
#: Decimals of a MPa to which rows held at one stress are matched (the held stress is r x a given UCS) [1].
HELD_STRESS_DIGITS = 2


def row(folder: Path) -> dict | None:
    """The CSV row of one creep run folder (None where it holds no finished creep run)."""
    try:
        s = json.loads((folder / "summary.json").read_text())
    except (OSError, ValueError):
        return None
    if "driving_stress_ratio" not in s:
        return None
    p = s["params"]
    res, sc = p["resolution"], p["stress_corrosion"]
    return {"run": folder.name, "seed": s["seed"], "width_mm": 1e3 * p["specimen"]["width"],
            "height_mm": 1e3 * p["specimen"]["height"], "bonds_per_face_1": res["nodes_per_face"],
            "cell_rings_1": res.get("cell_rings", ADDED_KEYS["resolution.cell_rings"]),
            "cell_ring_growth_1": res.get("cell_ring_growth", ADDED_KEYS["resolution.cell_ring_growth"]),
            "law": sc["law"], "reading": sc.get("reading", ADDED_KEYS["stress_corrosion.reading"]),
            "driving_stress_ratio_1": s["driving_stress_ratio"], "given_ucs_mpa": round(1e-6 * s["ucs_pa"], 6),
            "held_mpa": round(1e-6 * s["stress_pa"], 6), "failed": s["failed"],
            "lifetime_s": s["lifetime_s"] if s["failed"] else None, "creep_time_end_s": s["creep_time_end_s"],
            "n_events_1": s.get("n_events"), "broken_ramp_1": s.get("broken_ramp"),
            "broken_creep_1": s.get("broken_creep"), "cpu_s": round(s["cpu_s"], 1), "end_reason": s.get("end_reason"),
            "code_version": s.get("code_version")}


def _specimen(r) -> tuple:
    return (float(r["width_mm"]), float(r["height_mm"]), int(r["seed"]), int(r["cell_rings_1"]),
            float(r["cell_ring_growth_1"]))


def own_ucs(ucs_rows) -> dict:
    """{(specimen, seed, rings, grading, K): UCS [MPa]} of the UCS CSV rows that reached a peak."""
    return {(*_specimen(r), int(r["bonds_per_face_1"])): float(r["ucs_mpa"]) for r in ucs_rows
            if r.get("peak_reached", "True") != "False"}


def _line(label, by_k: dict) -> str:
    ks = sorted(by_k)
    lifetimes = [by_k[k][0] for k in ks]
    changes = log_changes(lifetimes)
    cells = ", ".join(f"{k}: {t:.4g} s ({n} events)" + ("" if i == 0 else f" [{changes[i]:+.2f}]")
                      for i, (k, (t, n)) in enumerate(zip(ks, [by_k[k] for k in ks])))
    finest = abs(changes[-1]) if len(ks) > 1 else float("nan")
    verdict = ("one K" if len(ks) < 2 else
               f"{'within' if finest < CONVERGED_LOG_CHANGE else 'not within'} {CONVERGED_LOG_CHANGE:g}")
    return f"| {label} | {cells} | {verdict} |"


def series(rows, ucs_rows) -> str:
    """Markdown: the lifetimes against K at a ratio of each own UCS and at one held stress (see the module)."""
    own = own_ucs(ucs_rows)
    at_ratio, at_stress = {}, {}
    for r in rows:
        if r["failed"] != "True" or r["lifetime_s"] in (None, ""):
            continue
        spec, k = _specimen(r), int(r["bonds_per_face_1"])
        value = (float(r["lifetime_s"]), int(r["n_events_1"]))
        ucs, given = own.get((*spec, k)), float(r["given_ucs_mpa"])
        if ucs is not None and abs(given / ucs - 1.0) <= OWN_UCS_TOLERANCE:
            at_ratio.setdefault((*spec, r["law"], r["reading"], float(r["driving_stress_ratio_1"])), {})[k] = value
        held = round(float(r["held_mpa"]), HELD_STRESS_DIGITS)
        at_stress.setdefault((*spec, r["law"], r["reading"], held), {})[k] = value
    head = ("| specimen [mm], seed, rings (grading), law, reading, {} | K: lifetime (events) [d ln t_f from the coarser K] "
            f"| finest change against {CONVERGED_LOG_CHANGE:g} |\n|---|---|---|")
    out = ["At a ratio r of each discretisation's own UCS:", "", head.format("r")]
    for (w, h, seed, rings, growth, law, reading, ratio), by_k in sorted(at_ratio.items()):
        out.append(_line(f"{w:g} x {h:g}, {seed}, {rings} ({growth:g}), {law}, {reading}, {ratio:g}", by_k))
    out += ["", "At one held stress:", "", head.format("held [MPa]")]
    for (w, h, seed, rings, growth, law, reading, held), by_k in sorted(at_stress.items()):
        if len(by_k) > 1:
            out.append(_line(f"{w:g} x {h:g}, {seed}, {rings} ({growth:g}), {law}, {reading}, {held:.2f}", by_k))
    return "\n".join(out) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folders", nargs="+", type=Path, help="creep run folders (or, with --series, CSVs of this script)")
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--series", action="store_true", help="the arguments are CSVs of this script: write the "
                    "lifetimes against K as a markdown table")
    ap.add_argument("--ucs", nargs="*", type=Path, default=[], help="with --series: ucs_runs CSVs of "
                    "studies.model_convergence (the own UCS of each discretisation)")
    a = ap.parse_args(argv)
    if a.series:
        rows = read_csvs(a.folders, "lifetime CSVs of this script")
        ucs_rows = read_csvs(a.ucs, "ucs_runs CSVs of studies.model_convergence")
        if rows is None or ucs_rows is None:
            return 2
        return write_markdown(lambda: series(rows, ucs_rows), len(rows), a.out, a.folders + a.ucs,
                              "the CSVs of this script and of studies.model_convergence")
    rows = sorted((r for r in map(row, a.folders) if r),
                  key=lambda r: (r["law"], r["reading"], r["held_mpa"], r["bonds_per_face_1"], r["run"]))
    if not rows:
        print("error: no finished creep run among the folders; fix: give creep run folders that hold a summary.json",
              file=sys.stderr)
        return 2
    write_rows(rows, a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
