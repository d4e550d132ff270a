"""What the static engine's numerical core costs, measured in the calling process (pure numpy/scipy): the hooks of
``bench --static`` (reached through the engine registry, :mod:`.engine`) and of the study scripts
``studies/static_engine_cost.py`` and ``studies/static_engine_probe.py``.

All times are the process's CPU time (``time.process_time``): what waiting for a core on a shared machine does not
inflate.  The creep holds and UCS tests that these numbers accompany are the test protocols' own
(:mod:`grainfrac_yade.protocols.creep`, :mod:`grainfrac_yade.protocols.ucs`) run on a static scene; what is here only
reads a scene's solver and path (:func:`solver_counters`, :func:`path_summary`) or times the sequentially linear
path alone for a number of breaks (:func:`timed_path`: the cost per equilibrium and per break, and the break
sequence that the fast and the plain direct solver must share).
"""
from __future__ import annotations

import dataclasses
import hashlib
import time

from ...errors import NumericalFailure
from ...grains import layout_for
from .cascade import Path
from .network import build_static_network
from .solver import Equilibrium

#: Cascades of at least this many bonds are listed by :func:`path_summary` [1].
LARGE_CASCADE = 10


def counters(eq, cpu, records, bonds) -> dict:
    """The solver's counters and the CPU per equilibrium, per break (a record: a crossing and its cascade, as the
    study page counts them) and per bond broken; ``cpu``: CPU seconds of the path timed."""
    c = eq.counters
    d = dataclasses.asdict(c)
    d.update(cpu_s=cpu, cpu_per_equilibrium_s=cpu / max(c.equilibria, 1),
             equilibria_per_break=c.equilibria / max(records, 1), cpu_per_break_s=cpu / max(records, 1),
             cpu_per_bond_s=cpu / max(bonds, 1), iterations_per_equilibrium=c.iterations / max(c.equilibria, 1))
    return d


def sequence_hash(records) -> tuple:
    """Hash of the break sequence (canonical bond numbers in order) and its length."""
    seq = [int(k) for r in records for k in r.bonds]
    return hashlib.sha1(repr(seq).encode()).hexdigest()[:12], len(seq)


def solver_counters(scene) -> dict:
    """The equilibrium solver's counters of a static ``scene`` so far (equilibria, active-set iterations,
    factorisations, solves, their CPU, ...), by name."""
    return dataclasses.asdict(scene.eq.counters)


def path_summary(scene) -> dict:
    """What a static ``scene``'s path recorded (and its network's dofs): its breaks (records: a crossing and its cascade), the bonds broken
    along them, the break sequence's hash, the largest platen stress at which a bond reached its strength (with
    its axial strain), the largest cascade and every cascade of :data:`LARGE_CASCADE` bonds or
    more as (axial strain, bonds, platen stress before and after [Pa])."""
    recs, height = scene.path.records, scene.net.height
    h, n = sequence_hash(recs)
    sizes = [len(r.bonds) for r in recs]
    top = max(recs, key=lambda r: r.stress_before, default=None)
    return {"dofs": scene.net.ndof, "records": len(recs), "bonds": n, "sequence_hash": h, "largest_cascade": max(sizes, default=0),
            "largest_stress_before_break": (top.stress_before, top.closure / height) if top else (None, None),
            "large_cascades": [(r.closure / height, len(r.bonds), r.stress_before, r.stress_after)
                               for r in recs if len(r.bonds) >= LARGE_CASCADE]}


def sequence(records) -> list:
    """(bonds, stress before, stress after [Pa]) of every record: what a comparison of two paths reads."""
    return [([int(k) for k in r.bonds], r.stress_before, r.stress_after) for r in records]


def timed_path(specimen, params, breaks: int, max_strain: float, settings=None) -> dict:
    """The sequentially linear path of ``specimen``'s static network from the intact state in the platen closure,
    for ``breaks`` records or to ``max_strain`` (no stop rule, no peak: a cost measurement), timed.  ``settings``:
    keyword arguments of :class:`.solver.Equilibrium` (``reuse_factor=False``: the plain direct solver;
    ``max_low_rank_contacts``).  Returns the network's size and build CPU, the first equilibrium's CPU, where the
    path stopped, the solver's counters with the CPU per equilibrium and per break, the sequence's hash and the
    sequence itself (``sequence``)."""
    t0 = time.process_time()
    net = build_static_network(specimen, params, layout_for(specimen, params))
    out = {"bonds": net.n_bonds, "dofs": net.ndof, "build_cpu_s": time.process_time() - t0}
    eq = Equilibrium(net, **(settings or {}))
    t1 = time.process_time()
    state = eq.initial(0.0)
    out["first_equilibrium_cpu_s"] = time.process_time() - t1
    if breaks <= 0:
        return out
    path = Path(eq)
    t2 = time.process_time()
    end = "max strain or break count"
    try:
        state = path.run_closure(state, max_strain * net.height, stop=lambda s_, rec: len(rec) >= breaks)
    except NumericalFailure as exc:        # reported with the path so far
        state, end = path.last_state or state, f"numerical failure: {exc}"[:300]
    cpu = time.process_time() - t2
    nb = sum(len(r.bonds) for r in path.records)
    out["path"] = {"breaks": nb, "records": len(path.records), "strain": state.closure / net.height,
                   "stress_mpa": state.stress / 1e6, "end": end, "sequence_hash": sequence_hash(path.records)[0],
                   **counters(eq, cpu, len(path.records), nb)}
    out["sequence"] = sequence(path.records)
    return out
