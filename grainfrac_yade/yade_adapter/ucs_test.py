"""Strain-controlled uniaxial compression between rigid platens (issue 4)."""
from __future__ import annotations

import time

import numpy as np

from .platens import Platens
from .scene import broken_counts, build_scene


def run_ucs(specimen, params, progress=None, scene=None):
    """Run the test; return (history columns, result dict, scene, broken-at-peak snapshot)."""
    t0 = time.time()
    scene = scene or build_scene(specimen, params)
    ucs = params.ucs
    platens = Platens(scene, ucs.platen_lateral)
    scene.extras.append(platens)
    closing_speed = ucs.strain_rate * platens.height
    platens.set_axial_velocity(closing_speed)
    dt = scene.O.dt
    steps_per_row = max(1, int(round(ucs.record_strain_increment / (ucs.strain_rate * dt))))
    cols = {k: [] for k in ("dem_step", "dem_time_s", "axial_strain", "lateral_strain", "axial_stress_pa",
                            "broken_total", "broken_tensile", "broken_shear", "broken_inter", "broken_intra")}
    peak, peak_snapshot = 0.0, (scene.broken.copy(), scene.break_mode.copy())
    while True:
        scene.run(steps_per_row)
        stress = platens.axial_stress()
        strain = platens.axial_strain()
        row = dict(dem_step=scene.O.iter, dem_time_s=scene.O.time, axial_strain=strain,
                   lateral_strain=platens.lateral_strain(), axial_stress_pa=stress, **broken_counts(scene))
        for k, v in row.items():
            cols[k].append(v)
        if stress > peak:
            peak = stress
            peak_snapshot = (scene.broken.copy(), scene.break_mode.copy())
        if progress and len(cols["dem_step"]) % 50 == 0:
            progress(f"strain {strain:.5f}  stress {stress / 1e6:7.1f} MPa  broken {row['broken_total']}")
        if strain >= ucs.max_strain or (peak > 0 and stress < ucs.stop_stress_ratio * peak):
            break
        if not np.isfinite(stress):
            raise FloatingPointError("axial stress is not finite: the DEM step is unstable "
                                     "(lower numerics.timestep_safety)")
    result = {"dem_steps": int(scene.O.iter), "wall_s": time.time() - t0, "dem_timestep_s": dt,
              "n_bonds": scene.n_bonds, **broken_counts(scene)}
    return cols, result, scene, peak_snapshot
