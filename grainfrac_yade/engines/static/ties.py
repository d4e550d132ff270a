"""The static engine's discrete decisions on floating-point numbers, made so that round-off cannot flip them (pure).

Two machines compute the same state only to round-off: numpy picks its SIMD kernels when it is imported (with and
without AVX-512, ``tan`` and ``sin`` differ in the last bit, and with them every bond's stiffness and friction
coefficient) and OpenBLAS picks its kernels per CPU (sums in another order).  Measured on 4 x 8 mm (rigid cells,
seed 4) between OpenBLAS's Cooperlake and Haswell kernels: the platen stress along the path 1.1e-14 apart (median),
1.7e-12 at most.  A decision that compares two such numbers exactly (the most overstressed of two bonds, a contact's
normal gap with zero) flips where they are that close, and one flip changes the path from there on.  Every decision
of the engine is therefore one of three kinds:

* **a tie rule**: values within :data:`DECISION_REL_TOL` of the largest (relative to it) are equal, and the tie goes
  to the first bond in the network's canonical order (:func:`first_of_largest`, :func:`ranked`).  The canonical order
  is by contact point, then the two nodes' positions (:func:`canonical_order`), each coordinate rounded to
  :data:`DECISION_REL_TOL` of the points' extent (the leftmost first, then the lowest): numbering-free and round-off
  free, never an input numbering;
* **a threshold with memory** (hysteresis): a contact keeps its status (open or closed, stick or slip) while it is
  within :data:`DECISION_REL_TOL` of its switching point, in force (:func:`.contacts.trial_status`);
* **a test with a measured gap**: what it separates lies orders of magnitude apart on both sides of its threshold
  (a singular factor's pivots, :data:`.solver.PIVOT_RATIO`; a singular update's capacitance,
  :data:`.tangent.CAPACITANCE_PIVOT_RATIO`; the load on a mechanism, :data:`.solver.LOADED_MECHANISM`), each stated
  where it is defined.

1e-9 lies three orders of magnitude above the largest round-off measured between two CPUs and is the resolution the
path finds bond crossings at anyway (:data:`.cascade.BRACKET_TOL`): two bonds whose ratios differ by less reach their
strength at the same closure to the path's resolution.  What remains is a knife edge of probability ~ round-off /
tolerance per decision (a value within round-off of a tolerance's edge).  tests/test_static_roundoff.py runs a path
and a creep hold with every bond's stiffness and strength changed at round-off and asserts the same breaks and end.
Not covered: a contact next to an unloaded mechanism (a cell held only by the solver's ground springs) moves with the
solve's round-off over those springs, ~1e-3 of the largest contact force, and its status with it
(docs/studies/paper_static.md, "Across CPUs").
"""
from __future__ import annotations

import numpy as np

#: Relative tolerance of the static engine's ties and thresholds [1] (module doc): values closer than this, relative
#: to the scale named where it is used, are equal.
DECISION_REL_TOL = 1e-9


def first_of_largest(values: np.ndarray, candidates: np.ndarray) -> int:
    """The candidate (a canonical bond number) with the largest ``values[candidate]``; values within
    :data:`DECISION_REL_TOL` of the largest (relative to it) are tied and the first in canonical order wins; among
    infinite largest values, the first infinite one."""
    r = values[candidates]
    top = r.max()
    tied = candidates[r >= top - DECISION_REL_TOL * abs(top)] if np.isfinite(top) else candidates[np.isinf(r)]
    return int(tied.min())


def ranked(values: np.ndarray, candidates: np.ndarray) -> np.ndarray:
    """``candidates`` by decreasing ``values[candidate]`` (finite, >= 0), values counted in steps of
    :data:`DECISION_REL_TOL` of the largest, equal steps in canonical order."""
    v = values[candidates]
    top = float(v.max(initial=0.0))
    level = np.floor(v / (DECISION_REL_TOL * top)) if top > 0 else np.zeros(len(v))
    return candidates[np.lexsort((candidates, -level))]


def canonical_order(point: np.ndarray, first_node_pos: np.ndarray, second_node_pos: np.ndarray) -> np.ndarray:
    """Bond order by contact point (x, then y), then by the first and the second node's positions (fem bonds of two
    faces meeting at a corner share the point and may share a node), every coordinate rounded to
    :data:`DECISION_REL_TOL` of the contact points' extent: numbering-free, and the same for coordinates a round-off
    apart."""
    pts = np.asarray(point, float)[:, :2]
    extent = float(np.ptp(pts, axis=0).max()) if len(pts) else 0.0
    grid = DECISION_REL_TOL * extent if extent > 0 else 1.0
    key = [np.round(np.asarray(a, float)[:, :2] / grid) for a in (pts, first_node_pos, second_node_pos)]
    return np.lexsort((key[2][:, 1], key[2][:, 0], key[1][:, 1], key[1][:, 0], key[0][:, 1], key[0][:, 0]))
