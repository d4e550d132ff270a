"""``bench``: what a creep run costs on this machine, every number from one run.

Scenes: the specimen (10 x 20 mm, seed 1; ``--quick`` a smaller one) with rigid cells at 1 and at 8
spheres per cell and with finite-element cells (``params/presets/fem_coarse.toml``), each ramped as a
creep run ramps it to 0.7 x its own ``calibration.reference_ucs`` (``--ratio``), then held by the
servo with the stress-corrosion engine in place and relaxed to equilibrium, as in a creep run; then
a few events of the event clock are timed, and the scene is measured at the held load after them:

1. DEM steps per second and the engine overhead: the wall time of N DEM steps taken four ways,
   interleaved in time (their order rotates each repeat) so that each ratio compares neighbouring
   windows of this shared machine:
   ``yade_only`` (``O.run(N)`` in YADE's own thread: its engines only, nothing from Python), ``python_stepping``
   (``O.step()`` N times from Python, no driver), ``drivers`` (:meth:`GrainScene.run`, as a creep run
   steps: the servo before each step, break bookkeeping after it), ``relaxation_loop`` (as
   :meth:`CreepRun.relax` steps: ``GrainScene.run`` in chunks of ``creep.check_period`` with the
   break marking, failure and equilibrium checks between chunks).  Engine overhead = wall(drivers) /
   wall(yade_only), the median of the per-repeat ratios (with quartiles and range); ``*_cpu``: the
   same ratio of the process's CPU time, which waiting for a core does not inflate (on this VM it
   follows the wall time: the spread between windows is in the CPU's speed, not in waiting).
   ``drivers_s_per_step``: one call of the drivers (the servo) timed alone, and the overhead it
   implies, 1 + that x the YADE-only steps per second.
2. Per-event cost of the event clock over a few events: relaxation DEM steps and wall time per
   event, the clock's own work between two relaxations (law, bond reads and writes, hand-over,
   history row), and the time to read the forces of all intact bonds once and to write all their
   strengths once (:class:`StressCorrosion`), each the median of a few repeats.
3. Peak memory (``ru_maxrss``, cumulative: scenes run one after the other in one process).

Unless ``--quick``: creep to failure with the event and with the paper clock at 1 sphere per cell,
same specimen and load, one run each (DEM steps, wall time, lifetime).

``--static``: the static engine's part instead (:mod:`.bench_static`): static against YADE CPU per creep event,
static CPU per event against specimen size and its exponent in the dofs, events, equilibria and active-set
iterations per event, CPU per quiet event, peak memory.

No number here is comparable with another run's: the machine is shared and noisy.  Ratios are
only formed between windows of the same run.
"""
from __future__ import annotations

import datetime as _dt
import os
import platform
import resource
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

from ..engines.registry import ENGINE_NAMES, engine, engine_for
from ..protocols.timed_creep import TimedCreepRun
from .bench_static import HOLD_STRESS_PA, STATIC_OUT, STATIC_QUICK_OUT, run_static_bench, settings_for, static_tables

#: Where the full bench writes by default.
DEFAULT_OUT = Path(__file__).resolve().parents[2] / "docs" / "bench.json"
#: The finite-element-cells preset.
FEM_PRESET = Path(__file__).resolve().parents[2] / "params" / "presets" / "fem_coarse.toml"
#: Benchmarked scenes: key, label, extra parameter files, overrides (applied after the user's).
SCENES = (
    ("rigid_1", "rigid, 1 sphere/cell", (), ("resolution.grain_model=rigid", "resolution.spheres_per_cell=1")),
    ("rigid_8", "rigid, 8 spheres/cell", (), ("resolution.grain_model=rigid", "resolution.spheres_per_cell=8")),
    ("fem", "finite-element cells", (FEM_PRESET,), ()),
)
#: The scene of the clocks-to-failure comparison.
FAILURE_SCENE = "rigid_1"
#: Driving-stress ratio of calibration.reference_ucs held in every scene.
DEFAULT_RATIO = 0.7
#: Where ``bench --fem-sizes`` writes by default.
FEM_SIZES_OUT = DEFAULT_OUT.with_name("bench_fem_sizes.json")
#: Specimens of the finite-element size comparison: name, width [m], height [m] (the paper's: section 3.1).
FEM_SIZES = (("10x20", 10e-3, 20e-3), ("paper", 31.7e-3, 63.4e-3))
#: Seeds of the finite-element size comparison.
FEM_SEEDS = (1, 2, 3)
#: DEM steps of the loading ramp before and inside the timed window of the size comparison (the
#: profile of docs/studies/fem_speed.md: 200 and 1,000).
FEM_WARMUP_STEPS, FEM_TIMED_STEPS = 200, 1000


