"""``elastic``: static linear-elastic reference of a specimen (no YADE); summary.json and histograms."""
from __future__ import annotations

import argparse

from ..elastic import GRAIN_MODELS, contact_ratios, elastic_summary
from ..geometry.grainmesh import CONTACT_PLACEMENTS
from ..geometry.specimen import build_specimen
from ..grains import grain_model
from ..params import FlagOverride, require_plane
from ..runs.runio import code_version, commit_run_dir, prepare_run_dir, write_json


#: Static models of the YADE fem cells and the grain model each one solves.
CLUSTER_MODELS = {"fem": "fem"}
#: Names ``--grains`` no longer takes, and the fix.
RETIRED_GRAINS = {"deformable": "the triangle-mesh reference is called mesh now; fix: --grains mesh",
                  "lattice": "the spring lattice was retired, fem cells superseded it; fix: --grains fem"}


def register(sub, common):
    p = sub.add_parser("elastic", help="static elastic reference: E, nu and the contact stress tail "
                                       "of rigid, mesh and fem cells (seconds, no YADE)")
    common(p)
    p.add_argument("--grains", type=_grains, choices=GRAIN_MODELS, default="mesh",
                   help="rigid: the project's rigid cells and bonds; mesh: triangle-mesh cells with "
                        "Table 1 moduli (the paper's deformable blocks, the reference); fem: the YADE "
                        "finite-element cells solved statically (default: mesh)")
    p.add_argument("--nodes-per-face", type=int,
                   help="mesh and fem: contact nodes per face (resolution.nodes_per_face, default 2 = "
                        "UDEC's corner sub-contacts)")
    p.add_argument("--contacts", choices=CONTACT_PLACEMENTS, default="corners",
                   help="mesh: contact nodes at the face ends (trapezoid shares) or sub-segment centres")
    p.add_argument("--rings", type=int, help="mesh and fem: radial mesh refinement of each cell (fem: "
                                             "resolution.cell_rings; default 1 = one fan of triangles)")
    p.add_argument("--platens", choices=("cells", "wall"), default="cells",
                   help="cells: the end cells move with the platens, as in the YADE tests; wall: only nodes "
                        "on the walls (triangle meshes only)")
    p.set_defaults(func=cmd_elastic, with_params=True, param_overrides=_model_overrides)


def _grains(text: str) -> str:
    """``--grains`` value; one line for a retired name."""
    if text in RETIRED_GRAINS:
        raise argparse.ArgumentTypeError(f"{text!r}: {RETIRED_GRAINS[text]}")
    return text


def _model_overrides(args) -> list:
    out = ([FlagOverride("resolution.nodes_per_face", args.nodes_per_face, "--nodes-per-face")]
           if args.nodes_per_face is not None else [])
    if args.grains in CLUSTER_MODELS:
        out.append(f"resolution.grain_model={CLUSTER_MODELS[args.grains]}")
        if args.rings is not None:
            out.append(FlagOverride("resolution.cell_rings", args.rings, "--rings"))
    return out


def cmd_elastic(args, params) -> int:
    require_plane(params, "elastic")
    out = args.out or f"results/elastic_seed{args.seed}"
    # the mesh reference takes the fem cells' rings unless --rings says otherwise
    rings = args.rings if args.rings is not None else params.resolution.cell_rings
    summary = run_elastic_to_folder(params, args.seed, out, args.grains, params.resolution.nodes_per_face, args.contacts,
                                    rings, args.platens, overwrite=args.overwrite)
    for name, s in summary["models"].items():
        print(f"{name:10s} E {s['young_pa'] / 1e9:6.1f} GPa  nu {s['poisson']:.3f}  shear/applied p50 "
              f"{s['shear_stress_ratio_p50']:.2f} p99 {s['shear_stress_ratio_p99']:.2f} max "
              f"{s['shear_stress_ratio_max']:.2f}  tension/applied max {s['tension_stress_ratio_max']:.2f}")
    print(f"-> {out}")
    return 0


def run_elastic_to_folder(params, seed, out, grains="mesh", nodes_per_face=2, contacts="corners",
                          rings=1, platens="cells", overwrite=False) -> dict:
    """Solve ``grains`` and, for comparison, the rigid cells (and for fem cells the mesh reference
    at the same contact nodes, with ``relative_error_vs_reference``); write summary.json and the
    histogram PNG.

    ``summary.json`` holds the chosen model's keys at the top level and every solved model under
    ``models``.
    """
    from ..analysis.figures import contact_stress_histograms
    out = prepare_run_dir(out, "elastic", params, seed, overwrite=overwrite)
    specimen = build_specimen(params, seed)
    models, ratios = {}, {}
    # the YADE cells are always compared with the mesh reference at the same contact nodes per face
    names = [grains, "rigid"] + (["mesh"] if grains in CLUSTER_MODELS else [])
    for name in dict.fromkeys(names):
        layout = None if name == "mesh" else grain_model(name).build_layout(specimen, params)
        s, net, sol = elastic_summary(specimen, params, name, layout, nodes_per_face, contacts, rings,
                                      platens=platens if name != "rigid" else "cells")
        models[name] = s
        ratios[name] = contact_ratios(net, sol)
    summary = dict(models[grains])
    if grains in CLUSTER_MODELS:
        ref = models["mesh"]
        summary["relative_error_vs_reference"] = {k: v / ref[k] - 1.0 for k, v in models[grains].items()
                                                  if isinstance(v, float) and k in ref and ref[k]}
    summary.update(models=models, seed=seed, n_cells=specimen.n_cells, platens=platens,
                   stiffness_scale=params.calibration.stiffness_scale, code_version=code_version())
    write_json(out / "summary.json", summary)
    size = f"{specimen.tessellation.box[0] * 1e3:.1f} x {specimen.tessellation.box[1] * 1e3:.1f} mm"
    contact_stress_histograms(ratios, out / "contact_stress_histogram.png", title=f"{size}, seed {seed}")
    commit_run_dir(out)   # a replacing run (--overwrite) takes the old one's place
    return summary
