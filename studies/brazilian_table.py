"""Markdown tables of the Brazilian disc study (studies/brazilian_study.sh): every variant, every seed.

    python3 -m studies.brazilian_table results/brazilian_ldb results/brazilian_study > docs/brazilian_study.md

A folder holding seed*/summary.json is one variant (results/brazilian_ldb: the paper-width disc);
a folder of such folders holds several (results/brazilian_study/<variant>/).  Brazilian and UCS
variants are tabulated apart; levers are compared with their baseline on the same seeds.
"""
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from grainfrac_yade.api import split_peak_index

LAB_TENSILE, LAB_UCS = 9.0e6, 200e6   # shared/reference/ldb_lab_properties.csv


def variants(roots):
    out = {}
    for root in map(Path, roots):
        for folder in sorted({p.parent.parent for p in root.rglob("seed*/summary.json")}):
            runs = {}
            for f in sorted(folder.glob("seed*/summary.json")):
                s = json.loads(f.read_text())
                if "tensile_strength_pa" in s and "split_found" not in s:   # summary of older code: from history
                    h = pd.read_csv(f.parent / "history.csv")
                    ip, split = split_peak_index(h["load_n"].values, h["broken_total"].values)
                    s["split_found"] = split is not None
                    s["max_tensile_stress_pa"] = float(h["tensile_stress_pa"].max())
                runs[int(s["seed"])] = s
            out["d31.7_base" if folder.name == "brazilian_ldb" else folder.name] = runs
    return out


def fmt(values, scale, digits=1):
    v = np.asarray(values, float) / scale
    sd = f" +- {v.std(ddof=1):.{digits}f}" if len(v) > 1 else ""
    return f"{v.mean():.{digits}f}{sd}"


def main(roots):
    vs = variants(roots)
    bz = {k: v for k, v in vs.items() if all("tensile_strength_pa" in s for s in v.values())}
    ucs = {k: v for k, v in vs.items() if all("ucs_pa" in s for s in v.values())}
    print("# Brazilian disc study (`bash studies/brazilian_study.sh`)\n")
    print("Calibrated parameters (shipped defaults: rigid cells, 1 sphere per cell, params/calibration.toml) "
          "unless the variant says; 1 mm grains; jaws over 10 deg, fixed across the diameter; "
          "sigma_t = 2 P / (pi D t). Central share: broken bonds within |x - x_c| <= D/6 (0.42 of the area) "
          "at the end of the test / at the failure load (the peak before the split: the first drop below 0.8 x "
          "the peak with new breaks). Later max: a higher load after the split (halves crushed), not the "
          "strength. Split / post-peak end: runs whose load dropped below 0.8 x its peak with new breaks / "
          "below brazilian.stop_load_ratio = 0.5 (else the test ended at 1 % diametral strain: its failure "
          "load is a lower bound). First cracks r/R: median distance from the centre of the "
          "first 5 % of the broken bonds. Wall times on one core of a shared, loaded machine.\n")
    print("## Brazilian tests\n")
    print("| variant | n | sigma_t [MPa] | per seed [MPa] | split / post-peak end | later max / failure load "
          "| central share end / peak | first cracks r/R | broken at end | DEM steps | wall [s] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name, runs in bz.items():
        r = list(runs.values())
        ok = [s for s in r if s.get("tensile_strength_pa")]
        each = ", ".join("%.2f" % (s["tensile_strength_pa"] / 1e6) for s in ok)
        later = max(s.get("max_tensile_stress_pa", s["tensile_strength_pa"]) / s["tensile_strength_pa"] for s in ok)
        print(f"| {name} | {len(ok)} | {fmt([s['tensile_strength_pa'] for s in ok], 1e6, 2)} | {each} "
              f"| {sum(bool(s.get('split_found', True)) for s in ok)} / {sum(bool(s['peak_reached']) for s in ok)} "
              f"| {'-' if later < 1.0005 else f'up to {later:.2f}'} "
              f"| {np.mean([s['central_band_fraction'] for s in ok]):.2f} / "
              f"{np.mean([s['central_band_fraction_at_peak'] for s in ok]):.2f} "
              f"| {np.median([s['first_cracks_radius_ratio'] for s in ok]):.2f} "
              f"| {np.mean([s['broken_total'] for s in ok]):.0f} | {np.mean([s.get('steps', s.get('dem_steps')) for s in ok]):.0f} "
              f"| {np.mean([s['wall_s'] for s in ok]):.0f} |")
    if "d31.7_base" in bz:
        ok = [s for s in bz["d31.7_base"].values() if s.get("tensile_strength_pa")]
        sig = np.mean([s["tensile_strength_pa"] for s in ok])
        ref = ok[0]["reference_ucs_pa"]
        print(f"\nPaper-width disc: sigma_t {sig / 1e6:.2f} MPa = {sig / LAB_TENSILE:.2f} x the lab's 9 MPa; "
              f"calibrated UCS {ref / 1e6:.1f} MPa / sigma_t = {ref / sig:.1f} (lab: {LAB_UCS / 1e6:.0f} / 9 = "
              f"{LAB_UCS / LAB_TENSILE:.1f}; paper's UDEC UCS 234.5 / 9 = {234.5e6 / LAB_TENSILE:.1f}).")
    if ucs:
        print("\n## UCS tests\n")
        print("| variant | n | UCS [MPa] | per seed [MPa] | E [GPa] | wall [s] |")
        print("|---|---|---|---|---|---|")
        for name, runs in ucs.items():
            r = [s for s in runs.values() if s.get("ucs_pa")]
            each = ", ".join("%.1f" % (s["ucs_pa"] / 1e6) for s in r)
            print(f"| {name} | {len(r)} | {fmt([s['ucs_pa'] for s in r], 1e6)} | {each} "
                  f"| {fmt([s['young_pa'] for s in r], 1e9)} "
                  f"| {np.mean([s['wall_s'] for s in r]):.0f} |")
    base_b, base_u = bz.get("d15_base"), ucs.get("ucs10x20_base")
    if base_b:
        print("\n## Levers against the baseline, same seeds (15 mm discs; UCS of 10 x 20 mm)\n")
        print("| lever | seeds | sigma_t / baseline | UCS / baseline | UCS/sigma_t (small specimens) |")
        print("|---|---|---|---|---|")
        for name, runs in bz.items():
            if not name.startswith("d15_") or name == "d15_base":
                continue
            seeds = sorted(set(runs) & set(base_b))
            st = np.mean([runs[k]["tensile_strength_pa"] for k in seeds])
            st0 = np.mean([base_b[k]["tensile_strength_pa"] for k in seeds])
            lever = name[4:]
            u_runs = ucs.get(f"ucs10x20_{lever}")
            u_txt, ratio = "-", "-"
            if u_runs and base_u:
                us = sorted(set(u_runs) & set(base_u) & set(seeds))
                u, u0 = (np.mean([x[k]["ucs_pa"] for k in us]) for x in (u_runs, base_u))
                u_txt, ratio = f"{u / u0:.3f}", f"{u / st:.1f} (baseline {u0 / st0:.1f})"
            print(f"| {lever} | {','.join(map(str, seeds))} | {st / st0:.3f} | {u_txt} | {ratio} |")


if __name__ == "__main__":
    main(sys.argv[1:])
