"""Probe of the static engine on one specimen: the UCS test on its plain path, its cost, and a creep test (no YADE).

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.static_engine_probe --width 10e-3 --height 20e-3 --seed 1 \
        [--params params/presets/fem_coarse.toml] [--max-strain 0.008] [--creep-stress 160e6] [--time-limit 1e13]

The UCS protocol (:func:`grainfrac_yade.api.run_ucs`) on the static engine's plain path (``numerics.engine =
"static"``, ``numerics.static_relaxation = "none"``: a status set that does not settle ends the test as a numerical
failure; ``--set`` wins over both), to ``--max-strain`` (``ucs.max_strain``).  Prints one JSON line: the largest
platen stress of the history and, exact, the largest stress at which a bond reached its strength (the path's
breaks), their strains, the stress at the strains of :data:`PROBE_STRAINS`, how the test ended, E (the first
row's secant), bonds broken, the solver's counters (CPU split, equilibria and active-set iterations per break),
the cascades of 10 bonds or more; with --creep-stress, the creep test on the same plain path (``bench --static``'s
timed hold, :func:`grainfrac_yade.api.static_hold`): lifetime or end, events, CPU per event.
"""
from __future__ import annotations

import argparse
import json
import time

import numpy as np

from grainfrac_yade.api import build_specimen, engine, load_parameters, run_ucs, static_hold

#: Axial strains at which the stress is read [1]: around the YADE peaks of 10 x 20 mm (fem 0.38-0.46 %).
PROBE_STRAINS = (0.002, 0.003, 0.004)
#: The static engine's plain path (overridable with --set).
PLAIN_STATIC = ("numerics.engine=static", "numerics.static_relaxation=none")


def specimen_arguments(ap):
    """The arguments the static-engine study scripts take: parameter files, specimen size and seed, creep stress."""
    ap.add_argument("--params", action="append", default=[])
    ap.add_argument("--width", type=float, default=10e-3)
    ap.add_argument("--height", type=float, default=20e-3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--creep-stress", type=float)
    ap.add_argument("--time-limit", type=float, default=1e13)
    ap.add_argument("--set", action="append", default=[])
    return ap


def static_params(a, *extra):
    """Parameters of the parsed ``specimen_arguments`` on the static engine's plain path (files, size, ``extra``
    overrides, then --set: the user's win)."""
    return load_parameters(extra_files=a.params,
                           overrides=[f"specimen.width={a.width}", f"specimen.height={a.height}", *PLAIN_STATIC,
                                      f"stress_corrosion.creep_time_limit={a.time_limit}", *extra, *a.set])


def ucs_probe(p, seed) -> dict:
    """The UCS test of ``p`` (module doc) as the probe's JSON reports it."""
    t0 = time.process_time()
    specimen = build_specimen(p, seed)
    cols, result, scene, _ = run_ucs(specimen, p)
    cpu = time.process_time() - t0
    static = engine(p.numerics.engine)
    c, path = static.timings.solver_counters(scene), static.timings.path_summary(scene)
    strain, stress = np.asarray(cols["axial_strain"]), np.asarray(cols["axial_stress_pa"])
    k = int(np.argmax(stress)) if len(stress) else 0
    breaks = max(path["records"], 1)
    return {"bonds": scene.n_bonds, "dofs": path["dofs"],
            "largest_row_stress_mpa": float(stress[k]) / 1e6 if len(stress) else None,
            "largest_row_strain": float(strain[k]) if len(strain) else None,
            "largest_stress_at_a_break_mpa": path["largest_stress_before_break"][0] / 1e6,
            "largest_stress_at_a_break_strain": path["largest_stress_before_break"][1],
            "stress_at_mpa": {f"{e:g}": float(np.interp(e, strain, stress)) / 1e6 if len(strain) and strain[-1] >= e
                              else None for e in PROBE_STRAINS},
            "young_gpa": float(stress[0] / strain[0]) / 1e9 if len(strain) and strain[0] > 0 else None,
            "end": result["end_reason"][:300], "numerical_failure": result["numerical_failure"],
            "broken_end": int(scene.broken.sum()), "broken_at_largest_row": int(cols["broken_total"][k]) if len(stress) else 0,
            "breaks": path["records"], "largest_cascade": path["largest_cascade"], "cpu_s": cpu,
            "equilibria": c["equilibria"], "active_set_iterations": c["iterations"],
            "factorisations": c["factorisations"], "solves": c["solves"], "factor_cpu_s": c["factor_seconds"],
            "solve_cpu_s": c["solve_seconds"], "splits": c["splits"],
            "cpu_per_equilibrium_s": cpu / max(c["equilibria"], 1),
            "iterations_per_equilibrium": c["iterations"] / max(c["equilibria"], 1),
            "equilibria_per_break": c["equilibria"] / breaks, "cpu_per_break_s": cpu / breaks,
            #: cascades of 10 bonds or more: (strain, bonds, stress before and after [MPa])
            "large_cascades": [(e, n, sb / 1e6, sa / 1e6) for e, n, sb, sa in path["large_cascades"]]}


def main(argv=None):
    ap = specimen_arguments(argparse.ArgumentParser())
    ap.add_argument("--max-strain", type=float, help="ucs.max_strain (default: the parameters')")
    ap.add_argument("--skip-ucs", action="store_true")
    ap.add_argument("--max-events", type=int, default=2000)
    a = ap.parse_args(argv)
    extra = [f"ucs.max_strain={a.max_strain}"] if a.max_strain else []
    p = static_params(a, *extra)
    out = {"grain_model": p.resolution.grain_model, "seed": a.seed}
    if not a.skip_ucs:
        out["ucs"] = ucs_probe(p, a.seed)
    if a.creep_stress:
        hold = static_hold(p, a.seed, a.creep_stress, a.max_events)
        times = hold.pop("times")
        out["creep"] = {"stress_mpa": a.creep_stress / 1e6, "failed": hold["failed"], "reason": hold["end"][:300],
                        "lifetime_s": hold["creep_time_s"], "events": hold["events"], "broken": hold["broken"],
                        "cpu_s": hold["cpu_s"], "cpu_per_event_s": hold["cpu_per_event_s"],
                        "equilibria_per_event": hold["equilibria_per_event"],
                        "iterations_per_equilibrium": hold["iterations_per_equilibrium"],
                        "bonds_per_event_p50_max": [float(np.median(hold["event_broken"])), max(hold["event_broken"])]
                        if hold["events"] else None, "counters": hold["counters"],
                        "event_times_s": times[::max(1, len(times) // 30)]}
    print(json.dumps(out))


if __name__ == "__main__":
    main()