@dataclass(frozen=True)
class BenchSettings:
    """How much of each measurement a bench takes."""
    width_m: float
    height_m: float
    window_s: float       # wall time aimed at per timing window
    repeats: int          # timing windows per way of stepping (and bond read/write repeats)
    events: int           # event-clock events timed per scene
    to_failure: bool      # creep to failure with both clocks (1 sphere per cell)


FULL = BenchSettings(width_m=10e-3, height_m=20e-3, window_s=0.4, repeats=25, events=5, to_failure=True)
#: About a minute on this 2-core machine: a smaller specimen (the retired spring lattice's ramp and
#: first relaxation alone took about a minute at 10 x 20 mm; at 6 x 12 mm, seed 1, its ramp took 170k
#: DEM steps and the load was not held), short windows, 2 events, no runs to failure.
QUICK = BenchSettings(width_m=5e-3, height_m=10e-3, window_s=0.2, repeats=5, events=2, to_failure=False)


def register(sub, common):
    p = sub.add_parser("bench", help="benchmark: DEM steps/s, engine overhead, per-event cost, memory, machine "
                                     "(docs/bench.json and a markdown table)")
    p.add_argument("--quick", action="store_true",
                   help=f"about a minute: {QUICK.width_m * 1e3:g} x {QUICK.height_m * 1e3:g} mm, short windows, "
                        f"{QUICK.events} events per scene, no runs to failure")
    p.add_argument("--out", help=f"JSON file to write (default {DEFAULT_OUT.relative_to(DEFAULT_OUT.parents[1])}; "
                                 "with --quick, results/bench_quick.json)")
    from ._args import seed_type
    p.add_argument("--seed", type=seed_type, default=1, help="specimen seed (default 1)")
    p.add_argument("--ratio", type=float, default=DEFAULT_RATIO,
                   help="creep load as a ratio of each scene's calibration.reference_ucs (default 0.7)")
    p.add_argument("--params", action="append", default=[], metavar="FILE",
                   help="TOML file merged over the shipped parameters, under each scene's own settings")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="override one parameter in every scene (a scene's own keys win)")
    p.add_argument("--fem-sizes", action="store_true",
                   help="only the finite-element size comparison: params/presets/fem_coarse.toml on 10 x 20 mm and the "
                        "paper's 31.7 x 63.4 mm, seeds 1-3, critical and actual DEM step and the CPU cost of "
                        f"{FEM_TIMED_STEPS} loading steps (default out: "
                        f"{FEM_SIZES_OUT.relative_to(FEM_SIZES_OUT.parents[1])}; about 5 CPU min)")
    p.add_argument("--creep-stress", type=float, metavar="MPA",
                   help="with --fem-sizes: also one paper-size creep run to failure at this stress [MPa] "
                        "(seed 1, event clock), with its CPU time and relaxation steps per event; with --static: the "
                        f"held stress (default {HOLD_STRESS_PA / 1e6:g})")
    p.add_argument("--static", action="store_true",
                   help="only the static engine's part: static against YADE CPU per creep event (fem cells, 10 x 20 "
                        "mm), static CPU per event on 10 x 20, 20 x 40 and 31.7 x 63.4 mm and its exponent in the dofs, "
                        "events, equilibria and iterations per event, CPU per quiet event, peak memory (default out: "
                        f"{STATIC_OUT.relative_to(STATIC_OUT.parents[1])}; with --quick tiny specimens, "
                        f"{STATIC_QUICK_OUT}; about 5 CPU min, seconds with --quick)")
    p.add_argument("--static-large", action="store_true",
                   help="with --static: also the 63.4 x 126.8 mm specimen (~142,500 dofs; its hold did not "
                        "finish in 36 CPU min: docs/studies/static_bench.md)")
    p.set_defaults(func=cmd_bench)


