"""A creep test into a run folder: summary.json, history.csv, cracks.csv, the initial bond stresses, the
strain-time figure, the crack maps at fractions of the lifetime and the VTK series asked for (the test
itself: :mod:`.creep`); going on with an interrupted one (:func:`resume_creep_folder`); which UCS a
driving-stress ratio refers to.  Engine-neutral: the test runs on the engine of the parameters
(``numerics.engine``)."""
from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from ..analysis.creep_analysis import CreepStages, MinimumCreepRate, damage_index, minimum_creep_rate, resolve_creep_stages
from ..analysis.durations import readable_duration
from ..analysis.runparams import load_run_parameters
from ..engines.registry import engine_for, require_dynamic
from ..errors import GrainfracError
from ..geometry.specimen import build_specimen
from ..params import load_parameters, require_plane
from ..runs.columns import STEPS_COUNTED_KEY, steps_counted
from ..runs.runio import (CHECKPOINT, SUMMARY, check_files, checkpoint_folder, commit_run_dir, comparable_parameters,
                          prepare_run_dir, read_checkpoint_state, remove_checkpoints, summary_header, write_csv,
                          write_json)
from ..wave import budget_fields
from . import creep as creep_test
from ..kernel.cracks import bond_segments, broken_counts, crack_table
from .snapshots import write_life_series


#: Where a ratio's reference strength can come from (summary.json ``ucs_source``).
UCS_FROM_CALIBRATION = "calibration.reference_ucs"
#: Parameters that change the UCS a specimen has: a run that differs from the shipped values in one of them
#: has another strength than calibration.reference_ucs, which was measured with the shipped values
#: (params/calibration.toml: the paper-size specimen, seeds 1-5).  Prefixes of dotted keys.
STRENGTH_KEYS = ("specimen.", "composition.", "contacts.", "grains.", "resolution.", "numerics.", "ucs.",
                 "calibration.strength_scale", "calibration.stiffness_scale", "calibration.shear_stiffness_ratio_scale",
                 "calibration.tensile_cohesion_ratio_scale", "calibration.inter_mineral_strength_ratio",
                 "calibration.strength_weibull_modulus")


def reference_differences(params) -> list:
    """"key: calibrated X, run Y" for each parameter in :data:`STRENGTH_KEYS` in which ``params`` differ from
    the shipped ones, with which calibration.reference_ucs was calibrated ([] if none)."""
    run = comparable_parameters(params.to_dict())
    shipped = comparable_parameters(load_parameters().to_dict())
    keys = sorted(k for k in set(run) | set(shipped) if k.startswith(STRENGTH_KEYS))
    return [f"{k}: calibrated {shipped.get(k)!r}, run {run.get(k)!r}" for k in keys if shipped.get(k) != run.get(k)]


def ucs_reference(params, ucs_source: str) -> dict:
    """summary.json keys saying which UCS the ratio refers to: ``ucs_source`` and, for the calibrated
    reference, ``ucs_reference_differences`` (:func:`reference_differences`; [] for a UCS given, which is
    this specimen's own by the giver's word)."""
    diffs = reference_differences(params) if ucs_source == UCS_FROM_CALIBRATION else []
    return {"ucs_source": ucs_source, "ucs_reference_differences": diffs}


