"""Critical DEM step of rigid and finite-element cells against the edge-collapse threshold
(``specimen.min_edge_fraction``), by specimen size and seed: docs/regularisation_steps.csv and the tables of
docs/studies/regularisation.md.  Pure numpy (grainfrac_yade.dem_step.critical_dem_step, the YADE scene's bound),
no YADE.

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.regularisation_steps [--table-only]

Rigid cells: the shipped defaults.  Finite-element cells: params/presets/fem_calibrated.toml.
"""
from __future__ import annotations

import argparse
import csv
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

from grainfrac_yade.api import PARAMS_DIR, build_specimen, critical_dem_step, layout_for, load_parameters

CSV = ROOT / "docs" / "regularisation_steps.csv"
FRACTIONS = (0.0, 0.01, 0.02, 0.05, 0.10)
SIZES = {"10x20": (10e-3, 20e-3), "paper": (31.7e-3, 63.4e-3)}
SEEDS = (1, 2, 3)
MODELS = {"rigid": [], "fem": [PARAMS_DIR / "presets" / "fem_calibrated.toml"]}
FIELDS = ("specimen", "seed", "min_edge_fraction", "n_cells", "n_faces", "edges_collapsed", "edges_kept_short",
          "shortest_face_m", "faces_below_5pct", "rigid_step_s", "fem_step_s", "fem_bodies")


def measure(size, seed, fraction) -> dict:
    w, h = SIZES[size]
    row = {"specimen": size, "seed": seed, "min_edge_fraction": fraction}
    s = None
    for model, extra in MODELS.items():
        p = load_parameters(extra_files=extra, overrides=[f"specimen.width={w}", f"specimen.height={h}",
                                                          f"specimen.min_edge_fraction={fraction}"])
        s = s or build_specimen(p, seed)   # the presets leave the specimen section alone: one specimen
        lay = layout_for(s, p)
        row[f"{model}_step_s"] = critical_dem_step(s, p, lay)
        if model == "fem":
            row["fem_bodies"] = lay.n_spheres
    t = s.tessellation
    row.update(n_cells=t.n_cells, n_faces=t.n_faces, edges_collapsed=s.edges_collapsed,
               edges_kept_short=s.edges_kept_short, shortest_face_m=float(t.face_measure.min()),
               faces_below_5pct=int(np.sum(t.face_measure < 0.05 * p.specimen.grain_size)))
    return row


def table(rows) -> str:
    out = ["| specimen | threshold | edges collapsed (seeds 1/2/3) | shortest face / grain | rigid step [s] "
           "(gain) | fem step [s] (gain) |", "|---|---|---|---|---|---|"]
    base = {(r["specimen"], r["seed"]): r for r in rows if float(r["min_edge_fraction"]) == 0}
    for size in SIZES:
        for f in FRACTIONS:
            rs = sorted([r for r in rows if r["specimen"] == size and float(r["min_edge_fraction"]) == f],
                        key=lambda r: int(r["seed"]))
            if not rs:
                continue

            def cell(key):
                vals = [float(r[key]) for r in rs]
                gain = [float(r[key]) / float(base[(size, r["seed"])][key]) for r in rs]
                return " / ".join(f"{v:.3g}" for v in vals) + " (x " + " / ".join(f"{g:.2f}" for g in gain) + ")"
            out.append(f"| {size} | {100 * f:g} % | {' / '.join(str(r['edges_collapsed']) for r in rs)} | "
                       + " / ".join(f"{float(r['shortest_face_m']) / 1e-3:.2g}" for r in rs)
                       + f" | {cell('rigid_step_s')} | {cell('fem_step_s')} |")
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--table-only", action="store_true", help="print the table of the stored CSV")
    args = ap.parse_args()
    if not args.table_only:
        rows = []
        for size in SIZES:
            for seed in SEEDS:
                for f in FRACTIONS:
                    rows.append(measure(size, seed, f))
                    print({k: rows[-1][k] for k in ("specimen", "seed", "min_edge_fraction", "edges_collapsed",
                                                    "rigid_step_s", "fem_step_s")}, flush=True)
        with CSV.open("w", newline="") as fh:
            wr = csv.DictWriter(fh, fieldnames=FIELDS)
            wr.writeheader()
            for r in rows:
                wr.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()})
    with CSV.open() as fh:
        print(table(list(csv.DictReader(fh))))


if __name__ == "__main__":
    main()
