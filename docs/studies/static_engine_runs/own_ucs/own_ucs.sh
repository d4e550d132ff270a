#!/bin/bash
# Lifetimes at 0.7 and 0.85 of each engine's own UCS (fem as printed, 10 x 20 mm, seeds 1-3).
# Own UCS: YADE at 0.15 /s (docs/studies/static_validation.md: 257.8 / 334.0 / 287.2 MPa, damping 0.2);
# hybrid at cascade limit 1 (docs/studies/static_engine.md, 79b4d9f: 267.9 / 321.1 / 287.4 MPa).
cd "$(git rev-parse --show-toplevel)"; mkdir -p results/own_ucs
declare -A Y=([1]=257.8 [2]=334.0 [3]=287.2) H=([1]=267.9 [2]=321.1 [3]=287.4)
for R in 0.85 0.7; do for S in 1 2 3; do
  for E in hybrid yade; do
    if [ $E = hybrid ]; then U=${H[$S]}; X="--set numerics.handover_cascade_bonds=1"; else U=${Y[$S]}; X=""; fi
    ST=$(python3 -c "print(round($R*$U,2))")
    D=results/own_ucs/own_${E}_r${R}_s$S
    [ -f $D/summary.json ] && continue
    OMP_NUM_THREADS=1 /usr/bin/python3 -m grainfrac_yade creep --engine $E --params params/presets/fem_coarse.toml --stress $ST --width 10e-3 --height 20e-3 --seed $S $X --out $D > $D.log 2>&1
  done
done; done
