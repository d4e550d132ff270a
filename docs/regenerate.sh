#!/bin/bash
# Regenerates the study numbers and figures quoted in docs/studies/ and docs/ from the code you have.
#   bash docs/regenerate.sh list          # the targets, what each feeds and its cost
#   bash docs/regenerate.sh TARGET ...    # run targets (results/ folders, then their analysis)
#   bash docs/regenerate.sh all           # everything: about a day on this 2-core machine
# Costs are wall times measured on this machine (2 cores, yade-batch -j 2 unless said); the docs/studies
# page each target feeds says which of its numbers came from which run. Every run folder records
# its code version (run.json), and `analyze` warns when a study mixes versions.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=/usr/bin/python3
export OMP_NUM_THREADS=1
batch() {  # batch TABLE SCRIPT STUDY
  mkdir -p "results/$3"
  yade-batch -j 2 --log "results/$3/%.log" "$1" "yade_scripts/$2"
}

declare -A WHAT=(
  [elastic]="docs/studies/deformable_grains.md static tables, docs/elastic_reference.md (static solves, no YADE): about 5 min on one core"
  [bench]="docs/studies/benchmark.md, docs/bench.json: about 6 min on one core"
  [calibration]="docs/studies/ucs_calibration.md calibration, params/calibration.toml (rigid cells, 5 seeds x 2 rounds): about 35 min"
  [calibration_check]="docs/studies/ucs_calibration.md, calibration and resolution paper-size rows: the shipped factors measured again (params/calibration_check_ldb.table): about 25 min on one core"
  [resolution]="docs/studies/ucs_calibration.md resolution (params/resolution_small.table): about 20 min"
  [fem_ucs]="docs/studies/deformable_grains.md fem UCS table (params/fem_ucs_small.table): about 30 min"
  [fem_creep]="docs/studies/deformable_grains.md fem creep table and the fem beta1 (params/fem_creep_small.table): about 20 min on 2 cores"
  [lifetime_small]="docs/studies/lifetime.md 10 x 20 mm (params/lifetime_small*.table, lifetime_spread_small): about 1 h"
  [lifetime_ldb]="docs/studies/lifetime.md paper size, docs/studies/creep.md 160 MPa table, beta1 calibration (params/lifetime_ldb*.table): 5-8 h"
  [creep_numerics]="docs/studies/creep.md creep numerics (params/creep_numerics_small.table): about 1 h"
  [brazilian]="docs/studies/brazilian.md (params/brazilian_ldb.table, studies/brazilian_study.sh)"
  [accuracy_cost]="docs/studies/accuracy_cost.md, docs/accuracy_cost.{csv,md}, docs/figures/accuracy_cost.png (params/accuracy_cost.toml): about 70 min on 2 cores"
  [accuracy_cost_paper_size]="docs/studies/accuracy_cost.md paper-size spot checks (params/accuracy_cost_paper_size.table): about 1 h on 2 cores"
  [step_floor]="docs/studies/accuracy_cost.md per-cell mass scaling: docs/step_floor_steps.{csv,md} (scene builds and 200-step ramps, rigid and fem cells, 10 x 20 mm and paper size): about 6 min on one core"
  [threshold]="docs/studies/creep.md long-term strength table (params/threshold_study_tiny.table, 4 x 8 mm): about 5 min on 2 cores"
  [regularisation]="docs/studies/regularisation.md: critical DEM step of rigid and fem cells against specimen.min_edge_fraction (docs/regularisation_steps.csv, no YADE: about 15 min on one core) and paired UCS/E of fem cells with the intact-joint guard at 0-10 %, without it and of rigid cells at 0, 2, 5 % (docs/regularisation_ucs.csv, 33 UCS runs: 38 CPU min measured on 2 shared cores) and the static contact-stress tails of fem cells (docs/regularisation_tails.csv, 30 static solves, no YADE: 80 s)"
  [lab_bands]="docs/studies/lab_bands.md: grain-size CV against lloyd_iterations (no YADE, seconds) and paired fem UCS (5 x 10 mm) and Brazilian (10 mm disc) runs per lever on the contacts: about 10 min on one core"
  [paper_fem]="docs/studies/paper_fem.md tables: docs/studies/paper_fem/ucs_runs.csv (params/paper_fem_ucs.table, about 6 CPU h) and docs/studies/paper_fem/runs.csv (params/paper_fem_creep.table, 9 paper-size fem creep runs: more than 1.2 CPU h each, not all measured)"
  [lab_calibration]="docs/studies/lab_calibration.md: the joint calibration's design (15 points x 2 seeds of a 10 x 20 mm fem UCS and a 10 mm disc, about 90 CPU s each), its fit and the candidate on seeds 1-3: about 50 min on one core"
  [lab_creep]="docs/studies/lab_calibration.md creep of the preset and of the corner candidate, and the preset's rate check (params/ldb_lab_creep.table, lab_corner_creep.table, ldb_lab_rate_ucs.table; 10 x 20 mm fem: 47-520 CPU s per creep row, the 0.4 rows the dearest): about 1.5 h on one core"
  [fem_mesh]="docs/studies/paper_fem.md mesh resolution: 10 x 20 mm fem UCS at 2 and 3 bonds per face (the 10 x 20 mm rows of params/fem_size_mesh_ucs.table: 94-164 and about 500 CPU s) and the creep rows at 0.7 and 0.85 of each run's own UCS that studies/fem_size_mesh.py writes from them"
  [lab_disc_size]="docs/studies/lab_calibration.md disc-size probe: fem Brazilian discs of 10, 20 and 31.7 mm (params/lab_disc_size.table, 14 discs: 43-57 CPU s at 10 mm, 6-12 CPU min at 20 mm, 31.7 mm not measured)"
  [paper_static]="docs/studies/paper_static.md creep rows and docs/studies/paper_static/runs.csv, report/ (params/paper_static_inertial_creep.table: 20 paper-size fem creep rows on the static engine, 5.5-15 CPU min each: about 3.5 h on one core)"
  [lifetime_sensitivity]="docs/studies/paper_static.md lifetime sensitivity, docs/studies/paper_static/lifetime_sensitivity.{csv,md} (params/lifetime_sensitivity_static_small.table and lifetime_mesh_static_small.table: 40 rows of 10 x 20 mm fem creep on the static engine, 10 s to 3 min each: about 35 min on one core)"
  [model_convergence]="docs/studies/model_convergence.md rows and docs/studies/model_convergence/ucs_runs.csv (params/model_convergence_ucs.table: 10 x 20 mm fem UCS on the static engine at 8-24 bonds per face and 1-2 radial rings, 10-40 CPU min each, one core)"
  [confined]="docs/studies/confined.md (params/confined_*_small.table): about 20 min UCS + 40 min creep on one core"
)

