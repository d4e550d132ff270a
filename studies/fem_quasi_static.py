"""Is a finite-element UCS test quasi-static?  Table of the runs of params/fem_quasi_static_small.table
(and any other UCS folders given), grouped by platen strain rate and mass scaling.

    /usr/bin/python3 -m studies.fem_quasi_static results/fem_quasi_static [more folders] [--csv RUNS.csv]

Per (strain rate, density scale): the UCS, E, CI/UCS and CD/UCS of each seed, their mean, the change of
the mean UCS against the next faster setting of the same density scale (paired seeds only), the
loading time to the peak in wave crossings of the specimen, the DEM steps and CPU time per run.
Wave crossings: t_peak / (H / c), with t_peak = peak axial strain / strain rate (DEM time) and
c = sqrt(E / (rho x density_scale)) from the run's own E and the grains' mean density.
A pure reader of run folders (no YADE).
"""
import json
import math
import sys
from collections import defaultdict
from pathlib import Path


def runs(folders):
    for folder in folders:
        for f in sorted(Path(folder).glob("*/summary.json")):
            s = json.loads(f.read_text())
            if s.get("ucs_pa") is None or not s.get("peak_reached", True):
                continue
            p = s["params"]
            rho = sum(g["density"] for g in p["grains"].values()) / len(p["grains"])
            rate, ds = p["ucs"]["strain_rate"], p["numerics"]["density_scale"]
            c = math.sqrt(s["young_pa"] / (rho * ds))
            crossings = (s["peak_axial_strain"] / rate) / (p["specimen"]["height"] / c)
            yield {"rate": rate, "ds": ds, "seed": s["seed"], "ucs": s["ucs_pa"] / 1e6, "young": s["young_pa"] / 1e9,
                   "ci": s["crack_initiation_pa"] / s["ucs_pa"], "cd": s["crack_damage_pa"] / s["ucs_pa"],
                   "steps": s.get("steps", s.get("dem_steps")), "cpu": s["cpu_s"], "crossings": crossings,
                   "verlet_q": p["numerics"].get("verlet_radius_quantile", 0.0), "run": f.parent.name}


def table(rows):
    groups = defaultdict(dict)
    for r in rows:
        groups[(r["verlet_q"], r["ds"], -r["rate"])][r["seed"]] = r
    out = ["| Verlet quantile | density scale | strain rate [1/s] | seeds | UCS per seed [MPa] | mean UCS [MPa] | "
           "paired change vs the next faster rate | E [GPa] | CI/UCS | CD/UCS | wave crossings to peak | "
           "DEM steps / run | CPU [s] / run |", "|" + "---|" * 13]
    previous = {}
    for (vq, ds, neg_rate), by_seed in sorted(groups.items()):
        seeds = sorted(by_seed)
        rs = [by_seed[k] for k in seeds]
        mean = lambda key: sum(r[key] for r in rs) / len(rs)   # noqa: E731
        change = ""
        before = previous.get((vq, ds))
        if before:
            common = sorted(set(seeds) & set(before))
            if common:
                d = [by_seed[k]["ucs"] / before[k]["ucs"] - 1 for k in common]
                change = f"{100 * sum(d) / len(d):+.1f} % (seeds {', '.join(map(str, common))}: " + \
                         ", ".join(f"{100 * x:+.1f}" for x in d) + ")"
        previous[(vq, ds)] = by_seed
        per_seed = " / ".join(f"{r['ucs']:.1f}" for r in rs)
        out.append(f"| {vq:g} | {ds:g} | {-neg_rate:g} | {', '.join(map(str, seeds))} | "
                   f"{per_seed} | {mean('ucs'):.1f} | {change} | {mean('young'):.1f} | "
                   f"{mean('ci'):.2f} | {mean('cd'):.2f} | {mean('crossings'):.0f} | {mean('steps'):,.0f} | "
                   f"{mean('cpu'):,.0f} |")
    return "\n".join(out)


def write_csv(rows, path):
    """One line per run, units in the column names."""
    import csv
    names = {"rate": "strain_rate_per_s", "ds": "density_scale", "seed": "seed", "ucs": "ucs_mpa",
             "young": "young_gpa", "ci": "ci_over_ucs", "cd": "cd_over_ucs", "steps": "dem_steps", "cpu": "cpu_s",
             "crossings": "wave_crossings_to_peak", "verlet_q": "verlet_radius_quantile", "run": "run"}
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(names.values())
        for r in rows:
            w.writerow([r[k] for k in names])


if __name__ == "__main__":
    args = sys.argv[1:]
    csv_path = None
    if "--csv" in args:
        i = args.index("--csv")
        csv_path = args[i + 1]
        del args[i:i + 2]
    rows = list(runs(args))
    if csv_path:
        write_csv(rows, csv_path)
    print(table(rows))
