"""The static path's failure criterion: paper Eq. 4-5 on each bond's own stress, or on each face's resultant (pure
numpy; ``numerics.static_failure``, :mod:`grainfrac_yade.failure_criterion`).

:class:`BondFailure` (the default) is :mod:`.contacts`' per-bond criterion as it was: :func:`.contacts.overstress`,
:func:`.contacts.failing`, :func:`.contacts.crossing_increment` on every bond's own forces and area, a bond breaking
alone.

:class:`FaceFailure` evaluates the same functions on each face's resultant over its intact bonds:

    F_n = sum F_n,i,   F_s = sum F_s,i (signed),   A = sum A_i,   sigma = F_n / A,   tau = |F_s| / A,

(the bonds of one face share one tangent: the fem cells' bonds take the face's normal and join the node of the
face's first cell to one of its second, so their signed shear forces add; tests/test_static_face_failure.py checks
it on the layouts) against the face's strength J^T, J^C, phi: its bonds' common values (per face by construction:
the mineral pair's Table 2 values times the face's Weibull multiplier, :func:`grainfrac_yade.layout.bond_properties`;
a creep test with face failure corrodes them alike, as it reads the face, :func:`grainfrac_yade.failure_criterion.
reading_refusal`), or where they differ (a strength scatter per bond) their area-weighted mean.  Every bond of a face
gets the face's ratio, mode and crossing increment; when a face fails all its intact bonds break at once
(:meth:`FaceFailure.group`).  The resultant is linear in the bond forces, so the crossing increment along a straight
path is :func:`.contacts.crossing_increment` of the resultants.  A face with one intact bond is evaluated on that
bond's own numbers, so with one bond per face the two criteria give the same results to the bit.
"""
from __future__ import annotations

import numpy as np

from ...errors import GrainfracError
from ...failure_criterion import FAILURE_BOND, FAILURE_FACE
from ...law import Stresses
from . import contacts as cl


class BondFailure:
    """Paper Eq. 4-5 on each bond's own stress (module doc); ``net`` a :class:`.network.StaticNetwork` (its areas and
    friction read at each call)."""
    name = FAILURE_BOND

    def __init__(self, net):
        self.net = net

    def overstress(self, fn, fs, jt, jc, broken):
        """(ratio, mode) per bond (:func:`.contacts.overstress`)."""
        return cl.overstress(fn, fs, self.net.area, jt, jc, self.net.tan_friction)

    def modes(self, fn, fs, jt, jc, broken, idx):
        """The failure modes of bonds ``idx``."""
        n = self.net
        return cl.overstress(fn[idx], fs[idx], n.area[idx], jt[idx], jc[idx], n.tan_friction[idx])[1]

    def failing(self, fn, fs, jt, jc, broken):
        """Bonds at their strength (:func:`.contacts.failing`)."""
        return cl.failing(fn, fs, self.net.area, jt, jc, self.net.tan_friction)

    def crossing_increment(self, fn0, fs0, fn1, fs1, jt, jc, broken):
        """Per bond, the control increment to its strength (:func:`.contacts.crossing_increment`)."""
        return cl.crossing_increment(fn0, fs0, fn1, fs1, self.net.area, jt, jc, self.net.tan_friction)

    def group(self, bond: int, broken) -> np.ndarray:
        """The bonds that break with ``bond``: itself."""
        return np.array([bond], np.int64)

    def law_stresses(self, stresses, state, canon):
        """The :class:`~grainfrac_yade.law.Stresses` a degradation law's criteria read for this criterion, from the
        bonds' own ``stresses`` (layout numbers; ``state``: the path's, ``canon``: canonical number of each layout
        bond): those."""
        return stresses


