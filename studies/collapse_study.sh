#!/bin/bash
# Collapse criterion study: do creep lifetimes depend on how long a run waits for its final collapse?
# Old criterion (creep.collapse_strain_increment = 0): failure = no equilibrium within
# creep.max_relaxation_steps; new: the servo saturated closing while the axial strain grows by more
# than creep.collapse_strain_increment.  10 x 20 mm, calibrated defaults, event clock, seeds 1-3,
# ratios 0.7 and 0.85 of calibration.reference_ucs, creep-time limit 1e13 s (slow runs end by failure).
# One YADE run at a time, OMP_NUM_THREADS=1; a finished run (summary.json) is skipped, so rerunning
# resumes; the table is rewritten after every setting (partial results).
#   bash studies/collapse_study.sh            # about 1 h on one core of this shared machine
#   bash studies/collapse_study.sh table      # only the table, from the runs there are
# Writes results/collapse_study/<setting>/s<seed>_r<ratio>/ (10 x 20 mm), .../small4x8/ (the 4 x 8 mm
# reference runs of tests/test_reference_creep.py), .../paper_tiny/ and docs/collapse_study.md.
cd "$(dirname "$0")/.."
export OMP_NUM_THREADS=1
out=results/collapse_study; mkdir -p $out
py="nice -n 5 /usr/bin/python3"

