"""``bench --static``: what the static engine costs per creep event, every number from one run of one process.

Finite-element cells (``params/presets/fem_coarse.toml``), seed 1 (``--seed``), a creep hold at 160 MPa
(``--creep-stress``) with the event clock, as the static engine's cost tables (docs/studies/static_bench.md):

1. **Static against YADE per creep event** on 10 x 20 mm (``--quick``: 4 x 8 mm): the creep test of
   :mod:`grainfrac_yade.protocols.creep` on each engine in turn, in this process, for a few events each (ramp, first
   relaxation, then the event clock).  An event's CPU runs from the end of one relaxation of the event clock's loop
   to the end of the next (the law, the bonds written, the clock's bookkeeping and the relaxation: YADE's dynamic
   relaxation, the static engine's solve back to the held stress).  The ratio YADE / static of the mean CPU per
   event is formed within the run; the steps per event are DEM steps (YADE) and equilibria solved (static).
2. **Static CPU per event against specimen size** (10 x 20, 20 x 40 and the paper's 31.7 x 63.4 mm; 63.4 x 126.8
   mm with ``--static-large``; ``--quick``: 3 x 6, 4 x 8 and 6 x 12 mm): the same creep test on the static engine's
   plain path (``numerics.static_relaxation = "none"``, :data:`SIZE_SERIES_OVERRIDES`), timed as in part 1
   (:func:`static_hold`), with the solver's counters read through the engine registry (the static engine's
   ``solver_counters`` and ``path_summary``), the same number of events from the start of each hold: dofs, the
   scene's build (layout, network, first equilibrium), the ramp (the protocol's strain-controlled ramp, the
   servo's hold and the event loop's first relaxation: CPU, equilibria, bonds broken), events, CPU, equilibria and
   active-set iterations per event, CPU per quiet event (one that breaks only what the creep law took to failure),
   the peak memory so far (``ru_maxrss``: cumulative, the sizes run smallest first), and the exponent b of CPU per
   event ~ dofs^b fitted by least squares in log-log over the sizes.  (Until this measured the protocol, it timed
   the static core's own creep hold, a second driver since retired: docs/studies/static_bench.md says what moved.)

3. **The collapse** on the comparison's specimen: the same creep hold to its end with the static engine and its
   inertial relaxation (``numerics.static_relaxation = "inertial"``: the core's own small-strain dynamics where the
   static regain gives out) and with the hybrid engine (YADE's dynamic stint there): lifetime, events, the end, the
   CPU of the whole run and of the dynamic part (``static_relaxation_cpu_s``, ``dynamic_stint_cpu_s``), and their
   ratio hybrid / inertial, formed within the run.

All times are the process's CPU time (``time.process_time``), which waiting for a core does not inflate; on this
shared machine they still vary by ~20 % between runs, so no number here is comparable with another run's.  The JSON
(``--out``, default ``docs/bench_static.json``; ``--quick``: ``results/bench_static_quick.json``) is rewritten after
each part, so that partial results survive an interruption; the markdown tables are printed at the end.
"""
from __future__ import annotations

import datetime as _dt
import math
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from ..engines.registry import engine_for
from ..errors import GrainfracError
from ..geometry.specimen import build_specimen
from ..params import load_parameters, require_plane
from ..protocols.creep import run_creep
from ..protocols.creep_output import end_reason
from ..protocols.timed_creep import TimedCreepRun
from ..runs.runio import code_version, write_json

#: The checkout's root (paths in the JSON are written relative to it where they lie inside it).
ROOT = Path(__file__).resolve().parents[2]
#: Where ``bench --static`` writes by default, and with ``--quick``.
STATIC_OUT = ROOT / "docs" / "bench_static.json"
STATIC_QUICK_OUT = Path("results/bench_static_quick.json")
#: The held stress [Pa]: the static engine's creep holds (docs/studies/static_engine.md) and YADE's paper-size ones.
HOLD_STRESS_PA = 160e6
#: The clock of every hold: the event clock (the static engine has no dynamics for the paper's clock, Eq. 8).
CLOCK = "event"
#: The size series' own settings: the plain static path (a status set that does not settle ends the hold as a
#: numerical failure), the path whose cost per event the size series has measured since it timed the static core's
#: own hold; the relaxations (``numerics.static_relaxation``) are the collapse's part.
SIZE_SERIES_OVERRIDES = ("numerics.static_relaxation=none",)
#: Events between two progress lines of a size's hold (event 0: the end of its ramp) [1].
EVENT_LINES = 5
#: The largest specimen (name, width [m], height [m]): ~142,500 dofs; its hold of 20 events did not finish in 36 CPU
#: minutes (docs/studies/static_bench.md).
LARGE_SIZE = ("63.4x126.8", 63.4e-3, 126.8e-3)


