"""Lever study beyond the parameters: Brazilian 15 mm discs and UCS 10 x 20 mm with the levers of
grainfrac_yade.engines.yade.levers (slits, strength scatter, blocked rotation), the contacts' J^T at 0.1,
the face-lined clumps' UCS (8 spheres per cell), and rotational resistance with J^T x 0.25 and 0.1.  Run by studies/brazilian_study.sh (one YADE run at a
time, in this process); a finished run (summary.json) is skipped.

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.brazilian_levers results/brazilian_study
"""
import sys
from pathlib import Path


from grainfrac_yade.api import (Levers, build_specimen, engine_for, load_parameters, prepare_run_dir,
                                run_brazilian_to_folder, run_ucs, summary_header, tensile_scale_overrides, ucs_summary,
                                write_json)

SEEDS = (1, 2, 3)
DISC = [("brazilian.diameter", 15e-3)]
BLOCK = [("specimen.width", 10e-3), ("specimen.height", 20e-3)]


def ucs_with_levers(params, seed, out, levers):
    """A UCS test whose scene gets ``levers`` before loading (as the brazilian command does)."""
    out = prepare_run_dir(out, "ucs", params, seed, overwrite=True)
    specimen = build_specimen(params, seed)
    mechanics = engine_for(params)
    scene = mechanics.build_scene(specimen, params)
    applied = mechanics.apply_levers(scene, levers, seed)
    hist, result, _, _ = run_ucs(specimen, params, scene=scene)
    summary = ucs_summary(hist)
    summary.update(result, **applied)
    summary.update(summary_header(params, seed), n_cells=specimen.n_cells)
    write_json(out / "summary.json", summary)
    return summary


def main(root):
    root = Path(root)
    base = load_parameters()
    variants = {
        "slit0.3": ([], Levers(slit_fraction=0.3)),
        "slit0.6": ([], Levers(slit_fraction=0.6)),
        "cv0.5": ([], Levers(strength_cv=0.5)),
        "norotation": ([], Levers(block_rotation=True)),
        "tensile0.1": (tensile_scale_overrides(base, 0.1), Levers()),
        "spc8": ([("resolution.spheres_per_cell", 8)], Levers()),
        # combinations: rotational resistance (bound: none; physical: face-lined clumps) with weak tension
        "norotation_tensile0.25": (tensile_scale_overrides(base, 0.25), Levers(block_rotation=True)),
        "spc8_tensile0.25": ([("resolution.spheres_per_cell", 8)] + tensile_scale_overrides(base, 0.25), Levers()),
        "spc8_tensile0.1": ([("resolution.spheres_per_cell", 8)] + tensile_scale_overrides(base, 0.1), Levers()),
    }
    for name, (overrides, levers) in variants.items():
        for seed in SEEDS:
            disc = root / f"d15_{name}" / f"seed{seed}"
            if name != "spc8" and not (disc / "summary.json").exists():
                s = run_brazilian_to_folder(load_parameters(overrides=DISC + overrides), seed, disc, overwrite=True,
                                            levers=levers)
                print(f"{disc}: sigma_t {s['tensile_strength_pa'] / 1e6:.2f} MPa ({s['wall_s']:.0f} s)", flush=True)
            block = root / f"ucs10x20_{name}" / f"seed{seed}"
            if not (block / "summary.json").exists():
                s = ucs_with_levers(load_parameters(overrides=BLOCK + overrides), seed, block, levers)
                print(f"{block}: UCS {s['ucs_pa'] / 1e6:.1f} MPa ({s['wall_s']:.0f} s)", flush=True)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "results/brazilian_study")
