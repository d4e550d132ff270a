"""Cost of the static engine's numerical core against specimen size (no YADE): one JSON line.

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.static_engine_cost --params params/presets/fem.toml \
        --width 31.7e-3 --height 63.4e-3 --seed 1 --breaks 20 [--creep-stress 160e6 --events 5] [--direct]

Builds the network, times the first equilibrium, follows the UCS path for ``--breaks`` breaks (or to
``--max-strain``) and, with ``--creep-stress``, a creep hold for ``--events`` events (the ramp to the held stress
included, reported apart).  ``--direct``: every tangent factorised by SuperLU (no factor reuse), the reference
for the fast path.  Prints dofs, CPU per equilibrium, per break, per event, equilibria per break, the solver's
counters and the break sequence's hash (to compare the fast and the direct path).
"""
from __future__ import annotations

import argparse
import hashlib
import json
import math
import sys
import time

from grainfrac_yade.clocks import EventClock
from grainfrac_yade.errors import NumericalFailure
from grainfrac_yade.grains import layout_for
from grainfrac_yade.law import build_law
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.static.cascade import Path
from grainfrac_yade.static.creep import creep_hold
from grainfrac_yade.static.failure import FailureRule
from grainfrac_yade.static.network import build_static_network
from grainfrac_yade.static.solver import Equilibrium

from .static_engine_probe import specimen_arguments


def counters(eq, cpu, records, bonds):
    """The solver's counters and the CPU per equilibrium, per break (a record: a crossing and its cascade, as the
    study page counts them) and per bond broken."""
    c = eq.counters
    d = {k: getattr(c, k) for k in vars(c)}
    d.update(cpu_s=cpu, cpu_per_equilibrium_s=cpu / max(c.equilibria, 1),
             equilibria_per_break=c.equilibria / max(records, 1), cpu_per_break_s=cpu / max(records, 1),
             cpu_per_bond_s=cpu / max(bonds, 1), iterations_per_equilibrium=c.iterations / max(c.equilibria, 1))
    return d


def sequence_hash(records):
    """Hash of the break sequence (canonical bond numbers in order) and its length."""
    seq = [int(k) for r in records for k in r.bonds]
    return hashlib.sha1(repr(seq).encode()).hexdigest()[:12], len(seq)


def sequence(records):
    """(bonds, stress before, stress after [Pa]) of every record: what --dump writes for comparisons."""
    return [([int(k) for k in r.bonds], r.stress_before, r.stress_after) for r in records]


def main(argv=None):
    ap = specimen_arguments(argparse.ArgumentParser())
    ap.add_argument("--breaks", type=int, default=10**9)
    ap.add_argument("--max-strain", type=float, default=0.02)
    ap.add_argument("--events", type=int, default=5)
    ap.add_argument("--direct", action="store_true")
    ap.add_argument("--max-low-rank", type=int, help="changed contacts from a kept factor (solver default if unset)")
    ap.add_argument("--dump", help="write the break sequences (path and creep) to this JSON file")
    a = ap.parse_args(argv)
    p = load_parameters(extra_files=a.params,
                        overrides=[f"specimen.width={a.width}", f"specimen.height={a.height}"] + a.set)
    t0 = time.process_time()
    s = build_specimen(p, a.seed)
    net = build_static_network(s, p, layout_for(s, p))
    settings = {"reuse_factor": False} if a.direct else {}
    if a.max_low_rank is not None and not a.direct:
        settings["max_low_rank_contacts"] = a.max_low_rank
    out = {"seed": a.seed, "width": a.width, "height": a.height, "bonds": net.n_bonds, "dofs": net.ndof,
           "direct": a.direct, "build_cpu_s": time.process_time() - t0}
    eq = Equilibrium(net, **settings)
    t1 = time.process_time()
    st = eq.initial(0.0)
    out["first_equilibrium_cpu_s"] = time.process_time() - t1
    if a.breaks > 0:
        path = Path(eq)
        t2 = time.process_time()
        end = "max strain or break count"
        try:
            st = path.run_closure(st, a.max_strain * net.height, stop=lambda s_, rec: len(rec) >= a.breaks)
        except NumericalFailure as exc:        # reported with the path so far, as the probe does
            st, end = getattr(path, "last_state", st), f"numerical failure: {exc}"[:300]
        cpu = time.process_time() - t2
        nb = sum(len(r.bonds) for r in path.records)
        h, n = sequence_hash(path.records)
        out["path"] = {"breaks": nb, "records": len(path.records), "strain": st.closure / net.height,
                       "stress_mpa": st.stress / 1e6, "end": end, "sequence_hash": h, **counters(eq, cpu, len(path.records), nb)}
    if a.creep_stress:
        eq2 = Equilibrium(net, **settings)
        path2 = Path(eq2)
        law = build_law(p.stress_corrosion)
        clock = EventClock(p.stress_corrosion.max_strength_loss_fraction, a.time_limit)
        ramp = {}
        orig_hold = path2.hold

        def hold(state, target, rule):      # the first call is the ramp: time it apart
            t = time.process_time()
            r = orig_hold(state, target, rule)
            if not ramp:
                ramp.update(cpu_s=time.process_time() - t, equilibria=eq2.counters.equilibria,
                            broken=int(r[0].broken.sum()), strain=r[0].closure / net.height)
            calls[0] += 1
            print(json.dumps({"event": calls[0] - 1, "cpu_s": time.process_time() - t3, "creep_time_s": clock.creep_time,
                              "broken": int(r[0].broken.sum()), "strain": r[0].closure / net.height,
                              "equilibria": eq2.counters.equilibria}), file=sys.stderr, flush=True)
            return r
        calls = [0]
        path2.hold = hold
        t3 = time.process_time()
        res = creep_hold(eq2, law, clock, a.creep_stress, FailureRule(p.creep.collapse_strain_increment),
                         max_events=a.events, path=path2)
        cpu = time.process_time() - t3
        ev_cpu = cpu - ramp.get("cpu_s", 0.0)
        ev_eq = eq2.counters.equilibria - ramp.get("equilibria", 0)
        h, n = sequence_hash(path2.records)
        out["creep"] = {"stress_mpa": a.creep_stress / 1e6, "ramp": ramp, "events": res.events,
                        "failed": res.failed, "reason": res.reason[:300], "lifetime_s": res.lifetime,
                        "broken": res.broken, "cpu_s": cpu, "events_cpu_s": ev_cpu,
                        "cpu_per_event_s": ev_cpu / max(res.events, 1),
                        "equilibria_per_event": ev_eq / max(res.events, 1),
                        "cpu_per_event_equilibrium_s": ev_cpu / max(ev_eq, 1), "sequence_hash": h,
                        "times": res.times[:5], "counters": counters(eq2, cpu, len(path2.records), n)}
    if a.dump:
        with open(a.dump, "w") as fh:
            json.dump({"path": sequence(path.records) if a.breaks > 0 else [],
                       "creep": sequence(path2.records) if a.creep_stress else [],
                       "creep_times": res.times if a.creep_stress else []}, fh)
    print(json.dumps(out, default=lambda x: None if isinstance(x, float) and not math.isfinite(x) else str(x)))


if __name__ == "__main__":
    main()
