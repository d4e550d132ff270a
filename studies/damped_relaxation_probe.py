"""A static creep hold whose regains relax by overdamped implicit steps where the static statuses do not settle
(grainfrac_yade.engines.static.damped): one JSON line (no YADE).

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.damped_relaxation_probe --params params/presets/fem.toml \
        --width 10e-3 --height 20e-3 --seed 1 --creep-stress 160e6 [--plain]

``--plain``: the plain static path (a status set that does not settle ends the hold as a numerical failure).

What a change of the core must keep is in the line's hashes: ``break_sha256`` of the bonds broken, in order, with
the count reached after each event, and ``creep_times_sha256`` of the events' creep times to full precision;
``cpu_per_event_blocks`` is the mean CPU per event [s] over each block of :data:`CPU_BLOCK` events (the cascade and
the regain after the law's step).
"""
from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from dataclasses import asdict

import numpy as np

from grainfrac_yade.clocks import EventClock
from grainfrac_yade.law import build_law
from grainfrac_yade.engines.static.cascade import Path
from grainfrac_yade.engines.static.creep import creep_hold
from grainfrac_yade.engines.static.damped import MAX_RELAXATION_STEPS, REST_TOLERANCE, AnchoredEquilibrium, RelaxingPath
from grainfrac_yade.engines.static.failure import FailureRule
from grainfrac_yade.engines.static.solver import Equilibrium

from .static_engine_probe import specimen_arguments, specimen_network

#: Events per block of the CPU-per-event list [1].
CPU_BLOCK = 50


def recorded(path):
    """(bonds broken, CPU at the end of each regain): ``path``'s breaks and regains (the ramp's first) recorded."""
    bonds, cpu = [], []
    breaking, holding = path.break_bond, path.hold

    def break_bond(state, bond, mode):
        bonds.append(int(bond))
        return breaking(state, bond, mode)

    def hold(state, target, rule):
        out = holding(state, target, rule)
        cpu.append(time.process_time())
        return out
    path.break_bond, path.hold = break_bond, hold
    return bonds, cpu


def sha256(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


def main(argv=None):
    ap = specimen_arguments(argparse.ArgumentParser())
    ap.add_argument("--max-steps", type=int, default=MAX_RELAXATION_STEPS, help="pseudo-time steps of one relaxation")
    ap.add_argument("--tolerance", type=float, default=REST_TOLERANCE, help="relative unbalanced force at rest")
    ap.add_argument("--events", type=int, default=10**6)
    ap.add_argument("--plain", action="store_true", help="the plain static path, no relaxation")
    a = ap.parse_args(argv)
    t0 = time.process_time()
    p, net = specimen_network(a)
    eq = Equilibrium(net)
    anchored = AnchoredEquilibrium(net)
    path = Path(eq) if a.plain else RelaxingPath(eq, anchored, a.tolerance, max_steps=a.max_steps)
    solve = anchored.solve

    def counted(closure, base, release=None):     # a progress line every 100 anchored solves, to stderr
        out = solve(closure, base, release)
        if anchored.counters.equilibria % 100 == 0:
            print(f"anchored solves {anchored.counters.equilibria}: closure {closure:.6g} m, stress {out.stress:.6g} "
                  f"Pa, broken {int(out.broken.sum())}, CPU {time.process_time() - t0:.1f} s", file=sys.stderr,
                  flush=True)
        return out
    anchored.solve = counted
    bonds, cpu = recorded(path)
    sc = p.stress_corrosion
    clock = EventClock(sc.max_strength_loss_fraction, sc.creep_time_limit)
    res = creep_hold(eq, build_law(sc), clock, a.creep_stress, FailureRule(p.creep.collapse_strain_increment),
                     max_events=a.events, path=path)
    rel = getattr(path, "relaxations", [])
    per = np.diff(cpu)      # the events' CPU: from the end of one regain to the end of the next
    print(json.dumps({
        "seed": a.seed, "width": a.width, "height": a.height, "dofs": net.ndof, "bonds": net.n_bonds,
        "relaxing": not a.plain, "tolerance": None if a.plain else a.tolerance, "stress_pa": a.creep_stress, "events": res.events,
        "failed": res.failed, "numerical_failure": res.numerical_failure, "end": res.reason,
        "creep_time_s": res.lifetime, "broken": res.broken,
        "strain_end": res.strains[-1] if res.strains else None, "cpu_s": time.process_time() - t0,
        "relaxations": len(rel), "relaxation_steps": [r.steps for r in rel],
        "relaxation_broken": [r.broken for r in rel],
        "relaxation_failure": [r.failure for r in rel],
        "relaxation_unsettled": [r.unsettled for r in rel],
        "relaxation_closure_growth_m": [r.state.closure - r.start_closure for r in rel],
        "equilibria": eq.counters.equilibria,
        "break_sha256": sha256(json.dumps([bonds, res.broken_counts])),
        "creep_times_sha256": sha256(" ".join(repr(t) for t in res.times)),
        "cpu_per_event_blocks": [float(np.mean(per[i:i + CPU_BLOCK])) for i in range(0, len(per), CPU_BLOCK)],
        "counters": asdict(eq.counters)}))


if __name__ == "__main__":
    main()
