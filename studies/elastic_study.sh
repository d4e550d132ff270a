#!/bin/bash
# elastic reference table: 10x20 mm seeds 1,3,5 and paper size seed 2, Tables 1 and 2 as printed
# Regenerates docs/elastic_reference.md's table (about 2 min on one core): bash studies/elastic_study.sh
cd "$(dirname "$0")/.."
out=results/elastic_study; mkdir -p $out
for spec in "10e-3 20e-3 1" "10e-3 20e-3 3" "10e-3 20e-3 5" "31.7e-3 63.4e-3 2"; do
 set -- $spec
 for m in "rigid 2 corners 1 cells" "mesh 2 corners 1 cells" "mesh 2 corners 1 wall" "mesh 2 corners 4 cells" "mesh 3 corners 2 cells" "mesh 5 corners 4 cells" "fem 2 corners 1 cells" "fem 3 corners 1 cells" "fem 4 corners 1 cells" "mesh 4 corners 1 cells"; do
  set -- $spec $m
  /usr/bin/python3 -m grainfrac_yade elastic --width $1 --height $2 --seed $3 --grains $4 --nodes-per-face $5 --contacts $6 --rings $7 --platens $8 \
    --set calibration.stiffness_scale=1 $( [ "$4" = fem ] && echo "--set resolution.contact_inset=0.001" ) \
    --out $out/w$1_s$3_$4_k$5_r$7_$8 --overwrite > /dev/null
 done
done
/usr/bin/python3 - > docs/elastic_reference.md <<'PY'
import glob, json, os
print("# Static elastic reference: every run of `bash studies/elastic_study.sh`\n")
print("Tables 1 and 2 as printed (stiffness factor 1), uniaxial compression between smooth platens.")
print("Run name: specimen width, seed, model, contact nodes per face (k), radial rings (r), platens.")
print("Ratios are contact stress over the applied stress; `per face` sums the forces of a face's")
print("contacts over the face.  `mesh` is the triangle-mesh reference (the paper's deformable blocks).")
print("`fem` is the YADE finite-element cells (params/presets/fem_coarse.toml, contact inset 0.001) solved")
print("statically (the YADE scene gives the same forces within 1e-8, tests/test_fem_scene.py).\n")
print("| run | E [GPa] | nu | shear p50 | p99 | max | per face p99 | per face max | tension p99 | tension max |")
print("|---|---|---|---|---|---|---|---|---|---|")
for f in sorted(glob.glob("results/elastic_study/*/summary.json")):
    d = json.load(open(f))
    print(f"| {os.path.basename(os.path.dirname(f))} | {d['young_pa'] / 1e9:.1f} | {d['poisson']:.3f} | "
          + " | ".join(f"{d[k]:.2f}" for k in ("shear_stress_ratio_p50", "shear_stress_ratio_p99",
                                               "shear_stress_ratio_max", "face_shear_stress_ratio_p99",
                                               "face_shear_stress_ratio_max", "tension_stress_ratio_p99",
                                               "tension_stress_ratio_max")) + " |")
PY
