"""Strain-controlled uniaxial compression between rigid platens (the UCS of paper section 3.1), or
confined (biaxial) compression with ``confinement.stress`` sigma_3 > 0 on the side walls
(:mod:`.confinement`: isotropic stage to sigma_1 = sigma_3 first, then the same axial loading; the
post-peak stop rule then applies to the deviator sigma_1 - sigma_3).

The test ends once the axial stress falls below ``ucs.stop_stress_ratio`` of its peak with bonds
broken since the peak (post-peak; a drop without a break is elastic ringing, e.g. of a one-cell-wide
column set in motion from rest: measured 3.4 MPa then below 2.4 MPa, no bond broken), or at ``ucs.max_strain`` (then the largest stress so far is only a lower bound of the strength), or
on a numerical failure (NaN or infinite measures, a DEM step above the critical one): no result.
The result dict says which in ``end_reason`` (and ``peak_reached``, ``numerical_failure``).
"""
from __future__ import annotations

import time

from ..errors import NumericalFailure
from .confinement import Confinement, broken_apart_reason, consolidate, young_estimate
from .platens import Platens
from .scene import broken_counts, build_scene, check_value, softened_past_peak


def run_ucs(specimen, params, progress=None, scene=None):
    """Run the test; return (history columns, result dict, scene, broken-at-peak snapshot).

    The history holds only finite rows (a row with a NaN or infinite value ends the run as a
    numerical failure instead).
    """
    t0, c0 = time.time(), time.process_time()
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
    peak, broken_at_peak, peak_snapshot = 0.0, 0, (scene.broken.copy(), scene.break_mode.copy())
    numerical, peak_reached = False, False
    confining = params.confinement.stress
    consolidation = {}
    broken_apart = ""
    try:
        if confining > 0:
            scene.extras.append(Confinement(scene, confining))
            consolidation = consolidate(scene, platens, confining, params.creep, young_estimate(params))
            platens.set_axial_velocity(closing_speed)
            broken_apart = end = broken_apart_reason(scene, confining)
            if broken_apart and progress:
                progress(end)
        while not broken_apart:
            scene.run(steps_per_row)
            stress = platens.axial_stress()
            strain = platens.axial_strain()
            row = dict(dem_step=scene.O.iter, dem_time_s=scene.O.time, axial_strain=strain,
                       lateral_strain=platens.lateral_strain(), axial_stress_pa=stress, **broken_counts(scene))
            for k, v in row.items():
                check_value(k, v, scene.O.iter)
            for k, v in row.items():
                cols[k].append(v)
            if stress > peak:
                peak, broken_at_peak = stress, row["broken_total"]
                peak_snapshot = (scene.broken.copy(), scene.break_mode.copy())
            if progress and len(cols["dem_step"]) % 50 == 0:
                progress(f"strain {strain:.5f}  stress {stress / 1e6:7.1f} MPa  broken {row['broken_total']}")
            if softened_past_peak(stress - confining, peak - confining, row["broken_total"], broken_at_peak,
                                  ucs.stop_stress_ratio):
                peak_reached = True
                end = (f"post-peak: the axial stress fell below {ucs.stop_stress_ratio:g} x its peak" if confining == 0
                       else f"post-peak: the deviator fell below {ucs.stop_stress_ratio:g} x its peak")
                break
            if strain >= ucs.max_strain:
                end = (f"axial strain reached ucs.max_strain = {ucs.max_strain:g} before the stress fell below "
                       f"{ucs.stop_stress_ratio:g} x its peak: the largest stress is a lower bound of the strength")
                break
    except NumericalFailure as exc:
        numerical, end = True, f"numerical failure: {exc}"
        if progress:
            progress(end)
    result = {"dem_steps": int(scene.O.iter), "wall_s": time.time() - t0, "cpu_s": time.process_time() - c0, "dem_timestep_s": dt,
              "n_bonds": scene.n_bonds, **broken_counts(scene), "numerical_failure": numerical,
              "peak_reached": peak_reached, "end_reason": end,
              "failed_before_test": bool(broken_apart), "confining_stress_pa": confining, **consolidation}
    return cols, result, scene, peak_snapshot
