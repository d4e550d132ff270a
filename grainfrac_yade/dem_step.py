"""The critical-step arithmetic that every grain model shares (pure numpy; no YADE).

A DEM step is stable when it is shorter than every body's own oscillation period: the bound is the
conservative one of each body on its own, sqrt(m / K) and, for bodies that rotate, sqrt(I / K_rot)
(:func:`oscillation_steps`); each grain model of :mod:`grainfrac_yade.grains` says what its bodies,
their masses and their stiffnesses are, and YADE's scene sets the same masses and
``numerics.timestep_safety`` x the same step.  ``numerics.step_floor_quantile`` raises the masses of
the cells whose own step is shortest (:func:`lift_short_steps`).
"""
from __future__ import annotations

import numpy as np

from .layout import step_floor_factors


def oscillation_steps(n_bodies: int, ends: np.ndarray, k: np.ndarray, lever_sq: np.ndarray,
                      mass: np.ndarray, inertia: np.ndarray) -> np.ndarray:
    """(n_bodies,) the smaller of sqrt(m/K) and sqrt(I/K_rot) of each body, for springs of stiffness ``k``
    joining ``ends`` (c, 2).

    K sums k over a body's springs, K_rot sums k x ``lever_sq`` ((2c,): the first ends' squared
    lever arms, then the second ends').
    """
    k_body = np.bincount(ends.ravel(), weights=np.repeat(k, 2), minlength=n_bodies)
    with np.errstate(divide="ignore"):
        t_trans = np.sqrt(mass / k_body)
        k_rot = np.bincount(np.concatenate([ends[:, 0], ends[:, 1]]), weights=np.tile(k, 2) * lever_sq,
                            minlength=n_bodies)
        t_rot = np.sqrt(inertia / k_rot)
    return np.minimum(t_trans, t_rot)


def cell_steps(body_step: np.ndarray, body_cell: np.ndarray, n_cells: int) -> np.ndarray:
    """(n_cells,) the smallest own step of each cell's bodies [s]."""
    steps = np.full(n_cells, np.inf)
    np.minimum.at(steps, body_cell, body_step)
    return steps


def lift_short_steps(quantile: float, body_step: np.ndarray, body_cell: np.ndarray, mass: np.ndarray,
                     inertia: np.ndarray) -> tuple:
    """Per-body ``mass`` and ``inertia`` with ``numerics.step_floor_quantile`` applied: every body of a cell
    whose smallest own step (``body_step``, bodies of cell ``body_cell``) lies below the quantile of the
    cells' steps is made heavier by the cell's :func:`grainfrac_yade.layout.step_floor_factors`."""
    n_cells = int(body_cell.max()) + 1
    f = step_floor_factors(cell_steps(body_step, body_cell, n_cells), quantile)[body_cell]
    return mass * f, inertia * f