def cmd_bench(args) -> int:
    from ..errors import GrainfracError
    from ..runs.runio import write_json
    if args.static_large and not args.static:
        raise GrainfracError("--static-large belongs to the static engine's bench; fix: add --static")
    if args.static and args.fem_sizes:
        raise GrainfracError("--static and --fem-sizes are two benches; fix: run them one at a time")
    if args.static:
        out = Path(args.out or (STATIC_QUICK_OUT if args.quick else STATIC_OUT))
        out.parent.mkdir(parents=True, exist_ok=True)
        stress = HOLD_STRESS_PA if args.creep_stress is None else args.creep_stress * 1e6
        load_start = os.getloadavg()[0]
        header = {"machine": machine()}
        result = run_static_bench(settings_for(args.quick, args.static_large), seed=args.seed, stress=stress,
                                  preset=FEM_PRESET, extra_files=args.params, overrides=args.overrides, header=header,
                                  peak_rss=peak_rss_mb, progress=print, out=out)
        result["machine"]["load_average_1min"] = f"{load_start:.2f} at the start, {os.getloadavg()[0]:.2f} at the end"
        result["bench"]["quick"] = bool(args.quick)
        write_json(out, result)
        print(static_tables(result))
        print(f"written: {out}")
        return 0
    if args.creep_stress is not None and not args.fem_sizes:
        raise GrainfracError("--creep-stress belongs to the finite-element size comparison or the static bench; fix: "
                             "add --fem-sizes or --static")
    if args.fem_sizes:
        out = Path(args.out or FEM_SIZES_OUT)
        out.parent.mkdir(parents=True, exist_ok=True)
        result = run_fem_sizes(extra_files=args.params, overrides=args.overrides, creep_stress_mpa=args.creep_stress,
                               progress=print, out=out)
        print(fem_sizes_table(result))
        print(f"written: {out}")
        return 0
    settings = QUICK if args.quick else FULL
    out = Path(args.out or ("results/bench_quick.json" if args.quick else DEFAULT_OUT))
    out.parent.mkdir(parents=True, exist_ok=True)
    result = run_bench(settings, seed=args.seed, ratio=args.ratio, extra_files=args.params,
                       overrides=args.overrides, progress=print)
    write_json(out, result)
    print(markdown_tables(result))
    print(f"written: {out}")
    return 0


# ---------------------------------------------------------------------------------------- the run
def run_bench(settings: BenchSettings, seed=1, ratio=DEFAULT_RATIO, extra_files=(), overrides=(),
              progress=None) -> dict:
    """Every measurement of the bench, as the JSON stores it."""
    from ..errors import GrainfracError
    from ..runs.runio import code_version
    progress = progress or (lambda msg: None)
    if not 0 < ratio < 1:
        raise GrainfracError(f"--ratio {ratio}: a driving-stress ratio must lie in (0, 1); fix: e.g. --ratio 0.7")
    t0 = time.perf_counter()
    load_start = os.getloadavg()[0]
    user_overrides = [f"specimen.width={settings.width_m}", f"specimen.height={settings.height_m}", *overrides]

    def params_of(key, *more):
        _, _, files, own = next(s for s in SCENES if s[0] == key)
        return scene_params(extra_files, files, user_overrides, [*own, *more])

    result = {
        "bench": {"quick": settings is QUICK, "settings": asdict(settings), "seed": seed, "load_ratio": ratio,
                  "load_refers_to": "calibration.reference_ucs of each scene's parameters",
                  "code_version": code_version(), "argv": list(sys.argv),
                  "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")},
        "machine": machine(),
        "scenes": {},
    }
    for key, label, _, _ in SCENES:
        s = result["scenes"][key] = {"label": label, **bench_scene(params_of(key), seed, ratio, settings)}
        progress(f"{label}: {s['steps_per_s']:.0f} DEM steps/s, engine overhead {s['engine_overhead']:.3f}, "
                 f"{_num(s['events'].get('relaxation_steps_median'), '.0f')} relaxation steps per event")
    if settings.to_failure:
        result["clocks_to_failure"] = {
            "scene": FAILURE_SCENE,
            **clocks_to_failure(lambda clock: params_of(FAILURE_SCENE, f"stress_corrosion.clock={clock}"), seed,
                                ratio, progress=progress)}
    result["peak_rss_mb"] = peak_rss_mb()
    result["bench"]["wall_s"] = time.perf_counter() - t0
    result["machine"]["load_average_1min"] = f"{load_start:.2f} at the start, {os.getloadavg()[0]:.2f} at the end"
    return result


