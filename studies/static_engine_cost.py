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
import json
import math
import sys
import time

from grainfrac_yade.errors import NumericalFailure
from grainfrac_yade.grains import layout_for
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.engines.static.bench_timing import counters, sequence_hash, timed_creep_hold
from grainfrac_yade.engines.static.cascade import Path
from grainfrac_yade.engines.static.network import build_static_network
from grainfrac_yade.engines.static.solver import Equilibrium

from .static_engine_probe import specimen_arguments


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
        def progress(line):     # one JSON line per event on stderr, as before
            print(json.dumps(line), file=sys.stderr, flush=True)
        hold = timed_creep_hold(net, p, a.creep_stress, a.events, time_limit=a.time_limit, settings=settings,
                                progress=progress)
        path2, res = hold["path"], hold["result"]
        out["creep"] = {"stress_mpa": a.creep_stress / 1e6, "ramp": hold["ramp"], "events": hold["events"],
                        "failed": res.failed, "reason": res.reason[:300], "lifetime_s": res.lifetime,
                        "broken": res.broken, "cpu_s": hold["cpu_s"], "events_cpu_s": hold["events_cpu_s"],
                        "cpu_per_event_s": hold["cpu_per_event_s"] or 0.0,
                        "equilibria_per_event": hold["equilibria_per_event"] or 0.0,
                        "cpu_per_event_equilibrium_s": hold["events_cpu_s"] / max(sum(hold["event_equilibria"]), 1),
                        "cpu_per_quiet_event_s": hold["cpu_per_quiet_event_s"], "quiet_events": hold["quiet_events"],
                        "sequence_hash": hold["sequence_hash"], "times": res.times[:5], "counters": hold["counters"]}
    if a.dump:
        with open(a.dump, "w") as fh:
            json.dump({"path": sequence(path.records) if a.breaks > 0 else [],
                       "creep": sequence(path2.records) if a.creep_stress else [],
                       "creep_times": res.times if a.creep_stress else []}, fh)
    print(json.dumps(out, default=lambda x: None if isinstance(x, float) and not math.isfinite(x) else str(x)))


if __name__ == "__main__":
    main()