def resume_creep_folder(folder, progress=None) -> dict | None:
    """Go on with the interrupted creep run in ``folder`` from its checkpoint; its summary, or None if
    the run is already finished.  Parameters (params.json), seed and load (the checkpoint) are the
    run's own; GrainfracError (one line) if the folder holds no creep run or no checkpoint."""
    folder = Path(folder)
    try:
        command = json.loads((folder / "run.json").read_text()).get("command")
    except (OSError, ValueError, AttributeError):
        raise GrainfracError(f"{folder}: no run here (run.json missing or unreadable); fix: give the --out folder "
                             "of a creep run") from None
    if command != "creep":
        raise GrainfracError(f"{folder}: holds a {command!r} run, not a creep run; fix: give the folder of a creep run")
    if (folder / SUMMARY).exists():
        return None
    if checkpoint_folder(folder) is not None:
        check_files(checkpoint_folder(folder))
    state = read_checkpoint_state(folder)
    if state is None and checkpoint_folder(folder) is not None:
        where = checkpoint_folder(folder)
        raise GrainfracError(f"{where}: the checkpoint's state file ({where.name}/state.json) is unreadable (not the "
                             "JSON this code writes: garbage or truncated); fix: start the run again with the same "
                             "command (run.json) and --overwrite")
    if state is None:
        raise GrainfracError(f"{folder}: no checkpoint to resume from ({CHECKPOINT}/ missing: the run stopped before "
                             "the end of its ramp, or was started by code without checkpoints); fix: start it again "
                             "with the same command (run.json) and --overwrite")
    values = state.get("run_values") or {}
    if not all(k in values for k in ("seed", "stress_pa", "driving_stress_ratio", "ucs_pa")):
        raise GrainfracError(f"{folder}: the checkpoint lacks the run's seed and load; fix: start the run again "
                             "with --overwrite")
    params = load_run_parameters(folder).params
    return run_creep_to_folder(params, int(values["seed"]), folder, values["stress_pa"],
                               values["driving_stress_ratio"], values["ucs_pa"], progress=progress, resume=True)