def scene_params(user_files, scene_files, user_overrides, scene_overrides):
    """Parameters of one scene: the shipped files, the user's files, the scene's files, then the
    user's overrides and the scene's own (which win)."""
    from ..params import load_parameters, require_plane
    params = load_parameters(extra_files=[*user_files, *scene_files], overrides=[*user_overrides, *scene_overrides])
    require_plane(params, "bench")
    return params


def bench_scene(params, seed, ratio, settings: BenchSettings) -> dict:
    """Ramp, hold and relax one scene as a creep run does; time a few events, then its stepping and bond I/O."""
    from ..errors import GrainfracError
    from ..geometry.specimen import build_specimen
    engine = engine_for(params)
    stress = ratio * params.calibration.reference_ucs
    specimen = build_specimen(params, seed)
    run = TimedCreepRun(specimen, params, stress, max_events=settings.events,
                        at_hold=lambda r: {**engine.timings.time_stepping(r, settings.window_s, settings.repeats),
                                           **engine.timings.time_bond_io(r.corr, settings.repeats)})
    run.run()
    if run.measured is None:
        raise GrainfracError(f"bench: the scene ({params.resolution.grain_model} cells, "
                             f"{params.resolution.spheres_per_cell} spheres/cell) did not reach the creep phase at "
                             f"{stress / 1e6:.1f} MPa ({run.failure_reason}); fix: a lower --ratio")
    sc = run.scene
    return {
        "grain_model": params.resolution.grain_model, "spheres_per_cell": params.resolution.spheres_per_cell,
        "stress_pa": stress, "n_cells": specimen.n_cells, "n_bodies": sc.counts()["n_bodies"],
        "n_bonds": sc.n_bonds, "n_interactions": sc.counts()["n_interactions_listed"], "dem_timestep_s": sc.dt,
        "ramp_steps": run.rows[0]["step"], "ramp_wall_s": run.ramp_wall_s,
        "steps_to_first_equilibrium": run.hold_steps, "equilibrium_at_hold": run.initial_bond_stresses is not None,
        "held_after_events": not run.failed,
        **run.measured,
        "events": run.event_costs(),
        "peak_rss_mb_after": peak_rss_mb(),
    }


def clocks_to_failure(params_for_clock, seed, ratio, progress=None) -> dict:
    """Creep to failure with the event and with the paper clock, one run each, same specimen and load.

    ``params_for_clock(clock)`` gives the parameters with ``stress_corrosion.clock`` set."""
    from ..geometry.specimen import build_specimen
    out = {}
    for clock in ("event", "paper"):
        params = params_for_clock(clock)
        stress = out["stress_pa"] = ratio * params.calibration.reference_ucs
        t0, c0 = time.perf_counter(), time.process_time()
        run = TimedCreepRun(build_specimen(params, seed), params, stress)
        run.run()
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        first, last = run.rows[0], run.rows[-1]
        creep_steps, creep_wall = last["step"] - first["step"], last["wall_s"] - first["wall_s"]
        out[clock] = {
            "failed": bool(run.failed), "numerical_failure": bool(run.numerical_failure),
            "failure_reason": run.failure_reason or "not failed",
            ("lifetime_s" if run.failed else "creep_time_end_s"): last["creep_time_s"],
            "n_events": run.n_events, "dem_steps": int(run.scene.steps), "wall_s": wall, "cpu_s": cpu,
            "creep_dem_steps": creep_steps, "creep_wall_s": creep_wall, "creep_steps_per_s": creep_steps / creep_wall,
        }
        if clock == "event":
            out[clock]["events"] = run.event_costs()
        progress(f"to failure, {clock} clock: {run.failure_reason or 'not failed'} at {last['creep_time_s']:.4g} s "
                 f"creep time, {out[clock]['dem_steps']} DEM steps, {wall:.1f} s")
    event, paper = out["event"], out["paper"]
    out["paper_over_event_dem_steps"] = paper["dem_steps"] / event["dem_steps"]
    out["paper_over_event_wall"] = paper["wall_s"] / event["wall_s"]
    out["paper_over_event_cpu"] = paper["cpu_s"] / event["cpu_s"]
    if event.get("lifetime_s") and paper.get("lifetime_s"):
        out["paper_over_event_lifetime"] = paper["lifetime_s"] / event["lifetime_s"]
    return out