@dataclass(frozen=True)
class StaticBenchSettings:
    """How much a static bench measures: the specimen of the static-against-YADE comparison (name, width [m], height
    [m]; None: no comparison) and its events per engine; the specimens of the size series and their events."""
    compare: tuple | None
    compare_events: int
    sizes: tuple
    events: int


#: The full static bench: 5 events per engine on 10 x 20 mm (YADE's ramp and relaxations dominate it, a few CPU
#: minutes); 20 events per size (the paper-size ramp alone ~70-85 CPU s).
STATIC_FULL = StaticBenchSettings(compare=("10x20", 10e-3, 20e-3), compare_events=5,
                                  sizes=(("10x20", 10e-3, 20e-3), ("20x40", 20e-3, 40e-3), ("31.7x63.4", 31.7e-3, 63.4e-3)),
                                  events=20)
#: Seconds: YADE's tiny fem hold (4 x 8 mm, 3 events: ~3 CPU s) and three tiny static sizes.
STATIC_QUICK = StaticBenchSettings(compare=("4x8", 4e-3, 8e-3), compare_events=3,
                                   sizes=(("3x6", 3e-3, 6e-3), ("4x8", 4e-3, 8e-3), ("6x12", 6e-3, 12e-3)), events=5)


def settings_for(quick: bool, large: bool) -> StaticBenchSettings:
    """The full or quick settings, with the largest specimen added to the size series (``large``)."""
    base = STATIC_QUICK if quick else STATIC_FULL
    return StaticBenchSettings(base.compare, base.compare_events, base.sizes + ((LARGE_SIZE,) if large else ()),
                               base.events)


def size_params(preset, user_files, width, height, user_overrides, engine_name):
    """Parameters of one specimen: the shipped files, the user's, the fem preset, then the user's overrides and this
    bench's own (size, engine, the event clock: they win)."""
    params = load_parameters(extra_files=[*user_files, preset],
                             overrides=[*user_overrides, f"specimen.width={width}", f"specimen.height={height}",
                                        f"numerics.engine={engine_name}", f"stress_corrosion.clock={CLOCK}"])
    require_plane(params, "bench")
    return params


class EventCpuRun(TimedCreepRun):
    """A timed creep run (:class:`TimedCreepRun`, stopped after ``max_events``) that also marks, at the end of every
    relaxation of the event clock's loop (module doc): the process's CPU time, the scene's step count, the bonds
    broken, the clock's count of bonds the law took to failure, the axial strain and ``counters(scene)`` (the
    engine's solver counters; None: none)."""

    def __init__(self, *args, counters=None, on_mark=None, **kwargs):
        super().__init__(*args, **kwargs)
        self.in_event_loop = False
        self.counters, self.on_mark = counters, on_mark
        self.marks = []   # (CPU s, scene steps, broken, law's failures, strain, counters) after each relaxation

    def run_event_clock(self, resume=None):
        self.in_event_loop = True
        super().run_event_clock(resume)

    def relax(self, creep_time, safe_point=None, resume=None):
        ok = super().relax(creep_time, safe_point, resume)
        if self.in_event_loop:
            self.marks.append((time.process_time(), self.scene.steps, int(self.scene.broken.sum()),
                               self.clock.n_failures, self.platens.axial_strain(),
                               self.counters(self.scene) if self.counters is not None else None))
            if self.on_mark is not None:
                self.on_mark(self)
        return ok


def engine_events(params, seed, stress, events) -> dict:
    """One engine's creep test held at ``stress`` [Pa] for ``events`` events: its size, the CPU of the ramp and first
    relaxation, and the CPU and steps of each event (module doc)."""
    c0 = time.process_time()
    specimen = build_specimen(params, seed)
    run = EventCpuRun(specimen, params, stress, max_events=events)
    run.run()
    _require_events(run, params, stress)
    m = np.array([mk[:2] for mk in run.marks], float)
    cpu, steps = np.diff(m[:, 0]), np.diff(m[:, 1])
    counts = run.scene.counts()
    return {"engine": params.numerics.engine, "n_bodies": counts["n_bodies"], "n_bonds": run.scene.n_bonds,
            "ramp_and_first_relaxation_cpu_s": m[0, 0] - c0, "events": len(cpu), "event_cpu_s": cpu.tolist(),
            "event_steps": steps.astype(int).tolist(), "cpu_per_event_s": float(cpu.mean()),
            "steps_per_event": float(steps.mean()), "failed": bool(run.failed),
            "numerical_failure": bool(run.numerical_failure), "end": run.failure_reason or "events asked"}


