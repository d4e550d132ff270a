"""Paired UCS and Young's modulus of 10 x 20 mm specimens against the edge-collapse threshold
(``specimen.min_edge_fraction``), for finite-element cells (params/presets/fem_calibrated.toml) with and
without the guard of intact face-plane bonds (``numerics.keep_intact_joints``), and for rigid cells
(shipped defaults); seeds 1-3, one thread: docs/regularisation_ucs.csv and its table in
docs/studies/regularisation.md.  Each run about 1-5 min.

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.regularisation_ucs [--runs DIR] [--table-only]

Runs missing in DIR (default results/regularisation_ucs, one folder per variant and seed) are made with
``python3 -m grainfrac_yade ucs``; the differences are paired: same seed and variant, threshold against 0.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CSV = ROOT / "docs" / "regularisation_ucs.csv"
SEEDS = (1, 2, 3)
#: (name, parameter files, overrides, thresholds): each variant's thresholds start with 0, its pair base
VARIANTS = (
    ("fem_kept", ["params/presets/fem_calibrated.toml"], ["numerics.keep_intact_joints=true"],
     ("0.0", "0.01", "0.02", "0.05", "0.1")),
    ("fem_yade_rule", ["params/presets/fem_calibrated.toml"], ["numerics.keep_intact_joints=false"],
     ("0.0", "0.02", "0.05")),
    ("rigid", [], [], ("0.0", "0.02", "0.05")),
)
FIELDS = ("variant", "seed", "min_edge_fraction", "ucs_pa", "young_pa", "broken_total", "bonds_erased_by_sliding",
          "dem_steps", "cpu_s")


def run(runs: Path, variant, fraction: str, seed: int) -> Path:
    name, files, overrides, _ = variant
    out = runs / f"{name}_f{fraction}_s{seed}"
    if not (out / "summary.json").exists():
        cmd = [sys.executable, "-m", "grainfrac_yade", "ucs", *[a for f in files for a in ("--params", f)],
               "--width", "10e-3", "--height", "20e-3", "--seed", str(seed),
               "--set", f"specimen.min_edge_fraction={fraction}", *[a for o in overrides for a in ("--set", o)],
               "--out", str(out), "--overwrite"]
        subprocess.run(cmd, cwd=ROOT, check=True, env={**os.environ, "OMP_NUM_THREADS": "1"})
    return out


def measure(runs: Path) -> list:
    rows = []
    for variant in VARIANTS:
        for seed in SEEDS:
            for f in variant[3]:
                s = json.loads((run(runs, variant, f, seed) / "summary.json").read_text())
                rows.append({"variant": variant[0], "seed": seed, "min_edge_fraction": float(f),
                             "ucs_pa": s["ucs_pa"], "young_pa": s["young_pa"], "broken_total": s.get("broken_total"),
                             "bonds_erased_by_sliding": s.get("bonds_erased_by_sliding"),
                             "dem_steps": s.get("steps", s.get("dem_steps")), "cpu_s": s.get("cpu_s")})
                write(rows)          # partial results as they come
    return rows


def write(rows):
    with CSV.open("w", newline="") as fh:
        wr = csv.DictWriter(fh, fieldnames=FIELDS)
        wr.writeheader()
        wr.writerows(rows)


def table(rows) -> str:
    mean = lambda v: sum(v) / len(v)  # noqa: E731
    lines = ["| variant | threshold | UCS [MPa] seeds 1/2/3 | d UCS vs 0 [%] | E [GPa] | d E vs 0 [%] "
             "| bonds erased by sliding | CPU [s] |", "|---|---|---|---|---|---|---|---|"]
    for name, _, _, fractions in VARIANTS:
        mine = [r for r in rows if r["variant"] == name]
        base = {r["seed"]: r for r in mine if float(r["min_edge_fraction"]) == 0}
        for f in fractions:
            rs = [r for r in mine if float(r["min_edge_fraction"]) == float(f) and r["seed"] in base]
            if not rs:
                continue
            d_ucs = [100 * (float(r["ucs_pa"]) / float(base[r["seed"]]["ucs_pa"]) - 1) for r in rs]
            d_e = [100 * (float(r["young_pa"]) / float(base[r["seed"]]["young_pa"]) - 1) for r in rs]
            lines.append(
                f"| {name} | {100 * float(f):g} % | " + " / ".join(f"{float(r['ucs_pa']) / 1e6:.1f}" for r in rs)
                + " | " + " / ".join(f"{d:+.1f}" for d in d_ucs) + f" (mean {mean(d_ucs):+.1f})"
                + " | " + " / ".join(f"{float(r['young_pa']) / 1e9:.2f}" for r in rs)
                + " | " + " / ".join(f"{d:+.2f}" for d in d_e) + f" (mean {mean(d_e):+.2f})"
                + " | " + " / ".join(str(r["bonds_erased_by_sliding"]) for r in rs)
                + " | " + " / ".join(f"{float(r['cpu_s']):.0f}" for r in rs) + " |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=Path, default=ROOT / "results" / "regularisation_ucs")
    ap.add_argument("--table-only", action="store_true", help="print the table of the stored CSV")
    args = ap.parse_args()
    if not args.table_only:
        measure(args.runs)
    with CSV.open() as fh:
        rows = [{**r, "seed": int(r["seed"])} for r in csv.DictReader(fh)]
    print(table(rows))


if __name__ == "__main__":
    main()