def run_fem_sizes(extra_files=(), overrides=(), creep_stress_mpa=None, progress=None, out=None) -> dict:
    """Finite-element cells on 10 x 20 mm and on the paper's specimen, seeds 1-3: the critical DEM step by
    the core's bound (no YADE) and the scene's, the DEM step, and DEM steps and body-steps per CPU second of
    a loading ramp; the paper-size cost per body against the 10 x 20 mm one of the same seed.  With
    ``creep_stress_mpa``, one paper-size creep run to failure (seed 1).  ``out``: JSON rewritten after each
    scene, so that partial results survive an interruption."""
    from ..errors import GrainfracError
    from ..grains import critical_dem_step
    from ..runs.runio import code_version, write_json
    from ..geometry.specimen import build_specimen
    progress = progress or (lambda msg: None)
    if creep_stress_mpa is not None and not creep_stress_mpa > 0:
        raise GrainfracError(f"--creep-stress {creep_stress_mpa}: a creep stress must be positive [MPa]; fix: e.g. "
                             "--creep-stress 160")
    t0, load_start = time.perf_counter(), os.getloadavg()[0]
    result = {"bench": {"kind": "fem_sizes", "preset": str(FEM_PRESET.relative_to(FEM_PRESET.parents[2])),
                        "overrides": list(overrides), "warmup_steps": FEM_WARMUP_STEPS, "timed_steps": FEM_TIMED_STEPS,
                        "code_version": code_version(), "argv": list(sys.argv),
                        "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")},
              "machine": machine(), "scenes": []}

    def save():
        result["peak_rss_mb"] = peak_rss_mb()
        result["bench"]["wall_s"] = time.perf_counter() - t0
        result["machine"]["load_average_1min"] = f"{load_start:.2f} at the start, {os.getloadavg()[0]:.2f} now"
        if out is not None:
            write_json(out, result)

    for seed in FEM_SEEDS:
        for name, width, height in FEM_SIZES:
            params = scene_params(extra_files, (FEM_PRESET,), [f"specimen.width={width}", f"specimen.height={height}",
                                                              *overrides], ())
            specimen = build_specimen(params, seed)
            row = {"specimen": name, "seed": seed, "n_cells": specimen.n_cells,
                   "edges_collapsed": specimen.edges_collapsed,
                   "critical_step_core_s": critical_dem_step(specimen, params),
                   **engine_for(params).timings.loading_step_cost(specimen, params, FEM_WARMUP_STEPS, FEM_TIMED_STEPS)}
            result["scenes"].append(row)
            progress(f"fem {name}, seed {seed}: critical step {row['critical_step_s']:.3g} s, "
                     f"{row['dem_steps_per_cpu_s']:.1f} DEM steps / CPU s, "
                     f"{row['body_steps_per_cpu_s'] / 1e6:.2f} M body-steps / CPU s")
            save()
    by = {(r["specimen"], r["seed"]): r for r in result["scenes"]}
    result["paper_cost_per_body_over_small"] = {
        str(seed): by[("10x20", seed)]["body_steps_per_cpu_s"] / by[("paper", seed)]["body_steps_per_cpu_s"]
        for seed in FEM_SEEDS}
    if creep_stress_mpa is not None:
        result["paper_creep"] = paper_creep_to_failure(extra_files, overrides, creep_stress_mpa * 1e6, progress)
    save()
    return result


def paper_creep_to_failure(extra_files, overrides, stress, progress) -> dict:
    """One paper-size finite-element creep run to failure (seed 1, event clock): lifetime or what ended it, DEM
    steps, CPU time, and the relaxation steps per event."""
    from ..geometry.specimen import build_specimen
    _, width, height = FEM_SIZES[-1]
    params = scene_params(extra_files, (FEM_PRESET,), [f"specimen.width={width}", f"specimen.height={height}",
                                                      *overrides], ("stress_corrosion.clock=event",))
    t0, c0 = time.perf_counter(), time.process_time()
    run = TimedCreepRun(build_specimen(params, FEM_SEEDS[0]), params, stress)
    run.run()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    last = run.rows[-1]
    out = {"seed": FEM_SEEDS[0], "stress_pa": stress, "failed": bool(run.failed),
           "failure_reason": run.failure_reason or "not failed",
           "held_after_ramp": run.initial_bond_stresses is not None,
           ("lifetime_s" if run.failed else "creep_time_end_s"): last["creep_time_s"], "n_events": run.n_events,
           "dem_steps": int(run.scene.steps), "ramp_steps": run.rows[0]["step"], "wall_s": wall, "cpu_s": cpu,
           "events": run.event_costs()}
    progress(f"paper-size fem creep at {stress / 1e6:.0f} MPa: {out['failure_reason']} at {last['creep_time_s']:.4g} s "
             f"creep time, {out['dem_steps']} DEM steps, {cpu:.0f} CPU s")
    return out