def _require_events(run, params, stress):
    if len(run.marks) < 2:
        raise GrainfracError(f"bench --static: the {params.numerics.engine} engine's hold at {stress / 1e6:g} MPa timed "
                             f"no event ({run.failure_reason or 'it ended before the event clock'}); fix: a lower "
                             "--creep-stress")


def static_hold(params, seed, stress, events, progress=None) -> dict:
    """The creep test (:mod:`grainfrac_yade.protocols.creep`) of ``params`` on the static engine held at ``stress``
    [Pa] for at most ``events`` events, timed per event (module doc, part 2); ``params`` must name the static engine
    (or one that extends its scene).  Returns the scene's size and build CPU (layout, network, first equilibrium),
    the ramp's cost (CPU from the built scene to the end of the event loop's first relaxation, equilibria, active-set
    iterations, bonds broken, strain), the end, per-event lists (``event_cpu_s``, ``event_equilibria``,
    ``event_iterations``, ``event_broken``), their means, the CPU per quiet event (one that breaks only the bonds the
    law took to failure; None without one), the solver's counters, the path's break sequence hash, what the scene
    adds to a run's summary (``engine_keys``: e.g. its relaxations) and the events' creep times (``times``).  ``progress``:
    called with a dict after the ramp (event 0) and after each event."""
    static = engine_for(params)
    if static.timings is None or not hasattr(static.timings, "solver_counters"):
        raise GrainfracError(f"a timed static hold: numerics.engine = {params.numerics.engine!r} has no static solver "
                             "to count; fix: numerics.engine=static")
    c0 = time.process_time()
    specimen = build_specimen(params, seed)
    t0 = time.process_time()

    def mark(run):
        if progress is not None:
            cpu, _, broken, _, strain, c = run.marks[-1]
            progress({"event": len(run.marks) - 1, "cpu_s": cpu - t_run, "creep_time_s": run.clock.creep_time,
                      "broken": broken, "strain": strain, "equilibria": c["equilibria"]})
    run = EventCpuRun(specimen, params, stress, max_events=events, counters=static.timings.solver_counters, on_mark=mark)
    t_run = time.process_time()
    build = t_run - t0
    run.run()
    _require_events(run, params, stress)
    cpu = time.process_time() - t_run
    m = np.array([(c, b, f, s, k["equilibria"], k["iterations"]) for c, _, b, f, s, k in run.marks], float)
    ramp = {"cpu_s": m[0, 0] - t_run, "equilibria": int(m[0, 4]), "iterations": int(m[0, 5]), "broken": int(m[0, 1]),
            "strain": m[0, 3]}
    d = np.diff(m, axis=0)
    cpu_ev, broken, law_failed, eqs, its = d[:, 0], d[:, 1], d[:, 2], d[:, 4], d[:, 5]
    quiet = broken <= law_failed
    n = len(d)
    path = static.timings.path_summary(run.scene)
    c = static.timings.solver_counters(run.scene)
    c.update(cpu_s=cpu, cpu_per_equilibrium_s=cpu / max(c["equilibria"], 1),
             equilibria_per_break=c["equilibria"] / max(path["records"], 1),
             cpu_per_break_s=cpu / max(path["records"], 1), cpu_per_bond_s=cpu / max(path["bonds"], 1),
             iterations_per_equilibrium=c["iterations"] / max(c["equilibria"], 1))

    def mean(x):
        return float(x.mean()) if len(x) else None
    return {
        "dofs": path["dofs"], "bonds": run.scene.n_bonds, "specimen_cpu_s": t0 - c0, "build_cpu_s": build,
        "stress_pa": stress, "ramp": ramp, "events": n, "events_asked": events, "failed": bool(run.failed),
        "numerical_failure": bool(run.numerical_failure), "end": run.failure_reason or "events asked",
        "broken": int(run.scene.broken.sum()), "creep_time_s": run.clock.creep_time, "cpu_s": cpu,
        "events_cpu_s": float(cpu_ev.sum()), "cpu_per_event_s": mean(cpu_ev), "equilibria_per_event": mean(eqs),
        "iterations_per_event": mean(its),
        "iterations_per_equilibrium": float(its.sum() / eqs.sum()) if n and eqs.sum() else None,
        "bonds_per_event": mean(broken), "quiet_events": int(quiet.sum()), "cpu_per_quiet_event_s": mean(cpu_ev[quiet]),
        "event_cpu_s": cpu_ev.tolist(), "event_equilibria": eqs.astype(int).tolist(),
        "event_iterations": its.astype(int).tolist(), "event_broken": broken.astype(int).tolist(),
        "counters": c, "sequence_hash": path["sequence_hash"], "engine_keys": run.scene.summary_keys(),
        "times": [float(r["creep_time_s"]) for r in run.rows[2:]],   # the events' (rows 0, 1: the ramp's end, the hold)
    }


