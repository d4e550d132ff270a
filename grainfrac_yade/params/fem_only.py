"""Parameters that only fem cells give a meaning: refused in one line with rigid cells (or without what they act on)."""
from __future__ import annotations

from typing import Mapping

from ..errors import ParameterError


def check_fem_only(res, numerics, origins: Mapping):
    """Radial rings refine the triangle mesh of fem cells (a rigid cell has no mesh to refine; one ring none to
    grade); the static condensation of the cells' interior nodes needs cells with interior nodes (a rigid cell is
    one node, a bond node)."""
    if res.cell_rings > 1 and res.grain_model != "fem":
        raise ParameterError(origins.get("resolution.cell_rings", "parameters"), "resolution.cell_rings",
                             f"{res.cell_rings} with resolution.grain_model = {res.grain_model!r}: rings refine the "
                             "triangle mesh of fem cells, a rigid cell has none",
                             "set resolution.cell_rings = 1, or resolution.grain_model = \"fem\" "
                             "(params/presets/fem.toml)")
    if res.cell_ring_growth != 1.0 and res.cell_rings == 1:
        raise ParameterError(origins.get("resolution.cell_ring_growth", "parameters"), "resolution.cell_ring_growth",
                             f"{res.cell_ring_growth:g} with resolution.cell_rings = 1: the grading spaces the rings "
                             "of a cell, one ring (the fan of triangles) has none to space",
                             "set resolution.cell_rings >= 2, or resolution.cell_ring_growth = 1")
    if numerics.static_condensation != "none" and res.grain_model != "fem":
        raise ParameterError(origins.get("numerics.static_condensation", "parameters"), "numerics.static_condensation",
                             f"{numerics.static_condensation!r} with resolution.grain_model = {res.grain_model!r}: "
                             "it condenses out the interior nodes of fem cells, a rigid cell has none",
                             "set numerics.static_condensation = \"none\", or resolution.grain_model = \"fem\" "
                             "(params/presets/fem.toml)")
