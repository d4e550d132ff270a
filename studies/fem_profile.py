"""Where a DEM step of finite-element cells goes: per-engine timings of a loading ramp, one thread.

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.fem_profile --size small --seed 3 [--set KEY=VALUE ...]
    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.fem_profile --size paper --seed 3

Builds the specimen with ``params/presets/fem_coarse.toml`` (plus ``--params``/``--set``), moves the
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
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
ROOT = Path(__file__).resolve().parents[1]

from grainfrac_yade.api import load_parameters

SIZES = {"small": (10e-3, 20e-3), "mid": (20e-3, 40e-3), "paper": (31.7e-3, 63.4e-3)}
FEM_PRESET = ROOT / "params" / "presets" / "fem_coarse.toml"


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
    from grainfrac_yade.api import build_specimen, engine
    cost = engine("yade").loading_step_cost(build_specimen(p, a.seed), p, a.warmup, a.steps, engine_timing=True)
    print(json.dumps({"size": a.size, "seed": a.seed, "overrides": a.overrides, **cost}))


if __name__ == "__main__":
    main()