def compare_engines(settings, preset, user_files, overrides, seed, stress, progress) -> dict:
    """Static against YADE per creep event on ``settings.compare`` (module doc, part 1)."""
    name, width, height = settings.compare
    out = {"specimen": name, "width_m": width, "height_m": height, "events_asked": settings.compare_events}
    for engine_name in ("static", "yade"):
        params = size_params(preset, user_files, width, height, overrides, engine_name)
        r = out[engine_name] = engine_events(params, seed, stress, settings.compare_events)
        progress(f"{engine_name} engine, {name} mm: {r['events']} events, {r['cpu_per_event_s']:.3g} CPU s per event, "
                 f"{r['steps_per_event']:.0f} steps per event")
    out["yade_over_static_cpu_per_event"] = out["yade"]["cpu_per_event_s"] / out["static"]["cpu_per_event_s"]
    return out


#: The two ways through the collapse of part 3: (label, engine, static_relaxation).
COLLAPSE_ENGINES = (("static + inertial", "static", "inertial"), ("hybrid", "hybrid", "none"))


def collapse_runs(settings, preset, user_files, overrides, seed, stress, progress) -> dict:
    """The creep hold to its end on ``settings.compare``, the dynamic part in the core and in YADE (module doc,
    part 3)."""
    name, width, height = settings.compare
    out = {"specimen": name, "width_m": width, "height_m": height, "runs": []}
    for label, engine_name, relaxation in COLLAPSE_ENGINES:
        params = size_params(preset, user_files, width, height,
                             [*overrides, f"numerics.static_relaxation={relaxation}"], engine_name)
        c0 = time.process_time()
        run = run_creep(build_specimen(params, seed), params, stress)
        keys = run.scene.summary_keys()
        dyn_cpu = keys.get("static_relaxation_cpu_s", keys.get("dynamic_stint_cpu_s", 0.0))
        row = {"label": label, "engine": engine_name, "static_relaxation": relaxation, "failed": bool(run.failed),
               "numerical_failure": bool(run.numerical_failure),
               "lifetime_s": float(run.rows[-1]["creep_time_s"]) if run.failed and not run.numerical_failure else None,
               "events": int(run.n_events), "end": end_reason(run, params, float(run.rows[-1]["creep_time_s"])),
               "cpu_s": time.process_time() - c0,
               "dynamic_cpu_s": float(dyn_cpu),
               "dynamic_steps": int(keys.get("static_relaxation_steps", keys.get("dynamic_stint_dem_steps", 0)))}
        out["runs"].append(row)
        progress(f"collapse, {name} mm, {label}: {row['end']}, {row['events']} events, {row['cpu_s']:.3g} CPU s "
                 f"({row['dynamic_cpu_s']:.3g} in the dynamics)")
    a, b = out["runs"]
    out["hybrid_over_inertial_cpu"] = b["cpu_s"] / a["cpu_s"]
    out["hybrid_over_inertial_dynamic_cpu"] = (b["dynamic_cpu_s"] / a["dynamic_cpu_s"]
                                               if a["dynamic_cpu_s"] > 0 else None)
    return out


