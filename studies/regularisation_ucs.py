"""Paired UCS and Young's modulus of 10 x 20 mm finite-element cells against the edge-collapse threshold
(``specimen.min_edge_fraction`` 0, 2 %, 5 %; seeds 1-3; params/presets/fem_calibrated.toml; one thread):
docs/regularisation_ucs.csv and its table in docs/studies/regularisation.md.  Each run about 1-3 min.

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.regularisation_ucs [--runs DIR] [--table-only]

Runs missing in DIR (default results/regularisation_ucs, one folder f<threshold>_s<seed>) are made with
``python3 -m grainfrac_yade ucs``; the differences are paired: same seed, threshold against 0.
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
FRACTIONS = ("0.0", "0.02", "0.05")
SEEDS = (1, 2, 3)
PRESET = "params/presets/fem_calibrated.toml"


def run(runs: Path, fraction: str, seed: int) -> Path:
    out = runs / f"f{fraction}_s{seed}"
    if not (out / "summary.json").exists():
        cmd = [sys.executable, "-m", "grainfrac_yade", "ucs", "--params", PRESET, "--width", "10e-3",
               "--height", "20e-3", "--seed", str(seed), "--set", f"specimen.min_edge_fraction={fraction}",
               "--out", str(out), "--overwrite"]
        subprocess.run(cmd, cwd=ROOT, check=True, env={**os.environ, "OMP_NUM_THREADS": "1"})
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=Path, default=ROOT / "results" / "regularisation_ucs")
    ap.add_argument("--table-only", action="store_true", help="print the table of the stored CSV")
    args = ap.parse_args()
    if not args.table_only:
        rows = []
        for seed in SEEDS:
            for f in FRACTIONS:
                s = json.loads((run(args.runs, f, seed) / "summary.json").read_text())
                rows.append({"seed": seed, "min_edge_fraction": float(f), "ucs_pa": s["ucs_pa"],
                             "young_pa": s["young_pa"], "broken_total": s.get("broken_total"),
                             "dem_steps": s.get("steps", s.get("dem_steps")), "cpu_s": s.get("cpu_s")})
        with CSV.open("w", newline="") as fh:
            wr = csv.DictWriter(fh, fieldnames=list(rows[0]))
            wr.writeheader()
            wr.writerows(rows)
    with CSV.open() as fh:
        rows = list(csv.DictReader(fh))
    base = {r["seed"]: r for r in rows if float(r["min_edge_fraction"]) == 0}
    print("| threshold | UCS [MPa] seeds 1/2/3 | d UCS vs 0 [%] | E [GPa] | d E vs 0 [%] | CPU [s] |")
    print("|---|---|---|---|---|---|")
    for f in FRACTIONS:
        rs = [r for r in rows if float(r["min_edge_fraction"]) == float(f)]
        d_ucs = [100 * (float(r["ucs_pa"]) / float(base[r["seed"]]["ucs_pa"]) - 1) for r in rs]
        d_e = [100 * (float(r["young_pa"]) / float(base[r["seed"]]["young_pa"]) - 1) for r in rs]
        mean = lambda v: sum(v) / len(v)  # noqa: E731
        print(f"| {100 * float(f):g} % | " + " / ".join(f"{float(r['ucs_pa']) / 1e6:.1f}" for r in rs)
              + " | " + " / ".join(f"{d:+.1f}" for d in d_ucs) + f" (mean {mean(d_ucs):+.1f})"
              + " | " + " / ".join(f"{float(r['young_pa']) / 1e9:.2f}" for r in rs)
              + " | " + " / ".join(f"{d:+.2f}" for d in d_e) + f" (mean {mean(d_e):+.2f})"
              + " | " + " / ".join(f"{float(r['cpu_s']):.0f}" if r["cpu_s"] not in ("", "None") else "-" for r in rs)
              + " |")


if __name__ == "__main__":
    main()
