"""Does a specimen come to equilibrium under a held load, and how many DEM steps (wave crossings) does it take?

A creep run's first relaxation without stress corrosion, watched as it goes: the ramp of a creep run
(``creep.ramp_strain_rate``), then the stress servo holds ``--stress``, and every ``--log-every`` DEM steps a
row of ``relaxation.csv`` (written as it goes) records the axial strain and stress, the broken bonds, the
unbalanced force ratio that the creep run's equilibrium test reads (mean resultant on free bodies / mean
bond force, against ``creep.equilibrium_tolerance``) and whether that test passes.  Stops at the first
equilibrium (then ``--after`` more steps, to see that it stays), or after ``--max-steps``.  A creep run
would have called ``--max-steps`` beyond ``creep.max_relaxation_steps`` a failure ("no equilibrium").

Wave crossings: DEM steps x dt / (H / c), c = sqrt(E / (rho x numerics.density_scale)), E the servo's
modulus estimate (held stress / axial strain at the end of the ramp), rho the area-weighted Table 1 density.

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.hold_relaxation --params params/presets/fem_coarse.toml \\
        --set specimen.min_edge_fraction=0.02 --stress 160 --seed 1 --max-steps 150000 --out results/hold/fem160_s1
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

from grainfrac_yade.api import load_parameters

FIELDS = ("hold_steps", "crossings", "axial_strain", "axial_stress_pa", "broken_total", "unbalanced_ratio",
          "at_equilibrium", "servo_clipped", "cpu_s")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--params", action="append", default=[])
    ap.add_argument("--set", dest="overrides", action="append", default=[])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--stress", type=float, required=True, help="held axial stress [MPa]")
    ap.add_argument("--log-every", type=int, default=1000, help="DEM steps between rows")
    ap.add_argument("--max-steps", type=int, default=150000, help="DEM steps of the hold at most")
    ap.add_argument("--after", type=int, default=10000, help="DEM steps run on after the first equilibrium")
    ap.add_argument("--out", required=True, help="folder for relaxation.csv and summary.json (must not exist)")
    a = ap.parse_args(argv)
    out = Path(a.out)
    if out.exists():
        print(f"{out}: exists; fix: another --out (earlier results are never replaced)", file=sys.stderr)
        return 1
    params = load_parameters(extra_files=a.params, overrides=[*a.overrides, "stress_corrosion.enabled=false"])
    from grainfrac_yade.api import CreepRun, build_specimen, code_version, mean_bond_force, scene_density
    import numpy as np
    out.mkdir(parents=True)
    c0 = time.process_time()
    run = CreepRun(build_specimen(params, a.seed), params, a.stress * 1e6)
    run.ramp()
    summary = {"seed": a.seed, "stress_pa": a.stress * 1e6, "params_files": a.params, "overrides": a.overrides,
               "code_version": code_version(), "ramp_steps": int(run.scene.steps),
               "ramp_failed": bool(run.failed), "ramp_broken": run.ramp_broken,
               "strain_after_ramp": run.platens.axial_strain(), "dem_step_s": run.scene.dt}
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    if run.failed:
        print(f"ramp failed: {run.failure_reason}")
        return 0
    run.hold_servo()
    crossing_steps = run.hold_budget.crossing_steps   # the servo's: its modulus estimate, the scene's density
    summary.update(servo_young_pa=run.servo.platens.height / (run.servo.gain * run.hold_budget.servo_response_steps),
                   density_kg_m3=scene_density(params), crossing_time_s=crossing_steps * run.scene.dt,
                   crossing_steps=crossing_steps, **run.hold_budget.as_dict())
    done, equilibrium_at = 0, None
    with open(out / "relaxation.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        w.writeheader()
        while done < a.max_steps and (equilibrium_at is None or done < equilibrium_at + a.after):
            clipped = 0
            for _ in range(a.log_every // params.creep.check_period):
                run.scene.run(params.creep.check_period)
                done += params.creep.check_period
                clipped += run.servo.clipped != 0
                balanced = run.at_equilibrium(run.servo)
                if balanced and equilibrium_at is None:
                    equilibrium_at = done
            _, unbalanced_ratio = run.unbalanced(mean_bond_force(run.scene, np.flatnonzero(~run.scene.broken)))
            w.writerow({"hold_steps": done, "crossings": done / crossing_steps,
                        "axial_strain": run.platens.axial_strain(), "axial_stress_pa": run.servo.stress,
                        "broken_total": int(run.scene.broken.sum()), "unbalanced_ratio": unbalanced_ratio,
                        "at_equilibrium": bool(balanced), "servo_clipped": clipped,
                        "cpu_s": time.process_time() - c0})
            f.flush()
    summary.update(hold_steps=done, first_equilibrium_steps=equilibrium_at,
                   first_equilibrium_crossings=None if equilibrium_at is None else equilibrium_at / crossing_steps,
                   broken_end=int(run.scene.broken.sum()), strain_end=run.platens.axial_strain(),
                   cpu_s=time.process_time() - c0)
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main())