def size_series(settings, preset, user_files, overrides, seed, stress, progress, peak_rss, save, rows) -> list:
    """The creep test on the static engine's plain path on each specimen of ``settings.sizes`` (module doc, part 2),
    appended to ``rows`` (the result's list, so that ``save()`` after each size writes it)."""
    for name, width, height in settings.sizes:
        params = size_params(preset, user_files, width, height, [*overrides, *SIZE_SERIES_OVERRIDES], "static")
        progress(f"static engine, {name} mm: ramp to {stress / 1e6:g} MPa")

        def event_line(e, name=name):   # where a long hold stands: its ramp, then every EVENT_LINES-th event
            if e["event"] % EVENT_LINES == 0:
                progress(f"  {name} mm, event {e['event']}: {e['cpu_s']:.1f} CPU s, {e['equilibria']} equilibria, "
                         f"{e['broken']} bonds broken")
        hold = static_hold(params, seed, stress, settings.events, progress=event_line)
        hold.pop("times")
        rows.append({"specimen": name, "width_m": width, "height_m": height, **hold, "peak_rss_mb_after": peak_rss()})
        save()
        progress(f"static engine, {name} mm ({hold['dofs']} dofs): built in {hold['build_cpu_s']:.2f} CPU s, ramp "
                 f"{hold['ramp']['cpu_s']:.2f} CPU s, {hold['events']} events, "
                 f"{_num(hold['cpu_per_event_s'], '.3g')} CPU s per event")
    return rows


def dofs_exponent(rows) -> dict:
    """The exponent b of CPU per event ~ dofs^b: least squares in log-log over the sizes that timed an event (and of
    CPU per quiet event where two sizes or more had one)."""
    out = {}
    for key in ("cpu_per_event_s", "cpu_per_quiet_event_s"):
        pts = [(r["dofs"], r[key]) for r in rows if r.get(key)]
        if len(pts) >= 2:
            x, y = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
            out[key[:-2] + "_exponent"] = float(np.polyfit(x, y, 1)[0])   # key without its unit "_s"
            out[key[:-2] + "_sizes"] = len(pts)
    return out


def run_static_bench(settings: StaticBenchSettings, preset, seed=1, stress=HOLD_STRESS_PA, extra_files=(),
                     overrides=(), header=None, peak_rss=None, progress=None, out=None) -> dict:
    """Every measurement of ``bench --static``, as the JSON stores it; ``preset``: the fem cells' parameter file
    (``params/presets/fem_coarse.toml``), ``header``: entries put first (the machine), ``peak_rss``: the process's peak
    memory so far [MB], ``out``: the JSON rewritten after each part."""
    if not stress > 0:
        raise GrainfracError(f"--creep-stress {stress / 1e6:g}: a creep stress must be positive [MPa]; fix: e.g. "
                             "--creep-stress 160")
    progress = progress or (lambda msg: None)
    t0, c0 = time.perf_counter(), time.process_time()
    result = {**(header or {}),
              "bench": {"kind": "static", "settings": asdict(settings), "seed": seed, "stress_pa": stress,
                        "clock": CLOCK, "preset": _shown(preset), "overrides": list(overrides),
                        "code_version": code_version(), "argv": list(sys.argv),
                        "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")}}

    def save():
        result["peak_rss_mb"] = peak_rss()
        result["bench"]["wall_s"], result["bench"]["cpu_s"] = time.perf_counter() - t0, time.process_time() - c0
        if out is not None:
            write_json(out, result)

    if settings.compare is not None:
        result["engines_per_event"] = compare_engines(settings, preset, extra_files, overrides, seed, stress, progress)
        result["peak_rss_mb_after_comparison"] = peak_rss()
        save()
    if settings.compare is not None:
        result["collapse"] = collapse_runs(settings, preset, extra_files, overrides, seed, stress, progress)
        save()
    result["sizes"] = []
    size_series(settings, preset, extra_files, overrides, seed, stress, progress, peak_rss, save, result["sizes"])
    result["dofs_scaling"] = dofs_exponent(result["sizes"])
    save()
    return result


