"""How many Voronoi cells a specimen's box holds at a grain size: what parameter checks and the tessellation share."""
from __future__ import annotations

import math


def cell_count(box, grain_size: float) -> float:
    """Number of cells whose mean equivalent diameter is ``grain_size``, as a float: the box's area (volume) over a
    cell's, pi d^2 / 4 (pi d^3 / 6); inf where that overflows a float (a box of 1e308 m), never an error."""
    box = [float(b) for b in box]
    cell = math.pi / 4 * grain_size**2 if len(box) == 2 else math.pi / 6 * grain_size**3
    return math.prod(box) / cell
