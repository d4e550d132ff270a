"""The levers on the lab bands (Brazilian tensile strength, crack thresholds), measured: docs/studies/lab_bands.md.

Two parts, each writing one CSV into docs/studies/ (units in the column names):

* ``grain-size``: the coefficient of variation of the cells' equivalent diameter against
  ``specimen.lloyd_iterations`` (the lever on the grain-size spread; pure numpy, no YADE), all cells and
  the interior cells (no face on a wall, which the box does not cut);
* ``levers``: one paired UCS test and one paired Brazilian test per lever setting (one seed, one run at a
  time, one thread), each against the same specimen without the lever.

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.lab_bands grain-size
    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.lab_bands levers --params params/presets/fem_coarse.toml \\
        --out results/lab_bands [--only NAME ...]

Rows of ``levers`` already in the CSV are kept (a run replaces the row of its setting and seed); ``--only``
runs the named settings, ``--seed`` another specimen (default 1).
"""
from __future__ import annotations

import argparse
import csv
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

from grainfrac_yade.api import build_specimen, load_parameters

GRAIN_SIZE_CSV = ROOT / "docs" / "studies" / "lab_bands_grain_size.csv"
LEVERS_CSV = ROOT / "docs" / "studies" / "lab_bands_levers.csv"
LLOYD_ITERATIONS = (0, 1, 2, 3, 5, 10)
GRAIN_SIZE_SEEDS = (1, 2, 3)
#: Specimens of the grain-size part: the paper's and the small one of the lever runs [m].
GRAIN_SIZE_SPECIMENS = {"31.7x63.4": (31.7e-3, 63.4e-3), "5x10": (5e-3, 10e-3)}
#: The lever runs: the smallest specimens where the measures mean something (about 60 cells in the
#: UCS specimen, 100 in the disc) [m].
UCS_SIZE = (5e-3, 10e-3)
DISC_DIAMETER = 10e-3
SEED = 1   # the default seed of the lever runs (--seed)
#: Lever settings: name -> overrides (the baseline has none).  Magnitudes: far enough from 1 that a
#: paired difference is the lever's, not a change of the crack path alone.
SETTINGS = {
    "baseline": [],
    "ks_over_kn_x2.5": ["calibration.shear_stiffness_ratio_scale=2.5"],
    "tensile_over_cohesion_x0.5": ["calibration.tensile_cohesion_ratio_scale=0.5"],
    "tensile_over_cohesion_x0.25": ["calibration.tensile_cohesion_ratio_scale=0.25"],
    "inter_over_intra_0.7": ["calibration.inter_mineral_strength_ratio=0.7"],
    "weibull_m3": ["calibration.strength_weibull_modulus=3.0"],
    "weibull_m1.5": ["calibration.strength_weibull_modulus=1.5"],
    "lloyd_0": ["specimen.lloyd_iterations=0"],
}
LEVER_FIELDS = ("setting", "overrides", "test", "seed", "size_m", "n_cells", "ucs_pa", "young_pa", "poisson",
                "crack_initiation_pa", "crack_damage_pa", "ci_over_ucs", "cd_over_ucs", "tensile_strength_pa",
                "split_found", "cpu_s")


def grain_size_rows() -> list:
    rows = []
    for name, (w, h) in GRAIN_SIZE_SPECIMENS.items():
        for n in LLOYD_ITERATIONS:
            p = load_parameters(overrides=[f"specimen.width={w}", f"specimen.height={h}",
                                           f"specimen.lloyd_iterations={n}"])
            for seed in GRAIN_SIZE_SEEDS:
                t = build_specimen(p, seed).tessellation
                d = t.equivalent_diameter()
                interior = np.setdiff1d(np.arange(t.n_cells), t.boundary_cell)
                rows.append({"specimen_mm": name, "lloyd_iterations": n, "seed": seed, "n_cells": t.n_cells,
                             "mean_diameter_m": float(d.mean()), "cv_diameter_all": float(d.std(ddof=1) / d.mean()),
                             "cv_diameter_interior": float(d[interior].std(ddof=1) / d[interior].mean()),
                             "n_interior": int(len(interior)),
                             "cv_area_interior": float(t.cell_measure[interior].std(ddof=1)
                                                       / t.cell_measure[interior].mean())})
    return rows


def _write(path: Path, rows, fields):
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        w.writerows(rows)


def run_setting(name, extra_files, out: Path, seed: int = SEED) -> list:
    rows = measure(extra_files, SETTINGS[name], seed, out / f"{name}_seed{seed}")
    return [{"setting": name, **{k: v for k, v in r.items() if k in LEVER_FIELDS}} for r in rows]