def fem_sizes_table(result: dict) -> str:
    """``bench --fem-sizes`` as markdown: one row per specimen and seed, the cost ratio, the creep run."""
    b, m = result["bench"], result["machine"]
    lines = [f"Finite-element size bench ({b['date']}, {b['code_version']}): {m['cpu_model']}, {m['cores']} cores, "
             f"YADE {m['yade']}, OMP_NUM_THREADS {m['omp_num_threads']}; load average {m['load_average_1min']}; "
             f"{b['preset']} {' '.join('--set ' + o for o in b['overrides'])}; {b['timed_steps']} loading DEM steps "
             f"after {b['warmup_steps']}; peak memory {result['peak_rss_mb']:.0f} MB; wall time {b['wall_s']:.0f} s.", "",
             "| specimen | seed | cells | edges collapsed | bodies | critical step, core [s] | critical step, scene [s] | "
             "DEM step [s] | DEM steps / CPU s | body-steps / CPU s |", "|" + "---|" * 10]
    for r in result["scenes"]:
        lines.append(f"| {r['specimen']} | {r['seed']} | {r['n_cells']} | {r['edges_collapsed']} | {r['n_bodies']} | "
                     f"{r['critical_step_core_s']:.3g} | {r['critical_step_s']:.3g} | {r['dem_step_s']:.3g} | "
                     f"{r['dem_steps_per_cpu_s']:.1f} | {r['body_steps_per_cpu_s'] / 1e6:.2f} M |")
    ratios = result.get("paper_cost_per_body_over_small", {})
    if ratios:
        lines += ["", "Cost per body, paper size over 10 x 20 mm (seeds " + ", ".join(ratios) + "): " +
                  " / ".join(f"x {v:.2f}" for v in ratios.values()) + "."]
    c = result.get("paper_creep")
    if c:
        life = f"lifetime {c['lifetime_s']:.4g} s" if c["failed"] else f"not failed by {c['creep_time_end_s']:.4g} s"
        lines += ["", f"Paper-size creep at {c['stress_pa'] / 1e6:.0f} MPa (seed {c['seed']}): {c['failure_reason']}, "
                      f"{life}, {c['n_events']} events, relaxation steps per event {_event_steps(c['events'])}, "
                      f"{c['dem_steps']} DEM steps ({c['ramp_steps']} in the ramp), {c['cpu_s']:.0f} CPU s."]
    return "\n".join(lines)


