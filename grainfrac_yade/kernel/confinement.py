"""Confined tests, the engine-neutral part: whether a specimen survived the isotropic stage (sigma_1 = sigma_3)
that an engine brings it to (YADE: :func:`grainfrac_yade.engines.yade.confinement.consolidate`)."""
from __future__ import annotations

import numpy as np

#: Share of the bonds broken in the isotropic stage at which the specimen counts as broken apart before
#: the test proper: with half its bonds gone there is no specimen left whose strength the axial stage
#: could measure (a confinement 1e6 times too large broke all 239 bonds of a small specimen).
BROKEN_APART_FRACTION = 0.5


def broken_apart_reason(scene, stress: float, lost: str = "no strength measured") -> str:
    """"" if the specimen is intact after the isotropic stage at ``stress`` [Pa], else why it is not
    (:data:`BROKEN_APART_FRACTION` of its bonds or more broken; ``lost``: what the test cannot give then)."""
    broken, total = int(np.count_nonzero(scene.broken)), scene.n_bonds
    if total and broken >= BROKEN_APART_FRACTION * total:
        return (f"the specimen broke apart in the isotropic stage at sigma_3 = {stress / 1e6:.4g} MPa ({broken} of "
                f"{total} bonds broken before axial loading): {lost}; fix: a smaller confinement")
    return ""