def volumetric_crack_initiation(folder: Path, summary: dict) -> float:
    """Crack initiation read from the crack volumetric strain of the UCS run in ``folder`` (as the lab
    reads it: grainfrac_yade.analysis.ucs_analysis.crack_initiation_volumetric_stress) [Pa]."""
    from grainfrac_yade.api import crack_initiation_volumetric_stress
    rows = list(csv.DictReader((Path(folder) / "history.csv").open()))
    col = {k: np.array([float(r[k]) for r in rows]) for k in ("axial_stress_pa", "axial_strain", "lateral_strain")}
    return crack_initiation_volumetric_stress(col["axial_stress_pa"], col["axial_strain"], col["lateral_strain"],
                                              summary["young_pa"], summary["poisson"])


def measure(extra_files, overrides, seed: int, prefix: Path, ucs_size=UCS_SIZE, disc_diameter=DISC_DIAMETER) -> list:
    """One UCS test (``ucs_size`` = (width, height) [m]) into ``prefix``_ucs and one Brazilian test
    (``disc_diameter`` [m]) into ``prefix``_brazilian with ``overrides``: their two rows of
    :data:`LEVER_FIELDS` (without the setting's name; the UCS row also has ``crack_initiation_volumetric_pa``, the Brazilian
    row ``broken_total``)."""
    from grainfrac_yade.api import run_brazilian_to_folder, run_ucs_to_folder
    rows, prefix = [], Path(prefix)
    w, h = ucs_size
    p = load_parameters(extra_files=extra_files, overrides=[f"specimen.width={w}", f"specimen.height={h}", *overrides])
    t0 = time.process_time()
    folder = prefix.with_name(prefix.name + "_ucs")
    s = run_ucs_to_folder(p, seed, folder, overwrite=True)
    ucs = s["ucs_pa"]
    rows.append({"overrides": " ".join(overrides), "test": "ucs", "seed": seed,
                 "size_m": f"{w}x{h}", "n_cells": s["n_cells"], "ucs_pa": ucs, "young_pa": s["young_pa"],
                 "poisson": s["poisson"], "crack_initiation_pa": s["crack_initiation_pa"],
                 "crack_damage_pa": s["crack_damage_pa"],
                 "ci_over_ucs": s["crack_initiation_pa"] / ucs if s["crack_initiation_pa"] else None,
                 "cd_over_ucs": s["crack_damage_pa"] / ucs if s["crack_damage_pa"] else None,
                 "crack_initiation_volumetric_pa": volumetric_crack_initiation(folder, s),
                 "cpu_s": time.process_time() - t0})
    p = load_parameters(extra_files=extra_files, overrides=[f"brazilian.diameter={disc_diameter}", *overrides])
    t0 = time.process_time()
    s = run_brazilian_to_folder(p, seed, prefix.with_name(prefix.name + "_brazilian"), overwrite=True)
    rows.append({"overrides": " ".join(overrides), "test": "brazilian", "seed": seed,
                 "size_m": f"{disc_diameter}", "n_cells": s.get("n_cells"),
                 "tensile_strength_pa": s["tensile_strength_pa"], "split_found": s["split_found"],
                 "broken_total": s["broken_total"], "cpu_s": time.process_time() - t0})
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("part", choices=("grain-size", "levers"))
    ap.add_argument("--params", action="append", default=[], help="parameter files merged over the shipped ones")
    ap.add_argument("--out", default=str(ROOT / "results" / "lab_bands"), help="run folders (levers)")
    ap.add_argument("--only", nargs="+", choices=list(SETTINGS), help="settings to run (levers)")
    ap.add_argument("--seed", type=int, default=SEED, help="specimen seed of the lever runs")
    args = ap.parse_args(argv)
    if args.part == "grain-size":
        rows = grain_size_rows()
        _write(GRAIN_SIZE_CSV, rows, list(rows[0]))
        print(f"written {GRAIN_SIZE_CSV}")
        return 0
    kept = list(csv.DictReader(LEVERS_CSV.open())) if LEVERS_CSV.exists() else []
    for name in args.only or list(SETTINGS):
        new = run_setting(name, args.params, Path(args.out), args.seed)
        kept = [r for r in kept if (r["setting"], int(r["seed"])) != (name, args.seed)] + new
        _write(LEVERS_CSV, kept, LEVER_FIELDS)
        print(name, [(r["test"], r.get("ucs_pa") or r.get("tensile_strength_pa"), round(r["cpu_s"], 1)) for r in new],
              flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
