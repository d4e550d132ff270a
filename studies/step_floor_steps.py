"""DEM step and stepping speed with per-cell mass scaling (``numerics.step_floor_quantile``), by model
and specimen size: docs/studies/accuracy_cost.md.

For each (model, specimen, seed, quantile) the scene is built, its critical step and DEM step read,
and a short loading ramp of ``--steps`` DEM steps timed in CPU seconds (one thread).  The cost of a
quasi-static test scales as 1 / DEM step at a given number of steps per second, so the gain of a
floor is the ratio of DEM steps; the timing shows that the steps themselves cost the same.

    /usr/bin/python3 -m studies.step_floor_steps [--steps 200] [--out docs/step_floor_steps.csv]
    /usr/bin/python3 -m studies.step_floor_steps --summary-only     # the markdown summary of an existing CSV
"""
from __future__ import annotations

import argparse
import csv
import os
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

from grainfrac_yade.api import build_specimen, load_parameters

#: (model label, parameter files) of the scenes measured.
MODELS = (("rigid, 1 sphere per cell (default)", []),
          ("fem cells (params/presets/fem_calibrated.toml)", ["params/presets/fem_calibrated.toml"]))
#: (label, width [m], height [m], seeds)
SPECIMENS = (("10 x 20 mm", 10e-3, 20e-3, (1, 2, 3, 4, 5)), ("31.7 x 63.4 mm (paper)", 31.7e-3, 63.4e-3, (1, 2, 3)))
QUANTILES = (0.0, 0.05, 0.5)


def measure(files, width, height, seed, quantile, steps):
    from grainfrac_yade.api import engine
    p = load_parameters(extra_files=files, overrides=[f"specimen.width={width!r}", f"specimen.height={height!r}",
                                                      f"numerics.step_floor_quantile={quantile!r}"])
    scene = engine("yade").build_scene(build_specimen(p, seed), p)
    platens = scene.attach_platens()
    platens.set_axial_velocity(1e-4 * platens.height / (steps * scene.dt))
    scene.run(10)   # first steps: collider set-up
    start = time.process_time()
    scene.run(steps)
    cpu = time.process_time() - start
    return {"dt_critical_s": scene.dt_critical, "dem_step_s": scene.dt, "steps_per_cpu_s": steps / cpu}


def summary_markdown(rows) -> str:
    """Per (model, specimen, quantile): the range of DEM-step gains over seeds and the median steps per CPU s."""
    import statistics
    groups = {}
    for r in rows:
        groups.setdefault((r["model"], r["specimen"], float(r["step_floor_quantile"])), []).append(r)
    lines = ["| model | specimen | step floor quantile | seeds | DEM step [s] | gain in DEM step (min-max) | "
             "DEM steps per CPU s (median) |", "|---|---|---|---|---|---|---|"]
    for (model, size, q), g in groups.items():
        gain = [float(r["dem_step_gain"]) for r in g]
        dt = [float(r["dem_step_s"]) for r in g]
        rate = statistics.median(float(r["steps_per_cpu_s"]) for r in g)
        lines.append(f"| {model} | {size} | {q:g} | {len(g)} | {min(dt):.3g}-{max(dt):.3g} | "
                     f"{min(gain):.2f}-{max(gain):.2f} | {rate:.0f} |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--out", default="docs/step_floor_steps.csv")
    ap.add_argument("--paper-seeds", type=int, nargs="*", default=None, help="paper-size seeds (default 1 2 3)")
    ap.add_argument("--summary-only", action="store_true", help="only write the markdown summary of --out")
    args = ap.parse_args(argv)
    md = Path(args.out).with_suffix(".md")
    if args.summary_only:
        with open(args.out, newline="") as fh:
            md.write_text(summary_markdown(list(csv.DictReader(fh))))
        print(f"wrote {md}")
        return
    rows = []
    for model, files in MODELS:
        for size, w, h, seeds in SPECIMENS:
            if args.paper_seeds is not None and "paper" in size:
                seeds = tuple(args.paper_seeds)
            for seed in seeds:
                base = None
                for q in QUANTILES:
                    m = measure(files, w, h, seed, q, args.steps)
                    base = base or m
                    row = {"model": model, "specimen": size, "seed": seed, "step_floor_quantile": q, **m,
                           "dem_step_gain": m["dem_step_s"] / base["dem_step_s"]}
                    rows.append(row)
                    print(", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in row.items()),
                          flush=True)
    with open(args.out, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    md.write_text(summary_markdown(rows))
    print(f"wrote {args.out} and {md}")


if __name__ == "__main__":
    main()
