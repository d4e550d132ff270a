"""Mesh resolution of finite-element lifetimes: the creep table at fractions of each specimen's own UCS.

    /usr/bin/python3 -m studies.fem_size_mesh results/fem_size_mesh_ucs --out params/fem_mesh_creep.table

Reads the finished UCS runs of ``params/fem_size_mesh_ucs.table`` of one specimen size (``--width``, default
10 mm) and writes a batch table of creep rows at ``--ratios`` (default 0.7 and 0.85) of each run's own UCS:
one row per (bonds per face, seed, ratio), with the UCS run's specimen, mesh and numerics, and the creep keys
of the paper-size study (servo at 2 wave crossings, relaxations up to 20, creep time limit 1e13 s).  So that
a mesh's lifetime is compared at the same driving ratio, not at the same stress.  A pure reader of run
folders (no YADE).
"""
import argparse
import json
import sys
from pathlib import Path

from grainfrac_yade.api import flatten

#: Parameter columns copied from each UCS run into its creep rows (the specimen, the mesh, the numerics).
COPIED = ("resolution.grain_model", "resolution.nodes_per_face", "resolution.contact_inset",
          "numerics.verlet_radius_quantile", "numerics.density_scale", "calibration.strength_scale",
          "calibration.stiffness_scale", "specimen.width", "specimen.height", "specimen.min_edge_fraction")
#: Creep keys of every row: the paper-size study's hold (docs/studies/paper_fem.md) and a time limit long
#: enough for the 0.7 rows (10 x 20 mm fem lifetimes at 0.7 of the UCS were 1e5-9e5 s, regularisation.md).
CREEP_KEYS = {"creep.servo_response_crossings": 2, "creep.max_relaxation_crossings": 20,
              "stress_corrosion.creep_time_limit": 1e13}


def cell(v) -> str:
    return repr(v) if isinstance(v, str) else f"{v:g}" if isinstance(v, float) else str(v)


def ucs_runs(folder: Path, width: float) -> list:
    """The finished UCS runs in ``folder`` of specimen width ``width`` [m], sorted by (bonds per face, seed)."""
    runs = []
    for f in sorted(folder.glob("*/summary.json")):
        s = json.loads(f.read_text())
        if s.get("ucs_pa") is None or abs(s["params"]["specimen"]["width"] - width) > 1e-12:
            continue
        runs.append(s)
    return sorted(runs, key=lambda s: (s["params"]["resolution"]["nodes_per_face"], s["seed"]))


def creep_rows(runs: list, ratios) -> tuple:
    """(columns, rows) of the creep table: per run and ratio, its parameters, ``ratio`` and ``ucs`` [Pa]."""
    columns = ["ratio", "ucs", *COPIED, *CREEP_KEYS, "seed", "study", "description"]
    rows = []
    for s in runs:
        p = flatten(s["params"])
        copied = [cell(p[c]) for c in COPIED] + [cell(v) for v in CREEP_KEYS.values()]
        name = f"w{1e3 * p['specimen.width']:g}_k{p['resolution.nodes_per_face']}"
        for ratio in ratios:
            rows.append([f"{ratio:g}", f"{s['ucs_pa']:.6e}", *copied, str(s["seed"]), "'fem_mesh_creep'",
                         f"'{name}_r{ratio:g}_s{s['seed']}'"])
    return columns, rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="studies.fem_size_mesh", description=__doc__.split("\n\n")[0])
    ap.add_argument("ucs_folder", type=Path)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--width", type=float, default=10e-3, help="specimen width of the UCS runs used [m]")
    ap.add_argument("--ratios", default="0.7,0.85", help="fractions of each run's own UCS, comma-separated")
    a = ap.parse_args(argv)
    ratios = [float(r) for r in a.ratios.split(",")]
    runs = ucs_runs(a.ucs_folder, a.width)
    if not runs:
        print(f"error: {a.ucs_folder}: no finished UCS run of width {a.width:g} m; fix: run "
              "params/fem_size_mesh_ucs.table first", file=sys.stderr)
        return 2
    columns, rows = creep_rows(runs, ratios)
    head = ["# Written by studies/fem_size_mesh.py from the UCS runs in " + str(a.ucs_folder) + " (do not edit):",
            "# creep with the paper's beta at " + ", ".join(f"{r:g}" for r in ratios) + " of each run's own UCS "
            "(column ucs [Pa]), the paper-size study's hold.",
            "#   python3 -m grainfrac_yade batch " + str(a.out) + " --jobs 1",
            "#   python3 -m grainfrac_yade analyze results/fem_mesh_creep"]
    a.out.write_text("\n".join(head + [" ".join(columns)] + [" ".join(r) for r in rows]) + "\n")
    print(f"{a.out}: {len(rows)} rows from {len(runs)} UCS runs")
    return 0


if __name__ == "__main__":
    sys.exit(main())