def run_creep_to_folder(params, seed, out, stress, ratio, ref_ucs, overwrite=False, progress=None,
                        vtk_times=None, resume=False, vtk_every=None, vtk_fractions=None, ucs_source=None) -> dict:
    """Run a creep test into ``out``; summary.json is written last (it marks the run finished).

    Checkpoints go to ``out/checkpoint/`` during the run (end of the ramp, then every
    ``numerics.checkpoint_interval`` s) and are removed once summary.json is written.  ``resume``: go on
    from the checkpoint in ``out`` instead of starting (``out`` keeps its run.json and params.json).

    VTK series in ``out/vtk/`` (only reading the scene; with none of these options no VTK file):
    ``vtk_times`` (creep times [s]) and ``vtk_every`` (every k-th history row) during the run, plus
    the end; ``vtk_fractions`` (of the lifetime) after it, from the bonds' break times.

    A numerical failure (NaN/inf, a stalled clock) gives ``numerical_failure: true``, ``failed:
    null`` (unknown) and ``lifetime_s: null``, with the reason in ``failure_reason``; so does a confined
    specimen that broke apart in the isotropic stage, with ``failed_before_test: true`` (no history.csv,
    no strain-time figure; its cracks are the ramp's).
    """
    from ..analysis.figures import MAP_FRACTIONS, run_bond_stress_figure, run_strain_time_figure
    from ..analysis.plotting import crack_map
    t0, c0 = time.time(), time.process_time()
    require_plane(params, "creep")
    if params.stress_corrosion.clock == "paper":
        require_dynamic(params, "the paper clock (its unbalanced force, Eq. 8)")
    out = Path(out) if resume else prepare_run_dir(out, "creep", params, seed, overwrite=overwrite)
    specimen = build_specimen(params, seed)
    run_values = {"seed": seed, "stress_pa": stress, "driving_stress_ratio": ratio, "ucs_pa": ref_ucs}
    if vtk_fractions:
        run_values["vtk_fractions"] = [float(f) for f in vtk_fractions]   # a resumed run writes them too
    outputs = {"history_sink": lambda rows: write_csv(out / "history.csv", history_columns(rows)),
               "run_values": run_values}
    if resume:
        state = read_checkpoint_state(out) or {}
        if state.get("run", {}).get("vtk"):
            outputs.update(vtk_folder=out / "vtk")
        vtk_fractions = (state.get("run_values") or {}).get("vtk_fractions")
        if vtk_fractions:
            run_values["vtk_fractions"] = vtk_fractions   # kept in the checkpoints written from here on
        run = creep_test.resume_creep(specimen, params, stress, out, progress=progress, **outputs)
        t0 -= state.get("wall_s", 0.0)   # wall time of the run up to its checkpoint
        c0 -= state.get("cpu_s", 0.0)    # CPU time of this process up to it (checkpoints older than the key: 0)
    else:
        if vtk_times is not None or vtk_every:
            outputs.update(vtk_folder=out / "vtk", vtk_times=vtk_times or (), vtk_every=vtk_every or 0)
        run = creep_test.run_creep(specimen, params, stress, progress=progress, checkpoint_folder=out, **outputs)
    numerical = bool(run.numerical_failure)
    no_test = numerical or run.failed_before_test   # no creep result: neither a lifetime nor a survival
    if ucs_source is None:   # a resumed run, or a caller that did not say: the calibrated value or one given
        ucs_source = UCS_FROM_CALIBRATION if ref_ucs == params.calibration.reference_ucs else "given"
    rows = run.rows or [row_before_history(run, broken_counts(run.scene))]
    hist = history_columns(rows)
    broken_creep = hist["broken_total"] - run.ramp_broken
    t_end = float(hist["creep_time_s"][-1])
    lifetime = t_end if run.failed and not numerical else None
    # stages and the minimum creep rate from the history before the collapse row (the failure itself would
    # dominate every rate)
    unresolved = "no lifetime" if lifetime is None else "too short a history"
    resolvable = lifetime is not None and len(rows) > 3
    stages = (resolve_creep_stages(hist["creep_time_s"][:-1], hist["axial_strain"][:-1], t_end) if resolvable
              else CreepStages(None, None, unresolved))
    min_rate = (minimum_creep_rate(hist["creep_time_s"][:-1], hist["axial_strain"][:-1], t_end) if resolvable
                else MinimumCreepRate(None, unresolved))
    hist["broken_creep"] = broken_creep
    if not no_test:   # D_n = N(t) / N(t_f): no t_f without a result (a numerical failure's last count is no failure's)
        hist["damage_index"] = damage_index(broken_creep, broken_creep[-1])
    if run.rows:
        write_csv(out / "history.csv", hist)
    write_crack_list(out / "cracks.csv", run)
    summary = {
        "lifetime_s": lifetime, "lifetime_readable": readable_duration(lifetime),
        "failed": None if no_test else run.failed, "failure_reason": run.failure_reason,
        "failed_in_first_relaxation": failed_in_first_relaxation(run, params, lifetime),
        "end_reason": end_reason(run, params, t_end),
        "numerical_failure": numerical, "failed_on_loading": run.failed_on_loading,
        "failed_before_test": run.failed_before_test,
        "creep_time_end_s": t_end, "stress_pa": stress, "driving_stress_ratio": ratio, "ucs_pa": ref_ucs,
        **ucs_reference(params, ucs_source),
        "confining_stress_pa": params.confinement.stress, **getattr(run, "consolidation", {}),
        "clock": params.stress_corrosion.clock, "law": params.stress_corrosion.law,
        "n_events": run.n_events, "broken_ramp": run.ramp_broken, "broken_creep": int(broken_creep[-1]),
        "broken_total": int(hist["broken_total"][-1]), "macrocracks": int(hist["macrocracks"][-1]),
        "n_bonds": run.scene.n_bonds, "bonds_erased_by_sliding": run.scene.sliding_erasures(),
        **budget_fields(getattr(run, "hold_budget", None)),
        "steps": int(run.scene.steps), STEPS_COUNTED_KEY: steps_counted(engine_for(params)), "wall_s": time.time() - t0,
        "cpu_s": time.process_time() - c0, "engine": params.numerics.engine, **run.scene.summary_keys(),
        "primary_end_s": stages.primary_end_s, "tertiary_start_s": stages.tertiary_start_s,
        "creep_stages": stages.unresolved or "resolved",
        "min_creep_strain_rate_per_s": min_rate.rate_per_s, "min_creep_strain_rate": min_rate.unresolved or "resolved",
        "vtk_creep_times_s": run.vtk_written,
        "vtk_merged_times": run.vtk_merged,
        "vtk_times_not_reached_s": list(run.vtk_times) if run.vtk_folder is not None else [],
        **summary_header(params, seed),
    }
    if getattr(run, "resumes", None):
        summary["resumed_from"] = run.resumes   # checkpoints this run went on from (only in resumed runs)
    if run.initial_bond_stresses is not None:
        write_csv(out / "bond_stresses_start.csv", run.initial_bond_stresses)
        run_bond_stress_figure(run.initial_bond_stresses, stress, out / "bond_stresses_start.png")
        t = run.initial_bond_stresses["shear_stress_pa"]
        summary.update(shear_stress_p99_pa=float(np.percentile(t, 99)), shear_stress_max_pa=float(t.max()),
                       shear_utilisation_max=float(np.max(run.initial_bond_stresses["shear_utilisation"])))
    if not run.failed_before_test:   # a specimen broken apart before the ramp has no strain-time curve
        run_strain_time_figure(hist, summary, out / "strain_time.png")
    t_ref = lifetime if lifetime else t_end
    if vtk_fractions:
        write_life_series(run, out / "vtk", [f * t_ref for f in vtk_fractions], vtk_fractions)
        summary["vtk_life_fractions"] = [float(f) for f in vtk_fractions]
    for frac in MAP_FRACTIONS:
        t = frac * t_ref
        idx = np.flatnonzero(run.scene.broken & (run.break_time <= t))
        crack_map(specimen, out / f"crack_map_t{frac:.2f}.png", bond_segments(run.scene, idx),
                  run.scene.break_mode[idx], macro=run.macro_time[idx] <= t,
                  title=f"{stress / 1e6:.0f} MPa: cracks at t = {t:.4g} s ({frac:.0%} of "
                        f"{'lifetime' if lifetime else 'run'})")
    write_json(out / "summary.json", summary)   # last: marks the run finished
    remove_checkpoints(out)                     # a finished run has nothing to resume
    commit_run_dir(out)                         # a replacing run (--overwrite) takes the old one's place
    return summary