def peak_rss_mb() -> float:
    """Peak resident memory of this process so far [MB] (Linux reports kB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def machine() -> dict:
    import numpy
    return {"cpu_model": cpu_model(), "cores": os.cpu_count(), "cores_usable": len(os.sched_getaffinity(0)),
            "omp_num_threads": os.environ.get("OMP_NUM_THREADS", "unset"), "python": platform.python_version(),
            **{name: engine(name).version() for name in ENGINE_NAMES}, "numpy": numpy.__version__,
            "platform": platform.platform()}


# ------------------------------------------------------------------------------------------- table
def markdown_tables(result: dict) -> str:
    """The bench as markdown: the machine line, stepping and per-event tables, the clocks to failure."""
    b, m = result["bench"], result["machine"]
    st = b["settings"]
    scenes = result["scenes"].values()
    lines = [f"{'Quick bench' if b['quick'] else 'Bench'} ({b['date']}, {b['code_version']}): {m['cpu_model']}, "
             f"{m['cores']} cores, Python {m['python']}, YADE {m['yade']}, numpy {m['numpy']}, OMP_NUM_THREADS "
             f"{m['omp_num_threads']}; load average {m['load_average_1min']}. Specimen {st['width_m'] * 1e3:g} x "
             f"{st['height_m'] * 1e3:g} mm, seed {b['seed']}, held at {b['load_ratio']:g} x calibration.reference_ucs;"
             f" {st['repeats']} interleaved windows per way of stepping; peak memory {result['peak_rss_mb']:.0f} MB; "
             f"bench wall time {b['wall_s']:.0f} s.", "",
             "| scene | bodies / bonds | load [MPa] | DEM step [s] | DEM steps/s, creep run | YADE only | "
             "engine overhead, wall (quartiles) | CPU time | from the servo's cost [us/step] | O.step() loop alone "
             "| with equilibrium checks |",
             "|" + "---|" * 11]
    for s in scenes:
        lo, hi = s["engine_overhead_quartiles"]
        lines.append(
            f"| {s['label']} | {s['n_bodies']} / {s['n_bonds']} | {s['stress_pa'] / 1e6:.1f} | "
            f"{s['dem_timestep_s']:.3g} | {s['steps_per_s']:.0f} | {s['steps_per_s_yade_only']:.0f} | "
            f"{s['engine_overhead']:.3f} ({lo:.2f}-{hi:.2f}) | {s['engine_overhead_cpu']:.3f} | "
            f"{s['engine_overhead_from_driver_cost']:.3f} ({s['drivers_s_per_step'] * 1e6:.0f}) | "
            f"{s['python_stepping_overhead']:.3f} | {s['relaxation_loop_overhead']:.3f} |")
    lines += ["", "| scene | relaxation steps/event: median, mean, max (events) | relaxation wall/event [s] | "
                  "clock work/event [ms] | read all bonds [ms] | write all strengths [ms] | law, all bonds [ms] | "
                  "peak memory so far [MB] |", "|" + "---|" * 8]
    for s in scenes:
        lines.append(f"| {s['label']} | {_event_steps(s['events'])} | "
                     f"{_num(s['events'].get('relaxation_wall_s_median'), '.3f')} | "
                     f"{_num(_ms(s['events'].get('clock_work_s_median')), '.2f')} | {s['read_all_bonds_s'] * 1e3:.2f} | "
                     f"{s['write_all_strengths_s'] * 1e3:.2f} | {s['time_to_failure_all_bonds_s'] * 1e3:.2f} | "
                     f"{s['peak_rss_mb_after']:.0f} |")
    c = result.get("clocks_to_failure")
    if c:
        lines += ["", f"Creep to failure, {result['scenes'][c['scene']]['label']}, {c['stress_pa'] / 1e6:.1f} MPa, "
                      "one run per clock:", "",
                  "| clock | lifetime [s] | events | DEM steps | wall [s] | CPU [s] | creep-phase DEM steps/s | "
                  "relaxation steps/event: median, mean, max (events) | final wait [DEM steps] |", "|" + "---|" * 9]
        for clock in ("event", "paper"):
            r = c[clock]
            ev = r.get("events", {})
            life = f"{r['lifetime_s']:.4g}" if r["failed"] else f"not failed by {r['creep_time_end_s']:.4g}"
            lines.append(f"| {clock} | {life} | {r['n_events']} | {r['dem_steps']} | {r['wall_s']:.1f} | "
                         f"{r['cpu_s']:.1f} | {r['creep_steps_per_s']:.0f} | {_event_steps(ev) if ev else '-'} | "
                         f"{_num(ev.get('final_relaxation_steps'), 'd')} |")
        ratios = (f"paper / event: DEM steps x{c['paper_over_event_dem_steps']:.2f}, wall x{c['paper_over_event_wall']:.2f}, "
                  f"CPU x{c['paper_over_event_cpu']:.2f}")
        if "paper_over_event_lifetime" in c:
            ratios += f", lifetime x{c['paper_over_event_lifetime']:.3f}"
        lines += ["", ratios + "."]
    return "\n".join(lines)


def _event_steps(events: dict) -> str:
    if "relaxation_steps_median" not in events:
        return f"- ({events['n_events_timed']})"
    return (f"{events['relaxation_steps_median']:.0f}, {events['relaxation_steps_mean']:.0f}, "
            f"{events['relaxation_steps_max']:.0f} ({events['n_events_timed']})")


def _ms(seconds):
    return None if seconds is None else seconds * 1e3


def _num(value, fmt: str) -> str:
    return "-" if value is None else format(value, fmt)