def static_tables(result: dict) -> str:
    """``bench --static`` as markdown: the machine line, static against YADE per event, the size series."""
    b, m = result["bench"], result.get("machine", {})
    lines = [f"Static bench ({b['date']}, {b['code_version']}): {m.get('cpu_model', '?')}, {m.get('cores', '?')} cores, "
             f"OMP_NUM_THREADS {m.get('omp_num_threads', '?')}, {m.get('static', '')}, YADE {m.get('yade', '?')}; load "
             f"average {m.get('load_average_1min', '?')}. Fem cells ({Path(b['preset']).name}), seed {b['seed']}, held at "
             f"{b['stress_pa'] / 1e6:g} MPa, {b['clock']} clock; peak memory {result['peak_rss_mb']:.0f} MB; bench "
             f"{b['cpu_s']:.0f} CPU s ({b['wall_s']:.0f} s wall)."]
    c = result.get("engines_per_event")
    if c:
        lines += ["", f"Per creep event, {c['specimen']} mm, the creep protocol on each engine:", "",
                  "| engine | bodies / bonds | ramp + first relaxation [CPU s] | events | CPU per event [s] | "
                  "steps per event |", "|---|---|---|---|---|---|"]
        for name, steps in (("static", "equilibria"), ("yade", "DEM steps")):
            r = c[name]
            lines.append(f"| {name} | {r['n_bodies']} / {r['n_bonds']} | {r['ramp_and_first_relaxation_cpu_s']:.2f} | "
                         f"{r['events']} | {r['cpu_per_event_s']:.4g} | {r['steps_per_event']:.0f} {steps} |")
        lines += ["", f"YADE / static, CPU per event: x {c['yade_over_static_cpu_per_event']:.1f}."]
    k = result.get("collapse")
    if k:
        lines += ["", f"The collapse, {k['specimen']} mm, the hold to its end with the dynamic part in the core and in "
                  "YADE:", "", "| run | end | lifetime [s] | events | CPU [s] | of it the dynamics [CPU s], steps |",
                  "|---|---|---|---|---|---|"]
        for r in k["runs"]:
            life = f"{r['lifetime_s']:.5g}" if r["lifetime_s"] else "-"
            lines.append(f"| {r['label']} | {r['end']} | {life} | {r['events']} | {r['cpu_s']:.3g} | "
                         f"{r['dynamic_cpu_s']:.3g}, {r['dynamic_steps']} |")
        ratio = k["hybrid_over_inertial_dynamic_cpu"]
        lines += ["", f"Hybrid / static + inertial, CPU of the run: x {k['hybrid_over_inertial_cpu']:.1f}"
                  + (f"; of the dynamics: x {ratio:.1f}." if ratio else "; the inertial run needed no dynamics.")]
    lines += ["", f"Per creep event against size, the creep test on the static engine's plain path ({b['settings']['events']} "
              "events asked each):", "",
              "| specimen [mm] | dofs | bonds | build [CPU s] | ramp: CPU [s], equilibria, bonds broken | events | "
              "CPU per event [s] | equilibria per event | iterations per event | iterations per equilibrium | "
              "quiet events | CPU per quiet event [s] | end | peak memory so far [MB] |", "|" + "---|" * 14]
    for r in result["sizes"]:
        ramp = r["ramp"]
        lines.append(f"| {r['specimen']} | {r['dofs']:,} | {r['bonds']:,} | {r['build_cpu_s']:.2f} | "
                     f"{ramp['cpu_s']:.2f}, {ramp['equilibria']}, {ramp['broken']} | {r['events']} | "
                     f"{_num(r['cpu_per_event_s'], '.4g')} | {_num(r['equilibria_per_event'], '.2f')} | "
                     f"{_num(r['iterations_per_event'], '.2f')} | {_num(r['iterations_per_equilibrium'], '.2f')} | "
                     f"{r['quiet_events']} | {_num(r['cpu_per_quiet_event_s'], '.4g')} | {r['end']} | "
                     f"{r['peak_rss_mb_after']:.0f} |")
    s = result.get("dofs_scaling", {})
    if "cpu_per_event_exponent" in s:
        text = (f"CPU per event ~ dofs^b: b = {s['cpu_per_event_exponent']:.2f} over {s['cpu_per_event_sizes']} sizes")
        if "cpu_per_quiet_event_exponent" in s:
            text += (f"; per quiet event b = {s['cpu_per_quiet_event_exponent']:.2f} over "
                     f"{s['cpu_per_quiet_event_sizes']} sizes")
        lines += ["", text + " (least squares in log-log)."]
    return "\n".join(lines)


def _shown(path) -> str:
    """``path`` relative to the checkout's root where it lies inside it (a JSON that does not name this machine)."""
    path = Path(path).resolve()
    return str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path)


def _num(value, fmt: str) -> str:
    return "-" if value is None or (isinstance(value, float) and not math.isfinite(value)) else format(value, fmt)
