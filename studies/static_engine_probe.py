"""Probe of the static engine's numerical core on one specimen: UCS path, cost, geometry (no YADE).

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.static_engine_probe --width 10e-3 --height 20e-3 --seed 1 \
        [--params params/presets/fem.toml] [--creep-stress 160e6] [--time-limit 1e13]

Prints one JSON line: the path's peak, where it ended, E, bonds broken, CPU split (factorisations, solves),
equilibria and active-set iterations per break; the geometry at the strains of the YADE peaks (largest slip of
broken contacts over the bond's share of its face, largest rotation of a rigid cell) and, with --creep-stress,
a creep hold's lifetime, events and CPU per event.
"""
from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np

from grainfrac_yade.clocks import EventClock
from grainfrac_yade.grains import layout_for
from grainfrac_yade.law import build_law
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.engines.static.cascade import Path
from grainfrac_yade.engines.static.creep import creep_hold
from grainfrac_yade.engines.static.failure import FailureRule
from grainfrac_yade.engines.static.network import build_static_network
from grainfrac_yade.engines.static.solver import MAX_ACTIVE_SET_ITERATIONS, STATUS_CHANGES_PER_ITERATION, Equilibrium
from grainfrac_yade.engines.static.ucs import ucs_path

#: Axial strains at which the geometry is read [1]: around the YADE peaks of 10 x 20 mm seed 1 (fem 0.38 %,
#: docs/studies/paper_fem/mesh/ucs_runs.csv) and beyond.
#: Cascades of at least this many bonds are listed [1].
CASCADE_REPORT = 10
PROBE_STRAINS = (0.002, 0.003, 0.004, 0.005, 0.01, 0.02)


def geometry(eq, state):
    n = eq.net
    b = state.broken
    ds = n.ct @ state.u
    share = n.area / n.thickness
    slip = float(np.max(np.abs(ds[b]) / share[b])) if b.any() else 0.0
    rot = n.dofs[:, 2]
    theta = float(np.abs(state.u[rot[rot >= 0]]).max()) if (rot >= 0).any() else 0.0
    return {"strain": state.closure / n.height, "stress_mpa": state.stress / 1e6, "broken": int(b.sum()),
            "max_shear_disp_over_bond_length": slip, "max_cell_rotation_rad": theta}


