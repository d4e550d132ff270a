"""What the static engine's numerical core costs, measured in the calling process (pure numpy/scipy): the timings of
``bench --static`` (reached through the engine registry, :mod:`.engine`) and of the study script
``studies/static_engine_cost.py``.

All times are the process's CPU time (``time.process_time``): what waiting for a core on a shared machine does not
inflate.  A creep hold here is the core's own (:func:`.creep.creep_hold`: the event clock fed by static stresses,
the ramp to the held stress first), timed per event: an event is the creep law's interval to the next bond failure,
the cascade at the reached closure and the regain of the held stress (:meth:`.cascade.Path.hold`), so an event's
CPU runs from the end of one regain to the end of the next.  A *quiet* event breaks only the bonds the creep law took
to failure (the clock's count): no cascade, nothing more on the regain, what a hold costs per event when nothing
else happens.
"""
from __future__ import annotations

import hashlib
import time

import numpy as np

from ...clocks import EventClock
from ...grains import layout_for
from ...law import build_law
from .cascade import Path
from .creep import creep_hold
from .failure import FailureRule
from .network import build_static_network
from .solver import Equilibrium



def counters(eq, cpu, records, bonds) -> dict:
    """The solver's counters and the CPU per equilibrium, per break (a record: a crossing and its cascade, as the
    study page counts them) and per bond broken; ``cpu``: CPU seconds of the path timed."""
    c = eq.counters
    d = {k: getattr(c, k) for k in vars(c)}
    d.update(cpu_s=cpu, cpu_per_equilibrium_s=cpu / max(c.equilibria, 1),
             equilibria_per_break=c.equilibria / max(records, 1), cpu_per_break_s=cpu / max(records, 1),
             cpu_per_bond_s=cpu / max(bonds, 1), iterations_per_equilibrium=c.iterations / max(c.equilibria, 1))
    return d


def sequence_hash(records) -> tuple:
    """Hash of the break sequence (canonical bond numbers in order) and its length."""
    seq = [int(k) for r in records for k in r.bonds]
    return hashlib.sha1(repr(seq).encode()).hexdigest()[:12], len(seq)


def timed_network(specimen, params) -> tuple:
    """(the static network of ``specimen``, CPU seconds to build it: layout, rows, canonical order)."""
    t = time.process_time()
    net = build_static_network(specimen, params, layout_for(specimen, params))
    return net, time.process_time() - t


def timed_creep_hold(net, params, stress: float, events: int, time_limit: float | None = None, settings=None,
                     progress=None) -> dict:
    """A creep hold of ``net`` at ``stress`` [Pa] for at most ``events`` events, timed per event (module doc).

    ``params``: the law (``[stress_corrosion]``) and the failure rule (``creep.collapse_strain_increment``);
    ``time_limit``: creep time limit [s] (default ``stress_corrosion.creep_time_limit``); ``settings``: keyword
    arguments of :class:`.solver.Equilibrium` (e.g. ``reuse_factor=False``, the direct path); ``progress``: called
    with a dict after the ramp (event 0) and after each event.  Returns the ramp's cost, the hold's end, per-event
    lists (``event_cpu_s``, ``event_equilibria``, ``event_iterations``, ``event_broken``), their means, the CPU per
    quiet event (module doc; None without one), the solver's counters and the path itself
    (``path``, ``result``: not JSON; the caller drops them)."""
    eq = Equilibrium(net, **(settings or {}))
    path = Path(eq)
    law = build_law(params.stress_corrosion)
    sc = params.stress_corrosion
    clock = EventClock(sc.max_strength_loss_fraction, sc.creep_time_limit if time_limit is None else time_limit)
    marks = []   # (cpu, equilibria, iterations, broken, law's failures, strain) at the end of the ramp and each regain
    hold = path.hold

    def timed_hold(state, target, rule):
        out = hold(state, target, rule)
        c = eq.counters
        marks.append((time.process_time(), c.equilibria, c.iterations, int(out[0].broken.sum()), clock.n_failures,
                      out[0].closure / net.height))
        if progress is not None:
            progress({"event": len(marks) - 1, "cpu_s": marks[-1][0] - t0, "creep_time_s": clock.creep_time,
                      "broken": marks[-1][3], "strain": marks[-1][5], "equilibria": c.equilibria})
        return out

    path.hold = timed_hold
    t0 = time.process_time()
    res = creep_hold(eq, law, clock, stress, FailureRule(params.creep.collapse_strain_increment), max_events=events,
                     path=path)
    cpu = time.process_time() - t0
    if not marks:   # the ramp itself gave up (numerical failure): nothing timed
        marks.append((time.process_time(), eq.counters.equilibria, eq.counters.iterations, res.broken,
                      clock.n_failures, float("nan")))
    m = np.array(marks, float)
    ramp = {"cpu_s": m[0, 0] - t0, "equilibria": int(m[0, 1]), "iterations": int(m[0, 2]), "broken": int(m[0, 3]),
            "strain": m[0, 5]}
    d = np.diff(m[:, :5], axis=0)
    cpu_ev, eqs, its, broken, law_failed = d[:, 0], d[:, 1], d[:, 2], d[:, 3], d[:, 4]
    quiet = broken <= law_failed
    n = len(d)

    def mean(x):
        return float(x.mean()) if len(x) else None
    return {
        "stress_pa": stress, "ramp": ramp, "events": n, "events_asked": events, "failed": bool(res.failed),
        "numerical_failure": bool(res.numerical_failure), "end": res.reason or "events asked", "broken": res.broken,
        "creep_time_s": res.lifetime, "cpu_s": cpu, "events_cpu_s": float(cpu_ev.sum()),
        "cpu_per_event_s": mean(cpu_ev), "equilibria_per_event": mean(eqs), "iterations_per_event": mean(its),
        "iterations_per_equilibrium": float(its.sum() / eqs.sum()) if n and eqs.sum() else None,
        "bonds_per_event": mean(broken), "quiet_events": int(quiet.sum()), "cpu_per_quiet_event_s": mean(cpu_ev[quiet]),
        "event_cpu_s": cpu_ev.tolist(), "event_equilibria": eqs.astype(int).tolist(),
        "event_iterations": its.astype(int).tolist(), "event_broken": broken.astype(int).tolist(),
        "counters": counters(eq, cpu, len(path.records), sequence_hash(path.records)[1]),
        "sequence_hash": sequence_hash(path.records)[0], "times": list(res.times), "path": path, "result": res,
    }