class FaceFailure(BondFailure):
    """Paper Eq. 4-5 on each face's resultant, the face failing as a whole (module doc)."""
    name = FAILURE_FACE

    def __init__(self, net):
        super().__init__(net)
        face = np.asarray(net.bond_face, np.int64)
        if len(face) == 0 or face.min() < 0:
            raise GrainfracError("numerics.static_failure = \"face\": every bond needs its face (a link between "
                                 "nodes of one cell has none); fix: numerics.static_failure = \"bond\"")
        self.order = np.argsort(face, kind="stable")
        f = face[self.order]
        self.starts = np.flatnonzero(np.r_[True, f[1:] != f[:-1]])
        self.counts = np.diff(np.r_[self.starts, len(face)])
        self.of_bond = np.empty(len(face), np.int64)
        self.of_bond[self.order] = np.repeat(np.arange(len(self.starts)), self.counts)
        #: one bond of each face (the face's first in canonical order)
        self.first = self.order[self.starts]
        self._face_index = np.repeat(np.arange(len(self.starts)), self.counts)
        #: (broken mask, members) and (J^T, J^C, members, face strengths) of the last call: a relaxation's steps
        #: call with the same ones many times
        self._members_cache, self._strength_cache = None, None
        tphi = net.tan_friction
        if np.any(tphi != tphi[self.first][self.of_bond]):
            raise GrainfracError("numerics.static_failure = \"face\": the bonds of a face have different friction "
                                 "angles (a face's strength is one mineral pair's); fix: numerics.static_failure = "
                                 "\"bond\"")

    # ------------------------------------------------------------------ face resultants
    def _members(self, broken):
        """(sorted mask, single, one, area) of the bonds each face's resultant sums: its intact ones (all of them
        where none is intact), in face order; ``single``: faces with one such bond (evaluated on its own numbers),
        ``one``: where a single face's bond lies in face order; ``area``: each face's summed area."""
        broken = np.asarray(broken, bool)
        cached = self._members_cache
        if cached is not None and np.array_equal(cached[0], broken):
            return cached[1]
        intact = ~broken[self.order]
        n_intact = np.add.reduceat(intact.astype(np.int64), self.starts)
        use = intact | (n_intact == 0)[self._face_index]
        n_use = np.add.reduceat(use.astype(np.int64), self.starts)
        one = np.maximum.reduceat(np.where(use, np.arange(len(use)), -1), self.starts)
        members = (use, n_use == 1, one)
        members += (self._sum(self.net.area, members),)
        self._members_cache = (broken.copy(), members)
        return members

    def _sum(self, x, members):
        """Per face, the sum of ``x`` over its member bonds (one member: its value, exactly)."""
        use, single, one = members[:3]
        xs = np.asarray(x, float)[self.order]
        total = np.add.reduceat(np.where(use, xs, 0.0), self.starts)
        return np.where(single, xs[one], total)

    def _strengths(self, jt, jc, members):
        """Per face (J^T, J^C) of :meth:`_strength` (kept while the strengths and members stay)."""
        cached = self._strength_cache
        if (cached is not None and cached[2] is members and np.array_equal(cached[0], jt)
                and np.array_equal(cached[1], jc)):
            return cached[3]
        out = (self._strength(jt, members), self._strength(jc, members))
        self._strength_cache = (np.array(jt, float), np.array(jc, float), members, out)
        return out

    def _strength(self, j, members):
        """Per face, its member bonds' common strength, or their area-weighted mean where they differ."""
        use = members[0]
        js = np.asarray(j, float)[self.order]
        lo = np.minimum.reduceat(np.where(use, js, np.inf), self.starts)
        hi = np.maximum.reduceat(np.where(use, js, -np.inf), self.starts)
        if np.array_equal(lo, hi):
            return lo
        mean = self._sum(j * self.net.area, members) / members[3]
        return np.where(lo == hi, lo, mean)

    def resultants(self, fn, fs, jt, jc, broken):
        """Per face (F_n, F_s signed, A, J^T, J^C, tan(phi)) of its intact bonds."""
        m = self._members(broken)
        return (self._sum(fn, m), self._sum(fs, m), m[3], *self._strengths(jt, jc, m),
                self.net.tan_friction[self.first])

    def overstress(self, fn, fs, jt, jc, broken):
        r, mode = cl.overstress(*self.resultants(fn, fs, jt, jc, broken))
        return r[self.of_bond], mode[self.of_bond]

    def modes(self, fn, fs, jt, jc, broken, idx):
        return self.overstress(fn, fs, jt, jc, broken)[1][idx]

    def failing(self, fn, fs, jt, jc, broken):
        return cl.failing(*self.resultants(fn, fs, jt, jc, broken))[self.of_bond]

    def crossing_increment(self, fn0, fs0, fn1, fs1, jt, jc, broken):
        m = self._members(broken)
        f0, s0, area, jt_f, jc_f, tphi = self.resultants(fn0, fs0, jt, jc, broken)
        x = cl.crossing_increment(f0, s0, self._sum(fn1, m), self._sum(fs1, m), area, jt_f, jc_f, tphi)
        return x[self.of_bond]

    def stresses(self, fn, fs, broken):
        """(sigma, tau) [Pa] per bond: its face's resultant stresses (what the criterion reads)."""
        m = self._members(broken)
        return (self._sum(fn, m) / m[3])[self.of_bond], (np.abs(self._sum(fs, m)) / m[3])[self.of_bond]

    def law_stresses(self, stresses, state, canon):
        """The face's resultant stresses (:meth:`stresses`) in place of the bonds' own, the driving ones kept: the
        event clock then fails a face where the path does, all its bonds in one event."""
        sigma, tau = self.stresses(state.fn, state.fs, state.broken)
        c = canon[stresses.index]
        return Stresses(stresses.index, sigma[c], tau[c], stresses.rate_normal, stresses.rate_shear)

    def group(self, bond: int, broken) -> np.ndarray:
        """The intact bonds of ``bond``'s face (with ``bond``), in canonical order: they break together."""
        f = self.of_bond[bond]
        members = self.order[self.starts[f]:self.starts[f] + self.counts[f]]
        keep = ~np.asarray(broken, bool)[members] | (members == bond)
        return np.sort(members[keep])


#: The criterion of each ``numerics.static_failure``.
CRITERIA = {FAILURE_BOND: BondFailure, FAILURE_FACE: FaceFailure}


def failure_for(params, net) -> BondFailure:
    """The run's failure criterion on ``net`` (``numerics.static_failure``)."""
    return CRITERIA[params.numerics.static_failure](net)