def specimen_arguments(ap):
    """The arguments both static-engine study scripts take: parameter files, specimen size and seed, creep stress."""
    ap.add_argument("--params", action="append", default=[])
    ap.add_argument("--width", type=float, default=10e-3)
    ap.add_argument("--height", type=float, default=20e-3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--creep-stress", type=float)
    ap.add_argument("--time-limit", type=float, default=1e13)
    ap.add_argument("--set", action="append", default=[])
    return ap


def specimen_layout(a):
    """(parameters, specimen, layout, static network) of the parsed ``specimen_arguments`` (files, size, seed,
    --set)."""
    p = load_parameters(extra_files=a.params,
                        overrides=[f"specimen.width={a.width}", f"specimen.height={a.height}"] + a.set)
    s = build_specimen(p, a.seed)
    lay = layout_for(s, p)
    return p, s, lay, build_static_network(s, p, lay)


def specimen_network(a):
    """(parameters, static network) of the parsed ``specimen_arguments`` (files, size, seed, --set)."""
    p, _, _, net = specimen_layout(a)
    return p, net


def main(argv=None):
    ap = specimen_arguments(argparse.ArgumentParser())
    ap.add_argument("--max-strain", type=float)
    ap.add_argument("--skip-ucs", action="store_true")
    ap.add_argument("--changes-per-iteration", type=int, default=STATUS_CHANGES_PER_ITERATION)
    ap.add_argument("--max-iterations", type=int, default=MAX_ACTIVE_SET_ITERATIONS)
    ap.add_argument("--max-events", type=int, default=2000)
    ap.add_argument("--direct", action="store_true", help="the plain direct path (every tangent factorised)")
    a = ap.parse_args(argv)
    size = [f"specimen.width={a.width}", f"specimen.height={a.height}"]
    p = load_parameters(extra_files=a.params, overrides=size + a.set)
    t0 = time.process_time()
    s = build_specimen(p, a.seed)
    lay = layout_for(s, p)
    net = build_static_network(s, p, lay)
    settings = {"changes_per_iteration": a.changes_per_iteration, "max_iterations": a.max_iterations,
                "reuse_factor": not a.direct}
    eq = Equilibrium(net, **settings)
    out = {"grain_model": lay.model, "seed": a.seed, "bonds": net.n_bonds, "dofs": net.ndof,
           "build_cpu_s": time.process_time() - t0}
    path = Path(eq)
    probes, todo = [], list(PROBE_STRAINS)
    orig = path.step

    def step(state, target=None, max_closure=math.inf):
        new, what = orig(state, target, max_closure)
        while todo and new.closure / net.height >= todo[0]:
            probes.append(geometry(eq, new))
            todo.pop(0)
        return new, what
    path.step = step
    if a.skip_ucs:
        a.max_strain = 1e-12
    t1 = time.process_time()
    r = ucs_path(eq, a.max_strain or p.ucs.max_strain, p.ucs.stop_stress_ratio, path=path)
    cpu = time.process_time() - t1
    c = eq.counters
    breaks = max(len(path.records), 1)
    cascade = [len(x.bonds) for x in path.records]
    out["ucs"] = {"peak_mpa": r.peak_stress / 1e6, "peak_strain": r.peak_strain, "young_gpa": r.young / 1e9,
                  "end": r.end[:300], "broken_end": int(r.broken[-1]) if len(r.broken) else 0,
                  "broken_at_peak": r.broken_at_peak, "breaks": len(path.records),
                  "largest_cascade": max(cascade) if cascade else 0, "cpu_s": cpu,
                  "equilibria": c.equilibria, "active_set_iterations": c.iterations,
                  "factorisations": c.factorisations, "solves": c.solves, "factor_cpu_s": c.factor_seconds,
                  "solve_cpu_s": c.solve_seconds, "splits": c.splits,
                  "cpu_per_equilibrium_s": cpu / max(c.equilibria, 1),
                  "iterations_per_equilibrium": c.iterations / max(c.equilibria, 1),
                  "equilibria_per_break": c.equilibria / breaks, "cpu_per_break_s": cpu / breaks}
    out["geometry"] = probes
    #: cascades of CASCADE_REPORT or more bonds: (strain, bonds, stress before and after [MPa])
    out["large_cascades"] = [(x.closure / net.height, len(x.bonds), x.stress_before / 1e6, x.stress_after / 1e6)
                             for x in path.records if len(x.bonds) >= CASCADE_REPORT]
    if a.creep_stress:
        eq2 = Equilibrium(net, **settings)
        law = build_law(p.stress_corrosion)
        clock = EventClock(p.stress_corrosion.max_strength_loss_fraction, a.time_limit)
        t2 = time.process_time()
        res = creep_hold(eq2, law, clock, a.creep_stress, FailureRule(p.creep.collapse_strain_increment),
                         max_events=a.max_events)
        cpu2 = time.process_time() - t2
        per_event = np.diff([0] + res.broken_counts)
        c2 = eq2.counters
        out["creep"] = {"stress_mpa": a.creep_stress / 1e6, "failed": res.failed, "reason": res.reason[:300],
                        "lifetime_s": res.lifetime, "events": res.events, "broken": res.broken, "cpu_s": cpu2,
                        "cpu_per_event_s": cpu2 / max(res.events, 1), "equilibria": c2.equilibria,
                        "active_set_iterations": c2.iterations, "factorisations": c2.factorisations,
                        "splits": c2.splits, "final_strain": res.strains[-1] if res.strains else None,
                        "iterations_per_equilibrium": c2.iterations / max(c2.equilibria, 1),
                        "equilibria_per_event": c2.equilibria / max(res.events, 1),
                        "factor_cpu_s": c2.factor_seconds, "solve_cpu_s": c2.solve_seconds,
                        "bonds_per_event_p50_max": [float(np.median(per_event)), int(np.max(per_event))]
                        if res.events else None,
                        "events_log": list(zip(res.times, res.strains, res.broken_counts))[::max(1, res.events // 30)]}
    print(json.dumps(out))


if __name__ == "__main__":
    main()
