"""Where a DEM step of finite-element cells goes: per-engine timings of a loading ramp, one thread.

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.fem_profile --size small --seed 3 [--set KEY=VALUE ...]
    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.fem_profile --size paper --seed 3

Builds the specimen with ``params/presets/fem.toml`` (plus ``--params``/``--set``), moves the
platens at ``ucs.strain_rate`` as a UCS test does, takes ``--warmup`` DEM steps, then ``--steps``
steps with YADE's engine timing on (``O.timingEnabled``) through ``GrainScene.run`` (as every test
steps), and prints one JSON line: bodies, interactions, the DEM step, DEM steps and body-steps per
CPU second, the share of each engine in YADE's engine time (``execTime``, a wall-clock count),
and the Python share of the window's wall time (the rest).  Ratios between two sizes come from two runs of this
script: run them back to back (the machine is shared).
"""
import argparse
import json
import os
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
ROOT = Path(__file__).resolve().parents[1]

from grainfrac_yade.params import load_parameters

SIZES = {"small": (10e-3, 20e-3), "mid": (20e-3, 40e-3), "paper": (31.7e-3, 63.4e-3)}
FEM_PRESET = ROOT / "params" / "presets" / "fem.toml"


def engine_times(O) -> dict:
    """Exec time [s] of each engine (YADE's ``execTime``; functors carry no time of their own here)."""
    return {(e.label or type(e).__name__): e.execTime * 1e-9 for e in O.engines}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", choices=SIZES, default="small")
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--warmup", type=int, default=200)
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--params", action="append", default=[])
    ap.add_argument("--set", dest="overrides", action="append", default=[])
    a = ap.parse_args(argv)
    w, h = SIZES[a.size]
    p = load_parameters(extra_files=[FEM_PRESET, *a.params],
                        overrides=[("specimen.width", w), ("specimen.height", h), *a.overrides])
    from grainfrac_yade.specimen import build_specimen
    from grainfrac_yade.yade_adapter.platens import Platens
    from grainfrac_yade.yade_adapter.scene import build_scene
    t0 = time.process_time()
    specimen = build_specimen(p, a.seed)
    scene = build_scene(specimen, p)
    build_cpu = time.process_time() - t0
    O = scene.O
    collider = next(e for e in O.engines if type(e).__name__ == "InsertionSortCollider")
    platens = Platens(scene, p.ucs.platen_lateral)
    scene.extras.append(platens)
    platens.set_axial_velocity(p.ucs.strain_rate * platens.height)
    scene.run(a.warmup)
    O.timingEnabled = True
    for e in O.engines:
        e.execTime, e.execCount = 0, 0
    c0, w0 = time.process_time(), time.time()
    scene.run(a.steps)
    cpu, wall = time.process_time() - c0, time.time() - w0
    engines = engine_times(O)
    yade_s = sum(engines.values())
    n_bodies = len(O.bodies)
    radii = [b.shape.radius for b in O.bodies if type(b.shape).__name__ == "Sphere"]
    out = {"size": a.size, "seed": a.seed, "overrides": a.overrides, "bodies": n_bodies,
           "spheres": len(radii), "interactions": len(O.interactions), "n_bonds": scene.n_bonds,
           "dem_step_s": O.dt, "critical_step_s": scene.dt_critical, "min_radius_m": min(radii),
           "median_radius_m": sorted(radii)[len(radii) // 2],
           "verlet_dist": collider.verletDist, "collider_runs": int(getattr(collider, "numAction", -1)),
           "build_cpu_s": build_cpu, "steps": a.steps, "cpu_s": cpu, "wall_s": wall,
           "dem_steps_per_cpu_s": a.steps / cpu, "body_steps_per_cpu_s": a.steps * n_bodies / cpu,
           "python_share_of_wall": max(0.0, 1 - yade_s / wall),
           "engine_share": {k: round(v / yade_s, 4) for k, v in sorted(engines.items(), key=lambda kv: -kv[1])}}
    print(json.dumps(out))


if __name__ == "__main__":
    main()
