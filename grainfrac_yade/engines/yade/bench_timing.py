"""Timing of creep scenes for the ``bench`` command: the ways of taking DEM steps and of reading and
writing bonds that a creep run uses (the creep run that times itself is engine-neutral:
:class:`grainfrac_yade.protocols.timed_creep.TimedCreepRun`)."""
from __future__ import annotations

import statistics
import time


#: DEM steps of the probe that sizes the timing windows.
PROBE_STEPS = 200
#: Ways of taking N DEM steps (see :func:`time_stepping`); engine overhead is "drivers" over "yade_only".
STEPPING_WAYS = ("yade_only", "python_stepping", "drivers", "relaxation_loop")
#: Polling interval [s] while YADE steps in its own thread: ``O.run(n, True)`` waits in quanta of
#: 40 ms (measured: 100 and 1000 DEM steps of a small scene both took 40.2 ms, 5000 took 201 ms),
#: too coarse for timing windows of 0.1-0.5 s.  The sleeping poll costs about no CPU time.
POLL_S = 2e-3


def time_stepping(run, window_s: float, repeats: int) -> dict:
    """DEM steps per second of the held scene taken four ways (:data:`STEPPING_WAYS`), interleaved;
    the overheads are medians of per-repeat ratios to ``yade_only``, with their quartiles and range.

    Adjacent windows of 0.1-0.5 s on this machine differ by up to 2 x in either direction, in CPU
    time as in wall time (measured: per-repeat ratios 0.47-2.2 around a median of 1.15): only the
    median of many repeats means something."""
    scene, O = run.scene, run.scene.O
    period = run.params.creep.check_period
    t = time.perf_counter()
    scene.run(PROBE_STEPS)
    probe = time.perf_counter() - t
    n = max(1, round(window_s / probe * PROBE_STEPS / period)) * period

    def python_stepping():
        for _ in range(n):
            O.step()

    def relaxation_loop():   # as CreepRun.relax steps, without stopping at equilibrium
        for _ in range(n // period):
            scene.run(period)
            run.mark_breaks(run.corr.creep_time)
            run.check_failure()
            run.at_equilibrium(run.servo)

    def yade_only():
        O.run(n)
        while O.running:
            time.sleep(POLL_S)

    ways = {"yade_only": yade_only, "python_stepping": python_stepping,
            "drivers": lambda: scene.run(n), "relaxation_loop": relaxation_loop}
    walls = {way: [] for way in STEPPING_WAYS}
    cpus = {way: [] for way in STEPPING_WAYS}
    for r in range(repeats):
        k = r % len(STEPPING_WAYS)
        for way in STEPPING_WAYS[k:] + STEPPING_WAYS[:k]:
            t, c = time.perf_counter(), time.process_time()
            ways[way]()
            walls[way].append(time.perf_counter() - t)
            cpus[way].append(time.process_time() - c)
    out = {"timing_window_steps": n, "timing_repeats": repeats}
    for way in STEPPING_WAYS:
        out[f"steps_per_s_{way}"] = n / statistics.median(walls[way])
    out["steps_per_s"] = out["steps_per_s_drivers"]
    for way, name in (("drivers", "engine_overhead"), ("python_stepping", "python_stepping_overhead"),
                      ("relaxation_loop", "relaxation_loop_overhead")):
        ratios = [a / b for a, b in zip(walls[way], walls["yade_only"])]
        q1, median, q3 = statistics.quantiles(ratios, n=4)
        out[name] = median
        out[f"{name}_quartiles"] = [q1, q3]
        out[f"{name}_range"] = [min(ratios), max(ratios)]
        # CPU time of the process (all threads): waiting for a core does not count
        out[f"{name}_cpu"] = statistics.median(a / b for a, b in zip(cpus[way], cpus["yade_only"]))
    out.update(time_drivers(scene, n, repeats))
    # the overhead the drivers' own cost implies: less noisy than the ratio of two noisy windows
    out["engine_overhead_from_driver_cost"] = 1.0 + out["drivers_s_per_step"] * out["steps_per_s_yade_only"]
    return out


def time_drivers(scene, calls: int, repeats: int) -> dict:
    """Wall time of one call of every driver's ``before_step`` (what :meth:`GrainScene.run` adds to
    each DEM step besides the break check), the median of ``repeats`` loops of ``calls`` calls
    without DEM steps in between (a servo sets the same platen speed again each time)."""
    walls = []
    for _ in range(repeats):
        t = time.perf_counter()
        for _ in range(calls):
            for d in scene.drivers:
                d.before_step(scene)
        walls.append((time.perf_counter() - t) / calls)
    return {"drivers": ", ".join(d.name for d in scene.drivers), "drivers_s_per_step": statistics.median(walls)}


def time_bond_io(corr, repeats: int) -> dict:
    """Wall time to read the forces of all intact bonds once, to write all their strengths once, and to
    evaluate the law's time to failure for all of them (medians of ``repeats``)."""
    idx = corr.intact()
    read, write, law = [], [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        stresses = corr.stresses(idx)
        t1 = time.perf_counter()
        corr.write(idx)   # the current strengths: writing them changes nothing
        t2 = time.perf_counter()
        corr.law.time_to_failure(corr.state.subset(idx), stresses)
        law.append(time.perf_counter() - t2)
        read.append(t1 - t0)
        write.append(t2 - t1)
    n = len(idx)
    return {"n_intact_bonds": n, "read_all_bonds_s": statistics.median(read),
            "write_all_strengths_s": statistics.median(write), "time_to_failure_all_bonds_s": statistics.median(law),
            "read_per_bond_s": statistics.median(read) / n, "write_per_bond_s": statistics.median(write) / n}


def loading_step_cost(specimen, params, warmup: int, steps: int, engine_timing: bool = False) -> dict:
    """CPU cost of DEM steps of a strain-controlled loading ramp (the platens at ``ucs.strain_rate``, as a
    UCS test moves them): ``warmup`` steps, then ``steps`` steps through :meth:`GrainScene.run` timed by
    the process's CPU clock (which waiting for a core does not inflate).

    Returns the scene's size, its DEM step and critical step, DEM steps and body-steps per CPU second,
    and with ``engine_timing`` the share of each engine in YADE's own engine time (``execTime``)."""
    from .platens import Platens
    from .scene import build_scene
    c0 = time.process_time()
    scene = build_scene(specimen, params)
    build_cpu = time.process_time() - c0
    O = scene.O
    platens = Platens(scene, params.ucs.platen_lateral)
    scene.extras.append(platens)
    platens.set_axial_velocity(params.ucs.strain_rate * platens.height)
    scene.run(warmup)
    if engine_timing:
        O.timingEnabled = True
        for e in O.engines:
            e.execTime, e.execCount = 0, 0
    c0, w0 = time.process_time(), time.perf_counter()
    scene.run(steps)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    n_bodies = len(O.bodies)
    out = {"n_bodies": n_bodies, "n_interactions": len(O.interactions), "n_bonds": scene.n_bonds,
           "dem_step_s": O.dt, "critical_step_s": scene.dt_critical, "build_cpu_s": build_cpu,
           "warmup_steps": warmup, "steps": steps, "cpu_s": cpu, "wall_s": wall,
           "dem_steps_per_cpu_s": steps / cpu, "body_steps_per_cpu_s": steps * n_bodies / cpu}
    if engine_timing:
        engines = {(e.label or type(e).__name__): e.execTime * 1e-9 for e in O.engines}
        yade_s = sum(engines.values())
        out["python_share_of_wall"] = max(0.0, 1 - yade_s / wall)
        out["engine_share"] = {k: round(v / yade_s, 4) for k, v in sorted(engines.items(), key=lambda kv: -kv[1])}
        collider = next((e for e in O.engines if type(e).__name__ == "InsertionSortCollider"), None)
        if collider is not None:
            out.update(verlet_dist=collider.verletDist, collider_runs=int(getattr(collider, "numAction", -1)))
    return out