def failed_in_first_relaxation(run, params, lifetime) -> bool:
    """Whether a failed event-clock run collapsed in the relaxation after its first creep event: the first bond the
    law broke brought the specimen down, with no creep damage before it, so its lifetime is that bond's corrosion
    time, not a creep life (the analysis leaves such runs out of its fits).  False for a run without a lifetime or
    with a lifetime of 0 (failed at load: no creep event at all), and for the paper clock (no relaxation after an
    event: it corrodes every step)."""
    return bool(lifetime is not None and lifetime > 0 and params.stress_corrosion.clock == "event"
                and run.n_events <= 1)


def end_reason(run, params, t_end) -> str:
    """Why the run ended: its failure or numerical failure, else why it stopped without failing."""
    sc = params.stress_corrosion
    if run.failed or run.numerical_failure or run.failed_before_test:
        return run.failure_reason
    if not sc.enabled:
        return "load held without stress corrosion (stress_corrosion.enabled = false): not failed"
    if t_end >= sc.creep_time_limit:
        return (f"creep time reached stress_corrosion.creep_time_limit = {sc.creep_time_limit:g} s: not failed, "
                "the lifetime is a lower bound")
    return ("no intact bond can fail under the held stresses (the degradation law gives an infinite time, e.g. "
            "every bond below its activation threshold): not failed")


def row_before_history(run, counts) -> dict:
    """Stand-in history row (creep time 0, no strain) for a run that ended before its first row
    (a numerical failure during the ramp); never written to history.csv."""
    return {"creep_time_s": 0.0, "axial_strain": 0.0, "lateral_strain": 0.0, "axial_stress_pa": 0.0, **counts,
            "macrocracks": 0, "step": int(run.scene.steps), "wall_s": 0.0}


def history_columns(rows) -> dict:
    """History rows (dicts) as columns {name: array}, as history.csv stores them."""
    return {k: np.array([r[k] for r in rows]) for k in rows[0]}


def write_crack_list(path, run):
    """cracks.csv: bond, creep time (empty for a crack of the ramp), phase (``ramp`` or ``creep``), mode, kind,
    position, orientation, segment end points and the creep time its cells separated (macrocrack; empty if
    never); docs/reference/output_files.md."""
    sc = run.scene
    idx = np.flatnonzero(sc.broken)
    seg = bond_segments(sc, idx)
    ramp = run.break_time[idx] < 0   # the driver marks cracks of the ramp with a negative creep time
    table = crack_table(sc, idx)
    write_csv(path, {
        "bond": table.pop("bond"), "creep_time_s": np.where(ramp, np.nan, run.break_time[idx]),
        "phase": np.where(ramp, "ramp", "creep"), **table,
        "x0_m": seg[:, 0, 0], "y0_m": seg[:, 0, 1], "x1_m": seg[:, 1, 0], "y1_m": seg[:, 1, 1],
        "macro_time_s": run.macro_time[idx]})
