"""``demo``: the main job. Builds the paper-size specimen and its YADE scene, writes summary and picture.

Later issues grow it into a small lifetime study (UCS, creep at three ratios, analysis).
"""
from __future__ import annotations

import time
from pathlib import Path


def register(sub, common):
    p = sub.add_parser("demo", help="main job: paper-size specimen (grows into a small lifetime study)")
    common(p, geometry=False)
    p.add_argument("--seed", type=int, default=1)
    p.set_defaults(func=cmd_demo)


def cmd_demo(args) -> int:
    from ..cli import load_params_from_args
    from ..runio import write_json
    from ..specimen import build_specimen
    from .specimen import run_specimen
    from ..yade_adapter.scene import build_scene
    params = load_params_from_args(args)
    out = Path(args.out or time.strftime("results/demo_%Y%m%d-%H%M%S"))  # a new folder each run
    t0 = time.time()
    print(f"[demo] building the specimen ({params.specimen.width * 1e3:.1f} x {params.specimen.height * 1e3:.1f} mm)")
    record = run_specimen(params, args.seed, out, draw_bonds=False, overwrite=args.overwrite)
    print("[demo] building the YADE scene")
    scene = build_scene(build_specimen(params, args.seed), params)
    record.update(n_bonds_yade=scene.O.interactions.countReal(), dem_timestep_s=scene.O.dt,
                  engines=scene.engine_names(), wall_s=time.time() - t0)
    write_json(out / "specimen.json", {k: v for k, v in record.items() if k != "out"})
    print(f"[demo] {record['n_cells']} cells, {record['n_bonds_yade']} bonds, DEM step {scene.O.dt:.3g} s")
    print(f"[demo] done in {record['wall_s']:.1f} s: {out / 'specimen.json'}, {out / 'specimen.png'}")
    return 0
