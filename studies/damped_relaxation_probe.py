"""A creep test on the static engine whose regains relax by overdamped implicit steps where the static statuses do
not settle (``numerics.static_relaxation = "overdamped"``), or on its plain path (``--plain``): one JSON line (no
YADE).

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.damped_relaxation_probe --params params/presets/fem_coarse.toml \
        --width 10e-3 --height 20e-3 --seed 1 --creep-stress 160e6 [--plain] [--events N]

The creep protocol (``bench --static``'s timed hold, :func:`grainfrac_yade.api.static_hold`) for at most ``--events``
events.  ``--plain``: the plain static path (a status set that does not settle ends the hold as a numerical
failure); ``--max-steps``: ``numerics.static_relaxation_steps`` (pseudo-time steps of one relaxation).

What a change of the core must keep is in the line's hashes: ``break_sha256`` of the path's break sequence (bonds
in the order they broke) with the count reached after each event, and ``creep_times_sha256`` of the events' creep
times to full precision; ``cpu_per_event_blocks`` is the mean CPU per event [s] over each block of
:data:`CPU_BLOCK` events (the law's step, the cascade and the regain after it).
"""
from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time

import numpy as np

from grainfrac_yade.api import static_hold

from .static_engine_probe import specimen_arguments, static_params

#: Events per block of the CPU-per-event list [1].
CPU_BLOCK = 50
#: Events between two progress lines on stderr [1].
PROGRESS_EVENTS = 50


def sha256(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


def main(argv=None):
    ap = specimen_arguments(argparse.ArgumentParser())
    ap.add_argument("--max-steps", type=int, help="numerics.static_relaxation_steps (default: the parameters')")
    ap.add_argument("--events", type=int, default=10**6)
    ap.add_argument("--plain", action="store_true", help="the plain static path, no relaxation")
    a = ap.parse_args(argv)
    t0 = time.process_time()
    extra = [] if a.plain else ["numerics.static_relaxation=overdamped"]
    if a.max_steps is not None:
        extra.append(f"numerics.static_relaxation_steps={a.max_steps}")
    p = static_params(a, *extra)

    def progress(e):
        if e["event"] % PROGRESS_EVENTS == 0:
            print(json.dumps(e), file=sys.stderr, flush=True)
    hold = static_hold(p, a.seed, a.creep_stress, a.events, progress=progress)
    per = np.asarray(hold["event_cpu_s"])
    counts = (hold["ramp"]["broken"] + np.cumsum(hold["event_broken"])).astype(int).tolist()
    print(json.dumps({
        "seed": a.seed, "width": a.width, "height": a.height, "dofs": hold["dofs"], "bonds": hold["bonds"],
        "relaxing": not a.plain, "stress_pa": a.creep_stress, "events": hold["events"], "failed": hold["failed"],
        "numerical_failure": hold["numerical_failure"], "end": hold["end"], "creep_time_s": hold["creep_time_s"],
        "broken": hold["broken"], "cpu_s": time.process_time() - t0, "ramp": hold["ramp"],
        "engine_keys": hold["engine_keys"], "equilibria": hold["counters"]["equilibria"],
        "break_sha256": sha256(json.dumps([hold["sequence_hash"], counts])),
        "creep_times_sha256": sha256(" ".join(repr(t) for t in hold["times"])),
        "cpu_per_event_blocks": [float(np.mean(per[i:i + CPU_BLOCK])) for i in range(0, len(per), CPU_BLOCK)],
        "counters": hold["counters"]}))


if __name__ == "__main__":
    main()
