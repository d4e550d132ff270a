#!/bin/bash
# elastic reference table: 10x20 mm seeds 1,3,5 and paper size seed 2, Tables 1 and 2 as printed
# Regenerates docs/elastic_reference.md's table (about 2 min on one core): bash docs/elastic_study.sh
cd "$(dirname "$0")/.."
out=results/elastic_study; mkdir -p $out
for spec in "10e-3 20e-3 1" "10e-3 20e-3 3" "10e-3 20e-3 5" "31.7e-3 63.4e-3 2"; do
 set -- $spec
 for m in "rigid 2 corners 1 cells" "deformable 2 corners 1 cells" "deformable 2 corners 1 wall" "deformable 2 corners 4 cells" "deformable 3 corners 2 cells" "deformable 5 corners 4 cells" "lattice 2 corners 1 cells" "lattice 3 corners 1 cells"; do
  set -- $spec $m
  /usr/bin/python3 -m grainfrac_yade elastic --width $1 --height $2 --seed $3 --grains $4 --nodes-per-face $5 --contacts $6 --rings $7 --platens $8 \
    --set calibration.stiffness_scale=1 --set resolution.grain_model=deformable --set resolution.nodes_per_face=$5 \
    --out $out/w$1_s$3_$4_k$5_r$7_$8 --overwrite > /dev/null
 done
done
