#!/bin/bash
# Brazilian disc study: the calibrated model's tensile strength and the levers a grain-based model has.
# One YADE run at a time, OMP_NUM_THREADS=1; a finished run (summary.json) is skipped, so rerunning resumes.
#   bash studies/brazilian_study.sh          # about 70 min on one core of this shared machine
# Writes results/brazilian_study/<variant>/seed<N>/ and docs/brazilian_study.md (table of every variant).
# The paper-width discs (31.7 mm, seeds 1-5) come from the yade-batch table params/brazilian_ldb.table
# (results/brazilian_ldb/), run first here if missing.
cd "$(dirname "$0")/.."
export OMP_NUM_THREADS=1
out=results/brazilian_study; mkdir -p $out results/brazilian_ldb
py=/usr/bin/python3
# J^T of Table 2's pure-mineral rows [Pa] (params/ldb_granite.toml): biotite, K-feldspar, quartz, plagioclase
tensile() {  # --set overrides multiplying every row's J^T by $1 (what `brazilian --tensile-scale` does)
  $py -c "
f = $1
for m, jt in (('biotite', 19e6), ('k_feldspar', 23e6), ('quartz', 26e6), ('plagioclase', 24e6)):
    print(f'--set contacts.{m}/{m}.tensile_strength={jt * f:.6g}', end=' ')"
}
resfric="--set contacts.biotite/biotite.residual_friction_ratio=1 --set contacts.k_feldspar/k_feldspar.residual_friction_ratio=1 --set contacts.quartz/quartz.residual_friction_ratio=1 --set contacts.plagioclase/plagioclase.residual_friction_ratio=1"
run() {  # run <command> <variant> <seed> <options...>
  local cmd=$1 name=$2 seed=$3; shift 3
  [ -f $out/$name/seed$seed/summary.json ] && return
  $py -m grainfrac_yade $cmd --seed $seed --out $out/$name/seed$seed --overwrite "$@" | tail -1
}
ls results/brazilian_ldb/seed5/summary.json > /dev/null 2>&1 || \
  { mkdir -p results/brazilian_ldb; yade-batch -j 1 --log 'results/brazilian_ldb/%.log' params/brazilian_ldb.table yade_scripts/brazilian.py > /dev/null; }
D15="--diameter 15e-3"
for s in 1 2 3 4 5; do run brazilian d15_base $s $D15; done
for s in 1 2 3; do
  run brazilian d15_rate_half $s $D15 --set brazilian.strain_rate=0.25
  run brazilian d15_arc20 $s $D15 --set brazilian.loading_arc_deg=20
  run brazilian d15_jaws_free $s $D15 --set brazilian.platen_lateral=free
  run brazilian d15_tensile0.5 $s $D15 --tensile-scale 0.5
  run brazilian d15_tensile0.25 $s $D15 --tensile-scale 0.25
  run brazilian d15_resfric1 $s $D15 $resfric
  run brazilian d15_spc8 $s $D15 --spheres-per-cell 8
  run ucs ucs10x20_base $s --width 10e-3 --height 20e-3
  run ucs ucs10x20_tensile0.5 $s --width 10e-3 --height 20e-3 $(tensile 0.5)
  run ucs ucs10x20_tensile0.25 $s --width 10e-3 --height 20e-3 $(tensile 0.25)
  run ucs ucs10x20_resfric1 $s --width 10e-3 --height 20e-3 $resfric
done
$py -m studies.brazilian_levers $out     # slits, strength scatter, no rotation, J^T x 0.1, UCS of 8 spheres per cell
# the most effective lever pair on one paper-width disc (about 5 min)
[ -f results/brazilian_study_paper/d31.7_spc8_tensile0.25/seed1/summary.json ] || \
  $py -m grainfrac_yade brazilian --seed 1 --spheres-per-cell 8 --tensile-scale 0.25 --overwrite \
    --out results/brazilian_study_paper/d31.7_spc8_tensile0.25/seed1 | tail -1
$py -m studies.brazilian_table results/brazilian_ldb $out results/brazilian_study_paper > docs/brazilian_study.md
cat docs/brazilian_study.md
