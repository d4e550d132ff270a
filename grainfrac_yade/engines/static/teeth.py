"""Saw-tooth softening of the intact bonds on the static path (pure numpy): a tooth is one more event.

With ``numerics.static_softening = "sawtooth"`` every bond carries a tooth index i (0 intact, :mod:`grainfrac_yade.
softening` for the teeth).  A bond that meets paper Eq. 4-5 on tooth i < N - 1 stays intact and moves to tooth i + 1:
its k_n and k_s are multiplied by k_{i+1} / k_i and its current strengths J^T, J^C (corroded, under a creep hold) by
f_{i+1} / f_i (both modes alike; the friction angle kept).  Its force then drops at the same relative displacement
(k_{i+1} / k_i < f_{i+1} / f_i: every ratio of paper Eq. 4-5 falls below 1), and the equilibrium is solved again at
the same closure, as after a break (the bond's released force, :func:`tooth_release`).  The tangent changes in that
bond's coefficients alone, so the kept factor's key is dropped (:meth:`.factoring.KeptFactor.stiffness_changed`) and
the next tangent is one contact away from the kept reference factor: a low-rank update of it.  On its last tooth a
bond breaks as without softening.  Tooth events are counted apart from breaks (``bond_softening_events``); a
checkpoint keeps every bond's tooth, k_n and k_s (exact doubles).
"""
from __future__ import annotations

import numpy as np

from ...softening import softening_of

#: The summary's count of tooth events (breaks are counted as without softening).
EVENTS_KEY = "bond_softening_events"


class BondTeeth:
    """The teeth of every bond of ``net`` (module doc): ``factors`` = (k_i / k_0, f_i / f_0) per tooth; ``tooth`` the
    current tooth of each bond (canonical order).  The network's k_n, k_s are changed in place (the condensed
    network and every equilibrium on it share those arrays); ``equilibria`` are told when they change."""

    def __init__(self, net, factors):
        self.net = net
        self.stiffness, self.strength = (np.asarray(f, float) for f in factors)
        self.tooth = np.zeros(net.n_bonds, np.int64)
        self.events = 0
        self.equilibria = []
        #: called with (bonds, f_{i+1} / f_i) after each tooth: what keeps its own copy of the strengths (a creep
        #: test's degradation law, :class:`.engine.StaticCorrosion`) scales it alike
        self.strength_listeners = []

    def softens(self, bonds):
        """Whether each of ``bonds`` (a canonical number or an array of them) takes another tooth (rather than
        breaking) when it meets its strength."""
        return self.tooth[bonds] < len(self.stiffness) - 1

    def advance(self, bonds, jt: np.ndarray, jc: np.ndarray) -> None:
        """Move ``bonds`` (canonical numbers, each on a tooth before its last) to their next tooth: k_n, k_s of the
        network and the strengths ``jt``, ``jc`` [Pa] in place (module doc)."""
        b = np.atleast_1d(np.asarray(bonds, np.int64))
        i = self.tooth[b]
        k_ratio = self.stiffness[i + 1] / self.stiffness[i]
        f_ratio = self.strength[i + 1] / self.strength[i]
        net = self.net
        net.kn[b] *= k_ratio
        net.ks[b] *= k_ratio
        jt[b] *= f_ratio
        jc[b] *= f_ratio
        self.tooth[b] = i + 1
        self.events += len(b)
        for eq in self.equilibria:
            eq.stiffness_changed()
        for follow in self.strength_listeners:
            follow(b, f_ratio)

    def summary_keys(self) -> dict:
        return {EVENTS_KEY: int(self.events)}

    def saved_arrays(self) -> dict:
        return {"bond_tooth": self.tooth.copy(), "bond_tooth_kn": self.net.kn.copy(),
                "bond_tooth_ks": self.net.ks.copy(), "bond_tooth_events": np.int64(self.events)}

    def restore_arrays(self, arrays: dict) -> None:
        """The teeth, stiffnesses and count of :meth:`saved_arrays` (absent: a fresh run's, nothing changed)."""
        if "bond_tooth" not in arrays:
            return
        self.tooth = np.asarray(arrays["bond_tooth"], np.int64).copy()
        self.net.kn[:] = arrays["bond_tooth_kn"]
        self.net.ks[:] = arrays["bond_tooth_ks"]
        self.events = int(arrays["bond_tooth_events"])
        for eq in self.equilibria:
            eq.stiffness_changed()


def teeth_for(params, net, kept: BondTeeth | None = None) -> BondTeeth | None:
    """The run's :class:`BondTeeth` on ``net``, or None for the brittle bond (:func:`grainfrac_yade.softening.
    softening_of`); ``kept``: a path's teeth to go on with (a path rebuilt on the same network), its equilibria
    forgotten (the new path's are told from then on)."""
    if kept is not None:
        kept.equilibria = []
        return kept
    factors = softening_of(params.numerics)
    return None if factors is None else BondTeeth(net, factors)


def tooth_release(eq, state, bond: int, fn_new: float, fs_new: float) -> np.ndarray:
    """(ndof,) what ``bond`` carried in ``state`` beyond its forces ``fn_new``, ``fs_new`` [N] on its next tooth, as a
    generalised force (as :meth:`.solver.Equilibrium.release_force` for a break): the dead load a split step ramps."""
    gn, gt = (rows[[bond]] for rows in eq.summed_rows(state.broken))
    return -(gn.T @ np.array([state.fn[bond] - fn_new]) + gt.T @ np.array([state.fs[bond] - fs_new]))