table() {
$py - "$out" > docs/collapse_study.md <<'EOF'
"""Markdown tables of the collapse study: one row per run, relative lifetime change against the old
default (collapse off, max_relaxation_steps 30000) on the same seed and ratio; per knob the largest
|relative change|; the paper-clock check."""
import json, re, sys
from pathlib import Path
import pandas as pd

root = Path(sys.argv[1])
REF = "off_m30000"
FINDINGS = """## Findings

- Old criterion alone: on these 10 x 20 mm runs lifetimes do not depend on the wait. max_relaxation_steps
  10,000, 30,000 and 100,000 give bit-identical lifetimes (the longest relaxation that still reached
  equilibrium took 7,300 DEM steps); the final relaxation takes all of it (30,000 steps = 28-38 % of a run;
  100,000 runs end at the strain cap after 70,000-89,000 steps, 54-60 %).
- New criterion, 10 x 20 mm: collapse_strain_increment 1e-3 to 1e-2 leaves every lifetime bit-identical at
  max_relaxation_steps 10,000, 30,000 and 100,000 (0.00 %); 6e-4 ends one run (seed 2, 0.85) one event early
  (-2.1 %), 2e-4 three runs (up to -13.2 %): cascades that the specimen arrests also saturate the servo, for
  up to 8.8e-4 of axial strain (instrumented runs of seeds 1-8 at both ratios, not part of this script).
  Default 3e-3 (the middle of the decade 1e-3-1e-2): the final collapse takes 10,000-16,700 DEM steps
  (mean 14,825) instead of 30,000, 16 % of a run's DEM steps saved, and no longer depends on
  max_relaxation_steps (30,000 and 100,000 give the same runs).
- Smaller specimens: 4 x 8 mm seed 1 at 0.5 x 300 MPa (a reference run of tests/test_reference_creep.py)
  holds a cascade that saturates the servo for 14,400 DEM steps and 3.3e-3 of strain (the stress fell to
  0.49 of the target) and then recovers, after 16,300 steps.  There the default 3e-3 (and 1e-3) ends the run
  8 events early, lifetime -95.6 %; so does the old criterion with max_relaxation_steps 10,000: at this
  size the lifetime depends on the wait whichever criterion is used, unless it exceeds that cascade
  (1e-2, or max_relaxation_steps 30,000 and more, leave both runs unchanged).  The 2 % target over a
  decade is met at 10 x 20 mm, not across specimen sizes.  Instrumented runs (not part of this script) at
  4 x 8 and 6 x 12 mm, 0.7 and 0.85 of calibration.reference_ucs, seeds 1-4, arrested at most 1.2e-3 and
  7e-4 of saturated strain; in them and in the two 4 x 8 mm runs above the held stress of an arrested
  cascade never fell below 0.49 of the target, while 15 of 16 collapses took it to about 0 (one to 0.42).
- Shipped (`inc1e-3_ratio0.25_mN`): increment 1e-3 counted only while the held stress is below 0.25 of the
  target (creep.collapse_stress_ratio). 10 x 20 mm: every lifetime and event count bit-identical to the old
  default at max_relaxation_steps 30,000 and 100,000 (the runs are identical: none reaches the backstop);
  the final collapse takes 6,450-18,650 DEM steps instead of 30,000, 15-27 % of each run's DEM steps saved.
  The 4 x 8 mm seed 1 run keeps its 16 events and lifetime (tests/test_reference_creep.py). All rows above
  without `_ratio` were run with creep.collapse_stress_ratio = 1 (saturation alone).
"""


def reason_kind(reason):
    return ("collapse" if reason.startswith("collapse") else "no equilibrium" if reason.startswith("no equilibrium")
            else "strain cap" if reason.startswith("axial strain") else reason[:30])


def read(f):
    s = json.loads(f.read_text())
    h = pd.read_csv(f.parent / "history.csv")
    return s, h, reason_kind(s["failure_reason"] or s.get("end_reason", ""))


def frame(base):
    """One row per run folder base/<setting>/s<seed>_r<ratio>/, with the relative change against REF."""
    rows = []
    for f in sorted(base.glob("*/s*_r*/summary.json")):
        m = re.fullmatch(r"(off|inc([0-9.e-]+)(?:_ratio([0-9.]+))?)_m(\d+)", f.parent.parent.name)
        if not m:
            continue
        s, h, kind = read(f)
        rows.append({"setting": f.parent.parent.name, "increment": float(m.group(2) or 0),
                     "stress_ratio": float(m.group(3) or 1), "max_steps": int(m.group(4)), "seed": int(s["seed"]),
                     "ratio": round(float(s["driving_stress_ratio"]), 3), "lifetime_s": s["lifetime_s"],
                     "n_events": s["n_events"], "dem_steps": s.get("steps", s.get("dem_steps")),
                     "final_steps": int(h[("step" if "step" in h else "dem_steps")].iloc[-1] - h[("step" if "step" in h else "dem_steps")].iloc[-2]), "ended_by": kind,
                     "wall_s": s["wall_s"]})
    if not rows:
        return None
    d = pd.DataFrame(rows)
    ref = d[d.setting == REF].set_index(["seed", "ratio"])
    d["rel"] = [(r.lifetime_s / ref.lifetime_s[(r.seed, r.ratio)] - 1) if (r.seed, r.ratio) in ref.index
                else float("nan") for r in d.itertuples()]
    d["saved"] = [(ref.dem_steps[(r.seed, r.ratio)] - r.dem_steps) if (r.seed, r.ratio) in ref.index
                  else float("nan") for r in d.itertuples()]
    return d.sort_values(["stress_ratio", "increment", "max_steps", "ratio", "seed"])


def knob(d, name, sel):
    x = d[sel]
    if x.setting.nunique() < 2:
        return
    settings = ", ".join(sorted(x.setting.unique(), key=lambda s: (len(s), s)))
    print(f"| {name} | {settings} | {len(x)} | {x.rel.abs().max():.2%} | "
          f"{x.final_steps.mean():,.0f} ({x.final_steps.min():,}-{x.final_steps.max():,}) |")


def tables(d, title):
    every = d
    print(f"## {title}: largest |relative lifetime change| per knob\n")
    print("| knob (10x range) | settings | runs | max abs rel. change vs off_m30000 | "
          "final-collapse DEM steps, mean (min-max) |")
    print("|---|---|---|---|---|")
    knob(d, "max_relaxation_steps, collapse off", d.increment == 0)
    for r in sorted(d.loc[d.stress_ratio < 1, "stress_ratio"].unique()):
        for i in sorted(d.loc[d.stress_ratio == r, "increment"].unique()):
            knob(d, f"max_relaxation_steps at collapse_strain_increment {i:g}, collapse_stress_ratio {r:g}",
                 (d.increment == i) & (d.stress_ratio == r))
    d = d[d.stress_ratio == 1]
    incs = sorted(d.loc[d.increment > 0, "increment"].unique())
    for m in sorted(d.max_steps.unique()):
        incs_m = sorted(d.loc[(d.increment > 0) & (d.max_steps == m), "increment"].unique())
        for lo in incs_m:
            dec = [i for i in incs_m if lo <= i <= 10 * lo * (1 + 1e-9)]
            if dec[-1] >= 9.99 * lo:
                knob(d, f"collapse_strain_increment {lo:g}-{dec[-1]:g} at max_relaxation_steps {m}",
                     d.increment.isin(dec) & (d.max_steps == m))
    for i in incs:
        knob(d, f"max_relaxation_steps at collapse_strain_increment {i:g}", d.increment == i)
    print(f"\n## {title}: every run\n")
    print("| setting | seed | ratio | lifetime [s] | rel. change | events | DEM steps | DEM steps saved vs off_m30000 | "
          "final-collapse DEM steps | ended by | wall [s] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in every.itertuples():
        rel = "" if pd.isna(r.rel) else f"{r.rel:+.2%}"
        saved = "" if pd.isna(r.saved) else f"{int(r.saved):,}"
        print(f"| {r.setting} | {r.seed} | {r.ratio} | {r.lifetime_s:.6g} | {rel} | {r.n_events} | {r.dem_steps:,} | "
              f"{saved} | {r.final_steps:,} | {r.ended_by} | {r.wall_s:.0f} |")
    print()


d = frame(root)
if d is None:
    sys.exit("no runs yet")
print("# Collapse criterion study (studies/collapse_study.sh)\n")
print("Calibrated defaults, event clock, creep-time limit 1e13 s. Setting `off_mN`: the old criterion alone "
      "(collapse_strain_increment 0) with max_relaxation_steps N; `incX_mN`: collapse_strain_increment X with "
      "max_relaxation_steps N as backstop. Relative change: lifetime / lifetime of `off_m30000` (the old default) "
      "on the same seed and load - 1. Final collapse: DEM steps of the last (failing) relaxation (history.csv, last "
      "row minus the row before). Ended by: collapse (new criterion), no equilibrium (max_relaxation_steps), "
      "strain cap (creep.failure_strain 0.02).\n")
print(FINDINGS)
tables(d, "10 x 20 mm, seeds 1-3, ratios 0.7 and 0.85 of calibration.reference_ucs")
small = frame(root / "small4x8")
if small is not None:
    tables(small, "4 x 8 mm, 0.5 x 300 MPa, seeds 1-2 (the event-clock runs of tests/test_reference_creep.py)")
paper = sorted(root.glob("paper_tiny/*/summary.json"))
if paper:
    print("## Paper clock (3 x 6 mm, seed 1, 0.8 x 300 MPa, record_period 100)\n")
    print("| collapse_strain_increment | lifetime [s] | DEM steps | ended by | failure_reason |")
    print("|---|---|---|---|---|")
    for f in paper:
        s, h, kind = read(f)
        print(f"| {f.parent.name[3:]} | {s['lifetime_s']:.10g} | {s.get('steps', s.get('dem_steps')):,} | {kind} | {s['failure_reason']} |")
EOF
cat docs/collapse_study.md
}
[ "$1" = table ] && { table; exit; }

run() {  # run <setting> <seed> <ratio> <options...>
  local name=$1 seed=$2 ratio=$3; shift 3
  local dir=$out/$name/s${seed}_r$ratio
  [ -f $dir/summary.json ] && return
  $py -m grainfrac_yade creep --width 10e-3 --height 20e-3 --seed $seed --ratio $ratio --overwrite --out $dir \
    --set stress_corrosion.creep_time_limit=1e13 --set numerics.checkpoint_interval=0 "$@" | tail -1
}
setting() {  # setting <increment> <max_relaxation_steps>: all seeds and ratios
  local inc=$1 m=$2 name
  if [ "$inc" = 0 ]; then name=off_m$m; else name=inc${inc}${3:+_ratio$3}_m$m; fi
  for r in 0.7 0.85; do for s in 1 2 3; do
    run $name $s $r --set creep.collapse_strain_increment=$inc --set creep.max_relaxation_steps=$m \
      --set creep.collapse_stress_ratio=${3:-1}
  done; done
  table > /dev/null
}
setting 0 30000                                  # reference: the old default
for m in 30000 100000; do for i in 2e-4 6e-4 2e-3; do setting $i $m; done; done
setting 0 10000; setting 0 100000
for m in 30000 100000; do for i in 1e-3 3e-3 6e-3 1e-2; do setting $i $m; done; done
for i in 1e-3 3e-3 1e-2; do setting $i 10000; done
# the shipped criterion: saturation with the held stress below 0.25 of the target
for m in 30000 100000; do setting 1e-3 $m 0.25; done

# 4 x 8 mm, 0.5 x 300 MPa, seeds 1-2: the event-clock runs of tests/test_reference_creep.py (same overrides)
small() {  # small <increment> <max_relaxation_steps>
  local inc=$1 m=$2 name dir s
  if [ "$inc" = 0 ]; then name=off_m$m; else name=inc${inc}_m$m; fi
  for s in 1 2; do
    dir=$out/small4x8/$name/s${s}_r0.5
    [ -f $dir/summary.json ] || $py -m grainfrac_yade creep --width 4e-3 --height 8e-3 --seed $s --ratio 0.5 \
      --ucs 300 --overwrite --out $dir --set stress_corrosion.creep_time_limit=1e30 --set numerics.checkpoint_interval=0 \
      --set creep.collapse_strain_increment=$inc --set creep.max_relaxation_steps=$m \
      --set creep.collapse_stress_ratio=1 | tail -1
  done
}
for m in 10000 30000 100000; do small 0 $m; done
for m in 30000 100000; do for i in 1e-3 3e-3 1e-2; do small $i $m; done; done

# paper clock: one tiny run (3 x 6 mm, seed 1, 0.8 x 300 MPa), criterion off and at 3e-3
for inc in 0 3e-3; do
  dir=$out/paper_tiny/inc$inc
  [ -f $dir/summary.json ] || $py -m grainfrac_yade creep --clock paper --width 3e-3 --height 6e-3 --seed 1 \
    --ratio 0.8 --ucs 300 --overwrite --out $dir --set stress_corrosion.creep_time_limit=1e13 \
    --set numerics.checkpoint_interval=0 --set creep.record_period=100 --set creep.collapse_strain_increment=$inc \
    --set creep.collapse_stress_ratio=1 | tail -1
done
table
