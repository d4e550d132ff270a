"""Static contact-stress tails of finite-element cells against the edge-collapse threshold
(``specimen.min_edge_fraction``): docs/regularisation_tails.csv and its table in docs/studies/regularisation.md.

The static uniaxial solve of ``grainfrac_yade.elastic`` (the one ``python3 -m grainfrac_yade elastic --grains fem``
runs; no YADE), Tables 1 and 2 as printed (params/presets/fem_coarse.toml), 10 x 20 mm and the paper's 31.7 x 63.4 mm,
seeds 1-3. Per bond and per face (the forces of a face's bonds summed over the face): the p99 and the largest
shear and tensile stress over the applied axial stress, and E and nu, each paired against threshold 0 of the
same seed.

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.regularisation_tails [--table-only]
"""
from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

from grainfrac_yade.api import PARAMS_DIR, build_specimen, elastic_summary, grain_model, load_parameters

CSV = ROOT / "docs" / "regularisation_tails.csv"
FEM_PRESET = PARAMS_DIR / "presets" / "fem_coarse.toml"
FRACTIONS = (0.0, 0.01, 0.02, 0.05, 0.10)
SIZES = {"10x20": (10e-3, 20e-3), "paper": (31.7e-3, 63.4e-3)}
SEEDS = (1, 2, 3)
#: Summary keys of the static solve kept per row (stress ratios: contact stress / applied axial stress).
TAIL_KEYS = ("shear_stress_ratio_p99", "shear_stress_ratio_max", "tension_stress_ratio_p99",
             "tension_stress_ratio_max", "face_shear_stress_ratio_p99", "face_shear_stress_ratio_max",
             "face_tension_stress_ratio_p99", "face_tension_stress_ratio_max")
FIELDS = ("specimen", "seed", "min_edge_fraction", "n_faces", "edges_collapsed", "young_gpa", "poisson") + TAIL_KEYS


def measure(size: str, seed: int, fraction: float) -> dict:
    w, h = SIZES[size]
    p = load_parameters(extra_files=[FEM_PRESET], overrides=[f"specimen.width={w}", f"specimen.height={h}",
                                                             f"specimen.min_edge_fraction={fraction}"])
    s = build_specimen(p, seed)
    layout = grain_model("fem").build_layout(s, p)
    summary, _, _ = elastic_summary(s, p, "fem", layout, p.resolution.nodes_per_face, "corners", 1, platens="cells")
    row = {"specimen": size, "seed": seed, "min_edge_fraction": fraction, "n_faces": s.tessellation.n_faces,
           "edges_collapsed": s.edges_collapsed, "young_gpa": summary["young_pa"] / 1e9,
           "poisson": summary["poisson"]}
    row.update({k: summary[k] for k in TAIL_KEYS})
    return row


def run(out: Path = CSV) -> list:
    rows = []
    for size in SIZES:
        for seed in SEEDS:
            for fraction in FRACTIONS:
                rows.append(measure(size, seed, fraction))
                print(f"{size} seed {seed} threshold {fraction}: done", file=sys.stderr, flush=True)
                write_csv(rows, out)   # partial results as they come
    return rows


def write_csv(rows: list, out: Path):
    with open(out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        w.writeheader()
        w.writerows(rows)


def read_csv(path: Path = CSV) -> list:
    with open(path, newline="") as f:
        return [{k: (v if k == "specimen" else float(v)) for k, v in r.items()} for r in csv.DictReader(f)]


def table(rows: list) -> str:
    """Markdown: per size and threshold, the seeds' paired change of each tail against threshold 0 [%]."""
    base = {(r["specimen"], int(r["seed"])): r for r in rows if r["min_edge_fraction"] == 0.0}
    shown = (("young_gpa", "E"), ("shear_stress_ratio_p99", "bond shear p99"), ("shear_stress_ratio_max", "bond shear max"),
             ("tension_stress_ratio_p99", "bond tension p99"), ("tension_stress_ratio_max", "bond tension max"),
             ("face_shear_stress_ratio_p99", "face shear p99"), ("face_shear_stress_ratio_max", "face shear max"),
             ("face_tension_stress_ratio_max", "face tension max"))
    lines = ["| specimen | threshold | " + " | ".join(label for _, label in shown) + " |",
             "|---|---|" + "---|" * len(shown)]
    for size in SIZES:
        for fraction in FRACTIONS[1:]:
            sel = sorted((r for r in rows if r["specimen"] == size and r["min_edge_fraction"] == fraction),
                         key=lambda r: r["seed"])
            if not sel:
                continue
            cells = []
            for key, _ in shown:
                changes = [100.0 * (r[key] / base[(size, int(r["seed"]))][key] - 1.0) for r in sel]
                cells.append(" / ".join(f"{c:+.1f}" for c in changes))
            lines.append(f"| {size} | {fraction:g} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--table-only", action="store_true", help="print the table of the stored CSV, solve nothing")
    args = ap.parse_args(argv)
    rows = read_csv() if args.table_only else run()
    print(table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
