"""Cost of the static engine's numerical core against specimen size (no YADE): one JSON line.

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.static_engine_cost --params params/presets/fem_coarse.toml \
        --width 31.7e-3 --height 63.4e-3 --seed 1 --breaks 20 [--creep-stress 160e6 --events 5] [--direct]

Builds the network, times the first equilibrium and follows the sequentially linear path for ``--breaks`` breaks
(or to ``--max-strain``: the static engine's ``timed_path``, a cost measurement with no stop rule) and, with
``--creep-stress``, the creep test on the static engine's plain path for ``--events`` events (``bench --static``'s
timed hold, :func:`grainfrac_yade.api.static_hold`; the ramp reported apart).  ``--direct``: every tangent of the
path factorised by SuperLU (no factor reuse), the reference for the fast path; it and ``--max-low-rank`` apply to
the path alone (the creep test runs on the engine's own solver).  Prints dofs, CPU per equilibrium, per break, per
event, equilibria per break, the solver's counters and the break sequence's hash (to compare the fast and the
direct path).
"""
from __future__ import annotations

import argparse
import json
import math
import sys

from grainfrac_yade.api import build_specimen, engine, static_hold

from .static_engine_probe import specimen_arguments, static_params


def main(argv=None):
    ap = specimen_arguments(argparse.ArgumentParser())
    ap.add_argument("--breaks", type=int, default=10**9)
    ap.add_argument("--max-strain", type=float, default=0.02)
    ap.add_argument("--events", type=int, default=5)
    ap.add_argument("--direct", action="store_true")
    ap.add_argument("--max-low-rank", type=int, help="changed contacts from a kept factor (solver default if unset)")
    ap.add_argument("--dump", help="write the path's break sequence and the creep events' times to this JSON file")
    a = ap.parse_args(argv)
    p = static_params(a)
    settings = {"reuse_factor": False} if a.direct else {}
    if a.max_low_rank is not None and not a.direct:
        settings["max_low_rank_contacts"] = a.max_low_rank
    timed = engine("static").timings.timed_path(build_specimen(p, a.seed), p, a.breaks, a.max_strain, settings)
    sequence = timed.pop("sequence", [])
    out = {"seed": a.seed, "width": a.width, "height": a.height, "direct": a.direct, **timed}
    times = []
    if a.creep_stress:
        def progress(line):     # one JSON line per event on stderr, as before
            print(json.dumps(line), file=sys.stderr, flush=True)
        hold = static_hold(p, a.seed, a.creep_stress, a.events, progress=progress)
        times = hold["times"]
        out["creep"] = {"stress_mpa": a.creep_stress / 1e6, "ramp": hold["ramp"], "events": hold["events"],
                        "failed": hold["failed"], "reason": hold["end"][:300], "lifetime_s": hold["creep_time_s"],
                        "broken": hold["broken"], "cpu_s": hold["cpu_s"], "events_cpu_s": hold["events_cpu_s"],
                        "cpu_per_event_s": hold["cpu_per_event_s"] or 0.0,
                        "equilibria_per_event": hold["equilibria_per_event"] or 0.0,
                        "cpu_per_event_equilibrium_s": hold["events_cpu_s"] / max(sum(hold["event_equilibria"]), 1),
                        "cpu_per_quiet_event_s": hold["cpu_per_quiet_event_s"], "quiet_events": hold["quiet_events"],
                        "sequence_hash": hold["sequence_hash"], "times": times[:5], "counters": hold["counters"]}
    if a.dump:
        with open(a.dump, "w") as fh:
            json.dump({"path": sequence, "creep_times": times}, fh)
    print(json.dumps(out, default=lambda x: None if isinstance(x, float) and not math.isfinite(x) else str(x)))


if __name__ == "__main__":
    main()