run_target() {
  case "$1" in
    elastic) bash studies/elastic_study.sh
             cp results/elastic_study/w31.7e-3_s2_mesh_k2_r1_cells/contact_stress_histogram.png docs/figures/elastic_contact_stress_ldb_seed2.png ;;
    bench) $PY -m grainfrac_yade bench ;;
    calibration) $PY -m grainfrac_yade calibrate --seeds 1 2 3 4 5 --rounds 2 --jobs 2 ;;
    calibration_check) batch params/calibration_check_ldb.table ucs.py calibration_check
                       $PY -m grainfrac_yade analyze-ucs results/calibration_check ;;
    resolution) batch params/resolution_small.table ucs.py resolution
                $PY -m grainfrac_yade analyze-ucs results/resolution ;;
    fem_ucs) batch params/fem_ucs_small.table ucs.py fem_ucs
             $PY -m grainfrac_yade analyze-ucs results/fem_ucs ;;
    fem_creep) batch params/fem_creep_small.table creep.py fem_creep
               $PY -m grainfrac_yade analyze results/fem_creep
               $PY -m grainfrac_yade calibrate-beta1 results/fem_creep --out params/presets/fem_stress_corrosion_calibrated.toml ;;
    lifetime_small) batch params/lifetime_small.table creep.py lifetime_small
                    batch params/lifetime_small_beta2x3.table creep.py lifetime_small_beta2x3
                    batch params/lifetime_spread_small.table creep.py lifetime_spread_small
                    $PY -m grainfrac_yade analyze results/lifetime_small ;;
    lifetime_ldb) batch params/lifetime_ldb.table creep.py lifetime_ldb
                  batch params/lifetime_ldb_beta2x3.table creep.py lifetime_ldb_beta2x3
                  $PY -m grainfrac_yade analyze results/lifetime_ldb
                  $PY -m grainfrac_yade analyze results/lifetime_ldb_beta2x3
                  cp results/lifetime_ldb_beta2x3/report/lifetime.png docs/figures/lifetime_ldb_beta2x3_seed1.png
                  $PY -m grainfrac_yade calibrate-beta1 results/lifetime_ldb ;;
    creep_numerics) batch params/creep_numerics_small.table creep.py creep_numerics ;;
    brazilian) if [ -f studies/brazilian_study.sh ]; then bash studies/brazilian_study.sh
               else batch params/brazilian_ldb.table brazilian.py brazilian_ldb; fi ;;
    confined) batch params/confined_ucs_small.table ucs.py confined_ucs
              $PY -m grainfrac_yade analyze-ucs results/confined_ucs
              batch params/confined_creep_small.table creep.py confined_creep
              batch params/confined_creep_normalised_small.table creep.py confined_creep_normalised
              $PY -m grainfrac_yade analyze results/confined_creep results/confined_creep_normalised \
                  --out results/confined_creep_both ;;
    accuracy_cost) $PY -m grainfrac_yade accuracy-cost --jobs 2
                   cp results/accuracy_cost/accuracy_cost.csv results/accuracy_cost/accuracy_cost.md docs/
                   cp results/accuracy_cost/accuracy_cost.png docs/figures/accuracy_cost.png ;;
    step_floor) $PY -m studies.step_floor_steps ;;
    lab_bands) $PY -m studies.lab_bands grain-size
               $PY -m studies.lab_bands levers --params params/presets/fem_coarse.toml --out results/lab_bands ;;
    regularisation) $PY -m studies.regularisation_steps
                    $PY -m studies.regularisation_ucs
                    $PY -m studies.regularisation_tails ;;
    threshold) for s in 1 2; do $PY -m grainfrac_yade ucs --width 4e-3 --height 8e-3 --seed $s \
                   --out results/threshold_tiny/ucs_seed$s --overwrite; done
               batch params/threshold_study_tiny.table creep.py threshold_tiny
               $PY -m grainfrac_yade analyze results/threshold_tiny
               cp results/threshold_tiny/report/lifetime.png docs/figures/threshold_tiny_lifetime.png ;;
    paper_fem) batch params/paper_fem_ucs.table ucs.py paper_fem_ucs
               $PY -m grainfrac_yade analyze-ucs results/paper_fem_ucs
               cp results/paper_fem_ucs/report/ucs_runs.csv docs/studies/paper_fem/ucs_runs.csv
               batch params/paper_fem_creep.table creep.py paper_fem_creep
               $PY -m grainfrac_yade analyze results/paper_fem_creep
               cp results/paper_fem_creep/report/runs.csv docs/studies/paper_fem/runs.csv ;;
    lab_calibration) $PY -m studies.lab_calibration design --n 14 --seeds 1 2 --csv docs/studies/lab_calibration_design.csv
                     $PY -m studies.lab_calibration fit --csv docs/studies/lab_calibration_design.csv \
                         --json docs/studies/lab_calibration_fit_square.json --square inverse_weibull_modulus
                     $PY -m studies.lab_calibration verify --json docs/studies/lab_calibration_fit_square.json \
                         --seeds 1 2 3 --csv docs/studies/lab_calibration_verify_square.csv
                     $PY -m studies.lab_calibration best --csv docs/studies/lab_calibration_design.csv \
                         --json docs/studies/lab_calibration_best.json --verify-csv docs/studies/lab_calibration_verify_best.csv
                     $PY -m studies.lab_calibration verify --json docs/studies/lab_calibration_best.json \
                         --seeds 1 2 3 --csv docs/studies/lab_calibration_verify_best.csv
                     $PY -m studies.lab_calibration preset --json docs/studies/lab_calibration_best.json \
                         --csv docs/studies/lab_calibration_verify_best.csv --design-csv docs/studies/lab_calibration_design.csv ;;
    lab_creep) $PY -m grainfrac_yade batch params/ldb_lab_creep.table --jobs 1
               $PY -m grainfrac_yade batch params/lab_corner_creep.table --jobs 1
               $PY -m grainfrac_yade batch params/ldb_lab_rate_ucs.table --jobs 1 --test ucs
               $PY -m grainfrac_yade analyze results/ldb_lab_creep
               $PY -m grainfrac_yade analyze results/lab_corner_creep
               $PY -m grainfrac_yade analyze-ucs results/ldb_lab_rate_ucs ;;
    fem_mesh) mkdir -p results && grep -v "'w20_" params/fem_size_mesh_ucs.table > results/fem_size_mesh_ucs_10mm.table
              $PY -m grainfrac_yade batch results/fem_size_mesh_ucs_10mm.table --jobs 1 --test ucs
              $PY -m grainfrac_yade analyze-ucs results/fem_size_mesh_ucs
              $PY -m studies.fem_size_mesh results/fem_size_mesh_ucs --out results/fem_mesh_creep.table
              $PY -m grainfrac_yade batch results/fem_mesh_creep.table --jobs 1
              $PY -m grainfrac_yade analyze results/fem_mesh_creep ;;
    lab_disc_size) batch params/lab_disc_size.table brazilian.py lab_disc_size
                   $PY -m studies.brazilian_table results/lab_disc_size ;;
    accuracy_cost_paper_size) batch params/accuracy_cost_paper_size.table creep.py accuracy_cost_paper_size
                              $PY -m grainfrac_yade analyze results/accuracy_cost_paper_size ;;
    paper_static) $PY -m grainfrac_yade batch params/paper_static_inertial_creep.table --jobs 1
                  $PY -m grainfrac_yade analyze results/paper_static_inertial --out docs/studies/paper_static/report
                  cp docs/studies/paper_static/report/runs.csv docs/studies/paper_static/runs.csv ;;
    lifetime_sensitivity) $PY -m grainfrac_yade batch params/lifetime_sensitivity_static_small.table --jobs 1
                          $PY -m grainfrac_yade batch params/lifetime_mesh_static_small.table --jobs 1
                          $PY -m studies.lifetime_sensitivity results/lifetime_sensitivity_static \
                              --out docs/studies/paper_static/lifetime_sensitivity ;;
    model_convergence) $PY -m grainfrac_yade batch params/model_convergence_ucs.table --test ucs --jobs 1
                       $PY -m studies.model_convergence results/model_convergence/* \
                           --out docs/studies/model_convergence/ucs_runs.csv ;;
    *) echo "regenerate.sh: unknown target '$1'; fix: one of: list all ${!WHAT[*]}" >&2; exit 2 ;;
  esac
}

if [ $# -eq 0 ] || [ "$1" = list ]; then
  for t in "${!WHAT[@]}"; do printf '%-16s %s\n' "$t" "${WHAT[$t]}"; done | sort
  exit 0
fi
targets=("$@")
[ "$1" = all ] && targets=(elastic bench calibration calibration_check resolution fem_ucs fem_creep lifetime_small
                           lifetime_ldb creep_numerics brazilian confined accuracy_cost accuracy_cost_paper_size step_floor threshold
                           regularisation lab_bands lab_calibration lab_creep lab_disc_size fem_mesh paper_fem paper_static
                           lifetime_sensitivity model_convergence)
for t in "${targets[@]}"; do
  echo "== $t: ${WHAT[$t]:-?}"
  start=$(date +%s)
  run_target "$t"
  echo "== $t done in $(( $(date +%s) - start )) s"
done
