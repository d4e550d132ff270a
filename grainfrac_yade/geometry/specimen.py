"""A grain-based specimen: Voronoi cells of four minerals (paper section 3.1, Fig. 2).

Pure numpy.  ``build_specimen(params, seed)`` is deterministic: the same
parameters and seed give the same specimen, bit for bit.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from .disc import check_disc_size, n_cells_for_disc, voronoi_disc
from ..errors import GrainfracError
from .minerals import allocate_minerals, area_fractions, clump_statistics, mineral_clumps
from ..params import Parameters
from .regularise import regularise
from .tessellation import Tessellation, n_cells_for, voronoi_box


@dataclass(frozen=True)
class Specimen:
    """Voronoi cells with minerals; faces know their mineral pair."""
    tessellation: Tessellation
    mineral: np.ndarray          # (n_cells,) int index into mineral_names
    mineral_names: tuple
    clump_label: np.ndarray      # (n_cells,) mineral clump of each cell
    thickness: float             # m, layer thickness (2D) or box depth (3D)
    seed: int
    edges_collapsed: int = 0     # short Voronoi edges collapsed (specimen.min_edge_fraction)
    edges_kept_short: int = 0    # interior edges below the threshold whose collapse would spoil a cell

    @property
    def n_cells(self) -> int:
        return self.tessellation.n_cells

    @property
    def face_minerals(self) -> np.ndarray:
        """(n_faces, 2) mineral index of the two cells of each face."""
        return self.mineral[self.tessellation.face_cells]

    @property
    def face_is_inter(self) -> np.ndarray:
        """(n_faces,) True where the face joins two minerals (inter-granular contact)."""
        fm = self.face_minerals
        return fm[:, 0] != fm[:, 1]

    @property
    def face_area(self) -> np.ndarray:
        """(n_faces,) contact area of each face [m^2]: length x thickness in 2D."""
        t = self.tessellation
        return t.face_measure * self.thickness if t.dim == 2 else t.face_measure

    def area_fractions(self) -> dict:
        fr = area_fractions(self.tessellation.cell_measure, self.mineral, len(self.mineral_names))
        return {name: float(f) for name, f in zip(self.mineral_names, fr)}

    def summary(self) -> dict:
        """Plain-JSON description (cells, faces, composition, clumps)."""
        t = self.tessellation
        eq = t.equivalent_diameter()
        return {
            "dimension": t.dim,
            "box_m": [float(x) for x in t.box],
            "thickness_m": self.thickness,
            "seed": self.seed,
            "n_cells": t.n_cells,
            "n_faces": t.n_faces,
            "n_faces_inter": int(self.face_is_inter.sum()),
            "n_faces_intra": int((~self.face_is_inter).sum()),
            ("shortest_face_m" if t.dim == 2 else "smallest_face_m2"):
                float(t.face_measure.min()) if t.n_faces else None,
            "edges_collapsed": self.edges_collapsed,
            "edges_kept_short": self.edges_kept_short,
            "mean_equivalent_diameter_m": float(eq.mean()),
            "std_equivalent_diameter_m": float(eq.std()),
            "mineral_area_fractions": self.area_fractions(),
            "mineral_clumps": clump_statistics(t.cell_measure, self.mineral, self.clump_label,
                                               self.mineral_names),
        }


def specimen_from_tessellation(tess: Tessellation, mineral, names, thickness: float, seed: int = 0) -> Specimen:
    """A specimen with minerals given per cell (tests, hand-made scenes)."""
    mineral = np.asarray(mineral, dtype=np.int64)
    return Specimen(tessellation=tess, mineral=mineral, mineral_names=tuple(names),
                    clump_label=mineral_clumps(tess.face_cells, mineral), thickness=thickness, seed=seed)


#: Largest specimen seed: 2**32 - 1, the range of a 32-bit seed (numpy's ``RandomState`` and ``np.random.seed``
#: accept no more; ``default_rng`` would take any size, but a seed beyond 64 bits no longer reads back as an
#: integer from the run tables, and no study needs more than a few billion specimens).
MAX_SEED = 2**32 - 1

#: Memory one cell takes while its specimen is built [bytes]: measured 11.4-11.9 kB per cell (peak resident
#: size of build_specimen, 2,559 and 25,465 cells, 2026-12-01); the YADE scene adds to it, so this is a
#: lower bound of a run's need.
BYTES_PER_CELL = 12e3


def memory_bytes() -> float:
    """Physical memory of this machine [bytes] (inf where the system does not say)."""
    try:
        return float(os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return float("inf")


def check_cell_count(n_cells: int, what: str, grain_size: float, flags: str = "") -> None:
    """Refuse, before anything is allocated, a specimen of more cells than this machine's memory holds
    (:data:`BYTES_PER_CELL` each): one line with the cell count (``flags``: the shortcut flags that gave the
    size, named first)."""
    limit = memory_bytes() / BYTES_PER_CELL
    if n_cells > limit:
        raise GrainfracError(f"{flags + ': ' if flags else ''}specimen.grain_size = {grain_size:g} m: {what} would have {n_cells:.3g} cells, more than "
                             f"this machine's memory holds (at most {limit:.3g} cells of {BYTES_PER_CELL / 1e3:g} kB); "
                             "fix: a larger grain size or a smaller specimen (e.g. --grain-size 1e-3)")


def build_specimen(params: Parameters, seed: int) -> Specimen:
    """Tessellate the specimen of ``params.specimen``, collapse its short edges
    (``specimen.min_edge_fraction``, :mod:`grainfrac_yade.geometry.regularise`) and allocate minerals (seeded)."""
    sp = params.specimen
    box = [sp.width, sp.height] if sp.dimension == 2 else [sp.width, sp.height, sp.thickness]
    check_cell_count(n_cells_for(box, sp.grain_size), f"the {' x '.join(f'{b * 1e3:g}' for b in box)} mm specimen",
                     sp.grain_size)
    rng = np.random.default_rng(seed)
    tess, reg = regularise(voronoi_box(box, sp.grain_size, rng, sp.lloyd_iterations), sp.min_edge_fraction,
                           sp.grain_size)
    names = params.minerals
    fractions = [params.composition[m] for m in names]
    mineral = allocate_minerals(tess.cell_measure, fractions, rng)
    return Specimen(tessellation=tess, mineral=mineral, mineral_names=names,
                    clump_label=mineral_clumps(tess.face_cells, mineral), thickness=sp.thickness, seed=seed,
                    edges_collapsed=reg.edges_collapsed, edges_kept_short=reg.edges_kept_short)


def build_disc_specimen(params, seed: int, diameter: float | None = None):
    """A disc specimen of ``params`` (diameter ``params.brazilian.diameter`` unless given).

    Grain size, Lloyd iterations, edge collapse (``specimen.min_edge_fraction``), composition and mineral
    allocation as
    :func:`build_specimen` (the same rng sequence: seeds, then minerals);
    deterministic for a seed.  Plane (2D) specimens only.
    """
    sp = params.specimen
    if sp.dimension != 2:
        raise GrainfracError(f"specimen.dimension = {sp.dimension}: discs are plane (2D) specimens; fix: set "
                             "specimen.dimension = 2")
    diameter = params.brazilian.diameter if diameter is None else diameter
    check_disc_size(diameter, sp.grain_size)
    check_cell_count(n_cells_for_disc(diameter, sp.grain_size), f"the {diameter * 1e3:g} mm disc", sp.grain_size)
    rng = np.random.default_rng(seed)
    tess, reg = regularise(voronoi_disc(diameter, sp.grain_size, rng, sp.lloyd_iterations), sp.min_edge_fraction,
                           sp.grain_size)
    names = params.minerals
    mineral = allocate_minerals(tess.cell_measure, [params.composition[m] for m in names], rng)
    return Specimen(tessellation=tess, mineral=mineral, mineral_names=names,
                    clump_label=mineral_clumps(tess.face_cells, mineral), thickness=sp.thickness, seed=seed,
                    edges_collapsed=reg.edges_collapsed, edges_kept_short=reg.edges_kept_short)
